//! `pinfeed map … --uncertain LIST`: ensemble maps ([`pinfeed::maps::ensemble`]). Every
//! member passes at every (d, θ0 on the grid); per d and input state (all θ0, and each stable
//! state) the pooled θf give the predicted bands (smallest arcs holding 90%) and the share of the
//! circle they cover. Standard output gets the band table; unless `--no-write`, the report directory
//! (`pinfeed-out/maps/<part>/ensemble/` by default) receives `README.md` headed by the regenerating
//! command, `ensemble.json` and one figure per input state (`ensemble_all.svg`,
//! `ensemble_state0.svg`, …): the predicted θf distributions and bands against d.

use super::map::{default_out_dir_for, MapArgs};
use anyhow::{anyhow, bail, Result};
use pinfeed::geometry::Polygon;
use pinfeed::maps::ensemble::{
    ensemble_maps_observed, stable_states_deg, EnsembleSpec, InputState,
};
use pinfeed::maps::theta_grid;
use pinfeed::mechanics::Fidelity;
use pinfeed::report::ensemble_report::{table, write_report, EnsembleReport};

/// Most members of an ensemble.
pub const MAX_MEMBERS: usize = 100_000;
/// Most passes (members × d × θ0) in one command.
pub const MAX_PASSES: usize = 20_000_000;

pub fn run(
    args: &MapArgs,
    recorded: &str,
    uncertain: &str,
    model: Fidelity,
    poly: &Polygon,
) -> Result<()> {
    if args.push.support.trim() != "uniform" {
        bail!("--support: with --uncertain the support is set by `support=` in the uncertain list; leave --support at uniform");
    }
    if !(1..=MAX_MEMBERS).contains(&args.members) {
        bail!(
            "--members must lie in [1, {MAX_MEMBERS}], got {}",
            args.members
        );
    }
    let spec = EnsembleSpec::nominal(args.push.mu_c, args.push.pin_radius, model, args.push.tol)
        .with_settings(uncertain)
        .map_err(|e| anyhow!("--uncertain: {e}"))?;
    let grid = theta_grid(args.theta_step).map_err(|e| anyhow!("--theta-step: {e}"))?;
    let passes = args.members * args.d.len() * grid.len();
    if passes > MAX_PASSES {
        bail!("{} members × {} d × {} θ0 = {passes} passes; at most {MAX_PASSES} are allowed in one command", args.members, args.d.len(), grid.len());
    }
    let pool = super::validate::pool(args.threads)?;
    let started = std::time::Instant::now();
    let bar = super::progress::bar(passes as u64, "passes", args.json || args.csv || args.quiet);
    let maps = pool
        .install(|| {
            ensemble_maps_observed(
                poly,
                &spec,
                &args.d,
                &grid,
                args.seed,
                args.members,
                &|| bar.inc(1),
            )
        })
        .map_err(anyhow::Error::msg)?;
    bar.finish_and_clear();
    eprintln!(
        "computed {} members × {} d × {} θ0 = {passes} passes ({}) in {:.3} s on {} threads",
        args.members,
        args.d.len(),
        grid.len(),
        model.name(),
        started.elapsed().as_secs_f64(),
        pool.current_num_threads()
    );
    let states = stable_states_deg(poly);
    let mut inputs = vec![InputState::All];
    inputs.extend((0..states.len()).map(|index| InputState::State { index }));
    let predicted = maps.predicted(&inputs, &states);
    let text = table(&predicted);
    println!(
        "{}  ensemble of {} members, seed {}",
        args.part, args.members, args.seed
    );
    for line in spec.describe() {
        println!("  {line}");
    }
    print!("{text}");
    if args.no_write {
        return Ok(());
    }
    let report = EnsembleReport {
        command: recorded.to_string(),
        part: &args.part,
        uncertain: spec.describe(),
        members: args.members,
        seed: args.seed,
        theta_step_deg: args.theta_step,
        predicted: &predicted,
        draws: &maps.members,
    };
    let out_dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| default_out_dir_for(args).join("ensemble"));
    write_report(&report, &inputs, &text, &out_dir, args.plot_dir.as_deref())?;
    eprintln!("report written to {}", out_dir.display());
    Ok(())
}
