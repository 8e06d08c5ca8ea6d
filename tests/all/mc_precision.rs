//! `pinfeed mc --precision E` (issue 53): each sweep point runs blocks of 1000 samples until the
//! 95% confidence sequence of its success rate is at most ±E wide, or its samples are spent. The
//! result does not depend on the thread count; a point stops at the first block boundary where the
//! half-width falls under E, with the tally of a fixed run of that many samples; the stopped
//! intervals cover a rate known exactly; a bad E is refused when the arguments are read.

use crate::support::{fresh_dir, pinfeed, pinfeed_json, pinfeed_ok};
use pinfeed::statistics::confidence_sequence;
use pinfeed::study::mc::sequential::{run_to_precision, Stop, BLOCK};
use pinfeed::study::mc::{Perturbations, Study};
use std::path::{Path, PathBuf};

/// A belt with no obstacle: a square part fed at a uniformly random orientation never turns, so it
/// ends within `tolerance` degrees of 0° or 180° with probability exactly 2·2t/360.
pub fn bare_scenario(tolerance: f64, orientation: &str) -> String {
    format!(
        r#"name = "bare"
seed = 1
[belt]
speed = 0.05
width = 0.1
length = 0.2
[part]
shape = "square"
scale = 0.01
mu_c = 0.5
mu_s = 0.3
[feed]
parts = 10
arrival = "periodic"
headway = 4.0
{orientation}
[goal]
[[goal.sets]]
name = "level"
orientations = [0.0, 180.0]
tolerance = {tolerance}
[output]
histogram_svg = false
"#
    )
}

/// A study file `study.toml` (with its scenario `bare.toml`) in `dir`.
fn write_study(dir: &Path, scenario: &str, body: &str) -> PathBuf {
    std::fs::write(dir.join("bare.toml"), scenario).unwrap();
    let p = dir.join("study.toml");
    std::fs::write(&p, format!("scenario = \"bare.toml\"\n{body}")).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn one_and_two_threads_give_the_same_report() {
    let d = fresh_dir("mc-precision-threads");
    // Stable states with jitter, the entry orientation's error swept: three success rates, so the
    // points stop after different numbers of blocks.
    let scenario = bare_scenario(5.0, "orientation = \"stable\"\njitter = 1.0");
    let study = write_study(
        &d,
        &scenario,
        "seed = 4\nsamples = 6000\n[uncertain.pose_theta]\ndistribution = \"normal\"\nsd = 1.0\n\
         [[sweep]]\nparameter = \"pose_theta.sd\"\nvalues = [0.0, 4.0, 30.0]\n",
    );
    let run = |threads: &str, out: &Path| {
        pinfeed_ok(&[
            "mc",
            s(&study),
            "--precision",
            "0.025",
            "--threads",
            threads,
            "--out",
            s(out),
        ])
    };
    let (a, b) = (d.join("out-1"), d.join("out-2"));
    let (one, two) = (run("1", &a), run("2", &b));
    let text = |o: &std::process::Output| {
        String::from_utf8(o.stdout.clone())
            .unwrap()
            .replace(s(&a), "OUT")
            .replace(s(&b), "OUT")
    };
    assert_eq!(text(&one), text(&two));
    for f in ["report.json", "report.md"] {
        assert_eq!(
            crate::support::report_text(&a, f),
            crate::support::report_text(&b, f),
            "{f}"
        );
    }
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("report.json")).unwrap()).unwrap();
    let used: Vec<u64> = r["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["samples"].as_u64().unwrap())
        .collect();
    assert!(used.iter().all(|n| n % BLOCK == 0), "{used:?}");
    assert!(
        used[0] != used[2],
        "the points stop at different blocks: {used:?}"
    );
    assert!(text(&one).contains("| success % [95% CS] | stopped on |"));
}

/// The success count of the only point of `pinfeed mc STUDY --samples N --json`.
fn successes(study: &Path, out: &Path, n: u64) -> u64 {
    let r = pinfeed_json(&[
        "mc",
        s(study),
        "--samples",
        &n.to_string(),
        "--json",
        "--quiet",
        "--out",
        s(out),
    ]);
    r["results"][0]["outcomes"]["success"].as_u64().unwrap()
}

#[test]
fn stops_at_the_first_block_where_the_half_width_is_under_e() {
    let d = fresh_dir("mc-precision-stop");
    let study = write_study(
        &d,
        &bare_scenario(9.0, "orientation = \"uniform\""),
        "seed = 9\nsamples = 20000\n",
    );
    let e = 0.02;
    let r = pinfeed_json(&[
        "mc",
        s(&study),
        "--precision",
        "0.02",
        "--json",
        "--quiet",
        "--out",
        s(&d.join("seq")),
    ]);
    let p = &r["results"][0];
    let n = p["samples"].as_u64().unwrap();
    let seq = &p["sequential"];
    assert_eq!(seq["stopped"], "precision");
    assert_eq!(
        (seq["precision"].as_f64(), seq["block"].as_u64()),
        (Some(e), Some(BLOCK))
    );
    assert!(n > BLOCK && n % BLOCK == 0, "{n}");
    assert!(r["command"].as_str().unwrap().contains("--precision 0.02"));
    // The tally is a fixed run's of n samples, whose sequence is under E; one block earlier it
    // was not.
    let k = successes(&study, &d.join("fixed"), n);
    assert_eq!(p["outcomes"]["success"].as_u64(), Some(k));
    let cs = confidence_sequence(k, n, 0.05);
    assert_eq!(seq["confidence_sequence"][0].as_f64(), Some(cs[0]));
    assert_eq!(seq["confidence_sequence"][1].as_f64(), Some(cs[1]));
    assert!(0.5 * (cs[1] - cs[0]) <= e);
    let k0 = successes(&study, &d.join("earlier"), n - BLOCK);
    let [lo, hi] = confidence_sequence(k0, n - BLOCK, 0.05);
    assert!(0.5 * (hi - lo) > e, "{k0} of {}", n - BLOCK);
    // A cap that is not a whole number of blocks: the last block is shorter, and the point stops
    // at the cap.
    let r = pinfeed_json(&[
        "mc",
        s(&study),
        "--samples",
        "1500",
        "--precision",
        "0.001",
        "--json",
        "--quiet",
        "--out",
        s(&d.join("cap")),
    ]);
    assert_eq!(r["results"][0]["samples"].as_u64(), Some(1500));
    assert_eq!(r["results"][0]["sequential"]["stopped"], "cap");
    assert_eq!(r["samples_per_point"].as_u64(), Some(1500));
    // Without --precision the report has no trace of it.
    let plain = pinfeed_ok(&[
        "mc",
        s(&study),
        "--samples",
        "1000",
        "--out",
        s(&d.join("plain")),
    ]);
    let plain = String::from_utf8(plain.stdout).unwrap();
    assert!(
        !plain.contains("CS") && !plain.contains("stopped"),
        "{plain}"
    );
    let json = std::fs::read_to_string(d.join("plain/report.json")).unwrap();
    assert!(!json.contains("sequential") && !json.contains("--precision"));
}

/// 200 studies of a rate known exactly (p = 2·2·9/360 = 0.1), each with its own seed, run to
/// ±0.03: the stopped 95% confidence sequences hold p in at least 190 of them.
#[test]
fn the_stopped_intervals_cover_a_known_rate() {
    let path = Path::new("bare.toml");
    let scene =
        pinfeed::scenario::parse(path, &bare_scenario(9.0, "orientation = \"uniform\"")).unwrap();
    let p = 0.1;
    let (mut held, mut samples) = (0, 0);
    for seed in 0..200 {
        let none = Perturbations::none(pinfeed::mechanics::support::SupportChoice::Uniform);
        let study = Study::of_scene("coverage", scene.clone(), 1000 + seed, 100_000, none).unwrap();
        let (tallies, stops) = run_to_precision(&study, 0.03, BLOCK, None, &|| {}).unwrap();
        assert_eq!(stops[0].stopped, Stop::Precision);
        let [lo, hi] = stops[0].confidence_sequence;
        held += usize::from(lo <= p && p <= hi);
        samples += tallies[0].samples;
    }
    assert!(held >= 190, "{held} of 200 stopped intervals hold p = {p}");
    // About 2000 samples a run (the half-width after 1000 is about 0.035, after 2000 0.025).
    assert!((300_000..=500_000).contains(&samples), "{samples}");
}

#[test]
fn bad_precisions_are_refused_naming_the_flag() {
    let d = fresh_dir("mc-precision-bad");
    let study = write_study(&d, &bare_scenario(9.0, "orientation = \"uniform\""), "");
    for bad in ["0", "0.5", "-0.1", "1", "nan", "inf", "abc", ""] {
        let flag = format!("--precision={bad}");
        let out = pinfeed(&["mc", s(&study), &flag, "--out", s(&d)]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{bad}");
        assert!(out.stdout.is_empty(), "{bad}");
        assert!(
            err.contains("--precision") && err.contains("(0, 0.5)"),
            "{bad}: {err}"
        );
        assert!(!d.join("report.json").exists(), "{bad}: nothing is run");
    }
    // The message docs/commands.md quotes.
    let out = pinfeed(&["mc", s(&study), "--precision", "0.5"]);
    assert!(String::from_utf8_lossy(&out.stderr).starts_with(
        "error: invalid value '0.5' for '--precision <E>': --precision must lie in (0, 0.5) "
    ));
    let out = pinfeed(&["mc", s(&study), "--precision", "0.1", "--shard", "0/2"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"));
}
