//! The belief per part and the online controller (docs/physics.md#belief-and-online-replanning):
//! Bayes' rule on the belief (normalisation, fusion, passes without contact), the online mode
//! against the policy it implies, determinism, and located errors.

use crate::online::{parse, refused};
use crate::support::{pinfeed, pinfeed_ok};
use pinfeed::engine::{self, RunOptions, RunResult};
use pinfeed::scenario::Scene;
use pinfeed::sensing::belief::{Belief, Update};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// A fresh folder under the system's temporary directory, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new() -> TempDir {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let d = std::env::temp_dir().join(format!(
            "pinfeed-belief-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        TempDir(d)
    }
    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

const SENSING: &str = "scenarios/tripoly1_sensing.toml";

fn online_of(r: &RunResult) -> pinfeed::engine::controller::OnlineSummary {
    let c = r.summary.controller.as_ref().expect("a controller summary");
    c.online.clone().expect("an online summary")
}

fn run(scene: &Scene, parts: u64) -> RunResult {
    let mut opts = RunOptions::from_scene(scene);
    opts.parts = parts;
    opts.keep_records = true;
    engine::run(scene, &opts, &mut |_| {}).unwrap()
}

/// The bundled sensing line with its rules removed, `[controller] mode = "online"`, a noiseless
/// sensor and `belief` (TOML lines) as `[controller.belief]`.
fn online_text(belief: &str) -> String {
    let text = std::fs::read_to_string(SENSING).unwrap();
    let head = text.split("[[rules]]").next().unwrap();
    let goal = &text[text.find("[goal]").unwrap()..];
    let head = head.replace(
        "templates = 32       # per stable state",
        "templates = 32\nnoise_force = 0.0\nnoise_torque = 0.0\nresolution_force = 0.0\nresolution_force_z = 0.0\nresolution_torque = 0.0",
    );
    let head = head.replace(
        "on_late = \"skip\"",
        &format!("on_late = \"skip\"\nmode = \"online\"\n\n[controller.belief]\n{belief}\n"),
    );
    format!("{head}\n{goal}")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(20261136), .. ProptestConfig::default() })]

    /// The posterior sums to 1 after any sequence of observations, and two independent readings
    /// fuse as the product of their likelihoods, in either order.
    #[test]
    fn the_posterior_sums_to_one_and_readings_fuse_as_a_product(
        prior in prop::collection::vec(0.01f64..1.0, 2..12),
        l1 in prop::collection::vec(-30.0f64..5.0, 12),
        l2 in prop::collection::vec(-30.0f64..5.0, 12),
    ) {
        let n = prior.len();
        let (l1, l2) = (&l1[..n], &l2[..n]);
        let mut a = Belief::new(&prior).unwrap();
        prop_assert_eq!(a.observe_log_likelihood(l1), Update::Updated);
        prop_assert_eq!(a.observe_log_likelihood(l2), Update::Updated);
        let sum: f64 = a.probabilities().iter().sum();
        prop_assert!((sum - 1.0).abs() < 1e-12, "sum {}", sum);
        let mut b = Belief::new(&prior).unwrap();
        b.observe_log_likelihood(l2);
        b.observe_log_likelihood(l1);
        let mut c = Belief::new(&prior).unwrap();
        let both: Vec<f64> = l1.iter().zip(l2).map(|(x, y)| x + y).collect();
        c.observe_log_likelihood(&both);
        // Bayes by hand: p ∝ prior · L1 · L2.
        let raw: Vec<f64> = (0..n).map(|h| prior[h] * (l1[h] + l2[h]).exp()).collect();
        let z: f64 = raw.iter().sum();
        for (h, r) in raw.iter().enumerate() {
            let want = r / z;
            for got in [a.probability(h), b.probability(h), c.probability(h)] {
                prop_assert!((got - want).abs() < 1e-9 * want.max(1e-300).max(1e-12) + 1e-12,
                    "h {}: {} vs {}", h, got, want);
            }
        }
    }

    /// A pass without contact removes exactly the hypotheses that would have touched, and
    /// scales the others by their chance of missing.
    #[test]
    fn a_pass_without_contact_removes_exactly_the_hypotheses_that_touch(
        prior in prop::collection::vec(0.01f64..1.0, 3..10),
        kinds in prop::collection::vec(0u8..3, 10),
    ) {
        let n = prior.len();
        let p_touch: Vec<f64> = kinds[..n].iter().map(|k| f64::from(*k) / 2.0).collect();
        prop_assume!(p_touch.iter().any(|&p| p < 1.0));
        let mut b = Belief::new(&prior).unwrap();
        prop_assert_eq!(b.observe_no_contact(&p_touch), Update::Updated);
        let z: f64 = (0..n).map(|h| prior[h] * (1.0 - p_touch[h])).sum();
        for h in 0..n {
            let p = b.probability(h);
            if p_touch[h] == 1.0 {
                prop_assert_eq!(p, 0.0);
            } else {
                let want = prior[h] * (1.0 - p_touch[h]) / z;
                prop_assert!((p - want).abs() < 1e-12, "{} vs {}", p, want);
            }
        }
    }
}

#[test]
fn repeated_noiseless_evidence_drives_the_truth_to_certainty() {
    // Each reading favours the truth (hypothesis 2) by a fixed factor: p(truth) → 1.
    let mut b = Belief::new(&[1.0; 5]).unwrap();
    let mut last = b.probability(2);
    for _ in 0..40 {
        b.observe_log_likelihood(&[-1.0, -1.0, 0.0, -1.0, -1.0]);
        assert!(b.probability(2) > last || b.probability(2) == 1.0);
        last = b.probability(2);
    }
    assert!(last > 1.0 - 1e-12, "{last}");
    assert!(b.entropy_bits() < 1e-9);
}

#[test]
fn with_a_noiseless_sensor_the_online_belief_finds_every_true_state() {
    let scene = parse(&online_text("offsets = 1\nsamples = 4\ntargets = 13"));
    let r = run(&scene, 60);
    let o = online_of(&r);
    assert_eq!(o.decisions, 60);
    assert_eq!(o.state_known, 60);
    assert_eq!(o.state_correct, 60, "{o:?}");
    assert!(
        o.entropy_prior_bits > 1.5,
        "three states: {}",
        o.entropy_prior_bits
    );
    assert!(
        o.entropy_posterior_bits < 0.05,
        "{}",
        o.entropy_posterior_bits
    );
    assert_eq!(o.inconsistent, 0);
}

/// The online mode with one sensor, and a policy made of its own choices (one per decided
/// state), give the same line part by part.
#[test]
fn a_policy_equal_to_the_online_choices_reproduces_the_online_run() {
    let text = online_text("offsets = 1\nsamples = 4\ntargets = 13");
    let scene = parse(&text);
    let mut opts = RunOptions::from_scene(&scene);
    opts.parts = 60;
    opts.keep_records = true;
    opts.sample_paths = 60; // keeps the controller's log
    let online = engine::run(&scene, &opts, &mut |_| {}).unwrap();
    // The decided state of each part (its record) and the online choice for it (the log).
    let mut choice_of = std::collections::BTreeMap::new();
    for rec in online
        .control
        .iter()
        .filter(|c| c.kind == pinfeed::engine::controller::ControlKind::Decision)
    {
        let part = &online.records[rec.part as usize];
        assert_eq!(part.part, rec.part);
        let state = part.sensed[0].label.clone().unwrap_or_default();
        let y = rec.what.split(['=', ' ']).nth(2).unwrap().to_string();
        let prev = choice_of.insert(state.clone(), y.clone());
        assert!(
            prev.as_ref().is_none_or(|p| *p == y),
            "state {state}: {prev:?} and {y}"
        );
    }
    assert!(choice_of.len() >= 2, "{choice_of:?}");
    let mut rules = String::new();
    for (state, y) in &choice_of {
        let label = state.trim_start_matches("probe=");
        rules += &format!(
            "[[rules]]\nsensor = \"probe\"\ndecides = \"{label}\"\npin = \"mover\"\ny = {y}\n\n"
        );
    }
    let policy_text = text
        .replace("mode = \"online\"", "mode = \"policy\"")
        .replace(
            "[controller.belief]\noffsets = 1\nsamples = 4\ntargets = 13\n",
            "",
        )
        .replace("[goal]", &format!("{rules}[goal]"));
    let policy = parse(&policy_text);
    let p = engine::run(&policy, &opts, &mut |_| {}).unwrap();
    assert_eq!(p.records.len(), online.records.len());
    for (a, b) in online.records.iter().zip(&p.records) {
        assert_eq!(
            (a.outcome, a.theta_out_deg, a.end_s),
            (b.outcome, b.theta_out_deg, b.end_s),
            "part {}",
            a.part
        );
    }
    assert_eq!(online.summary.outcomes, p.summary.outcomes);
}

#[test]
fn a_sensor_that_some_states_miss_gives_evidence_by_its_silence() {
    // tripoly2 with a sensor pin at d = −0.3 of its 3.2 cm radius: two of its states pass it
    // without touching; the online belief still decides every part.
    let text = online_text("offsets = 1\nsamples = 4\ntargets = 7")
        .replace("shape = \"tripoly1\"", "shape = \"tripoly2\"")
        .replace("weights = [1, 1, 1]  # 0°, 135°, 225°", "")
        .replace("y = -0.007           # d = −0.22", "y = -0.0096");
    let scene = parse(&text);
    let model = pinfeed::engine::prepare::online_model(&scene)
        .unwrap()
        .expect("an online model")
        .0;
    let never: Vec<usize> = (0..model.hypotheses.len())
        .filter(|&h| model.sensors[0].p_touch[h] == 0.0)
        .collect();
    assert!(!never.is_empty(), "some state never touches the sensor");
    let r = run(&scene, 80);
    let o = online_of(&r);
    assert!(o.no_contact_passes > 0, "{o:?}");
    assert_eq!(o.decisions, 80);
    assert_eq!(r.summary.sensors[0].untouched, o.no_contact_passes);
}

#[test]
fn online_runs_are_identical_for_any_thread_count() {
    let dir = TempDir::new();
    let scen = dir.path().join("online.toml");
    std::fs::write(&scen, online_text("offsets = 2\nsamples = 3\ntargets = 7")).unwrap();
    let study = dir.path().join("study.toml");
    std::fs::write(
        &study,
        "name = \"online-threads\"\nscenario = \"online.toml\"\nseed = 3\nsamples = 120\n\n[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = 0.3\nmax = 0.7\n",
    )
    .unwrap();
    let mut reports = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("t{threads}"));
        let s = study.to_str().unwrap();
        pinfeed_ok(&[
            "mc",
            s,
            "--threads",
            threads,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        for f in ["report.json", "report.md"] {
            reports.push(crate::support::report_text(&out, f));
        }
    }
    assert_eq!(reports[0], reports[2]);
    assert_eq!(reports[1], reports[3]);
    // The report tells what the controller decided and predicted, against what happened.
    let json: serde_json::Value = serde_json::from_str(&reports[0]).unwrap();
    let o = &json["results"][0]["online"];
    let decisions = o["decisions"].as_u64().expect("an online section");
    assert!(decisions > 100 && decisions <= 120, "{o}");
    let bins = o["calibration"].as_array().unwrap();
    let parts: u64 = bins.iter().map(|b| b["parts"].as_u64().unwrap()).sum();
    assert_eq!(parts, decisions);
    let observed = o["observed"].as_f64().unwrap();
    let weighted: f64 = bins
        .iter()
        .map(|b| b["observed"].as_f64().unwrap() * b["parts"].as_u64().unwrap() as f64)
        .sum::<f64>()
        / decisions as f64;
    assert!(
        (weighted - observed).abs() < 1e-12,
        "{weighted} vs {observed}"
    );
    assert!(
        o["entropy_posterior_bits"].as_f64().unwrap() < o["entropy_prior_bits"].as_f64().unwrap()
    );
    assert!(
        reports[1].contains("## Online controller"),
        "{}",
        reports[1]
    );
    // Shards carry the online counts and merge to the bytes of one run.
    let shards = dir.path().join("shards");
    let s = study.to_str().unwrap();
    for k in ["0/3", "1/3", "2/3"] {
        pinfeed_ok(&[
            "mc",
            s,
            "--shard",
            k,
            "--quiet",
            "--out",
            shards.to_str().unwrap(),
        ]);
    }
    let files: Vec<String> = (0..3)
        .map(|k| {
            let f = shards.join(format!("shard-000{k}-of-0003.json"));
            f.to_str().unwrap().to_string()
        })
        .collect();
    assert!(std::fs::read_to_string(&files[1])
        .unwrap()
        .contains("\"online\""));
    let merged = dir.path().join("merged");
    let mut args = vec!["merge", "--quiet", "--out", merged.to_str().unwrap()];
    args.extend(files.iter().map(String::as_str));
    pinfeed_ok(&args);
    let one = dir.path().join("t1");
    for f in ["report.json", "report.md"] {
        assert_eq!(
            crate::support::report_text(&one, f),
            crate::support::report_text(&merged, f),
            "{f}"
        );
    }
    let r = run(
        &parse(&online_text("offsets = 2\nsamples = 3\ntargets = 7")),
        40,
    );
    let q = run(
        &parse(&online_text("offsets = 2\nsamples = 3\ntargets = 7")),
        40,
    );
    assert_eq!(r.records, q.records);
}

#[test]
fn online_mode_errors_are_located() {
    let base = online_text("samples = 4");
    let e = refused(&base.replace("mode = \"online\"", "mode = \"oracle\""));
    assert!(e.contains("controller.mode") && e.contains("oracle"), "{e}");
    let e = refused(&base.replace("samples = 4", "samples = 1000"));
    assert!(
        e.contains("controller.belief.samples") && e.contains("[1, 64]"),
        "{e}"
    );
    let e = refused(&base.replace("samples = 4", "mu_c = []"));
    assert!(e.contains("controller.belief.mu_c"), "{e}");
    let e = refused(&base.replace("samples = 4", "mu_c = [0.5, 9.0]"));
    assert!(e.contains("controller.belief.mu_c[1]"), "{e}");
    // Issue 57 item 7: a class (or friction value) listed twice counted twice; refused like a
    // three-entry list, at the repeated entry.
    for (list, key) in [
        (
            "support = [\"uniform\", \"uniform\"]",
            "controller.belief.support[1]",
        ),
        (
            "support = [\"tripod\", \"uniform\", \"tripod\"]",
            "controller.belief.support",
        ),
        ("mu_c = [0.3, 0.5, 0.3]", "controller.belief.mu_c[2]"),
    ] {
        let e = refused(&base.replace("samples = 4", list));
        assert!(e.contains(&format!("key `{key}`: ")), "{list}: {e}");
        assert!(e.contains("once"), "{list}: {e}");
    }
    let e = refused(&base.replace("samples = 4", "colour = 3"));
    assert!(e.contains("colour"), "{e}");
    let e = refused(&base.replace("mode = \"online\"", "mode = \"policy\""));
    assert!(e.contains("controller.belief"), "{e}");
    // A sensor downstream of the moving pin: the online controller decides once every sensor
    // has read the part.
    let e = refused(&base.replace("x = 0.12\ny = -0.007", "x = 0.35\ny = -0.007"));
    assert!(e.contains("upstream"), "{e}");
    // The CLI reports it with the file and a non-zero exit.
    let dir = TempDir::new();
    let f = dir.path().join("bad.toml");
    std::fs::write(&f, base.replace("samples = 4", "targets = 1")).unwrap();
    let out = pinfeed(&["run", f.to_str().unwrap(), "--parts", "1"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml") && err.contains("controller.belief.targets"),
        "{err}"
    );
}

/// Parsing a scenario never runs the line: a belief whose model is too large to build parses,
/// and the build (`engine::prepare`, or the run that needs it) refuses it, located at
/// `[controller.belief]` in the file, with the numbers that make it too large.
#[test]
fn a_model_too_large_to_build_is_refused_at_the_belief_not_at_parse() {
    let text =
        online_text("offsets = 41\nsamples = 64\ntargets = 101\nmu_c = [0.3, 0.4, 0.5, 0.6, 0.7]");
    let scene = parse(&text);
    let located = |e: &pinfeed::scenario::ScenarioError| {
        let i = e.invalid().expect("a located error");
        assert_eq!(i.key, "controller.belief", "{e}");
        assert!(i.message.contains("would run the line"), "{e}");
        i.line
    };
    let e = engine::prepare::online_model(&scene).unwrap_err();
    let line = located(&e);
    assert_eq!(
        text.lines().nth(line - 1),
        Some("[controller.belief]"),
        "{e}"
    );
    // A run that is not given the model builds it, and refuses the same way.
    let opts = RunOptions::from_scene(&scene);
    match engine::run(&scene, &opts, &mut |_| {}) {
        Err(engine::EngineError::OnlineModel(e)) => assert_eq!(located(&e), line),
        other => panic!(
            "expected the model's error, got {:?}",
            other.map(|r| r.summary)
        ),
    }
    let dir = TempDir::new();
    let f = dir.path().join("huge.toml");
    std::fs::write(&f, &text).unwrap();
    let out = pinfeed(&["run", f.to_str().unwrap(), "--parts", "1"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("huge.toml:{line}:")) && err.contains("would run the line"),
        "{err}"
    );
}
