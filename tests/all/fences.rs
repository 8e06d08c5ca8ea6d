//! Fences (docs/physics.md#fences): flush stable orientations, the jam angle, the COR-tip bound, μs invariance,
//! short fences, mirror symmetry — for the contact model's fence path.

use crate::common::*;
use pinfeed::geometry::{wrap_deg, Polygon, Pose};
use pinfeed::maps::fence_pass_start;
use pinfeed::mechanics::{
    push_fence, ContactFeature, ContactOutcome, ContactSettings, ContactStatus, FenceSpec,
    Fidelity, Mode, PartModel,
};

/// A fence whose line crosses the part's path at y = d·a, clear of the part, starting 1.5a beyond
/// the part's band (the CLI's convention, `pinfeed::maps::fence_pass_start`), of length `len`
/// (units of a).
fn fence(p: &Polygon, angle_deg: f64, d: f64, len: f64, mu_f: f64) -> FenceSpec {
    fence_pass_start(p, d, angle_deg, Some(len * p.radius()), mu_f)
}

fn run_fence(m: &PartModel, p: &Polygon, th: f64, f: &FenceSpec, fid: Fidelity) -> ContactOutcome {
    let s = ContactSettings {
        fidelity: fid,
        ..ContactSettings::default()
    };
    let _ = p;
    push_fence(m, Pose::new(0.0, 0.0, th.to_radians()), f, &s, None)
}

/// Orientations at which hull edge j lies flush on a fence at angle α: its outward normal points at
/// α − 90° (against the fence normal).
fn flush_orientations(m: &PartModel, angle_deg: f64) -> Vec<f64> {
    let h = m.hull();
    (0..h.len())
        .map(|j| {
            let out = -h.inward_normal(j);
            wrap_deg(angle_deg - 90.0 - out.angle().to_degrees())
        })
        .collect()
}

/// A long fence at 30–60° leaves every tripoly2 with an edge flush: while it translates along the
/// fence its orientation is exactly one of the fence's flush orientations.
#[test]
fn long_fence_leaves_an_edge_flush() {
    let p = poly("tripoly2");
    let m = model(&p);
    for fid in FIDELITIES {
        for angle in [30.0, 40.0, 50.0, 60.0] {
            let flush = flush_orientations(&m, angle);
            let f = fence(&p, angle, 0.0, 20.0, 0.3);
            for k in 0..24 {
                let th = k as f64 * 15.0 + 1.0;
                let o = run_fence(&m, &p, th, &f, fid);
                assert_finite(&o, "fence");
                assert!(o.status.is_ok(), "{fid} α={angle} θ0={th}: {:?}", o.status);
                let seg = o
                    .segments
                    .iter()
                    .rev()
                    .find(|s| matches!(s.feature, ContactFeature::FenceEdge(_)))
                    .unwrap_or_else(|| panic!("{fid} α={angle} θ0={th}: never flush"));
                assert!(seg.s_end > seg.s_begin, "the flush edge translates");
                assert_eq!(
                    seg.theta_begin_rad, seg.theta_end_rad,
                    "a flush edge does not turn"
                );
                let th_f = wrap_deg(seg.theta_end_rad.to_degrees());
                let best = flush
                    .iter()
                    .map(|&q| ang_diff_deg(q, th_f).abs())
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    best < 1e-9,
                    "{fid} α={angle} θ0={th}: flush at {th_f}°, set {flush:?}"
                );
            }
        }
    }
}

/// The jam condition holds exactly at α + atan μf = 90°: just below the part slides along the fence;
/// at the angle and above it jams (reported, never integrated for ever).
#[test]
fn jam_exactly_at_the_predicted_angle() {
    let p = poly("tripoly2");
    let m = model(&p);
    for mu in [0.2, 0.5, 1.0] {
        let critical = 90.0 - f64::atan(mu).to_degrees();
        for fid in FIDELITIES {
            for th in [10.0, 200.0] {
                let below = run_fence(&m, &p, th, &fence(&p, critical - 0.05, 0.0, 20.0, mu), fid);
                assert!(
                    !matches!(below.status, ContactStatus::Jam { .. }),
                    "{fid} μf={mu} θ0={th}: jammed below the critical angle"
                );
                for angle in [critical, critical + 1e-6, critical + 2.0] {
                    let o = run_fence(&m, &p, th, &fence(&p, angle, 0.0, 20.0, mu), fid);
                    assert!(
                        matches!(o.status, ContactStatus::Jam { .. }),
                        "{fid} μf={mu} α={angle} θ0={th}: {:?}",
                        o.status
                    );
                    assert_finite(&o, "jam");
                }
            }
        }
    }
}

/// Peshkin & Sanderson's COR-locus tip is the slowest rotation: the exact model turns an edge flush
/// in no more belt travel than the tip model does.
#[test]
fn exact_aligns_no_later_than_the_cor_tip_bound() {
    let mut compared = 0;
    for name in ["tripoly1", "tripoly2", "square"] {
        let p = poly(name);
        let m = model(&p);
        for angle in [30.0, 45.0] {
            let f = fence(&p, angle, 0.0, 30.0, 0.0);
            for k in 0..12 {
                let th = k as f64 * 30.0 + 7.0;
                let first_flush = |fid| {
                    run_fence(&m, &p, th, &f, fid)
                        .segments
                        .iter()
                        .find(|s| matches!(s.feature, ContactFeature::FenceEdge(_)))
                        .map(|s| (s.s_begin, s.theta_begin_rad))
                };
                let (Some(exact), Some(tip)) =
                    (first_flush(Fidelity::Exact), first_flush(Fidelity::Tip))
                else {
                    continue;
                };
                if ang_diff_deg(exact.1.to_degrees(), tip.1.to_degrees()).abs() > 1e-6 {
                    continue; // they reached different edges: no common yardstick
                }
                assert!(
                    exact.0 <= tip.0 + 1e-9,
                    "{name} α={angle} θ0={th}: exact flush at travel {} after tip {}",
                    exact.0,
                    tip.0
                );
                compared += 1;
            }
        }
    }
    assert!(compared > 20, "only {compared} comparable pushes");
}

/// μs scales forces only: fence contacts are bit-identical for any μs, and the recorded fence
/// forces (units of m g) scale by exactly the ratio of the μs (40 here).
#[test]
fn fence_mu_s_invariance() {
    use pinfeed::mechanics::TraceSample;
    let p = poly("tripoly1");
    let m = model(&p);
    let f = fence(&p, 40.0, 0.2, 15.0, 0.4);
    for fid in FIDELITIES {
        let mut s = ContactSettings {
            fidelity: fid,
            mu_s: 0.05,
            ..ContactSettings::default()
        };
        let (mut ta, mut tb): (Vec<TraceSample>, Vec<TraceSample>) = (Vec::new(), Vec::new());
        let a = push_fence(&m, Pose::new(0.0, 0.0, 1.0), &f, &s, Some(&mut ta));
        s.mu_s = 2.0;
        let b = push_fence(&m, Pose::new(0.0, 0.0, 1.0), &f, &s, Some(&mut tb));
        assert_eq!(a, b, "{fid}");
        assert_eq!(ta.len(), tb.len());
        for (x, y) in ta.iter().zip(&tb) {
            assert_eq!(x.pose, y.pose);
            assert!(x.force.norm() > 0.0);
            assert!(
                (y.force.norm() / x.force.norm() - 40.0).abs() < 1e-11,
                "{fid}"
            );
        }
    }
}

/// A fence shorter than needed leaves parts in intermediate orientations (not flush).
#[test]
fn short_fence_leaves_intermediate_orientations() {
    let p = poly("tripoly2");
    let m = model(&p);
    let angle = 45.0;
    let flush = flush_orientations(&m, angle);
    let mut intermediate = 0;
    for k in 0..24 {
        let th = k as f64 * 15.0 + 1.0;
        let f = fence(&p, angle, 0.0, 1.6, 0.3);
        let o = run_fence(&m, &p, th, &f, Fidelity::Exact);
        assert!(o.status.is_ok(), "θ0={th}: {:?}", o.status);
        let th_f = wrap_deg(o.pose_final.theta_rad.to_degrees());
        if flush.iter().all(|&q| ang_diff_deg(q, th_f).abs() > 0.5) {
            intermediate += 1;
        }
    }
    assert!(
        intermediate >= 6,
        "only {intermediate} of 24 parts left unaligned by a short fence"
    );
}

/// A frictionless fence never sticks or jams, and slides with the force along the normal.
#[test]
fn frictionless_fence_always_slides() {
    let p = poly("square");
    let m = model(&p);
    for angle in [20.0, 70.0, 85.0] {
        let o = run_fence(
            &m,
            &p,
            10.0,
            &fence(&p, angle, 0.1, 20.0, 0.0),
            Fidelity::Exact,
        );
        assert!(o.status.is_ok(), "α={angle}: {:?}", o.status);
        for s in &o.segments {
            if matches!(
                s.feature,
                ContactFeature::FenceVertex(_) | ContactFeature::FenceEdge(_)
            ) {
                assert_eq!(s.mode, Mode::Slide);
            }
        }
    }
}

/// Mirror symmetry: reflecting the part about the belt axis, the fence angle, θ0 and d negates the
/// rotation.
#[test]
fn fence_mirror_symmetry() {
    let p = poly("tripoly2");
    let q = p.mirrored_y();
    let (mp, mq) = (model(&p), model(&q));
    for fid in FIDELITIES {
        for th in [20.0, 140.0, 250.0] {
            let a = run_fence(&mp, &p, th, &fence(&p, 35.0, 0.1, 12.0, 0.3), fid);
            let b = run_fence(&mq, &q, -th, &fence(&q, -35.0, -0.1, 12.0, 0.3), fid);
            assert!(
                (a.rotation_rad + b.rotation_rad).abs() < 1e-7,
                "{fid} θ0={th}: {} vs {}",
                a.rotation_rad.to_degrees(),
                b.rotation_rad.to_degrees()
            );
        }
    }
}

/// `pinfeed contact --fence` runs through the CLI with the same JSON as pins.
#[test]
fn cli_fence_contact() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args([
            "contact", "--part", "tripoly2", "--theta0", "0", "--d", "0", "--fence", "30", "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["status"], "ok");
    let kinds: Vec<String> = v["segments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["feature"]["kind"].as_str().unwrap().to_string())
        .collect();
    assert!(kinds.iter().any(|k| k == "fence_edge"), "{kinds:?}");
    for bad in ["90", "-95", "abc", "30:-2"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_pinfeed"))
            .args([
                "contact", "--part", "tripoly2", "--theta0", "0", "--d", "0", "--fence", bad,
            ])
            .output()
            .unwrap();
        assert!(!out.status.success(), "--fence {bad} accepted");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--fence"));
    }
}

/// A seeded sweep of fences (angle 5–85°, either side, μf 0–1.2, length 0.5–25a) over four parts and
/// all fidelities: every contact ends ok, jammed or held — never in a numerical status.
#[test]
fn fence_sweep_has_no_numerical_failures() {
    use rand::RngExt;
    let mut rng = pinfeed::random::stream(77, 0);
    let mut failures = Vec::new();
    for name in ["tripoly1", "tripoly2", "square", "lshape"] {
        let p = poly(name);
        let m = model(&p);
        for fid in FIDELITIES {
            for _ in 0..40 {
                let side = if rng.random::<bool>() { 1.0 } else { -1.0 };
                let angle = side * (5.0 + 80.0 * rng.random::<f64>());
                let mu = 1.2 * rng.random::<f64>();
                let len = 0.5 + 24.5 * rng.random::<f64>();
                let d = -0.8 + 1.6 * rng.random::<f64>();
                let th = 360.0 * rng.random::<f64>();
                let o = run_fence(&m, &p, th, &fence(&p, angle, d, len, mu), fid);
                assert_finite(&o, name);
                // The jam rule: a jam only where |α| + atan μf ≥ 90° (either sign of α), and a
                // flush edge on such a fence always jams.
                let steep = angle.abs() + mu.atan().to_degrees() >= 90.0;
                let jammed = matches!(o.status, ContactStatus::Jam { .. });
                assert!(
                    !jammed || steep,
                    "{name} {fid} α={angle} μf={mu}: jam below 90°"
                );
                let flush = o.segments.iter().any(|s| s.feature.kind() == "fence_edge");
                if steep && flush {
                    assert!(jammed, "{name} {fid} α={angle} μf={mu}: flush, no jam");
                }
                if !matches!(
                    o.status,
                    ContactStatus::Ok
                        | ContactStatus::Jam { .. }
                        | ContactStatus::TravelLimit { .. }
                ) {
                    failures.push(format!(
                        "{name} {fid} α={angle} μf={mu} L={len} d={d} θ0={th}: {:?}",
                        o.status
                    ));
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// A fence sliding on a vertex of the part's hull is served by that polygon vertex's slide
/// tables when the model has them for μf (a scene's model tabulates its fences' μf as well as its
/// pins' μc): the same pushes, the final poses within a tenth of the integrator's tolerance per
/// step (the tables agree with the live solve to 1e-10; the step sizes then differ slightly),
/// with fewer evaluations per push (a table's build is counted as the table's). tripoly2 and
/// the concave `lshape` (whose hull skips a reflex vertex), fences at ±20–50°, μf 0.3 and 0.6.
#[test]
fn fence_slides_on_hull_vertices_are_served_by_the_slide_tables() {
    for p in [
        pinfeed::geometry::part_from_spec("tripoly2").unwrap(),
        pinfeed::geometry::part_from_spec("lshape").unwrap(),
    ] {
        for mu_f in [0.3, 0.6] {
            let plain = model(&p);
            let tabled = model(&p).with_slide_tables(&[mu_f]);
            // Every hull vertex is one of the polygon's convex vertices.
            let (hull, poly) = (tabled.hull(), tabled.polygon());
            for k in 0..hull.len() {
                let i = tabled.hull_vertex_in_polygon(k).expect("a polygon vertex");
                assert_eq!(poly.vertex(i), hull.vertex(k));
                assert!(poly.vertex_is_convex(i));
            }
            let (mut e_plain, mut e_tabled, mut n) = (0u64, 0u64, 0);
            for angle in [-50.0, -20.0, 20.0, 35.0, 50.0] {
                for k in 0..24 {
                    let th = 15.0 * k as f64 + 0.37;
                    let d = -0.4 + 0.8 * ((k * 7 % 24) as f64) / 23.0;
                    let f = fence(&p, angle, d, 3.0, mu_f);
                    let a = run_fence(&plain, &p, th, &f, Fidelity::Exact);
                    let b = run_fence(&tabled, &p, th, &f, Fidelity::Exact);
                    assert_eq!(a.status, b.status, "{angle}° θ {th}");
                    let (pa, pb) = (a.pose_final, b.pose_final);
                    let dth = wrap_deg((pa.theta_rad - pb.theta_rad).to_degrees());
                    let dth = dth.min(360.0 - dth);
                    let tol = ContactSettings::default().tol;
                    assert!(dth.to_radians() < 0.1 * tol, "{angle}° θ {th}: Δθ {dth}°");
                    let r = p.radius();
                    let dp = (pa.x - pb.x).abs() + (pa.y - pb.y).abs();
                    assert!(dp < 0.1 * tol * r, "{angle}° θ {th}: Δp {:e} a", dp / r);
                    e_plain += a.evaluations;
                    e_tabled += b.evaluations;
                    n += usize::from(a.contact);
                }
            }
            assert!(n > 60, "{n} pushes touched the fence");
            let stats = tabled.slide_table_stats().unwrap();
            assert!(stats.tables > 0, "no vertex table was built: {stats:?}");
            assert!(
                e_tabled * 10 < e_plain * 9,
                "μf {mu_f}: {e_tabled} evaluations with tables against {e_plain} without"
            );
        }
    }
}

/// A fence meets a concave part where the part's own vertices are: the travel to first touch is
/// the smallest over the part's vertices (in the world at its pose) of the travel that brings
/// the fence's line to the vertex — the hull the contact model uses is in the part's frame, not
/// re-centred on the hull's own centroid.
#[test]
fn a_fence_first_touches_a_concave_part_at_its_own_vertices() {
    use pinfeed::mechanics::fence_first_touch;
    let l = pinfeed::geometry::part_from_spec("lshape").unwrap();
    let m = model(&l);
    for (k, angle) in [-40.0f64, -15.0, 20.0, 45.0].into_iter().enumerate() {
        for j in 0..12 {
            let pose = Pose::new(0.3, -0.2, (30.0 * j as f64 + 7.0 * k as f64).to_radians());
            let (s, c) = angle.to_radians().sin_cos();
            let e = pinfeed::geometry::Vec2::new(c, s);
            // A long fence whose line passes 4 units (perpendicular) clear of the part's
            // centroid, to its right.
            let through = pinfeed::geometry::Vec2::new(0.3 + 4.0 / s.abs(), -0.2);
            let start = through - e * 100.0;
            let f = FenceSpec {
                start,
                angle_rad: angle.to_radians(),
                length: 200.0,
                mu_f: 0.3,
                tail_radius: None,
            };
            // The line moved by (−t, 0) holds v when cross(e, v − start + t x̂) = 0, i.e.
            // t = cross(e, v − start) / sin α.
            let expected = l
                .world_vertices(&pose)
                .iter()
                .map(|&v| {
                    let d = v - start;
                    (e.x * d.y - e.y * d.x) / s
                })
                .fold(f64::INFINITY, f64::min);
            let Some(got) = fence_first_touch(&m, pose, &f) else {
                panic!(
                    "fence {angle}° θ {}°: no touch (expected {expected})",
                    30 * j
                )
            };
            assert!(
                (got - expected).abs() < 1e-9,
                "fence {angle}°, θ {}°: first touch at travel {got}, the part's vertices say {expected}",
                30 * j
            );
        }
    }
}

/// A part leaving over a fence's end ends where it ends at every integration tolerance: the
/// pivot about the end lets go as the edge's far vertex reaches the end, and that vertex, landed
/// within the event's error of the end, is at the end — not a new touch of the fence line, which
/// snapped the part back flush (the kite below at −45.05°, 1e-6: 334.6° where 1e-9 gives 1.7°).
/// Parts, angles, lengths and orientations over a grid, with a few angles 0.005° apart; the final
/// orientations at 1e-6 and 1e-9 agree within 0.05°.
#[test]
fn a_part_leaving_over_a_fence_end_ends_alike_at_every_tolerance() {
    let parts = [
        "vertices:0,0 20,-8 48,0 20,10",
        "tripoly2",
        "lshape",
        "random:3",
        "random:7",
    ];
    let mut angles: Vec<f64> = (0..9).map(|k| -50.0 + 12.5 * k as f64).collect();
    angles.extend([-45.055, -45.05, -45.045]);
    let mut cases = 0;
    for name in parts {
        let p = poly(name);
        let m = model(&p);
        // Short fences, which parts leave over the end; the kite's also at the length of the
        // line where this was found (78.489 mm).
        let last = if name.starts_with("vertices") {
            78.489 / p.radius()
        } else {
            3.0
        };
        let lengths = [1.4, 2.2, last];
        for &angle in &angles {
            for &len in &lengths {
                let f = fence(&p, angle, 0.0, len, 0.5);
                for k in 0..6 {
                    let th = if k == 0 {
                        4.0249
                    } else {
                        k as f64 * 61.0 + 7.0
                    };
                    let at = |tol: f64| {
                        let s = ContactSettings {
                            tol,
                            ..ContactSettings::default()
                        };
                        push_fence(&m, Pose::new(0.0, 0.0, th.to_radians()), &f, &s, None)
                    };
                    let (coarse, fine) = (at(1e-6), at(1e-9));
                    assert!(coarse.status.is_ok() && fine.status.is_ok(), "{name}");
                    let d = ang_diff_deg(
                        coarse.pose_final.theta_rad.to_degrees(),
                        fine.pose_final.theta_rad.to_degrees(),
                    );
                    assert!(
                        d.abs() < 0.05,
                        "{name} at {angle}°, length {len:.2}a, θ0 {th}°: {:.3}° at 1e-6, {:.3}° at 1e-9",
                        wrap_deg(coarse.pose_final.theta_rad.to_degrees()),
                        wrap_deg(fine.pose_final.theta_rad.to_degrees())
                    );
                    cases += 1;
                }
            }
        }
    }
    assert_eq!(cases, 5 * 12 * 3 * 6);
}
