//! Named regression tests for the command-line and polygon failures (fuzzing found
//! them on main at 844e5c1): huge polygons that printed inf/NaN or panicked, misleading refusals,
//! `Polygon::scaled` panicking at extreme factors, and nonsense numbers accepted with status `ok`.
//! Each test runs the reproducer from the issue and asserts the clean outcome: a refusal naming the
//! cause (exit status 1, no panic, nothing on stdout) or a correct, finite answer.

use crate::support::pinfeed;
use pinfeed::geometry::{part_from_spec, Polygon, PolygonError, Vec2};

/// The command must fail with exit status 1, print nothing on stdout, not panic, and say every
/// one of `words` (case-insensitive) on stderr. Returns stderr.
fn refused_saying(args: &[&str], words: &[&str]) -> String {
    let out = pinfeed(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(out.stdout.is_empty(), "{args:?} printed a result");
    let lower = err.to_lowercase();
    for w in words {
        assert!(
            lower.contains(&w.to_lowercase()),
            "{args:?}: stderr should say '{w}': {err}"
        );
    }
    err
}

/// `contact` on tripoly1 at θ0 = 10°, d = 0.2 with `extra` flags must be refused saying `words`.
fn contact_refused_saying(extra: &[&str], words: &[&str]) {
    let mut args = vec![
        "contact", "--part", "tripoly1", "--theta0", "10", "--d", "0.2",
    ];
    args.extend_from_slice(extra);
    refused_saying(&args, words);
}

fn json(args: &[&str]) -> serde_json::Value {
    let out = pinfeed(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// Every number in a JSON document, with its path.
fn numbers(v: &serde_json::Value, path: &str, out: &mut Vec<(String, f64)>) {
    match v {
        serde_json::Value::Number(n) => out.push((path.to_string(), n.as_f64().unwrap())),
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                numbers(x, &format!("{path}[{i}]"), out);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                numbers(x, &format!("{path}.{k}"), out);
            }
        }
        _ => {}
    }
}

const HUGE: &str = "4.6e106,9.7e105 -1.8e106,2.5e106 -3e106,-2e106 2e106,-3e106";
/// The same quadrilateral 1e70 times smaller (a ≈ 4.3e36): representable.
const BIG: &str = "4.6e36,9.7e35 -1.8e36,2.5e36 -3e36,-2e36 2e36,-3e36";
const UNIT: &str = "4.6,0.97 -1.8,2.5 -3,-2 2,-3";

/// Issue 11 item 3: printed centroid (−inf, −inf) and NaN with exit status 0.
#[test]
fn huge_polygon_part_is_refused_naming_the_overflow() {
    refused_saying(
        &["part", "--vertices", HUGE],
        &["polar moment", "overflows", "a ≈ 4.32e106"],
    );
    refused_saying(
        &["part", "--vertices", HUGE, "--json"],
        &["polar moment", "overflows"],
    );
}

/// Issue 11 item 3: `contact` on the same polygon panicked.
#[test]
fn huge_polygon_contact_is_refused_not_a_panic() {
    let part = format!("vertices:{HUGE}");
    refused_saying(
        &["contact", "--part", &part, "--theta0", "10", "--d", "0.2"],
        &["polar moment", "overflows"],
    );
}

/// Issue 11 item 8: refused with the misleading "vertex 1 repeats vertex 0".
#[test]
fn diamond_at_1e154_is_refused_for_its_size_not_a_repeated_vertex() {
    let err = refused_saying(
        &["part", "--vertices", "1e154,0 0,1e154 -1e154,0 0,-1e154"],
        &["area", "overflows"],
    );
    assert!(!err.contains("repeats"), "{err}");
    // 1e70 is representable: the same diamond is accepted with exact mass properties.
    let v = json(&[
        "part",
        "--vertices",
        "1e70,0 0,1e70 -1e70,0 0,-1e70",
        "--json",
    ]);
    let area = v["area"].as_f64().unwrap();
    assert!((area / 2e140 - 1.0).abs() < 1e-14, "{area}");
    assert!((v["a"].as_f64().unwrap() / 1e70 - 1.0).abs() < 1e-14);
}

/// The quadrilateral of the reproducer, at a size that can be represented, gives the answers of
/// the unit-size copy scaled: every number finite, the same stable states, the same rotation.
#[test]
fn large_polygon_has_finite_properties_and_contacts_like_the_unit_copy() {
    let big = json(&["part", "--vertices", BIG, "--json"]);
    let unit = json(&["part", "--vertices", UNIT, "--json"]);
    let mut nums = Vec::new();
    numbers(&big, "", &mut nums);
    for (path, x) in &nums {
        assert!(x.is_finite(), "{path} = {x}");
    }
    assert_eq!(big["stable_states_deg"], unit["stable_states_deg"]);
    let ratio = big["a"].as_f64().unwrap() / unit["a"].as_f64().unwrap();
    assert!((ratio / 1e36 - 1.0).abs() < 1e-12, "{ratio}");
    let contact = |v: &str| {
        json(&[
            "contact",
            "--part",
            &format!("vertices:{v}"),
            "--theta0",
            "10",
            "--d",
            "0.2",
            "--json",
        ])
    };
    let (b, u) = (contact(BIG), contact(UNIT));
    assert_eq!(b["status"], "ok");
    assert_eq!(u["status"], "ok");
    let (rb, ru) = (
        b["rotation_deg"].as_f64().unwrap(),
        u["rotation_deg"].as_f64().unwrap(),
    );
    assert!((rb - ru).abs() < 1e-9, "{rb} vs {ru}");
    let xb = b["com_final"][0].as_f64().unwrap() / 1e36;
    let xu = u["com_final"][0].as_f64().unwrap();
    assert!((xb - xu).abs() < 1e-9 * xu.abs().max(1.0), "{xb} vs {xu}");
}

/// Issue 11 item 1: `Polygon::scaled` panicked at factors ≤ ~1e-162 or ≥ ~1e150. `try_scaled`
/// says why instead; `scaled` keeps working across the representable range.
#[test]
fn scaling_out_of_range_is_an_error_naming_the_cause() {
    let p = part_from_spec("tripoly2").unwrap();
    for k in [1e-200, 1e-162, 1e-100, 1e100, 1e150, 1e200, f64::MAX] {
        match p.try_scaled(k) {
            Err(e @ PolygonError::NotRepresentable { .. }) => {
                let msg = e.to_string();
                assert!(msg.contains("flows double precision"), "{k}: {msg}");
                assert!(msg.contains("between about 1e-70 and 1e70"), "{k}: {msg}");
            }
            other => panic!("scale {k}: {other:?}"),
        }
    }
    for k in [0.0, -1.0, f64::NAN, f64::INFINITY, -0.0] {
        assert!(
            matches!(p.try_scaled(k), Err(PolygonError::BadScale(_))),
            "{k}"
        );
    }
    for k in [1e-60, 1e-30, 0.02, 1e30, 1e60] {
        let s = p.try_scaled(k).unwrap();
        assert!((s.radius() / (k * p.radius()) - 1.0).abs() < 1e-14, "{k}");
        assert!((s.area() / (k * k * p.area()) - 1.0).abs() < 1e-13, "{k}");
        assert!(s.polar_moment().is_normal(), "{k}");
        assert_eq!(s.stable_states().len(), p.stable_states().len(), "{k}");
    }
}

/// Polygon::new on tiny or huge coordinates: accepted exactly when its mass properties fit.
#[test]
fn polygons_at_extreme_magnitudes_are_accepted_or_refused_for_their_size() {
    let tri = [(-1.5, -0.5), (1.5, -0.5), (0.0, 1.0)];
    let at = |k: f64| -> Vec<Vec2> { tri.iter().map(|&(x, y)| Vec2::new(x * k, y * k)).collect() };
    let unit = Polygon::new(&at(1.0)).unwrap();
    for k in [1e-300, 1e-100, 1e100, 1e300] {
        assert!(
            matches!(
                Polygon::new(&at(k)),
                Err(PolygonError::NotRepresentable { .. })
            ),
            "{k}"
        );
    }
    // Subnormal coordinates too.
    assert!(matches!(
        Polygon::new(&at(1e-310)),
        Err(PolygonError::NotRepresentable { .. })
    ));
    for k in [1e-70, 1e-35, 1e35, 1e70] {
        let p = Polygon::new(&at(k)).unwrap();
        assert!(
            (p.radius() / k - unit.radius()).abs() < 1e-14 * unit.radius(),
            "{k}"
        );
        assert_eq!(p.stable_states().len(), 3);
        for (s, u) in p.stable_states().iter().zip(unit.stable_states()) {
            assert!((s.theta_rad - u.theta_rad).abs() < 1e-12, "{k}");
        }
    }
    // A power-of-two scale gives bit-identical results scaled back.
    let k = 2f64.powi(-200);
    let p = Polygon::new(&at(k)).unwrap();
    assert_eq!(p.radius(), unit.radius() * k);
    assert_eq!(p.area(), unit.area() * k * k);
    assert_eq!(p.stable_states(), {
        let mut s = unit.stable_states();
        for x in &mut s {
            x.height *= k;
        }
        s
    });
}

/// Issue 11 item 7: `contact --fence=30:1e20` returned contact false with status ok.
#[test]
fn contact_fence_length_1e20_is_refused() {
    contact_refused_saying(
        &["--fence=30:1e20"],
        &["--fence", "length", "1e6·a", "got 1e20"],
    );
    // The longest allowed fence (mechanics::limits::FENCE_LENGTH_A: 1e6·a, a = √½ for the
    // square) still works.
    let v = json(&[
        "contact",
        "--part",
        "square",
        "--theta0",
        "10",
        "--d",
        "0",
        "--fence=30:707106",
        "--json",
    ]);
    assert_eq!(v["contact"], true);
}

/// Issue 11 item 7: `--pin-radius 1e308` was accepted.
#[test]
fn contact_pin_radius_1e308_is_refused() {
    contact_refused_saying(
        &["--pin-radius", "1e308"],
        &["--pin-radius", "10·a", "got 1e308"],
    );
}

/// Issue 11 item 7: `--pin-speed 1e308` was accepted.
#[test]
fn contact_pin_speed_1e308_is_refused() {
    contact_refused_saying(
        &["--pin-speed", "1e308"],
        &["--pin-speed", "[-10, 10]", "got 1e308"],
    );
}

/// Issue 11 item 7: `--theta0 1e308` was accepted.
#[test]
fn contact_theta0_1e308_is_refused() {
    refused_saying(
        &[
            "contact", "--part", "tripoly1", "--theta0", "1e308", "--d", "0.2",
        ],
        &["--theta0", "[-1e6, 1e6]", "got 1e308"],
    );
    // Within the range, a turn of whole revolutions changes nothing.
    let r = |t: &str| {
        json(&[
            "contact", "--part", "tripoly1", "--theta0", t, "--d", "0.2", "--json",
        ])["theta_final_deg"]
            .as_f64()
            .unwrap()
    };
    assert!((r("10") - r("720010")).abs() < 1e-6);
}

/// d beyond the pin's reach is refused (it was a silent "no contact"); a moving pin reaches further.
#[test]
fn contact_d_beyond_reach_is_refused() {
    refused_saying(
        &[
            "contact", "--part", "tripoly1", "--theta0", "10", "--d", "1.2",
        ],
        &["--d", "out of range", "cannot touch"],
    );
    let v = json(&[
        "contact",
        "--part",
        "tripoly1",
        "--theta0",
        "10",
        "--d",
        "1.2",
        "--pin-speed",
        "0.5",
        "--json",
    ]);
    assert_eq!(v["status"], "ok");
}

/// The other contact ranges: friction, tolerance, each naming the flag, range and value.
#[test]
fn contact_friction_and_tolerance_ranges() {
    for (extra, words) in [
        (["--mu-c", "5.5"], ["--mu-c", "[0, 5]"]),
        (["--mu-s", "1e308"], ["--mu-s", "got 1e308"]),
        (["--mu-s", "5e-324"], ["--mu-s", "[1e-6, 100]"]),
        (["--tol", "1e-11"], ["--tol", "[1e-10, 0.01]"]),
        (["--tol", "0.5"], ["--tol", "got 0.5"]),
    ] {
        contact_refused_saying(&extra, &words);
    }
}

/// `--cases` rows are checked like flags, naming the file, line and column.
#[test]
fn cases_rows_out_of_range_name_line_and_column() {
    let dir = std::env::temp_dir().join(format!("pinfeed-regress-cases-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("cases.csv");
    let huge_row = format!("\"vertices:{HUGE}\",10,0.3,0.5,,");
    for (row, words) in [
        (
            "tripoly2,1e308,0.3,0.5,,",
            vec!["cases.csv:3", "column theta0"],
        ),
        (
            "tripoly2,10,5,0.5,,",
            vec!["cases.csv:3", "column d", "out of range"],
        ),
        ("tripoly2,10,0.3,50,,", vec!["cases.csv:3", "column mu_c"]),
        (
            "tripoly2,10,0.3,0.5,,1e308",
            vec!["cases.csv:3", "column pin_radius"],
        ),
        ("tripoly2,10,0.3,0.5,,", vec![]),
        (huge_row.as_str(), vec!["cases.csv:3", "polar moment"]),
    ] {
        let text = format!("part,theta0,d,mu_c,model,pin_radius\ntripoly2,10,0.3,0.5,,\n{row}\n");
        std::fs::write(&f, text).unwrap();
        let out = pinfeed(&["contact", "--cases", f.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{err}");
        if words.is_empty() {
            assert!(out.status.success(), "{row}: {err}");
            assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 3);
            continue;
        }
        assert_eq!(out.status.code(), Some(1), "{row}: {err}");
        for w in words {
            assert!(err.contains(w), "{row}: stderr should say '{w}': {err}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Absurd counts are refused before any work: they named no bound before, or allocated per item.
#[test]
fn absurd_counts_are_refused() {
    refused_saying(
        &[
            "run",
            "scenarios/quickstart.toml",
            "--parts",
            "1000000000000000000",
            "--quiet",
        ],
        &["--parts", "[1, 1000000000]"],
    );
    refused_saying(
        &[
            "compare",
            "scenarios/quickstart.toml",
            "--parts",
            "1000000000000000000",
        ],
        &["--parts"],
    );
    refused_saying(
        &[
            "mc",
            "studies/quickstart_mu_tripod.toml",
            "--samples",
            "1000000000000000000",
        ],
        &["--samples"],
    );
    refused_saying(
        &[
            "mc",
            "studies/quickstart_mu_tripod.toml",
            "--threads",
            "100000",
        ],
        &["--threads", "[1, 1024]"],
    );
    let map = ["map", "--part", "tripoly1", "--no-write"];
    for (extra, words) in [
        (vec!["--d=0.5", "--threads", "100000"], vec!["--threads"]),
        (
            vec![
                "--d=0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,0.95,0.99",
                "--theta-step",
                "0.001",
            ],
            vec!["contacts", "3600000"],
        ),
        (
            vec!["--d=0.5", "--theta-step", "1e300"],
            vec!["--theta-step", "got 1e300"],
        ),
        (
            vec!["--d=0.5", "--threshold", "1e300"],
            vec!["--threshold", "got 1e300"],
        ),
        (
            vec!["--d=0.5", "--pin-radius", "1e300"],
            vec!["--pin-radius"],
        ),
        (vec!["--fence", "30:1e300"], vec!["--fence", "length"]),
    ] {
        let mut args = map.to_vec();
        args.extend(extra);
        refused_saying(&args, &words);
    }
}
