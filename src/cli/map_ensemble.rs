//! `pinfeed map … --uncertain LIST`: ensemble maps ([`crate::maps::ensemble`]). Every
//! member passes at every (d, θ0 on the grid); per d and input state (all θ0, and each stable
//! state) the pooled θf give the predicted bands (smallest arcs holding 90%) and the share of the
//! circle they cover. Standard output gets the band table; unless `--no-write`, the report directory
//! (`pinfeed-out/maps/<part>/ensemble/` by default) receives `README.md` headed by the regenerating
//! command, `ensemble.json` and one figure per input state (`ensemble_all.svg`,
//! `ensemble_state0.svg`, …): the predicted θf distributions and bands against d.

use super::map::{command_line, default_out_dir_for, MapArgs};
use crate::geometry::Polygon;
use crate::maps::ensemble::{
    ensemble_maps_observed, stable_states_deg, EnsembleSpec, InputState, MemberDraw, PredictedBands,
};
use crate::maps::theta_grid;
use crate::mechanics::Fidelity;
use crate::report::map_table::predicted_bands_text;
use crate::report::plot_validate::plot_band_distributions;
use crate::report::shell_word;
use crate::report::validate_report::{write_report_files, ReportHead};
use anyhow::{anyhow, bail, Context, Result};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// Most members of an ensemble.
pub const MAX_MEMBERS: usize = 100_000;
/// Most passes (members × d × θ0) in one command.
pub const MAX_PASSES: usize = 20_000_000;

/// The document `ensemble.json`.
#[derive(Debug, Serialize)]
struct EnsembleReport<'a> {
    command: String,
    part: &'a str,
    uncertain: Vec<String>,
    members: usize,
    seed: u64,
    theta_step_deg: f64,
    predicted: &'a [PredictedBands],
    draws: &'a [MemberDraw],
}

/// The regenerating command of an ensemble map.
fn ensemble_command(args: &MapArgs, uncertain: &str) -> String {
    format!(
        "{} --uncertain {} --members {} --seed {}",
        command_line(args),
        shell_word(uncertain),
        args.members,
        args.seed
    )
}

/// The band table: one line per (d, input).
fn table(predicted: &[PredictedBands]) -> String {
    let mut s = String::from(
        "| d | input | passes | predicted bands (90%) | circle covered |\n|---|---|---|---|---|\n",
    );
    for p in predicted {
        let _ = writeln!(
            s,
            "| {:+} | {} | {} | {} | {:.1}% |",
            p.d,
            p.input,
            p.passes,
            predicted_bands_text(p),
            100.0 * p.coverage
        );
    }
    s
}

pub fn run(args: &MapArgs, uncertain: &str, model: Fidelity, poly: &Polygon) -> Result<()> {
    if args.support.trim() != "uniform" {
        bail!("--support: with --uncertain the support is set by `support=` in the uncertain list; leave --support at uniform");
    }
    if !(1..=MAX_MEMBERS).contains(&args.members) {
        bail!(
            "--members must lie in [1, {MAX_MEMBERS}], got {}",
            args.members
        );
    }
    let spec = EnsembleSpec::nominal(args.mu_c, args.pin_radius, model, args.tol)
        .with_settings(uncertain)
        .map_err(|e| anyhow!("--uncertain: {e}"))?;
    let grid = theta_grid(args.theta_step).map_err(|e| anyhow!("--theta-step: {e}"))?;
    let passes = args.members * args.d.len() * grid.len();
    if passes > MAX_PASSES {
        bail!("{} members × {} d × {} θ0 = {passes} passes; at most {MAX_PASSES} are allowed in one command", args.members, args.d.len(), grid.len());
    }
    let pool = super::validate::pool(args.threads)?;
    let started = std::time::Instant::now();
    let bar = super::progress::bar(passes as u64, "passes", args.json || args.csv);
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
        command: ensemble_command(args, uncertain),
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

fn write_report(
    report: &EnsembleReport,
    inputs: &[InputState],
    table: &str,
    out_dir: &Path,
    plot_dir: Option<&Path>,
) -> Result<()> {
    let head = ReportHead {
        title: format!("Ensemble map: {}", report.part),
        command: &report.command,
        intro: format!(
            "{} members, seed {}; uncertain:",
            report.members, report.seed
        ),
        bullets: &report.uncertain,
    };
    write_report_files(out_dir, "ensemble.json", report, head, |out_dir| {
        let plot_dir = plot_dir.unwrap_or(out_dir);
        std::fs::create_dir_all(plot_dir)
            .with_context(|| format!("creating {}", plot_dir.display()))?;
        let mut md = format!("Predicted bands: the smallest arcs (1° resolution, gaps under 5° closed, ends at the extreme passes they hold) that hold 90% of the passes pooled over the members and the input's θ0 (a stable state: the grid θ0 nearest it).\n\n{table}\n");
        for input in inputs {
            let label = input.label();
            let name = format!("ensemble_{}.svg", label.replace(':', ""));
            let of_input: Vec<&PredictedBands> = report
                .predicted
                .iter()
                .filter(|p| p.input == label)
                .collect();
            let title = format!("{}: predicted θf against d, input {label}", report.part);
            plot_band_distributions(&of_input, &[], &title, &plot_dir.join(&name))?;
            let _ = writeln!(md, "![{label}]({name})\n");
        }
        Ok(md)
    })
}
