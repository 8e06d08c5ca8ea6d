//! What the line adds to its contacts: a scenario's run against the very pushes
//! it asked for, run again as a bare batch.
//!
//! The line is run once with [`engine::run_capturing`] to collect every push (part model, obstacle,
//! pose at the first touch, settings, whether the line recorded its path). Then, alternating and
//! `reps` times each on the calling thread: the line itself ([`engine::run`]), the pushes as a bare
//! batch (no recorder), and the batch recording the pushes the line recorded (the same recorder
//! the line uses). The ratio line / recorded batch is what the event engine, the part stream, the
//! overlap checks and the bookkeeping cost on top of the contacts; the minimum over the repeats is
//! taken for each (the least disturbed run on a shared machine).
//!
//! Scenes on the map tier are refused: their pushes are answered by a map the batch would not use
//! (`pinfeed bench map-tier` measures that tier).

use crate::engine::{self, CapturedPush, RunOptions};
use crate::mechanics::{ContactOutcome, PartModel, Recorder};
use crate::scenario::Scene;
use crate::sensing::signal::KnotRecorder;
use crate::study::bench_error::BenchError;
use std::hint::black_box;
use std::time::Instant;

/// One scenario's measurement.
#[derive(Debug, Clone)]
pub struct LineCost {
    /// The scenario's name.
    pub scenario: String,
    /// The scene's contact model.
    pub fidelity: String,
    /// Parts the line ran.
    pub parts: u64,
    /// Pushes the line computed.
    pub pushes: usize,
    /// Pushes whose path the line recorded as it computed them.
    pub recorded: usize,
    /// Limit-surface evaluations over the pushes.
    pub evaluations: u64,
    /// Wall time (s, minimum over the repeats): the line, the bare batch, the batch recording
    /// what the line recorded.
    pub line_s: f64,
    /// The bare batch of the same pushes (s).
    pub bare_s: f64,
    /// The batch recording what the line recorded (s).
    pub bare_recorded_s: f64,
    /// The smallest and the largest line / recorded-batch ratio of one repeat (its line run over
    /// its own batch run): how far the ratio moves between runs on this machine.
    pub repeat_ratios: (f64, f64),
}

impl LineCost {
    /// Parts per second of the line.
    pub fn parts_per_s(&self) -> f64 {
        self.parts as f64 / self.line_s
    }
    /// Line time over the batch that records what the line records.
    pub fn ratio(&self) -> f64 {
        self.line_s / self.bare_recorded_s
    }
}

/// Run the captured pushes as a batch; `record` gives each recorded push the line's recorder.
fn batch(scene: &Scene, pushes: &[CapturedPush], record: bool) -> u64 {
    let mut evals = 0;
    for p in pushes {
        let model: &PartModel = p.model.as_ref().unwrap_or(&scene.part.model);
        let mut knots = KnotRecorder::default();
        let recorder = (record && p.recorded).then_some(&mut knots as &mut dyn Recorder);
        let out: ContactOutcome = p.pusher.push(model, p.pose, &p.settings, recorder);
        evals += black_box(out).evaluations;
    }
    evals
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed().as_secs_f64())
}

/// Measure `scene` over `parts` parts, `reps` alternating repeats.
pub fn measure(scene: &Scene, parts: u64, reps: usize) -> Result<LineCost, BenchError> {
    if scene.map_tier.is_some() {
        return Err(BenchError::MapTier(scene.name.clone()));
    }
    // An online controller's model is built once, here, not inside the timed runs.
    let opts = RunOptions {
        parts,
        online: crate::engine::prepare::online_model(scene)?,
        ..RunOptions::from_scene(scene)
    };
    let (first, pushes) = engine::run_capturing(scene, &opts)?;
    let evaluations = batch(scene, &pushes, false);
    if evaluations != first.summary.work.model_evaluations {
        return Err(BenchError::IncompleteCapture {
            batch: evaluations,
            line: first.summary.work.model_evaluations,
        });
    }
    let (mut line_s, mut bare_s, mut rec_s) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut repeat_ratios = (f64::INFINITY, f64::NEG_INFINITY);
    for _ in 0..reps.max(1) {
        let (r, t) = timed(|| engine::run(scene, &opts, &mut |_| {}));
        black_box(r?);
        line_s = line_s.min(t);
        bare_s = bare_s.min(timed(|| batch(scene, &pushes, false)).1);
        let t_rec = timed(|| batch(scene, &pushes, true)).1;
        rec_s = rec_s.min(t_rec);
        let ratio = t / t_rec;
        repeat_ratios = (repeat_ratios.0.min(ratio), repeat_ratios.1.max(ratio));
    }
    Ok(LineCost {
        scenario: scene.name.clone(),
        fidelity: scene.contact.fidelity.name().into(),
        parts,
        pushes: pushes.len(),
        recorded: pushes.iter().filter(|p| p.recorded).count(),
        evaluations,
        line_s,
        bare_s,
        bare_recorded_s: rec_s,
        repeat_ratios,
    })
}

/// The Markdown section for `rows`, headed by the command `cmd` that regenerates it.
pub fn section(rows: &[LineCost], cmd: &str) -> String {
    let mut s = format!(
        "## What the line adds to its contacts\n\n\
         Regenerate this section with:\n\n```\n{cmd}\n```\n\n\
         Each scenario is run once to capture every push it asks of the contact model, then, \
         alternating on one thread, the line itself and the same pushes as a bare batch (without \
         and with the recorder for the pushes the line records); the minimum wall time over the \
         repeats is shown, and **line / batch** is the line's over the batch with recording. The \
         batch makes exactly the line's limit-surface evaluations (checked). *In the repeats* is \
         the range of that ratio between one repeat's line and its own batch: how far it moves \
         from run to run on this machine. Machine: 2 cores, one used.\n\n\
         | scenario | model | parts | pushes (recorded) | evaluations / push | line s | bare batch s | batch with recording s | **line / batch** | in the repeats | parts/s |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} ({}) | {:.0} | {:.2} | {:.2} | {:.2} | **{:.3}** | {:.3}–{:.3} | {:.0} |\n",
            r.scenario,
            r.fidelity,
            r.parts,
            r.pushes,
            r.recorded,
            r.evaluations as f64 / r.pushes.max(1) as f64,
            r.line_s,
            r.bare_s,
            r.bare_recorded_s,
            r.ratio(),
            r.repeat_ratios.0,
            r.repeat_ratios.1,
            r.parts_per_s()
        ));
    }
    s.push_str(
        "\nTarget: line / batch ≤ 1.05 (the line adds at most 5% to its contacts). The parts per \
         second follow from the contact model's speed: see results/contact-model.md.\n",
    );
    s
}

/// The markers of the section in results/line-speed.md.
pub const MARKERS: (&str, &str) = ("<!-- line-cost:begin -->", "<!-- line-cost:end -->");
