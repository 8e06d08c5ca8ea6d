//! `pinfeed sense` end to end: the default command's JSON, and bad input refused with the flag named.

use crate::support::pinfeed;

#[test]
fn default_command_prints_matrices_and_accuracies_per_classifier() {
    let out = pinfeed(&[
        "sense",
        "--part",
        "tripoly1",
        "--d=-0.2",
        "--json",
        "--no-write",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let labels = v["evaluation"]["labels"].as_array().unwrap();
    assert_eq!(labels.len(), 3, "tripoly1 has three stable states");
    let factors = v["noise_factors"].as_array().unwrap().len();
    assert!(factors >= 3, "a default noise sweep");
    let trials = v["trials"].as_u64().unwrap();
    let classifiers = v["classifiers"].as_array().unwrap();
    assert!(classifiers.len() >= 2, "{classifiers:?}");
    let cells = v["evaluation"]["cells"].as_array().unwrap();
    for c in classifiers {
        let mine: Vec<_> = cells.iter().filter(|x| x["classifier"] == *c).collect();
        assert_eq!(mine.len(), factors, "one matrix per noise level for {c}");
        for cell in mine {
            let m = cell["confusion"]["counts"].as_array().unwrap();
            assert_eq!(m.len(), 3);
            let total: u64 = m
                .iter()
                .flat_map(|r| r.as_array().unwrap())
                .map(|x| x.as_u64().unwrap())
                .sum();
            assert_eq!(total, trials);
            for r in m {
                assert_eq!(r.as_array().unwrap().len(), 4, "3 decisions + unknown");
            }
            let acc = cell["accuracy"].as_f64().unwrap();
            let ci = cell["accuracy_ci95"].as_array().unwrap();
            assert!(ci[0].as_f64().unwrap() <= acc && acc <= ci[1].as_f64().unwrap());
            assert!(cell["mutual_information_bits"].as_f64().unwrap() >= 0.0);
        }
    }
    assert!(v["command"].as_str().unwrap().starts_with("pinfeed sense"));
}

#[test]
fn bad_input_is_refused_naming_the_flag() {
    let base = ["sense", "--part", "tripoly1", "--no-write", "--trials", "3"];
    let cases: &[(&[&str], &str)] = &[
        (&["--d=-0.2", "--rate", "0"], "--rate"),
        (&["--d=-0.2", "--rate=-5"], "--rate"),
        (&["--d=-0.2", "--threshold", "0"], "--threshold"),
        (&["--d=-0.2", "--noise-force=-0.1"], "--noise-force"),
        (&["--d=-0.2", "--noise-torque", "NaN"], "--noise-torque"),
        (&["--d=-0.2", "--height=-0.01"], "--height"),
        (&["--d=-0.2", "--jitter=-1"], "--jitter"),
        (&["--d", "NaN"], "--d"),
        (&["--d", "3"], "--d"),
        (&["--d=-0.2", "--hypotheses", "0,135,0"], "--hypotheses"),
        (&["--d=-0.2", "--hypotheses", "0,400"], "--hypotheses"),
        (&["--d=-0.2", "--hypotheses", "0,abc"], "--hypotheses"),
        (&["--d=-0.2", "--classifiers", "oracle"], "--classifiers"),
        (&["--d=-0.2", "--trials", "10000000"], "--trials"),
        (&["--d=-0.2", "--templates", "0"], "--templates"),
        (&["--d=-0.2", "--noise=-1"], "--noise"),
        (&["--d=-0.2", "--mu-c-range", "0.7:0.3"], "--mu-c-range"),
        (&["--d=-0.2", "--mu-c-range", "0.3"], "--mu-c-range"),
        (&["--d=-0.2", "--sensor", "sonar"], "--sensor"),
        (&["--d=-0.2", "--mass", "0"], "--mass"),
        (&["--d=-0.2", "--belt-speed", "inf"], "--belt-speed"),
        (&["--d=-0.2", "--pin-radius=-1"], "--pin-radius"),
        (&["--d=-0.2", "--part-typo", "x"], "--part-typo"),
        (&["--d=-0.2", "--theta-jitter", "1000"], "--theta-jitter"),
        (&["--d=-0.2", "--lowpass", "0"], "--lowpass"),
    ];
    for (extra, flag) in cases {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(extra);
        let out = pinfeed(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?} was accepted");
        assert!(!err.contains("panicked"), "{extra:?} panicked: {err}");
        assert!(
            err.contains(flag),
            "{extra:?}: the message names {flag}: {err}"
        );
    }
    // An unknown part names the part.
    let out = pinfeed(&["sense", "--part", "nosuch", "--d=0.1", "--no-write"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--part"));
}

/// `--pin-radius` is in part units, as in every command: 0.15 at the default scale 0.02 is a
/// 3 mm pin, and the same part in millimetres takes 3; a radius over 10·a is refused in part units.
#[test]
fn pin_radius_is_in_part_units() {
    let radius_m = |extra: &[&str]| {
        let mut a = vec![
            "sense",
            "--d=0.2",
            "--trials",
            "5",
            "--templates",
            "2",
            "--noise",
            "1",
            "--json",
            "--no-write",
        ];
        a.extend_from_slice(extra);
        let out = pinfeed(&a);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
        v["pin_radius_m"].as_f64().unwrap()
    };
    assert_eq!(
        radius_m(&["--part", "tripoly1", "--pin-radius", "0.15"]),
        0.003
    );
    assert_eq!(
        radius_m(&[
            "--part",
            "rect:40:20",
            "--scale",
            "0.001",
            "--pin-radius",
            "3"
        ]),
        0.003
    );
    let out = pinfeed(&[
        "sense",
        "--part",
        "tripoly1",
        "--d=0.2",
        "--pin-radius",
        "20",
        "--no-write",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("--pin-radius") && err.contains("part units"),
        "{err}"
    );
}
