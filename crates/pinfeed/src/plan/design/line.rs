//! A candidate design on the line: the emitted scenario parsed and run by the discrete-event
//! engine ([`crate::engine::run`]) — once with the parts far apart (the physics alone: no part
//! can meet another), then at shorter headways to find the line's own spacing of parts, then
//! the full check whose result is the design's verdict.

use super::LineCheck;
use crate::engine::{run, OutcomeCounts, RunOptions, RunResult};
use crate::scenario::Scene;
use crate::statistics::wilson_interval;
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
}

/// A design's scenario text, with its policy file's text if it names one: what the design writes.
/// On the line it is built once, in memory, and run at any headway by setting the
/// built scene's; [`Runnable::with_headway`] writes a headway into the text for the design's
/// output only.
#[derive(Debug, Clone, PartialEq)]
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

    /// Run `parts` parts at headway `h` with `seed`, keeping per-part records if asked: the
    /// scenario built for this one run (to run it at several headways, build it once with
    /// [`Line`]).
    pub(crate) fn run(
        &self,
        h: f64,
        parts: u64,
        seed: u64,
        records: bool,
    ) -> Result<(LineCheck, RunResult), LineError> {
        Line::new(self).run(h, parts, seed, records)
    }
}

/// A design on the line, run at any headway: its scenario is built in memory, with its policy's
/// text (no file is written) — its sensor pins trained, the costly step of a sensor scene — on
/// the first run only; a later run at another headway sets the built scene's feed headway to the
/// one [`Runnable::with_headway`] would write. Only the arrivals depend on `[feed] headway`, so a
/// run gives what building the scenario with that headway line would (a test checks it).
pub(crate) struct Line<'a> {
    runnable: &'a Runnable,
    /// The scene as built by the first run.
    scene: Option<Scene>,
}

impl<'a> Line<'a> {
    /// The design `runnable`, not built yet.
    pub(crate) fn new(runnable: &'a Runnable) -> Line<'a> {
        Line {
            runnable,
            scene: None,
        }
    }

    /// Run `parts` parts at headway `h` with `seed`, keeping per-part records if asked.
    pub(crate) fn run(
        &mut self,
        h: f64,
        parts: u64,
        seed: u64,
        records: bool,
    ) -> Result<(LineCheck, RunResult), LineError> {
        let scene = self.scene(h)?;
        let opts = RunOptions {
            parts,
            seed,
            sample_paths: 0,
            keep_records: records,
            online: None,
            stop: None,
        };
        let started = Instant::now();
        let res = run(scene, &opts, &mut |_| {})?;
        let check = LineCheck::of(&res.summary.outcomes, parts, h, started);
        Ok((check, res))
    }

    /// The scene at headway `h`: the built scene with its headway set, or (first, or at a headway
    /// the scenario would refuse, or for a scenario without a `headway = …` line) the scenario
    /// text with `h` written in, built.
    pub(crate) fn scene(&mut self, h: f64) -> Result<&Scene, LineError> {
        let written = written_headway(h).filter(|_| self.runnable.has_headway());
        if let (Some(scene), Some(headway)) = (self.scene.as_mut(), written) {
            scene.feed.arrival = scene.feed.arrival.with_headway(headway);
        } else {
            // Messages name the design's scenario as the file it is written to.
            let path = std::path::Path::new("design.toml");
            let policy = self.runnable.policy.as_ref().map(|(_, text)| text.as_str());
            let toml = self.runnable.with_headway(h);
            let draft = crate::scenario::SceneDraft::parse_with_policy(path, &toml, policy)?;
            self.scene = Some(draft.build()?);
        }
        Ok(self.scene.as_ref().expect("the scene was built"))
    }
}

impl Runnable {
    /// Does the scenario have a `headway = …` line for [`Self::with_headway`] to replace?
    fn has_headway(&self) -> bool {
        self.toml.lines().any(|l| l.starts_with("headway = "))
    }
}

/// The headway (s) a scenario reads from the line [`Runnable::with_headway`] writes for `h`: the
/// number as written ([`fmt_headway`]) read back by the TOML parser, if the scenario accepts it
/// (`None` otherwise: building the scenario reports the error).
fn written_headway(h: f64) -> Option<f64> {
    #[derive(serde::Deserialize)]
    struct Feed {
        headway: f64,
    }
    let feed: Feed = toml::from_str(&format!("headway = {}\n", fmt_headway(h))).ok()?;
    crate::scenario::limits::contains(crate::scenario::limits::HEADWAY, feed.headway)
        .then_some(feed.headway)
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
            lower95: crate::statistics::wilson_lower_one_sided(o.success, parts),
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
pub(crate) fn shortest_headway(
    line: &mut Line,
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
    let (iso, _) = line.run(hi, probe_parts, seed, false)?;
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
        let (c, _) = line.run(mid, probe_parts, seed, false)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scenario(file: &str) -> String {
        std::fs::read_to_string(crate::project_path(&format!("scenarios/{file}"))).unwrap()
    }

    /// A line built at one headway and run at others gives, at each, the scene and the run of the
    /// scenario text written with that headway and built afresh.
    fn reuse_matches_rebuilding(r: &Runnable, headways: &[f64]) {
        let mut line = Line::new(r);
        line.run(9.0, 3, 5, false).unwrap();
        for &h in headways {
            let (check, res) = line.run(h, 40, 5, true).unwrap();
            let path = std::path::Path::new("design.toml");
            let policy = r.policy.as_ref().map(|(_, t)| t.as_str());
            let built =
                crate::scenario::SceneDraft::parse_with_policy(path, &r.with_headway(h), policy)
                    .unwrap()
                    .build()
                    .unwrap();
            let reused = line.scene.as_ref().unwrap();
            assert_eq!(reused.feed.arrival, built.feed.arrival, "h = {h}");
            assert_eq!(format!("{reused:?}"), format!("{built:?}"), "h = {h}");
            let opts = RunOptions {
                parts: 40,
                seed: 5,
                sample_paths: 0,
                keep_records: true,
                online: None,
                stop: None,
            };
            let fresh = run(&built, &opts, &mut |_| {}).unwrap();
            assert_eq!(format!("{:?}", res.summary), format!("{:?}", fresh.summary));
            assert_eq!(format!("{:?}", res.records), format!("{:?}", fresh.records));
            assert_eq!(check.headway_s, h);
        }
    }

    #[test]
    fn a_design_built_in_memory_is_the_scene_its_written_files_load() {
        // A sensor line whose rules are in a policy file: built with the policy's text in memory,
        // as the planner builds it, and from the files written to a folder, as a user loads them.
        let toml = scenario("tripoly1_sensing.toml");
        let (rules, goal) = (
            toml.find("[[rules]]").unwrap(),
            toml.find("[goal]").unwrap(),
        );
        let policy_name = "design.policy.toml";
        let body = format!("{}{}", &toml[..rules], &toml[goal..]).replace(
            "[controller]\n",
            &format!("[controller]\npolicy = \"{policy_name}\"\n"),
        );
        let policy = format!("part = \"tripoly1\"\n\n{}", &toml[rules..goal]);
        let r = Runnable {
            toml: body,
            policy: Some((policy_name.to_string(), policy.clone())),
        };
        let mut line = Line::new(&r);
        let h = 7.5;
        let in_memory = format!("{:?}", line.scene(h).unwrap());
        assert!(
            in_memory.contains("decides"),
            "the policy's rules are in the scene"
        );
        let dir = std::env::temp_dir().join(format!("pinfeed_line_emit_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("design.toml");
        std::fs::write(&path, r.with_headway(h)).unwrap();
        std::fs::write(dir.join(policy_name), &policy).unwrap();
        let loaded = format!("{:?}", crate::scenario::load(&path).unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
        // The controller names its policy file where it was read from.
        let loaded = loaded.replace(&dir.join(policy_name).display().to_string(), policy_name);
        assert_eq!(in_memory, loaded);
    }

    #[test]
    fn a_sensor_line_run_at_several_headways_is_the_line_rebuilt_at_each() {
        let r = Runnable {
            toml: scenario("tripoly1_sensing.toml"),
            policy: None,
        };
        // Headways the text rounds (to 3 decimals) and one it keeps.
        reuse_matches_rebuilding(&r, &[4.4, 2.345_678_9, 1.0 / 3.0, 6.0004, 0.1 + 0.2]);
    }

    #[test]
    fn a_poisson_line_keeps_its_arrival_process() {
        let toml = scenario("quickstart.toml").replace(
            "arrival = \"periodic\" # or \"poisson\"",
            "arrival = \"poisson\"",
        );
        assert!(toml.contains("arrival = \"poisson\""));
        let r = Runnable { toml, policy: None };
        reuse_matches_rebuilding(&r, &[2.5, 1.0 / 7.0]);
    }

    #[test]
    fn the_headway_read_back_is_the_one_written() {
        for h in [
            4.4,
            2.345_678_9,
            1.0 / 3.0,
            0.1 + 0.2,
            1e-3,
            123_456.789_4,
            0.0015,
        ] {
            let text = fmt_headway(h);
            assert_eq!(
                written_headway(h),
                Some(text.parse::<f64>().unwrap()),
                "{h}"
            );
        }
        // Written as 0.0: the scenario refuses it, and so the line builds it to report the error.
        assert_eq!(written_headway(1e-4), None);
        assert_eq!(written_headway(f64::NAN), None);
    }
}
