//! A candidate design on the line: the emitted scenario parsed and run by the discrete-event
//! engine ([`crate::engine::run`]) — once with the parts far apart (the physics alone: no part
//! can meet another), then at shorter headways to find the line's own spacing of parts, then
//! the full check whose result is the design's verdict.

use super::LineCheck;
use crate::engine::{run, OutcomeCounts, RunOptions, RunResult};
use crate::statistics::wilson_interval;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Why a candidate could not be run on the line.
#[derive(Debug, thiserror::Error)]
pub enum LineError {
    /// The emitted scenario does not compile.
    #[error("the emitted scenario does not compile: {0}")]
    Scenario(#[from] crate::scenario::ScenarioError),
    /// The engine refused to run the design.
    #[error("the line could not run the design: {0}")]
    Engine(#[from] crate::engine::EngineError),
    /// A design file could not be written.
    #[error("writing the design's files to {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why it could not be written.
        source: std::io::Error,
    },
}

/// A scratch folder for a design's files while it is checked (a policy file must exist beside
/// the scenario that names it); removed when dropped.
pub(crate) struct Scratch {
    /// The folder (under the system's temporary folder).
    pub(crate) dir: PathBuf,
}

impl Scratch {
    /// Create a fresh folder `pinfeed-design-<process>-<n>` in the system's temporary folder; Err if it cannot be created.
    pub(crate) fn new() -> Result<Scratch, LineError> {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let dir = std::env::temp_dir().join(format!(
            "pinfeed-design-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir).map_err(|source| LineError::Io {
            path: dir.clone(),
            source,
        })?;
        Ok(Scratch { dir })
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A scenario with the feed's headway as a parameter (the `headway = …` line of `[feed]` is
/// replaced per run), with an optional policy file written beside it.
#[derive(Debug, Clone)]
pub struct Runnable {
    /// The scenario's text, whose `headway = …` line `with_headway` replaces.
    pub toml: String,
    /// The policy file the scenario names, if any: (file name, text).
    pub policy: Option<(String, String)>,
}

impl Runnable {
    /// The scenario with headway `h` (s).
    pub fn with_headway(&self, h: f64) -> String {
        let mut out = String::with_capacity(self.toml.len());
        for line in self.toml.lines() {
            if line.starts_with("headway = ") {
                out += &format!(
                    "headway = {}        # s: chosen on the line (see the header)\n",
                    fmt_headway(h)
                );
            } else {
                out += line;
                out.push('\n');
            }
        }
        out
    }

    /// Run `parts` parts at headway `h` with `seed`, keeping per-part records if asked.
    pub(crate) fn run(
        &self,
        scratch: &Scratch,
        h: f64,
        parts: u64,
        seed: u64,
        records: bool,
    ) -> Result<(LineCheck, RunResult), LineError> {
        let path = scratch.dir.join("design.toml");
        if let Some((name, text)) = &self.policy {
            let p = scratch.dir.join(name);
            crate::output::write_atomic(&p, text)
                .map_err(|source| LineError::Io { path: p, source })?;
        }
        let toml = self.with_headway(h);
        let scene = crate::scenario::parse(&path, &toml)?;
        let opts = RunOptions {
            parts,
            seed,
            sample_paths: 0,
            keep_records: records,
            online: None,
        };
        let started = Instant::now();
        let res = run(&scene, &opts, &mut |_| {})?;
        let check = LineCheck::of(&res.summary.outcomes, parts, h, started);
        Ok((check, res))
    }
}

/// A headway as written (s, 3 decimals at most).
pub fn fmt_headway(h: f64) -> String {
    let s = format!("{h:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

impl LineCheck {
    pub(crate) fn of(o: &OutcomeCounts, parts: u64, headway_s: f64, started: Instant) -> Self {
        LineCheck {
            parts,
            success: o.success,
            success_rate: o.success as f64 / parts.max(1) as f64,
            ci95: wilson_interval(o.success, parts),
            outcomes: *o,
            headway_s,
            elapsed_s: started.elapsed().as_secs_f64(),
        }
    }
}

/// One probe of the headway search: (headway s, parts, collisions, success rate).
pub type HeadwayProbe = (f64, u64, u64, f64);

/// The shortest headway in `[lo, hi]` (s) at which `probe_parts` parts show no collision and
/// keep their success with the parts far apart (at `hi`) within half its margin over `target`
/// (at least 0.2%; below the target, within 0.5%), by bisection on the logarithm (`steps` probes at most; `hi` is
/// taken to pass), then with a 25% reserve, rounded up to 0.1 s and at most `hi`. Returns it with
/// the probes. (Short headways fail by collisions, and on lines with moving pins by pins that
/// cannot reach the next part's position in time.)
#[allow(clippy::too_many_arguments)]
pub(crate) fn shortest_headway(
    r: &Runnable,
    scratch: &Scratch,
    (lo, hi): (f64, f64),
    target: f64,
    probe_parts: u64,
    seed: u64,
    steps: usize,
    deadline: Instant,
) -> Result<(f64, Vec<HeadwayProbe>), LineError> {
    let mut probes = Vec::new();
    // The same parts with the parts far apart: a probe is compared with them (paired), so the
    // sampling noise of a short run does not pass for a loss.
    let (iso, _) = r.run(scratch, hi, probe_parts, seed, false)?;
    let i = iso.success_rate;
    let floor = if i >= target {
        target.max(i - ((i - target) / 2.0).max(0.002))
    } else {
        i - 0.005
    };
    let (mut bad, mut good) = (lo, hi);
    for _ in 0..steps {
        if Instant::now() >= deadline || good / bad < 1.08 {
            break;
        }
        let mid = (bad * good).sqrt();
        let (c, _) = r.run(scratch, mid, probe_parts, seed, false)?;
        probes.push((mid, probe_parts, c.outcomes.collision, c.success_rate));
        if c.outcomes.collision == 0 && c.success_rate >= floor {
            good = mid;
        } else {
            bad = mid;
        }
    }
    let chosen = ((good * 1.25) * 10.0).ceil() / 10.0;
    Ok((chosen.min(hi), probes))
}
