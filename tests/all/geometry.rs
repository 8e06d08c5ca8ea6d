//! Library-level tests of the part geometry (docs/physics.md#the-part): mass properties, `a`, convexity, stable states
//! of the named parts, validation of bad vertex lists, and invariance of stable states and `a` under
//! rotation, scaling and translation of the input (property tests).

use pinfeed::geometry::polygon::convex_hull;
use pinfeed::geometry::{part_from_spec, PartSpecError, Polygon, PolygonError, Vec2};
use proptest::prelude::*;

use crate::shapes;

const DEG_TOL: f64 = 1e-6;

fn stable_deg(p: &Polygon) -> Vec<f64> {
    p.stable_states()
        .iter()
        .map(|s| s.theta_rad.to_degrees())
        .collect()
}

fn assert_states(got: &[f64], want: &[f64]) {
    assert_eq!(
        got.len(),
        want.len(),
        "stable states {got:?}, want {want:?}"
    );
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() < DEG_TOL,
            "stable states {got:?}, want {want:?}"
        );
    }
}

/// Smallest distance between two angles in degrees, on the circle.
fn circ_dist_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

/// `got` and `want` are the same multiset of angles modulo 360° (to `tol` degrees).
fn same_angles_mod_360(got: &[f64], want: &[f64], tol: f64) -> Result<(), String> {
    if got.len() != want.len() {
        return Err(format!("count differs: got {got:?}, want {want:?}"));
    }
    let mut used = vec![false; got.len()];
    for w in want {
        let hit = got
            .iter()
            .enumerate()
            .filter(|(i, _)| !used[*i])
            .map(|(i, g)| (i, circ_dist_deg(*g, *w)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match hit {
            Some((i, d)) if d <= tol => used[i] = true,
            _ => return Err(format!("{w}° not matched: got {got:?}, want {want:?}")),
        }
    }
    Ok(())
}

#[test]
fn tripoly1_properties_and_stable_states() {
    let p = part_from_spec("tripoly1").unwrap();
    assert!((p.area() - 2.25).abs() < 1e-12);
    assert!(p.offset().norm() < 1e-12);
    assert!((p.radius() - 2.5f64.sqrt()).abs() < 1e-12);
    assert!(p.is_convex());
    assert_states(&stable_deg(&p), &[0.0, 135.0, 225.0]);
}

#[test]
fn tripoly2_properties_and_stable_states() {
    let p = part_from_spec("tripoly2").unwrap();
    assert!((p.area() - 1.0).abs() < 1e-12);
    assert!(p.offset().norm() < 1e-12);
    // Farthest vertex (4/3, −1/3): a = √17 / 3.
    assert!((p.radius() - 17f64.sqrt() / 3.0).abs() < 1e-12);
    assert!(p.is_convex());
    // The hypotenuse's outward normal is at atan2(2, 1); 206.565° = 180° + atan(1/2).
    let third = 180.0 + 0.5f64.atan().to_degrees();
    assert!((third - 206.565).abs() < 1e-3);
    assert_states(&stable_deg(&p), &[0.0, 90.0, third]);
}

#[test]
fn stable_state_heights_are_radius_function_minima() {
    // Each stable state's height is the distance to its resting edge and equals depth_below(θ).
    for name in ["tripoly1", "tripoly2", "lshape", "ngon:7", "rect:3:1"] {
        let p = part_from_spec(name).unwrap();
        for s in p.stable_states() {
            assert!(
                (p.depth_below(s.theta_rad) - s.height).abs() < 1e-12,
                "{name}"
            );
            for dt in [-1e-3, 1e-3] {
                assert!(
                    p.depth_below(s.theta_rad + dt) > s.height,
                    "{name}: not a minimum"
                );
            }
        }
    }
}

#[test]
fn tripoly2_placed_anywhere_gives_same_answers() {
    // The same triangle typed in other coordinates (shifted, clockwise) is normalised to the same part.
    let p = Polygon::from_xy(&[(10.0, 4.0), (8.0, 5.0), (8.0, 4.0)]).unwrap();
    assert!((p.offset() - Vec2::new(26.0 / 3.0, 13.0 / 3.0)).norm() < 1e-12);
    assert!((p.area() - 1.0).abs() < 1e-12);
    let third = 180.0 + 0.5f64.atan().to_degrees();
    assert_states(&stable_deg(&p), &[0.0, 90.0, third]);
}

#[test]
fn square_rect_and_ngon_stable_states() {
    assert_states(
        &stable_deg(&part_from_spec("square").unwrap()),
        &[0.0, 90.0, 180.0, 270.0],
    );
    let r = part_from_spec("rect:3:1").unwrap();
    assert!((r.area() - 3.0).abs() < 1e-12);
    assert!((r.radius() - (1.5f64.powi(2) + 0.25).sqrt()).abs() < 1e-12);
    assert_states(&stable_deg(&r), &[0.0, 90.0, 180.0, 270.0]);
    let h = part_from_spec("ngon:6").unwrap();
    assert!((h.radius() - 1.0).abs() < 1e-12);
    // Hexagon of circumradius 1: area 3√3/2.
    assert!((h.area() - 1.5 * 3f64.sqrt()).abs() < 1e-12);
    assert_states(&stable_deg(&h), &[0.0, 60.0, 120.0, 180.0, 240.0, 300.0]);
}

#[test]
fn lshape_is_concave_and_rests_on_its_hull() {
    // Concave L of three unit squares: centroid (5/6, 5/6), stable states from its 5-edge hull,
    // including 225° on the hull edge that bridges the notch.
    let l = part_from_spec("lshape").unwrap();
    assert!(!l.is_convex());
    assert!((l.area() - 3.0).abs() < 1e-12);
    assert!((l.offset() - Vec2::new(5.0 / 6.0, 5.0 / 6.0)).norm() < 1e-12);
    let far = Vec2::new(2.0, 0.0) - l.offset(); // (2,0) and (0,2) are the farthest vertices
    assert!((l.radius() - far.norm()).abs() < 1e-12);
    assert_eq!(l.len(), 6);
    assert_eq!(l.hull().len(), 5);
    assert_states(&stable_deg(&l), &[0.0, 90.0, 180.0, 225.0, 270.0]);
}

#[test]
fn exactly_collinear_vertex_is_dropped_without_changing_the_part() {
    let with =
        Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]).unwrap();
    let without = Polygon::from_xy(&[(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]).unwrap();
    assert_eq!(with.len(), 4);
    assert!((with.area() - without.area()).abs() < 1e-15);
    assert_states(&stable_deg(&with), &stable_deg(&without));
}

#[test]
fn rejects_too_few_vertices() {
    for pts in [vec![], vec![(0.0, 0.0)], vec![(0.0, 0.0), (1.0, 0.0)]] {
        let n = pts.len();
        let e = Polygon::from_xy(&pts).unwrap_err();
        assert_eq!(e, PolygonError::TooFewVertices { count: n });
        assert!(e.to_string().contains("at least 3"));
    }
}

#[test]
fn rejects_collinear_and_zero_area() {
    let e = Polygon::from_xy(&[(0.0, 0.0), (1.0, 1.0), (3.0, 3.0), (2.0, 2.0)]).unwrap_err();
    assert_eq!(e, PolygonError::ZeroArea);
    assert!(e.to_string().contains("collinear"));
    // A sliver whose area is below the relative tolerance is degenerate too.
    let e = Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (2.0, 1e-14)]).unwrap_err();
    assert_eq!(e, PolygonError::ZeroArea);
}

#[test]
fn rejects_self_intersection() {
    // Bow tie.
    let e = Polygon::from_xy(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]).unwrap_err();
    assert!(matches!(e, PolygonError::SelfIntersecting { .. }), "{e}");
    assert!(e.to_string().contains("not simple"));
    // A vertex touching a non-adjacent edge.
    let e = Polygon::from_xy(&[(0.0, 0.0), (4.0, 0.0), (4.0, 2.0), (2.0, 0.0), (0.0, 2.0)])
        .unwrap_err();
    assert!(matches!(e, PolygonError::SelfIntersecting { .. }), "{e}");
    // A spike that runs back along its own edge.
    let e = Polygon::from_xy(&[(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)]).unwrap_err();
    assert!(matches!(e, PolygonError::SelfIntersecting { .. }), "{e}");
    // A vertex repeated non-consecutively (the ring visits it twice).
    let e = Polygon::from_xy(&[
        (0.0, 0.0),
        (2.0, 0.0),
        (1.0, 1.0),
        (2.0, 2.0),
        (0.0, 2.0),
        (1.0, 1.0),
    ])
    .unwrap_err();
    assert!(matches!(e, PolygonError::SelfIntersecting { .. }), "{e}");
}

#[test]
fn rejects_non_finite() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = Polygon::from_xy(&[(0.0, 0.0), (1.0, bad), (0.0, 1.0)]).unwrap_err();
        assert!(matches!(e, PolygonError::NonFinite { index: 1, .. }), "{e}");
        assert!(e.to_string().contains("non-finite"));
    }
}

#[test]
fn rejects_repeated_vertex() {
    let e = Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 1.0)]).unwrap_err();
    assert_eq!(
        e,
        PolygonError::RepeatedVertex {
            index: 2,
            previous: 1,
            hint: ""
        }
    );
    // Closing the ring by repeating the first vertex is refused with a hint.
    let e = Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.0, 0.0)]).unwrap_err();
    assert!(matches!(
        e,
        PolygonError::RepeatedVertex {
            index: 3,
            previous: 0,
            ..
        }
    ));
    assert!(e.to_string().contains("repeats"));
    assert!(e.to_string().contains("do not repeat the first vertex"));
}

#[test]
fn tiny_but_real_edges_are_kept() {
    // An edge of 1e-9 of the part's size is not a repeated vertex (module docs).
    let p = Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (1.0, 1e-9), (0.0, 1.0)]).unwrap();
    assert_eq!(p.len(), 4);
}

#[test]
fn bad_part_specs() {
    assert!(matches!(
        part_from_spec("blob"),
        Err(PartSpecError::Unknown(_))
    ));
    for bad in [
        "rect:2",
        "rect:0:1",
        "rect:a:1",
        "rect:1:-2",
        "rect:nan:1",
        "rect:inf:1",
        "ngon:2",
        "ngon:1001",
        "ngon:x",
        "ngon:-3",
        "ngon:4.5",
    ] {
        assert!(
            matches!(part_from_spec(bad), Err(PartSpecError::BadParameter { .. })),
            "{bad} accepted or wrong error: {:?}",
            part_from_spec(bad)
        );
    }
    assert!(matches!(
        part_from_spec("vertices:0,0 1,0 0,1 2"),
        Err(PartSpecError::BadVertexList(_))
    ));
    assert!(matches!(
        part_from_spec("vertices:0,0 1,0"),
        Err(PartSpecError::Polygon(PolygonError::TooFewVertices {
            count: 2
        }))
    ));
}

#[test]
fn scaled_and_mirrored_helpers() {
    // Polygon::scaled multiplies a by k and area by k²; mirroring y → −y (turning the part upside
    // down) maps a normal at angle α to −α, so a stable state θ to 180° − θ.
    let p = part_from_spec("tripoly2").unwrap();
    let s = p.scaled(2.5);
    assert!((s.radius() - 2.5 * p.radius()).abs() < 1e-12);
    assert!((s.area() - 6.25 * p.area()).abs() < 1e-12);
    assert!((s.polar_moment() - 2.5f64.powi(4) * p.polar_moment()).abs() < 1e-12);
    assert_states(&stable_deg(&s), &stable_deg(&p));
    let m = p.mirrored_y();
    let want: Vec<f64> = stable_deg(&p).iter().map(|t| 180.0 - t).collect();
    same_angles_mod_360(&stable_deg(&m), &want, DEG_TOL).unwrap();
}

// ---------------------------------------------------------------------------------------------
// Property tests on random simple polygons.

/// Star-shaped polygon about the origin, 3–11 vertices (see [`shapes::star_polygon`]).
fn star_polygon() -> impl Strategy<Value = Vec<(f64, f64)>> {
    shapes::star_polygon(3..12)
}

/// Convex polygon: the convex hull of 3–12 points on a random ellipse.
fn convex_polygon() -> impl Strategy<Value = Vec<(f64, f64)>> {
    (
        prop::collection::vec(0.0f64..std::f64::consts::TAU, 3..12),
        0.3f64..1.0,
        0.3f64..1.0,
        0.0f64..std::f64::consts::PI,
    )
        .prop_map(|(angles, ax, ay, tilt)| {
            let pts: Vec<Vec2> = angles
                .iter()
                .map(|t| Vec2::new(ax * t.cos(), ay * t.sin()).rotate(tilt))
                .collect();
            convex_hull(&pts).iter().map(|p| (p.x, p.y)).collect()
        })
        .prop_filter("need a proper triangle", |v: &Vec<(f64, f64)>| {
            v.len() >= 3 && Polygon::from_xy(v).is_ok()
        })
}

fn any_part() -> impl Strategy<Value = Vec<(f64, f64)>> {
    prop_oneof![star_polygon(), convex_polygon()]
}

fn transform(v: &[(f64, f64)], phi: f64, k: f64, shift: (f64, f64)) -> Vec<(f64, f64)> {
    v.iter()
        .map(|&(x, y)| {
            let p = Vec2::new(x, y).rotate(phi) * k;
            (p.x + shift.0, p.y + shift.1)
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, rng_seed: proptest::test_runner::RngSeed::Fixed(20261133), .. ProptestConfig::default() })]

    /// Generated parts are valid; convex ones are reported convex.
    #[test]
    fn generators_give_valid_parts(v in star_polygon(), c in convex_polygon()) {
        prop_assert!(Polygon::from_xy(&v).is_ok());
        let p = Polygon::from_xy(&c).unwrap();
        prop_assert!(p.is_convex());
        prop_assert!(!p.stable_states().is_empty());
    }

    /// Rotating the input by φ shifts every stable state by −φ (mod 360°) and keeps a and area.
    #[test]
    fn rotation_shifts_stable_states(v in any_part(), phi in -720.0f64..720.0) {
        let p = Polygon::from_xy(&v).unwrap();
        let q = Polygon::from_xy(&transform(&v, phi.to_radians(), 1.0, (0.0, 0.0))).unwrap();
        let want: Vec<f64> = stable_deg(&p).iter().map(|t| t - phi).collect();
        let got = stable_deg(&q);
        for t in &got {
            prop_assert!((0.0..360.0).contains(t), "{t} not wrapped");
        }
        same_angles_mod_360(&got, &want, 1e-7).map_err(TestCaseError::fail)?;
        prop_assert!((q.radius() - p.radius()).abs() <= 1e-12 * p.radius());
        // Area error is relative to the part's size², not its area (thin slivers occur).
        prop_assert!((q.area() - p.area()).abs() <= 1e-12 * p.radius().powi(2));
        prop_assert_eq!(q.is_convex(), p.is_convex());
    }

    /// Scaling by k > 0 keeps the stable states and multiplies a by k and area by k².
    #[test]
    fn scaling_keeps_stable_states(v in any_part(), log_k in -3.0f64..3.0) {
        let k = 10f64.powf(log_k);
        let p = Polygon::from_xy(&v).unwrap();
        let q = Polygon::from_xy(&transform(&v, 0.0, k, (0.0, 0.0))).unwrap();
        same_angles_mod_360(&stable_deg(&q), &stable_deg(&p), 1e-7).map_err(TestCaseError::fail)?;
        prop_assert!((q.radius() - k * p.radius()).abs() <= 1e-12 * k * p.radius());
        prop_assert!((q.area() - k * k * p.area()).abs() <= 1e-12 * (k * p.radius()).powi(2));
        let heights = |x: &Polygon| {
            let mut h: Vec<f64> = x.stable_states().iter().map(|s| s.height).collect();
            h.sort_by(f64::total_cmp);
            h
        };
        for (hq, hp) in heights(&q).iter().zip(heights(&p)) {
            prop_assert!((hq - k * hp).abs() <= 1e-12 * k * p.radius());
        }
    }

    /// Translating the input moves only the reported centroid; the part frame is unchanged.
    #[test]
    fn translation_changes_only_the_centroid(v in any_part(), dx in -1e3f64..1e3, dy in -1e3f64..1e3) {
        let p = Polygon::from_xy(&v).unwrap();
        let q = Polygon::from_xy(&transform(&v, 0.0, 1.0, (dx, dy))).unwrap();
        let tol = 1e-12 * (1.0 + dx.abs() + dy.abs());
        prop_assert!((q.offset() - p.offset() - Vec2::new(dx, dy)).norm() <= tol);
        prop_assert_eq!(q.len(), p.len());
        for (a, b) in q.vertices().iter().zip(p.vertices()) {
            prop_assert!((*a - *b).norm() <= tol);
        }
        prop_assert!((q.radius() - p.radius()).abs() <= tol);
        prop_assert!((q.area() - p.area()).abs() <= tol);
        same_angles_mod_360(&stable_deg(&q), &stable_deg(&p), 1e-7).map_err(TestCaseError::fail)?;
    }

    /// Rotation, scaling and translation together (the general similarity transform).
    #[test]
    fn similarity_transform(v in any_part(), phi in 0.0f64..360.0, log_k in -2.0f64..2.0,
                            dx in -50.0f64..50.0, dy in -50.0f64..50.0) {
        let k = 10f64.powf(log_k);
        let p = Polygon::from_xy(&v).unwrap();
        let q = Polygon::from_xy(&transform(&v, phi.to_radians(), k, (dx, dy))).unwrap();
        let want: Vec<f64> = stable_deg(&p).iter().map(|t| t - phi).collect();
        same_angles_mod_360(&stable_deg(&q), &want, 1e-7).map_err(TestCaseError::fail)?;
        prop_assert!((q.radius() - k * p.radius()).abs() <= 1e-10 * k * p.radius());
        prop_assert!((q.area() - k * k * p.area()).abs() <= 1e-10 * (k * p.radius()).powi(2));
    }

    /// Clockwise input (reversed ring) gives the same part.
    #[test]
    fn orientation_of_input_does_not_matter(v in any_part()) {
        let p = Polygon::from_xy(&v).unwrap();
        let rev: Vec<(f64, f64)> = v.iter().rev().copied().collect();
        let q = Polygon::from_xy(&rev).unwrap();
        prop_assert!((q.area() - p.area()).abs() <= 1e-12 * p.radius().powi(2));
        prop_assert!((q.radius() - p.radius()).abs() <= 1e-12 * p.radius());
        same_angles_mod_360(&stable_deg(&q), &stable_deg(&p), 1e-9).map_err(TestCaseError::fail)?;
    }
}
