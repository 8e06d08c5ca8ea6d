//! Tests of the first-contact query (`geometry::first_contact`): travel, contact point, touched
//! feature, inward normal and the grazing flag, against hand-computed values for convex and concave
//! parts, point pins (ρ = 0) and disc pins (ρ > 0), translated and rotated poses and a moving pin's
//! slanted path; plus property tests (first touch really is first; scale and rotation invariance).

use pinfeed::geometry::{
    first_contact, first_contact_travelling_x, part_from_spec, Feature, FirstContact, Polygon,
    Pose, Vec2,
};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, SQRT_2};

const LEFT: Vec2 = Vec2::new(-1.0, 0.0);

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

fn near(a: f64, b: f64, what: &str) {
    assert!((a - b).abs() < 1e-10, "{what}: got {a}, want {b}");
}

fn near_v(a: Vec2, b: Vec2, what: &str) {
    assert!((a - b).norm() < 1e-10, "{what}: got {a:?}, want {b:?}");
}

/// The L-shape placed so that world coordinates equal the coordinates it is defined in:
/// (0,0) (2,0) (2,1) (1,1) (1,2) (0,2); vertex 3 = (1,1) is the reflex corner of the notch.
fn lshape() -> (Polygon, Pose) {
    let l = part_from_spec("lshape").unwrap();
    let o = l.offset();
    (l, Pose::new(o.x, o.y, 0.0))
}

/// Unit square centred at the origin: vertices 0 (−½,−½), 1 (½,−½), 2 (½,½), 3 (−½,½).
fn square() -> Polygon {
    part_from_spec("square").unwrap()
}

/// Square rotated 45°: vertex 0 = (1,0) leads toward +x.
fn diamond() -> Polygon {
    Polygon::from_xy(&[(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]).unwrap()
}

fn expect(c: Option<FirstContact>, what: &str) -> FirstContact {
    c.unwrap_or_else(|| panic!("{what}: expected a contact, got none"))
}

/// At a pin path exactly level with the part's extreme: a grazing touch or nothing, never a push.
fn assert_not_entering(c: Option<FirstContact>, what: &str) {
    if let Some(c) = c {
        assert!(c.grazing, "{what}: entering contact {c:?}");
    }
}

// ------------------------------------------------------------------------------------------------
// Point pins on convex parts

#[test]
fn point_pin_on_square_edge() {
    let c = expect(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.1), 0.0),
        "square",
    );
    near(c.travel, 4.5, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            near(t, 0.6, "edge fraction");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near_v(c.point, v(0.5, 0.1), "point");
    near_v(
        c.pin_centre,
        c.point,
        "a point pin's centre is the contact point",
    );
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
}

#[test]
fn point_pin_on_tripoly1_slanted_edge() {
    // Edge 1 runs (1.5,−0.5)→(0,1); at y = 0.25 it is at x = 0.75, halfway along.
    let p = part_from_spec("tripoly1").unwrap();
    let c = expect(
        first_contact_travelling_x(&p, &Pose::default(), v(5.0, 0.25), 0.0),
        "tripoly1",
    );
    near(c.travel, 4.25, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            near(t, 0.5, "edge fraction");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near_v(c.point, v(0.75, 0.25), "point");
    near_v(c.normal, v(-1.0, -1.0) / SQRT_2, "normal");
    assert!(!c.grazing);
}

#[test]
fn point_pin_level_with_leading_vertex_enters_there() {
    // Diamond hit exactly at its leading vertex: reported as that vertex, not grazing, normal along
    // the bisector of the two edges' inward normals (here straight against the pin).
    let c = expect(
        first_contact_travelling_x(&diamond(), &Pose::default(), v(5.0, 0.0), 0.0),
        "diamond",
    );
    near(c.travel, 4.0, "travel");
    assert_eq!(c.feature, Feature::Vertex { index: 0 });
    near_v(c.point, v(1.0, 0.0), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
}

#[test]
fn point_pin_within_tolerance_of_vertex_reports_the_vertex() {
    // 1e-14 off the vertex level (below the 1e-12·a tolerance): still the vertex.
    for dy in [1e-14, -1e-14] {
        let c = expect(
            first_contact_travelling_x(&diamond(), &Pose::default(), v(5.0, dy), 0.0),
            "diamond",
        );
        assert_eq!(c.feature, Feature::Vertex { index: 0 });
        assert!(!c.grazing);
    }
    // 1e-6 off: an ordinary edge contact on the side it is on.
    let c = expect(
        first_contact_travelling_x(&diamond(), &Pose::default(), v(5.0, 1e-6), 0.0),
        "diamond",
    );
    assert!(matches!(c.feature, Feature::Edge { index: 0, .. }), "{c:?}");
    let c = expect(
        first_contact_travelling_x(&diamond(), &Pose::default(), v(5.0, -1e-6), 0.0),
        "diamond",
    );
    assert!(matches!(c.feature, Feature::Edge { index: 3, .. }), "{c:?}");
}

#[test]
fn point_pin_at_square_top_grazes() {
    // Exactly at max y: the pin slides along the top face: grazing (or nothing), never a push.
    let top = first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5), 0.0);
    assert_not_entering(top, "square top");
    if let Some(c) = top {
        assert_eq!(c.feature, Feature::Vertex { index: 2 });
        near(c.travel, 4.5, "travel");
    }
    // Slightly above: no contact at all.
    assert!(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5 + 1e-9), 0.0).is_none()
    );
    // Slightly below: an entering contact on the leading edge, just short of its end.
    let c = expect(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5 - 1e-9), 0.0),
        "below top",
    );
    assert!(!c.grazing);
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            assert!(t < 1.0 && t > 1.0 - 1e-8, "t = {t}");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near(c.travel, 4.5, "travel");
}

#[test]
fn point_pin_at_square_bottom_grazes() {
    // Mirror case at min y: vertex 1 = (½,−½) touched tangentially.
    let c = first_contact_travelling_x(&square(), &Pose::default(), v(5.0, -0.5), 0.0);
    assert_not_entering(c, "square bottom");
    assert!(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, -0.5 - 1e-9), 0.0).is_none()
    );
}

#[test]
fn point_pin_at_triangle_apex_grazes() {
    // tripoly1's apex (0,1) is a strict maximum of y: a pin at y = 1 only touches it.
    let p = part_from_spec("tripoly1").unwrap();
    let c = first_contact_travelling_x(&p, &Pose::default(), v(5.0, 1.0), 0.0);
    assert_not_entering(c, "apex");
    if let Some(c) = c {
        assert_eq!(c.feature, Feature::Vertex { index: 2 });
        near(c.travel, 5.0, "travel");
    }
    assert!(first_contact_travelling_x(&p, &Pose::default(), v(5.0, 1.0 + 1e-9), 0.0).is_none());
    let c = expect(
        first_contact_travelling_x(&p, &Pose::default(), v(5.0, 1.0 - 1e-9), 0.0),
        "below apex",
    );
    assert!(!c.grazing);
    assert!(matches!(c.feature, Feature::Edge { index: 1, .. }), "{c:?}");
}

#[test]
fn misses() {
    let sq = square();
    let pose = Pose::default();
    // Pin above the part, and a pin already past it (moving away).
    assert!(first_contact_travelling_x(&sq, &pose, v(5.0, 0.6), 0.0).is_none());
    assert!(first_contact_travelling_x(&sq, &pose, v(-5.0, 0.0), 0.0).is_none());
    // A disc whose edge clears the corner.
    assert!(first_contact_travelling_x(&sq, &pose, v(5.0, 0.76), 0.25).is_none());
    // min_travel beyond the only touch.
    assert!(first_contact(&sq, &pose, v(5.0, 0.0), LEFT, 0.0, 4.6).is_none());
}

// ------------------------------------------------------------------------------------------------
// Concave part: the L

#[test]
fn point_pin_enters_the_l_notch() {
    // At y = 1.5 the pin passes over the short arm and strikes the notch's inner wall, edge 3
    // (1,1)→(1,2), halfway up.
    let (l, pose) = lshape();
    let c = expect(
        first_contact_travelling_x(&l, &pose, v(5.0, 1.5), 0.0),
        "notch",
    );
    near(c.travel, 4.0, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 3);
            near(t, 0.5, "edge fraction");
        }
        f => panic!("expected edge 3, got {f:?}"),
    }
    near_v(c.point, v(1.0, 1.5), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
}

#[test]
fn point_pin_on_the_l_short_arm() {
    // Below the notch the pin strikes the short arm's end, edge 1 (2,0)→(2,1).
    let (l, pose) = lshape();
    let c = expect(
        first_contact_travelling_x(&l, &pose, v(5.0, 0.25), 0.0),
        "arm",
    );
    near(c.travel, 3.0, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            near(t, 0.25, "edge fraction");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near_v(c.normal, v(-1.0, 0.0), "normal");
}

#[test]
fn point_pin_level_with_the_notch_floor() {
    // At y = 1 the pin grazes the short arm's corner (2,1), slides along its top, and then runs
    // into the reflex corner (1,1), which it enters.
    let (l, pose) = lshape();
    let g = expect(
        first_contact_travelling_x(&l, &pose, v(5.0, 1.0), 0.0),
        "corner",
    );
    assert_eq!(g.feature, Feature::Vertex { index: 2 });
    near(g.travel, 3.0, "travel");
    near_v(g.point, v(2.0, 1.0), "point");
    assert!(g.grazing);
    // The caller continues past a grazing touch with min_travel.
    let c = expect(
        first_contact(&l, &pose, v(5.0, 1.0), LEFT, 0.0, g.travel + 1e-6),
        "reflex corner",
    );
    assert_eq!(c.feature, Feature::Vertex { index: 3 });
    near(c.travel, 4.0, "travel");
    near_v(c.point, v(1.0, 1.0), "point");
    assert!(!c.grazing);
    // Bisector of the inward normals (0,−1) of edge 2 and (−1,0) of edge 3.
    near_v(c.normal, v(-1.0, -1.0) / SQRT_2, "normal");
}

#[test]
fn point_pin_grazes_the_l_top() {
    // y = 2 is the L's max y: the pin touches the corner (1,2) tangentially, then nothing.
    let (l, pose) = lshape();
    let c = first_contact_travelling_x(&l, &pose, v(5.0, 2.0), 0.0);
    assert_not_entering(c, "L top");
    if let Some(c) = c {
        assert_eq!(c.feature, Feature::Vertex { index: 4 });
        near(c.travel, 4.0, "travel");
        assert!(first_contact(&l, &pose, v(5.0, 2.0), LEFT, 0.0, c.travel + 1e-6).is_none());
    }
    assert!(first_contact_travelling_x(&l, &pose, v(5.0, 2.0 + 1e-9), 0.0).is_none());
    let c = expect(
        first_contact_travelling_x(&l, &pose, v(5.0, 2.0 - 1e-9), 0.0),
        "below top",
    );
    assert!(!c.grazing);
    assert!(matches!(c.feature, Feature::Edge { index: 3, .. }), "{c:?}");
    near(c.travel, 4.0, "travel");
}

#[test]
fn point_pin_along_the_l_bottom_grazes() {
    // y = 0 is the L's min y: vertex 1 = (2,0) touched tangentially.
    let (l, pose) = lshape();
    let c = first_contact_travelling_x(&l, &pose, v(5.0, 0.0), 0.0);
    assert_not_entering(c, "L bottom");
    if let Some(c) = c {
        assert_eq!(c.feature, Feature::Vertex { index: 1 });
    }
}

// ------------------------------------------------------------------------------------------------
// Rotated and translated poses; a moving pin's slanted path

#[test]
fn rotated_square_hit_at_leading_vertex() {
    // Square at (1,2) turned 45°: its vertex 1 (½,−½) leads, at (1 + √2/2, 2).
    let pose = Pose::new(1.0, 2.0, FRAC_PI_4);
    let c = expect(
        first_contact_travelling_x(&square(), &pose, v(10.0, 2.0), 0.0),
        "rotated square",
    );
    assert_eq!(c.feature, Feature::Vertex { index: 1 });
    near(c.travel, 9.0 - SQRT_2 / 2.0, "travel");
    near_v(c.point, v(1.0 + SQRT_2 / 2.0, 2.0), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
}

#[test]
fn rotated_square_hit_on_edge() {
    // 0.2 above the leading vertex: edge 1 (vertex 1 → vertex 2), a fraction 0.2/(√2/2) along it.
    let pose = Pose::new(1.0, 2.0, FRAC_PI_4);
    let c = expect(
        first_contact_travelling_x(&square(), &pose, v(10.0, 2.2), 0.0),
        "rotated square",
    );
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            near(t, 0.2 * SQRT_2, "edge fraction");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near(c.travel, 9.0 - (SQRT_2 / 2.0 - 0.2), "travel");
    near_v(c.point, v(1.0 + SQRT_2 / 2.0 - 0.2, 2.2), "point");
    near_v(c.normal, v(-1.0, -1.0) / SQRT_2, "normal");
    assert!(!c.grazing);
}

#[test]
fn rotated_tripoly1_apex_forward() {
    // tripoly1 at (2,3) turned −90°: its apex (0,1) points along +x at world (3,3); the
    // hypotenuse becomes the back side. Apex hit head-on enters; normal = bisector = (−1,0).
    let p = part_from_spec("tripoly1").unwrap();
    let pose = Pose::new(2.0, 3.0, -FRAC_PI_2);
    let c = expect(
        first_contact_travelling_x(&p, &pose, v(10.0, 3.0), 0.0),
        "apex",
    );
    assert_eq!(c.feature, Feature::Vertex { index: 2 });
    near(c.travel, 7.0, "travel");
    near_v(c.point, v(3.0, 3.0), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
    // Half a unit higher: edge 2 (apex → (−1.5,−0.5)), now running from (3,3) to (1.5,4.5).
    let c = expect(
        first_contact_travelling_x(&p, &pose, v(10.0, 3.5), 0.0),
        "edge 2",
    );
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 2);
            near(t, 1.0 / 3.0, "edge fraction");
        }
        f => panic!("expected edge 2, got {f:?}"),
    }
    near(c.travel, 7.5, "travel");
    near_v(c.point, v(2.5, 3.5), "point");
    near_v(c.normal, v(-1.0, -1.0) / SQRT_2, "normal");
    // Level with the rotated part's top vertex (world (1.5, 4.5)): grazing, or nothing.
    assert_not_entering(
        first_contact_travelling_x(&p, &pose, v(10.0, 4.5), 0.0),
        "rotated top",
    );
}

#[test]
fn moving_pin_slanted_path() {
    // A moving pin travels along (−1, w) normalised. w = 2 from (1,−2): it crosses y = −½ at
    // x = ¼, striking the bottom edge (edge 0) ¾ of the way along; travel = ¾·√5.
    let dir = v(-1.0, 2.0).normalized();
    let c = expect(
        first_contact(&square(), &Pose::default(), v(1.0, -2.0), dir, 0.0, 0.0),
        "w = 2",
    );
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 0);
            near(t, 0.75, "edge fraction");
        }
        f => panic!("expected edge 0, got {f:?}"),
    }
    near(c.travel, 0.75 * 5f64.sqrt(), "travel");
    near_v(c.point, v(0.25, -0.5), "point");
    near_v(c.normal, v(0.0, 1.0), "normal");
    assert!(!c.grazing);
    // w = ½ from (5,−2): reaches x = ½ at y = ¼: the leading edge (edge 1), ¾ of the way up.
    let dir = v(-1.0, 0.5).normalized();
    let c = expect(
        first_contact(&square(), &Pose::default(), v(5.0, -2.0), dir, 0.0, 0.0),
        "w = 1/2",
    );
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            near(t, 0.75, "edge fraction");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near(c.travel, 4.5 * 1.25f64.sqrt(), "travel");
    near_v(c.point, v(0.5, 0.25), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
}

#[test]
fn unnormalised_direction_is_normalised() {
    // `dir` is documented as a unit vector; a scaled one must not change the travel.
    let a = first_contact(
        &square(),
        &Pose::default(),
        v(1.0, -2.0),
        v(-1.0, 2.0).normalized(),
        0.0,
        0.0,
    )
    .unwrap();
    let b = first_contact(
        &square(),
        &Pose::default(),
        v(1.0, -2.0),
        v(-3.0, 6.0),
        0.0,
        0.0,
    )
    .unwrap();
    near(a.travel, b.travel, "travel");
}

#[test]
fn travelling_x_is_the_belt_frame_picture() {
    // first_contact_travelling_x(pin) = first_contact(pin, −x); moving the part by +travel in x
    // instead puts the pin on the part's boundary.
    let p = part_from_spec("tripoly2").unwrap();
    let pose = Pose::new(-3.0, 0.4, 0.7);
    // The rotated part spans world y ≈ −0.28 … 1.0.
    for (y, r) in [(0.0, 0.0), (0.5, 0.0), (0.9, 0.0), (1.1, 0.2), (-0.4, 0.25)] {
        let pin = v(4.0, y);
        let a = first_contact_travelling_x(&p, &pose, pin, r).unwrap();
        let b = first_contact(&p, &pose, pin, LEFT, r, 0.0).unwrap();
        assert_eq!(a, b);
        let moved = Pose::new(pose.x + a.travel, pose.y, pose.theta_rad);
        let (dist, _) = p.distance_to_boundary(moved.apply_inverse(pin));
        near(dist, r, "pin on the moved part's boundary");
    }
}

// ------------------------------------------------------------------------------------------------
// Disc pins

#[test]
fn disc_pin_on_square_edge() {
    // Radius ¼: the centre stops ¼ short of the face.
    let c = expect(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.1), 0.25),
        "disc",
    );
    near(c.travel, 4.25, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 1);
            near(t, 0.6, "edge fraction");
        }
        f => panic!("expected edge 1, got {f:?}"),
    }
    near_v(c.point, v(0.5, 0.1), "point");
    near_v(c.pin_centre, v(0.75, 0.1), "centre");
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
}

#[test]
fn disc_pin_on_diamond_vertex() {
    // Radius ¼ at y = 0.1 touches the vertex (1,0): centre at (1 + √(1/16 − 1/100), 0.1);
    // the normal points from the pin centre to the vertex.
    let r: f64 = 0.25;
    let dx = (r * r - 0.01).sqrt();
    let c = expect(
        first_contact_travelling_x(&diamond(), &Pose::default(), v(5.0, 0.1), r),
        "disc on vertex",
    );
    assert_eq!(c.feature, Feature::Vertex { index: 0 });
    near(c.travel, 4.0 - dx, "travel");
    near_v(c.point, v(1.0, 0.0), "point");
    near_v(c.pin_centre, v(1.0 + dx, 0.1), "centre");
    near_v(c.normal, v(-dx / r, -0.1 / r), "normal");
    near_v(
        c.normal,
        (c.point - c.pin_centre).normalized(),
        "normal from centre to vertex",
    );
    assert!(!c.grazing);
}

#[test]
fn disc_pin_on_l_corner() {
    // Radius ¼ at y = 1.2 catches the short arm's corner (2,1): 3-4-5 geometry, centre (2.15, 1.2).
    let (l, pose) = lshape();
    let c = expect(
        first_contact_travelling_x(&l, &pose, v(5.0, 1.2), 0.25),
        "corner",
    );
    assert_eq!(c.feature, Feature::Vertex { index: 2 });
    near(c.travel, 2.85, "travel");
    near_v(c.point, v(2.0, 1.0), "point");
    near_v(c.pin_centre, v(2.15, 1.2), "centre");
    near_v(c.normal, v(-0.6, -0.8), "normal");
    assert!(!c.grazing);
}

#[test]
fn disc_pin_enters_the_l_notch() {
    // Radius ¼ at y = 1.5 clears the short arm and strikes the notch wall.
    let (l, pose) = lshape();
    let c = expect(
        first_contact_travelling_x(&l, &pose, v(5.0, 1.5), 0.25),
        "notch",
    );
    near(c.travel, 3.75, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 3);
            near(t, 0.5, "edge fraction");
        }
        f => panic!("expected edge 3, got {f:?}"),
    }
    near_v(c.point, v(1.0, 1.5), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
}

#[test]
fn disc_pin_fills_the_l_notch() {
    // Radius ½ at y = 1.5 just fits the notch: it grazes the arm's corner (2,1) on the way in, then
    // strikes the wall.
    let (l, pose) = lshape();
    let g = first_contact_travelling_x(&l, &pose, v(5.0, 1.5), 0.5);
    assert_not_entering(g, "arm corner");
    if let Some(g) = g {
        assert_eq!(g.feature, Feature::Vertex { index: 2 });
        near(g.travel, 3.0, "travel");
    }
    let c = expect(
        first_contact(&l, &pose, v(5.0, 1.5), LEFT, 0.5, 3.0 + 1e-6),
        "wall",
    );
    near(c.travel, 3.5, "travel");
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 3);
            near(t, 0.5, "edge fraction");
        }
        f => panic!("expected edge 3, got {f:?}"),
    }
    assert!(!c.grazing);
}

#[test]
fn disc_pin_grazing_square_top() {
    // The disc's lowest point exactly level with the top face: grazing or nothing.
    let r = 0.25;
    assert_not_entering(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5 + r), r),
        "disc at top",
    );
    assert!(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5 + r + 1e-9), r)
            .is_none()
    );
    // Slightly lower: it catches the corner (2) and pushes.
    let c = expect(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5 + r - 1e-9), r),
        "below",
    );
    assert_eq!(c.feature, Feature::Vertex { index: 2 });
    assert!(!c.grazing);
    near_v(c.point, v(0.5, 0.5), "point");
}

#[test]
fn disc_pin_tangent_to_top_never_pushes() {
    // A disc whose lowest point is level with the part's top (centre at top + ρ, rounded as f64
    // rounds it) only grazes: for many radii and heights, never an entering contact.
    for top in [0.5, 0.37, 1.3, 0.123] {
        let p = Polygon::from_xy(&[(-0.5, -0.5), (0.5, -0.5), (0.5, top), (-0.5, top)]).unwrap();
        let pose = Pose::new(p.offset().x, p.offset().y, 0.0);
        for i in 1..500 {
            let r = i as f64 * 0.00293;
            let c = first_contact_travelling_x(&p, &pose, v(5.0, top + r), r);
            assert_not_entering(c, &format!("top {top}, radius {r}"));
            // A hair lower it does push, at the corner.
            let c = first_contact_travelling_x(&p, &pose, v(5.0, top + r - 1e-7), r);
            let c = expect(c, "just below tangent");
            assert!(!c.grazing, "top {top}, radius {r}: {c:?}");
            assert_eq!(c.feature, Feature::Vertex { index: 2 });
        }
    }
}

#[test]
fn disc_pin_centre_level_with_face_end_reports_the_vertex() {
    // The centre level with the top face: the disc meets the corner (½,½) head-on. A hit at an
    // edge's end is reported as that vertex (module docs), with the centre-to-vertex normal.
    let c = expect(
        first_contact_travelling_x(&square(), &Pose::default(), v(5.0, 0.5), 0.25),
        "corner",
    );
    near(c.travel, 4.25, "travel");
    assert_eq!(c.feature, Feature::Vertex { index: 2 });
    near_v(c.point, v(0.5, 0.5), "point");
    near_v(c.normal, v(-1.0, 0.0), "normal");
    assert!(!c.grazing);
}

#[test]
fn disc_pin_slanted_path() {
    // Radius ¼ along (−1, 2)/√5 from (1,−2): centre reaches y = −¾ at x = 0.375.
    let dir = v(-1.0, 2.0).normalized();
    let c = expect(
        first_contact(&square(), &Pose::default(), v(1.0, -2.0), dir, 0.25, 0.0),
        "slanted disc",
    );
    match c.feature {
        Feature::Edge { index, t } => {
            assert_eq!(index, 0);
            near(t, 0.875, "edge fraction");
        }
        f => panic!("expected edge 0, got {f:?}"),
    }
    near(c.travel, 0.625 * 5f64.sqrt(), "travel");
    near_v(c.point, v(0.375, -0.5), "point");
    near_v(c.pin_centre, v(0.375, -0.75), "centre");
    near_v(c.normal, v(0.0, 1.0), "normal");
}

#[test]
fn zero_radius_disc_is_a_point_pin() {
    let p = part_from_spec("tripoly2").unwrap();
    let pose = Pose::new(0.3, -0.2, 1.1);
    for y in [-0.9, -0.3, 0.0, 0.4, 0.8] {
        let a = first_contact_travelling_x(&p, &pose, v(6.0, y), 0.0);
        let b = first_contact_travelling_x(&p, &pose, v(6.0, y), 1e-12);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                assert!((a.travel - b.travel).abs() < 1e-9);
                assert!((a.point - b.point).norm() < 1e-9);
            }
            _ => panic!("y = {y}: {a:?} vs {b:?}"),
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Property tests

/// Star-shaped polygon about the origin (simple by construction), radii in [0.2, 1].
fn star_polygon() -> impl Strategy<Value = Polygon> {
    crate::shapes::star_polygon(3..10).prop_map(|v| {
        let pts: Vec<Vec2> = v.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
        Polygon::new(&pts).unwrap()
    })
}

/// (start, unit direction, radius): a pin starting well outside the part (centred at the origin,
/// size ≤ 2) heading roughly in −x, possibly with a lateral velocity.
fn pin() -> impl Strategy<Value = (Vec2, Vec2, f64)> {
    (
        -1.5f64..1.5,
        -1.0f64..1.0,
        prop_oneof![Just(0.0), 0.0f64..0.4],
    )
        .prop_map(|(y, w, r)| {
            let dir = Vec2::new(-1.0, w).normalized();
            // Start 6 units back along the path from a point at height y near the part.
            (Vec2::new(0.0, y) - dir * 6.0, dir, r)
        })
}

/// Does a pin centred at part-frame point `c` (radius `r`) overlap the part by more than `slack`?
fn overlaps(p: &Polygon, c: Vec2, r: f64, slack: f64) -> bool {
    let (d, _) = p.distance_to_boundary(c);
    if p.contains(c) {
        d > slack
    } else {
        d < r - slack
    }
}

fn same_feature(a: Feature, b: Feature) -> bool {
    match (a, b) {
        (Feature::Vertex { index: i }, Feature::Vertex { index: j }) => i == j,
        (Feature::Edge { index: i, t: s }, Feature::Edge { index: j, t: u }) => {
            i == j && (s - u).abs() < 1e-9
        }
        _ => false,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(20261137), .. ProptestConfig::default() })]

    /// The reported touch is consistent (point on the boundary, at distance ρ from the pin centre,
    /// unit normal, entering unless grazing), no overlap happens earlier on the path, and an
    /// entering push overlaps just after.
    #[test]
    fn first_touch_is_first_and_consistent(poly in star_polygon(), (start, dir, r) in pin(),
                                           theta in 0.0f64..std::f64::consts::TAU) {
        let pose = Pose::new(0.0, 0.0, theta);
        let hit = first_contact(&poly, &pose, start, dir, r, 0.0);
        let at = |s: f64| pose.apply_inverse(start + dir * s);
        let end = match hit {
            Some(c) => {
                prop_assert!(c.travel >= 0.0);
                prop_assert!((c.pin_centre - (start + dir * c.travel)).norm() < 1e-9);
                prop_assert!(((c.point - c.pin_centre).norm() - r).abs() < 1e-9);
                let (d, _) = poly.distance_to_boundary(pose.apply_inverse(c.point));
                prop_assert!(d < 1e-9, "contact point off the boundary by {}", d);
                prop_assert!((c.normal.norm() - 1.0).abs() < 1e-12);
                if !c.grazing {
                    prop_assert!(dir.dot(c.normal) > 0.0, "entering push with normal {:?}", c.normal);
                    if dir.dot(c.normal) > 1e-3 {
                        prop_assert!(overlaps(&poly, at(c.travel + 1e-6), r, 0.0),
                                     "no overlap just after an entering contact");
                    }
                }
                if r > 0.0 {
                    if let Feature::Vertex { .. } = c.feature {
                        prop_assert!((c.normal - (c.point - c.pin_centre).normalized()).norm() < 1e-9);
                    }
                }
                c.travel
            }
            None => 12.0,
        };
        for k in 0..200 {
            let s = end * k as f64 / 200.0;
            prop_assert!(!overlaps(&poly, at(s), r, 1e-9), "overlap at travel {} before {:?}", s, hit);
        }
    }

    /// Scaling the whole scene by k scales the travel and keeps the feature, normal and grazing flag.
    #[test]
    fn scale_invariance(poly in star_polygon(), (start, dir, r) in pin(),
                        theta in 0.0f64..std::f64::consts::TAU, log_k in -3.0f64..3.0) {
        let k = 10f64.powf(log_k);
        let pose = Pose::new(0.1, -0.2, theta);
        let big = poly.scaled(k);
        let big_pose = Pose::new(pose.x * k, pose.y * k, theta);
        let a = first_contact(&poly, &pose, start, dir, r, 0.0);
        let b = first_contact(&big, &big_pose, start * k, dir, r * k, 0.0);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                prop_assert!((b.travel - k * a.travel).abs() <= 1e-9 * k);
                prop_assert!((b.point - a.point * k).norm() <= 1e-9 * k);
                prop_assert!(same_feature(a.feature, b.feature), "{:?} vs {:?}", a.feature, b.feature);
                prop_assert!((a.normal - b.normal).norm() < 1e-9);
                prop_assert_eq!(a.grazing, b.grazing);
            }
            _ => prop_assert!(false, "{:?} vs {:?}", a, b),
        }
    }

    /// Rotating the whole scene (pose, pin start and direction) by ψ rotates the answer.
    #[test]
    fn rotation_invariance(poly in star_polygon(), (start, dir, r) in pin(),
                           theta in 0.0f64..std::f64::consts::TAU,
                           psi in 0.0f64..std::f64::consts::TAU) {
        let pose = Pose::new(0.1, -0.2, theta);
        let turned = Pose::new(0.0, 0.0, psi);
        let pos = turned.apply(pose.position());
        let pose2 = Pose::new(pos.x, pos.y, theta + psi);
        let a = first_contact(&poly, &pose, start, dir, r, 0.0);
        let b = first_contact(&poly, &pose2, turned.apply(start), dir.rotate(psi), r, 0.0);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                prop_assert!((b.travel - a.travel).abs() <= 1e-9);
                prop_assert!((b.point - turned.apply(a.point)).norm() <= 1e-9);
                prop_assert!(same_feature(a.feature, b.feature), "{:?} vs {:?}", a.feature, b.feature);
                prop_assert!((b.normal - a.normal.rotate(psi)).norm() < 1e-9);
                prop_assert_eq!(a.grazing, b.grazing);
            }
            _ => prop_assert!(false, "{:?} vs {:?}", a, b),
        }
    }
}
