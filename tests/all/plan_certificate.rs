//! `pinfeed plan` on a part no line touching only its hull can orient (docs/commands.md, "Parts
//! no line can orient"): a certificate with its reason and bound, not a search that ends low.

use crate::plan_cli::{pinfeed, plan_json};

/// A hexagon of 20 mm with a notch 0.8 mm wide and 1 mm deep in one edge, drawn to 0.1 µm.
const NOTCHED: &str = "vertices:20,0 15.2,8.3138 14.134,8.1603 14.8,9.0067 10,17.3205 -10,17.3205 -20,0 -10,-17.3205 10,-17.3205";

/// The notched hexagon's design states the certificate (six-fold hull, no symmetry of its own,
/// a 2 mm pin cannot reach the notch, at most 1/6 in one window) and searches none of the modes
/// it covers: every mode is "impossible" and there is no design, quickly. A point pin reaches
/// the notch: then only the fence mode is ruled out and the pin modes are searched.
#[test]
fn a_hexagon_with_a_small_notch_gets_a_certificate_not_a_search() {
    let args = |pin: &'static str| {
        vec![
            "plan",
            "--part",
            NOTCHED,
            "--scale",
            "0.001",
            "--pin-radius",
            pin,
            "--no-write",
            "--json",
            "--time-limit",
            "20",
        ]
    };
    let (code, v) = plan_json(&args("2"));
    assert_ne!(code, 0, "{}", v["message"]);
    let c = &v["certificate"];
    assert_eq!(c["hull_symmetry"], 6, "{v}");
    assert_eq!(c["part_symmetry"], 1);
    assert_eq!(c["pins_reach_notches"], false);
    assert!((c["bound"].as_f64().unwrap() - 1.0 / 6.0).abs() < 1e-9);
    assert!(c["centroid_offset_a"].as_f64().unwrap() < 0.02);
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 4, "{v}");
    for m in modes {
        assert_eq!(m["outcome"], "impossible", "{m}");
    }
    assert_eq!(v["status"], "no_design", "{}", v["status"]);
    assert!(v["elapsed_s"].as_f64().unwrap() < 5.0, "{}", v["elapsed_s"]);
    // A point pin can touch the notch: fences alone are ruled out (the pin modes are searched,
    // here for 3 s, and end on the time limit).
    let mut point = args("0");
    let n = point.len();
    point[n - 1] = "3";
    let out = pinfeed(&point);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["certificate"]["pins_reach_notches"], true, "{v}");
    for m in v["modes"].as_array().unwrap() {
        let ruled_out = m["outcome"] == "impossible";
        assert_eq!(ruled_out, m["mode"] == "fences", "{m}");
    }
}
