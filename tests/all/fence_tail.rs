//! Fences that end in a curved tail (issue 52 item 3; docs/physics.md#fences): the exit on random
//! tripods, mirror symmetry, and bad tail radii refused where they are written. The tail against
//! ever finer straight pieces is the library's unit test
//! `mechanics::fence::tests::a_tail_agrees_with_ever_finer_straight_pieces`.

use crate::common::*;
use pinfeed::geometry::{wrap_deg, Polygon, Pose};
use pinfeed::maps::fence_pass_start;
use pinfeed::mechanics::{push_fence, ContactSettings, FenceSpec, PartModel, Support};
use std::process::Command;

/// The fence of the tests: the CLI's placement (`pinfeed contact --fence`), `len` units of a long,
/// μf 0.5, with a tail of `tail` units of a (or none).
fn fence(p: &Polygon, angle_deg: f64, len: f64, tail: Option<f64>) -> FenceSpec {
    let a = p.radius();
    fence_pass_start(p, 0.0, angle_deg, Some(len * a), 0.5).with_tail(tail.map(|r| r * a))
}

/// The signed angle (degrees) from the exit orientation `theta_deg` to the nearest orientation at
/// which a hull edge lies parallel to the belt with the part on the fence's side (`side` +1: the
/// part above the fence, a positive fence; −1 below): the orientation a tail aims for.
fn off_parallel(m: &PartModel, theta_deg: f64, side: f64) -> f64 {
    let h = m.hull();
    (0..h.len())
        .map(|j| {
            let out = -h.inward_normal(j);
            let parallel = wrap_deg(-side * 90.0 - out.angle().to_degrees());
            ang_diff_deg(theta_deg, parallel)
        })
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap()
}

/// Exit deviations from parallel over random tripods (seeds 1..=`tripods`) and eight θ0.
fn exits_on_tripods(p: &Polygon, f: &FenceSpec, tripods: u64) -> Vec<f64> {
    let settings = ContactSettings::default();
    let mut out = Vec::new();
    for seed in 1..=tripods {
        let mut rng = pinfeed::random::stream(seed, 0);
        let support = Support::random_tripod(p, &mut rng).unwrap();
        let m = PartModel::new(p, &support).unwrap();
        for k in 0..8 {
            let th = 7.0 + 45.0 * k as f64;
            let o = push_fence(&m, Pose::new(0.0, 0.0, th.to_radians()), f, &settings, None);
            assert!(o.status.is_ok(), "tripod {seed} θ0 {th}: {:?}", o.status);
            out.push(off_parallel(
                &m,
                o.pose_final.theta_rad.to_degrees(),
                f.angle_rad.signum(),
            ));
        }
    }
    out
}

fn spread(v: &[f64]) -> f64 {
    let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    hi - lo
}

/// A straight fence's exit depends on how the part pivots off its end, which depends on the
/// support: on random tripods the exit orientations of square and tripoly2 parts spread over
/// degrees (measured here, 6 tripods × 8 θ0: square 9.56°, tripoly2 13.84°). A tail of radius 40a
/// turns the flush edge nearly parallel to the belt whatever the support, and the exits spread by
/// at most 0.5° (measured 0.34° and 0.33°).
///
/// A circular tail does not bring the spread to zero: near its end the fence's tangent turns
/// parallel to the belt, the push on the part (∝ the sine of the tangent's angle) fades while the
/// fence still slides under the part, and the contact runs off the edge to a vertex at a small
/// angle that falls as 1/R (square: spread ≈ 9.5° / (R/a·√2): 2.6° at R = 4a, 0.77° at 17a, 0.47°
/// at 28a).
#[test]
fn a_tailed_fence_exits_aligned_on_random_tripods() {
    for name in ["square", "tripoly2"] {
        let p = poly(name);
        let straight = exits_on_tripods(&p, &fence(&p, 30.0, 6.0, None), 6);
        let tailed = exits_on_tripods(&p, &fence(&p, 30.0, 6.0, Some(40.0)), 6);
        let (s, t) = (spread(&straight), spread(&tailed));
        eprintln!("{name}: exit spread straight {s:.3}°, tailed {t:.3}°");
        assert!(s > 3.0, "{name}: a straight fence's exits spread only {s}°");
        assert!(t <= 0.5, "{name}: a tailed fence's exits spread {t}°");
        assert!(
            tailed.iter().all(|d| d.abs() <= 0.5),
            "{name}: a tailed exit is more than 0.5° off parallel: {tailed:?}"
        );
    }
}

/// Mirror symmetry: the part mirrored about the belt axis against the mirrored tailed fence (−α),
/// from the mirrored orientation, turns by exactly the opposite angle and ends at the mirrored
/// place.
#[test]
fn tailed_fences_are_mirror_symmetric() {
    let settings = ContactSettings::default();
    for name in ["tripoly2", "square"] {
        let p = poly(name);
        let q = p.mirrored_y();
        let (mp, mq) = (model(&p), model(&q));
        for (alpha, tail) in [(30.0, 3.0), (45.0, 8.0), (20.0, 0.5)] {
            let fp = fence(&p, alpha, 5.0, Some(tail));
            let fq = fence(&q, -alpha, 5.0, Some(tail));
            for th in [10.0f64, 80.0, 150.0, 230.0, 300.0] {
                let a = push_fence(
                    &mp,
                    Pose::new(0.0, 0.0, th.to_radians()),
                    &fp,
                    &settings,
                    None,
                );
                let b = push_fence(
                    &mq,
                    Pose::new(0.0, 0.0, (-th).to_radians()),
                    &fq,
                    &settings,
                    None,
                );
                let what = format!("{name} α {alpha} tail {tail}a θ0 {th}");
                assert!(
                    a.status.is_ok() && b.status.is_ok(),
                    "{what}: {:?} {:?}",
                    a.status,
                    b.status
                );
                assert!(
                    a.segments.iter().any(|s| matches!(
                        s.feature,
                        pinfeed::mechanics::ContactFeature::Edge(_)
                            | pinfeed::mechanics::ContactFeature::Vertex(_)
                    )),
                    "{what}: never on the tail"
                );
                assert!(
                    (a.rotation_rad + b.rotation_rad).abs() < 1e-7,
                    "{what}: {} vs {}",
                    a.rotation_rad.to_degrees(),
                    b.rotation_rad.to_degrees()
                );
                // Positions agree to the integration's error over a slide of some 10a (tol 1e-6).
                let (pa, pb) = (a.pose_final, b.pose_final);
                let tol = 1e-4 * p.radius();
                assert!(
                    (pa.x - pb.x).abs() < tol && (pa.y + pb.y).abs() < tol,
                    "{what}: ({}, {}) vs ({}, {})",
                    pa.x,
                    pa.y,
                    pb.x,
                    pb.y
                );
            }
        }
    }
}

/// `pinfeed ARGS`.
fn pinfeed(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .output()
        .unwrap()
}

/// A scenario with one tailed fence (tail radius as written, `value`).
fn scenario(value: &str) -> String {
    format!(
        "[belt]\nspeed = 0.05\nwidth = 0.2\nlength = 1.0\n\n[part]\nshape = \"tripoly2\"\nscale = 0.02\n\n\
         [feed]\nparts = 10\narrival = \"periodic\"\nheadway = 4.0\norientation = \"stable\"\n\n\
         [[obstacles]]\nkind = \"fence\"\nx = 0.3\ny = -0.09\nangle = 30\nlength = 0.1\n\
         tail_radius = {value}\n\n[goal]\nany = true\n"
    )
}

/// Bad tail radii are refused where they are written: file, line, column, key and the range (in
/// metres and in units of a); a good one runs. The CLI's `--tail` is refused by name with its
/// range.
#[test]
fn bad_tail_radii_are_located_errors() {
    let dir = std::env::temp_dir().join(format!("pinfeed-tail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // tripoly2 at scale 0.02: a = 0.0274874 m, so the range is [2.74874e-4, 27.4874] m.
    for (value, got) in [
        ("0", "got 0"),
        ("-0.05", "got -0.05"),
        ("nan", "must be a finite number"),
        ("1e-5", "got 1e-5"),
        ("40.0", "got 40"),
    ] {
        let path = dir.join("tail.toml");
        std::fs::write(&path, scenario(value)).unwrap();
        let out = pinfeed(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{value}: {stderr}");
        let head = format!("{}:22:15: key `obstacles[0].tail_radius`: ", path.display());
        assert!(
            stderr.contains(&head),
            "{value}: expected '{head}' in:\n{stderr}"
        );
        assert!(
            stderr.contains(got),
            "{value}: expected '{got}' in:\n{stderr}"
        );
        if !value.contains("nan") {
            assert!(
                stderr.contains("must lie in [0.000274874, 27.4874] m (10⁻² a to 10³ a"),
                "{value}: no range in:\n{stderr}"
            );
        }
    }
    // A good radius runs (and every part leaves through the tail).
    let path = dir.join("good.toml");
    std::fs::write(&path, scenario("0.1")).unwrap();
    let out = pinfeed(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let map = |tail| {
        let args = ["map", "--part", "square", "--fence", "30", "--tail", tail];
        [&args[..], &["--no-write"]].concat()
    };
    let contact = "contact --part square --theta0 0 --d 0 --fence 30 --tail NaN";
    for (args, words) in [
        (map("0"), ["--tail must lie in [", "got 0"]),
        (map("1e4"), ["--tail must lie in", "got 10000"]),
        (
            contact.split(' ').collect(),
            ["--tail must lie in", "got NaN"],
        ),
    ] {
        let out = pinfeed(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} was accepted");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        for w in words {
            assert!(stderr.contains(w), "{args:?}: expected '{w}' in:\n{stderr}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `pinfeed map --fence ANGLE --tail R` maps the tailed fence: every exit of the square lies
/// within a few degrees of parallel to the belt where the straight fence's lies 4.6° off.
#[test]
fn map_maps_a_tailed_fence() {
    let run = |tail: Option<&str>| {
        let mut args = vec![
            "map",
            "--part",
            "square",
            "--fence",
            "30:6",
            "--theta-step",
            "15",
            "--json",
            "--no-write",
        ];
        if let Some(t) = tail {
            args.extend(["--tail", t]);
        }
        let out = pinfeed(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let map = &v["maps"][0];
        let finals: Vec<f64> = map["samples"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["theta_final_deg"].as_f64().unwrap())
            .collect();
        (map["fence"].clone(), finals)
    };
    let (f0, straight) = run(None);
    let (f1, tailed) = run(Some("10"));
    assert!(f0.get("tail").is_none(), "{f0}");
    assert_eq!(f1["tail"], 10.0, "{f1}");
    let off = |v: &[f64]| {
        v.iter()
            .map(|t| ((t % 90.0) + 90.0) % 90.0)
            .map(|t| t.min(90.0 - t))
            .fold(0.0, f64::max)
    };
    assert!(off(&straight) > 4.0, "{straight:?}");
    assert!(off(&tailed) < 0.7, "{tailed:?}");
}
