//! `pinfeed map … --uncertain LIST`: ensemble maps ([`pinfeed::maps::ensemble`]). Every
//! member passes at every (d, θ0 on the grid); per d and input state (all θ0, and each stable
//! state) the pooled θf give the predicted bands (smallest arcs holding 90%) and the share of the
//! circle they cover. Standard output gets the band table; unless `--no-write`, the report directory
//! (`pinfeed-out/maps/<part>/ensemble/` by default) receives `README.md` headed by the regenerating
//! command, `ensemble.json` and one figure per input state (`ensemble_all.svg`,
//! `ensemble_state0.svg`, …): the predicted θf distributions and bands against d.

use super::map::{default_out_dir_for, MapArgs};
use anyhow::Result;
use pinfeed::contact_case::maps::{run_ensemble, MapRequest};
use pinfeed::report::ensemble_report::{table, write_report, EnsembleReport};

/// Run `pinfeed map --uncertain`; `recorded` is the command line its report records.
pub fn run(args: &MapArgs, recorded: &str, uncertain: &str, req: &MapRequest) -> Result<()> {
    let quiet = args.json || args.csv || args.quiet;
    let thetas = pinfeed::maps::theta_grid(args.theta_step).map_or(0, |g| g.len());
    let total = args.members * args.d.len() * thetas;
    let bar = super::progress::bar(total as u64, "passes", quiet);
    let run = run_ensemble(
        req,
        uncertain,
        args.members,
        args.seed,
        &super::flag,
        &|| bar.inc(1),
    );
    bar.finish_and_clear();
    let run = run?;
    eprintln!(
        "computed {} members × {} d × {} θ0 = {} passes, {} distinct pushes ({}) in {:.3} s on {} threads",
        args.members,
        args.d.len(),
        run.thetas,
        run.passes,
        run.maps.pushes,
        run.fidelity.name(),
        run.elapsed_s,
        run.threads
    );
    let text = table(&run.predicted);
    crate::outln!(
        "{}  ensemble of {} members, seed {}",
        args.part,
        args.members,
        args.seed
    );
    for line in run.spec.describe() {
        crate::outln!("  {line}");
    }
    crate::out!("{text}");
    if args.no_write {
        return Ok(());
    }
    let report = EnsembleReport {
        command: recorded.to_string(),
        part: &args.part,
        uncertain: run.spec.describe(),
        members: args.members,
        seed: args.seed,
        theta_step_deg: args.theta_step,
        predicted: &run.predicted,
        draws: &run.maps.members,
    };
    let out_dir = args
        .out_dir
        .clone()
        .unwrap_or_else(|| default_out_dir_for(args).join("ensemble"));
    write_report(
        &report,
        &run.inputs,
        &text,
        &out_dir,
        args.plot_dir.as_deref(),
    )?;
    eprintln!("report written to {}", out_dir.display());
    Ok(())
}
