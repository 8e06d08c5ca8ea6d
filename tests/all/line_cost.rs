//! `pinfeed bench line`: the pushes the line captures are exactly the pushes it
//! computed, the bare batch replays them with the same work, and the section lands in the report.

use pinfeed::engine::{run, run_capturing, RunOptions};
use pinfeed::study::line_cost::{measure, section};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn scene(name: &str) -> pinfeed::scenario::Scene {
    pinfeed::scenario::load(std::path::Path::new(&format!(
        "{ROOT}/scenarios/{name}.toml"
    )))
    .unwrap()
}

/// Capturing changes nothing in the run, and captures one push per contact solve, with the
/// recorded ones flagged as the line recorded them.
#[test]
fn capturing_leaves_the_run_alone_and_sees_every_push() {
    for name in ["quickstart", "crowded_belt", "tripoly1_sensing"] {
        let s = scene(name);
        let opts = RunOptions {
            parts: 60,
            ..RunOptions::from_scene(&s)
        };
        let plain = run(&s, &opts, &mut |_| {}).unwrap();
        let (captured, pushes) = run_capturing(&s, &opts).unwrap();
        let (a, b) = (
            serde_json::to_string(&plain.summary).unwrap(),
            serde_json::to_string(&captured.summary).unwrap(),
        );
        assert_eq!(a, b, "{name}: capturing changed the run");
        assert_eq!(
            pushes.len() as u64,
            plain.summary.work.contact_solves,
            "{name}"
        );
        // `traces_recorded` leaves out a sensor pin's pushes, which record its signal.
        let recorded = pushes.iter().filter(|p| p.recorded).count() as u64;
        let traces = plain.summary.work.traces_recorded;
        let sensed = plain.summary.work.sensor_readings;
        assert!(
            recorded >= traces && recorded <= traces + sensed,
            "{name}: {recorded} {traces} {sensed}"
        );
        if sensed == 0 {
            assert_eq!(recorded, traces, "{name}");
        }
    }
}

/// The measurement replays the line's own evaluations (it refuses otherwise) and reports a
/// positive ratio within the range of its repeats' own ratios; a scene on the map tier is refused
/// with the reason.
#[test]
fn the_batch_makes_the_lines_evaluations_and_map_scenes_are_refused() {
    let s = scene("quickstart");
    let r = measure(&s, 30, 2).unwrap();
    let opts = RunOptions {
        parts: 30,
        ..RunOptions::from_scene(&s)
    };
    let line = run(&s, &opts, &mut |_| {}).unwrap();
    assert_eq!(r.evaluations, line.summary.work.model_evaluations);
    assert_eq!(r.pushes as u64, line.summary.work.contact_solves);
    // Times are not asserted (a timed test fails on a loaded machine): only that they exist.
    assert!(r.ratio() > 0.0 && r.ratio().is_finite());
    assert!(r.bare_s > 0.0 && r.bare_recorded_s > 0.0);
    // The ratio of the fastest line to the fastest batch lies between the repeats' own ratios
    // (whichever repeat holds each minimum).
    let (lo, hi) = r.repeat_ratios;
    assert!(
        lo <= r.ratio() && r.ratio() <= hi,
        "{lo} {} {hi}",
        r.ratio()
    );
    let range = format!("| {lo:.3}–{hi:.3} |");
    let md = section(&[r], "CMD");
    assert!(
        md.contains("CMD") && md.contains("| quickstart | exact | 30 |") && md.contains(&range),
        "{md}"
    );

    let text = std::fs::read_to_string(format!("{ROOT}/scenarios/quickstart.toml"))
        .unwrap()
        .replace("fidelity = \"exact\"", "fidelity = \"map\"");
    let f = std::env::temp_dir().join(format!("pinfeed-line-cost-map-{}.toml", std::process::id()));
    std::fs::write(&f, text).unwrap();
    let m = pinfeed::scenario::load(&f).unwrap();
    assert!(m.map_tier.is_some());
    let e = measure(&m, 10, 1).unwrap_err().to_string();
    std::fs::remove_file(&f).unwrap();
    assert!(e.contains("map tier"), "{e}");
}

/// The CLI writes its marked section into the report and replaces it on a second run, leaving
/// the rest of the file alone; bad counts are refused naming the flag.
#[test]
fn the_cli_splices_its_section() {
    let dir = std::env::temp_dir().join(format!("pinfeed-line-cost-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("line-speed.md");
    std::fs::write(&out, "# Line speed\n\nkept\n").unwrap();
    let bench = |parts: &str| {
        Command::new(env!("CARGO_BIN_EXE_pinfeed"))
            .current_dir(ROOT)
            .args([
                "bench",
                "line",
                "--scenarios",
                "scenarios/quickstart.toml",
                "--parts",
                parts,
                "--reps",
                "1",
                "--out",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    for _ in 0..2 {
        let o = bench("20");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("# Line speed\n\nkept\n"));
    assert_eq!(text.matches("<!-- line-cost:begin -->").count(), 1);
    assert!(text.contains("bench line --scenarios scenarios/quickstart.toml --parts 20 --reps 1"));
    let bad = bench("0");
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--parts"));
    std::fs::remove_dir_all(&dir).unwrap();
}
