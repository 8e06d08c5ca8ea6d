//! The folder of a line run (`pinfeed run`): `summary.json` and, as the scenario's `[output]`
//! asks, the per-part CSV, the orientation histogram, the event and control logs, and the drawing
//! and animation asked for, written together ([`crate::output::Batch`]).

use crate::engine::RunResult;
use crate::output::Batch;
use crate::report::{animate, parts_csv, plot_line, plot_loop, plot_orientations};
use crate::report::{ReportError, ReportResult};
use crate::scenario::Scene;
use std::path::Path;

/// The pictures a run asks for besides the scenario's files.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunFiles<'a> {
    /// A drawing of sample parts on the line (SVG).
    pub draw: Option<&'a Path>,
    /// An animation of the line (SVG).
    pub animate: Option<&'a Path>,
    /// The animation's speed-up over real time.
    pub animate_speed: Option<f64>,
}

/// How many of the first parts have their paths recorded for a drawing.
pub const SAMPLE_POOL: usize = 64;

impl RunFiles<'_> {
    /// Set in `opts` what the run must record for these files and the scene's own outputs: the
    /// per-part records for the scenario's CSV and for an animation that shows sensor decisions,
    /// the paths of the first parts for a drawing ([`SAMPLE_POOL`]) or an animation.
    pub fn record_into(&self, scene: &Scene, opts: &mut crate::engine::RunOptions) {
        opts.keep_records = scene.output.parts_csv;
        if self.draw.is_some() {
            opts.sample_paths = SAMPLE_POOL;
        }
        if self.animate.is_some() {
            opts.sample_paths = opts.sample_paths.max(animate::DEFAULT_PARTS);
            let sensors = scene
                .obstacles
                .iter()
                .any(|o| matches!(o, crate::scenario::Obstacle::Pin(p) if p.sensor.is_some()));
            opts.keep_records |= sensors;
        }
    }
}

/// The files `pinfeed run` writes into a run's folder.
const RUN_FILES: [&str; 6] = [
    "summary.json",
    "parts.csv",
    "orientation_histogram.svg",
    "closed_loop.svg",
    "events.json",
    "control.json",
];

/// Write a run's files into `dir` (created), whole and together, and remove the files of an
/// earlier run that this one does not write; returns the summary's JSON.
pub fn write_run(
    scene: &Scene,
    result: &RunResult,
    dir: &Path,
    files: &RunFiles,
) -> ReportResult<String> {
    let summary = &result.summary;
    crate::report::error::create_dir(dir)?;
    // The run's files appear whole and together, or not at all (a full disk leaves the previous
    // run's files as they were, never a new summary beside a truncated figure).
    let mut batch = Batch::new();
    let json = crate::report::versioned::pretty(summary)?;
    let summary_path = dir.join("summary.json");
    batch
        .write(&summary_path, &json)
        .map_err(ReportError::writing(&summary_path))?;
    if scene.output.parts_csv {
        let p = dir.join("parts.csv");
        batch
            .produce(&p, |tmp| parts_csv::write_parts_csv(tmp, &result.records))
            .map_err(ReportError::writing(&p))?;
    }
    if scene.output.histogram_svg {
        let p = dir.join("orientation_histogram.svg");
        batch
            .produce(&p, |tmp| {
                plot_orientations::plot_orientation_histogram(scene, summary, tmp)
            })
            .map_err(ReportError::writing(&p))?;
    }
    if let Some(l) = &summary.closed_loop {
        let p = dir.join("closed_loop.svg");
        batch
            .produce(&p, |tmp| plot_loop::plot_loop(&summary.scenario, l, tmp))
            .map_err(ReportError::writing(&p))?;
    }
    if scene.effects.event_log {
        let p = dir.join("events.json");
        batch
            .write(&p, event_log("events", &result.events)?)
            .map_err(ReportError::writing(&p))?;
        if !result.control.is_empty() {
            let p = dir.join("control.json");
            batch
                .write(&p, event_log("control", &result.control)?)
                .map_err(ReportError::writing(&p))?;
        }
    }
    if let Some(p) = files.draw {
        let samples = plot_line::choose_samples(&result.paths, scene.output.draw_parts as usize);
        batch
            .produce(p, |tmp| plot_line::plot_line(scene, &samples, tmp))
            .map_err(ReportError::writing(p))?;
    }
    if let Some(p) = files.animate {
        let anim = animate::from_run(scene, result, animate::DEFAULT_PARTS);
        let aopts = animate::AnimateOptions {
            speedup: files.animate_speed,
        };
        let dur = (anim.t_end - anim.t_start) / aopts.speedup.unwrap_or(1.0);
        if files.animate_speed.is_some() && dur > animate::MAX_DURATION_S {
            return Err(ReportError::AnimationTooLong {
                speedup: aopts.speedup.unwrap_or(1.0),
                duration_s: dur,
                max_s: animate::MAX_DURATION_S,
            });
        }
        batch
            .write(p, animate::render(&anim, &aopts))
            .map_err(ReportError::writing(p))?;
    }
    batch
        .commit()
        .map_err(ReportError::writing_into("results", dir))?;
    // The folder holds this run's files only (a parts.csv or events.json of an earlier run whose
    // scenario asked for it does not outlive it).
    let written: Vec<String> = [
        Some("summary.json"),
        scene.output.parts_csv.then_some("parts.csv"),
        scene
            .output
            .histogram_svg
            .then_some("orientation_histogram.svg"),
        summary.closed_loop.as_ref().map(|_| "closed_loop.svg"),
        scene.effects.event_log.then_some("events.json"),
        (scene.effects.event_log && !result.control.is_empty()).then_some("control.json"),
    ]
    .into_iter()
    .flatten()
    .map(String::from)
    .collect();
    crate::report::stale::remove_stale(dir, &written, |n| RUN_FILES.contains(&n))
        .map_err(ReportError::removing("files", dir))?;
    Ok(json)
}

/// An event log's file: one compact JSON object, the version fields and the log under `key`.
fn event_log<T: serde::Serialize>(key: &str, log: &[T]) -> serde_json::Result<String> {
    let body: std::collections::BTreeMap<&str, &[T]> = [(key, log)].into();
    crate::report::versioned::compact(&body)
}
