//! One instant of one contact: which mode (stick, slide left, slide right, separate) is consistent,
//! and the part's twist in it (docs/physics.md#one-instant).
//!
//! Inputs are in the part frame, normalised units: contact point `p` (relative to the centroid), unit
//! normal `n` pointing into the part, and the pin's velocity `v_pin` relative to the belt.
//!
//! 1. n·v_pin ≤ 0: the pin is not pushing; the contact separates.
//! 2. The friction-cone edges f_L = R(+atan μc) n, f_R = R(−atan μc) n give edge twists ξ_L, ξ_R
//!    (normal to the limit surface at the edge wrenches) with contact velocities v_L, v_R.
//! 3. Stick iff v_pin lies in the cone spanned by v_R and v_L; then v_c(ξ) = v_pin.
//! 4. Otherwise slide on the violated side b with ξ = κ ξ_b, κ = (n·v_pin)/(n·v_b); a side with
//!    n·v_b ≤ ε can never slide and counts as stick.
//! 5. μc = 0: one force direction (the normal), always slide.
//!
//! Sliding left means the contact force is f_L: the pin slides along +t = ẑ×n relative to the part.
//!
//! Each mode also reports *margins*, continuous functions that are positive while the mode stays
//! consistent: for stick, μc λn ∓ λt (normalised by |f|), for slide-left/right the signed sine between
//! v_b and v_pin. The integrator locates the zero crossings of these as mode-switch events.

use super::part_model::{
    final_gap, point_velocity, wrench_of, Fidelity, PartModel, SolveFailure, Solved, Twist,
    WarmStick, WarmTwist,
};
use super::slide_table::{Side, SlideAt, TableTwist};
use crate::geometry::Vec2;
use serde::Serialize;

/// Contact mode at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// No relative sliding at the contact.
    Stick,
    /// Sliding with the force on the counter-clockwise cone edge (pin moves along +ẑ×n relative to the part).
    SlideLeft,
    /// Sliding with the force on the clockwise cone edge.
    SlideRight,
    /// Frictionless contact (μc = 0): the force is along the normal.
    Slide,
}

impl Mode {
    /// The mode's name in outputs: `stick`, `slide_left`, `slide_right` or `slide`.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Stick => "stick",
            Mode::SlideLeft => "slide_left",
            Mode::SlideRight => "slide_right",
            Mode::Slide => "slide",
        }
    }
}

/// Contact geometry at one instant (part frame, normalised units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeom {
    /// Contact point (part frame, normalised units).
    pub p: Vec2,
    /// Unit contact normal into the part (part frame).
    pub n: Vec2,
    /// The pin's velocity relative to the belt per unit of travel, rotated into the part frame.
    pub v_pin: Vec2,
    /// Where on the part the contact is, for the model's slide tables (`mechanics::slide_table`):
    /// an edge and ℓ, or a vertex and the normal's angle; `None` where no table applies (a
    /// fence's features, which are the hull's).
    pub slide_at: Option<SlideAt>,
}

/// The solved instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instant {
    /// Sticking or sliding (and to which side).
    pub mode: Mode,
    /// Part twist (part frame) scaled so that the normal velocity at the contact matches the pin's.
    pub twist: Twist,
    /// Contact force on the part (part frame), in units of μs m g.
    pub force: Vec2,
    /// Margins of the mode (positive while consistent): stick: [μcλn − λt, μcλn + λt]/|f|;
    /// slide-left: [sine(v_L, v_pin), 1]; slide-right: [1, sine(v_pin, v_R)]; slide: [1, 1].
    pub margins: [f64; 2],
}

/// Warm starts carried from instant to instant, and how accurately the exact solves need to
/// converge for the contact's integration tolerance (`gap`, see [`final_gap`]).
#[derive(Debug, Clone, Copy)]
pub struct Warm {
    /// Warm start of the slide-left solve.
    pub left: Option<WarmTwist>,
    /// Warm start of the slide-right solve.
    pub right: Option<WarmTwist>,
    /// Warm start of the frictionless (normal) solve.
    pub normal: Option<WarmTwist>,
    /// Warm start of the stick solve.
    pub stick: Option<WarmStick>,
    /// How closely the exact solves must converge (from the integration tolerance; see `final_gap`).
    pub gap: f64,
}

impl Warm {
    /// No warm starts yet, for a contact integrated at tolerance `tol`.
    pub fn for_tolerance(tol: f64) -> Warm {
        Warm {
            left: None,
            right: None,
            normal: None,
            stick: None,
            gap: final_gap(tol),
        }
    }
}

impl Warm {
    /// The warm start of the sliding solve in `mode` (frictionless slide: the normal's).
    fn slide_slot(&mut self, mode: Mode) -> &mut Option<WarmTwist> {
        match mode {
            Mode::SlideLeft => &mut self.left,
            Mode::SlideRight => &mut self.right,
            Mode::Slide | Mode::Stick => &mut self.normal,
        }
    }
}

/// Friction settings of the contact: μc and the friction-cone half-angle's sine and cosine
/// (precomputed: the cone edges are needed at every instant).
#[derive(Debug, Clone, Copy)]
pub struct Friction {
    /// Pin–part friction coefficient μc (≥ 0).
    pub mu_c: f64,
    sin_phi: f64,
    cos_phi: f64,
}

impl Friction {
    /// The friction of a contact with coefficient `mu_c` (≥ 0).
    pub fn new(mu_c: f64) -> Friction {
        let c = 1.0 / (1.0 + mu_c * mu_c).sqrt();
        Friction {
            mu_c,
            sin_phi: mu_c * c,
            cos_phi: c,
        }
    }
    /// The counter-clockwise friction-cone edge R(+atan μc) n.
    #[inline]
    pub fn left_edge(&self, n: Vec2) -> Vec2 {
        n.rotate_sc(self.sin_phi, self.cos_phi)
    }
    /// The clockwise friction-cone edge R(−atan μc) n.
    #[inline]
    pub fn right_edge(&self, n: Vec2) -> Vec2 {
        n.rotate_sc(-self.sin_phi, self.cos_phi)
    }
}

const GUARD: f64 = 1e-9;

/// Separation margin: the sine between the normal and the pin's velocity (positive while pushing).
#[inline]
pub fn push_margin(g: &ContactGeom) -> f64 {
    g.n.dot(g.v_pin) / g.v_pin.norm()
}

/// The exact sliding twist from the model's slide table, where it has one for this place, side
/// and μc and serves this coordinate (see `mechanics::slide_table`).
fn tabled_slide(
    model: &PartModel,
    fid: Fidelity,
    g: &ContactGeom,
    mu_c: f64,
    mode: Mode,
) -> Option<TableTwist> {
    if fid != Fidelity::Exact {
        return None;
    }
    let (place, t) = g.slide_at?.split();
    let side = match mode {
        Mode::SlideLeft => Side::Left,
        Mode::SlideRight => Side::Right,
        // The frictionless force is the left table's (R(+atan 0) n = n).
        Mode::Slide if mu_c == 0.0 => Side::Left,
        _ => return None,
    };
    model.slide_table(mu_c, place, side)?.at(t)
}

/// The exact sticking twist from the model's stick table for this edge, where it serves this
/// contact point and pin velocity (see `mechanics::stick_table`).
fn tabled_stick(model: &PartModel, fid: Fidelity, g: &ContactGeom) -> Option<(Solved, WarmStick)> {
    match (fid, g.slide_at?) {
        (Fidelity::Exact, SlideAt::Edge(k, ell)) => model.tabled_stick(k, ell, g.v_pin),
        _ => None,
    }
}

/// Slide with the force along `f_dir` (a cone edge, or the normal when frictionless): the twist
/// normalised to w·ξ = 1, the contact velocity it gives, and the force (units of μs m g).
#[allow(clippy::too_many_arguments)]
fn slide_instant(
    model: &PartModel,
    fid: Fidelity,
    g: &ContactGeom,
    f_dir: Vec2,
    mu_c: f64,
    warm: &mut Warm,
    mode: Mode,
    evals: &mut u64,
) -> Result<(Twist, Vec2, Vec2), SolveFailure> {
    if let Some(t) = tabled_slide(model, fid, g, mu_c, mode) {
        // ∇D = λ w at the tabled twist: the force is λ f; the slot's warm start stays usable by
        // a later solve the table does not serve.
        *warm.slide_slot(mode) = Some(WarmTwist {
            twist: t.twist,
            wrench: wrench_of(f_dir, g.p),
            lambda: t.lambda,
            hess: Some(t.hess),
        });
        return Ok((t.twist, point_velocity(t.twist, g.p), f_dir * t.lambda));
    }
    let gap = warm.gap;
    let slot = warm.slide_slot(mode);
    let (s, next) =
        model.twist_for_wrench(fid, wrench_of(f_dir, g.p), slot.as_ref(), gap, evals)?;
    *slot = Some(next);
    let vb = point_velocity(s.twist, g.p);
    Ok((s.twist, vb, Vec2::new(s.wrench[0], s.wrench[1])))
}

fn scaled_slide(g: &ContactGeom, xi: Twist, vb: Vec2) -> Twist {
    let k = g.n.dot(g.v_pin) / g.n.dot(vb);
    [xi[0] * k, xi[1] * k, xi[2] * k]
}

fn sine(a: Vec2, b: Vec2) -> f64 {
    a.cross(b) / (a.norm() * b.norm())
}

fn stick_instant(
    model: &PartModel,
    fid: Fidelity,
    g: &ContactGeom,
    fr: Friction,
    warm: &mut Warm,
    evals: &mut u64,
) -> Result<Instant, SolveFailure> {
    let (s, next) = match tabled_stick(model, fid, g) {
        Some(served) => served,
        None => model.stick_twist(fid, g.p, g.v_pin, warm.stick.as_ref(), warm.gap, evals)?,
    };
    warm.stick = Some(next);
    let f = Vec2::new(s.wrench[0], s.wrench[1]);
    let t = g.n.perp();
    let (ln, lt) = (f.dot(g.n), f.dot(t));
    let fn_ = f.norm().max(1e-300);
    Ok(Instant {
        mode: Mode::Stick,
        twist: s.twist,
        force: f,
        margins: [(fr.mu_c * ln - lt) / fn_, (fr.mu_c * ln + lt) / fn_],
    })
}

/// One side's slide: its instant and its margin.
struct SideSlide {
    instant: Instant,
    margin: f64,
}

/// Sliding on one cone edge (`sign` +1 left, −1 right): the scaled twist, the force, and the
/// margin — the signed sine between v_b and v_pin, forced negative when n·v_b ≤ ε (that side can
/// never slide: the guard for large μc of docs/physics.md#one-instant).
#[allow(clippy::too_many_arguments)]
fn slide_side(
    model: &PartModel,
    fid: Fidelity,
    g: &ContactGeom,
    f_dir: Vec2,
    mu_c: f64,
    sign: f64,
    warm: &mut Warm,
    evals: &mut u64,
) -> Result<SideSlide, SolveFailure> {
    let mode = if sign > 0.0 {
        Mode::SlideLeft
    } else {
        Mode::SlideRight
    };
    let (xi, vb, f) = slide_instant(model, fid, g, f_dir, mu_c, warm, mode, evals)?;
    let mut margin = sign * sine(vb, g.v_pin);
    if g.n.dot(vb) <= GUARD * vb.norm() {
        margin = margin.min(-1e-3);
    }
    Ok(SideSlide {
        instant: Instant {
            mode: Mode::Slide,
            twist: scaled_slide(g, xi, vb),
            force: f,
            margins: [1.0, 1.0],
        },
        margin,
    })
}

/// Solve the instant assuming `mode` (no consistency decision), returning margins for event location.
pub fn solve_in_mode(
    model: &PartModel,
    fid: Fidelity,
    g: &ContactGeom,
    fr: Friction,
    mode: Mode,
    warm: &mut Warm,
    evals: &mut u64,
) -> Result<Instant, SolveFailure> {
    match mode {
        Mode::Stick => stick_instant(model, fid, g, fr, warm, evals),
        Mode::Slide => {
            let (xi, vb, f) = slide_instant(model, fid, g, g.n, fr.mu_c, warm, mode, evals)?;
            Ok(Instant {
                mode,
                twist: scaled_slide(g, xi, vb),
                force: f,
                margins: [1.0, 1.0],
            })
        }
        Mode::SlideLeft => {
            let f_dir = fr.left_edge(g.n);
            let m = slide_side(model, fid, g, f_dir, fr.mu_c, 1.0, warm, evals)?;
            Ok(Instant {
                mode,
                margins: [m.margin, 1.0],
                ..m.instant
            })
        }
        Mode::SlideRight => {
            let f_dir = fr.right_edge(g.n);
            let m = slide_side(model, fid, g, f_dir, fr.mu_c, -1.0, warm, evals)?;
            Ok(Instant {
                mode,
                margins: [1.0, m.margin],
                ..m.instant
            })
        }
    }
}

/// Decide the consistent mode at an instant and solve it; `None` when the contact separates.
pub fn classify(
    model: &PartModel,
    fid: Fidelity,
    g: &ContactGeom,
    fr: Friction,
    warm: &mut Warm,
    evals: &mut u64,
) -> Result<Option<Instant>, SolveFailure> {
    if push_margin(g) <= 1e-12 {
        return Ok(None);
    }
    if fr.mu_c == 0.0 {
        return solve_in_mode(model, fid, g, fr, Mode::Slide, warm, evals).map(Some);
    }
    let left = solve_in_mode(model, fid, g, fr, Mode::SlideLeft, warm, evals)?;
    let right = solve_in_mode(model, fid, g, fr, Mode::SlideRight, warm, evals)?;
    let ml = left.margins[0];
    let mr = right.margins[1];
    if ml > 0.0 && (mr <= 0.0 || ml >= mr) {
        return Ok(Some(left));
    }
    if mr > 0.0 {
        return Ok(Some(right));
    }
    stick_instant(model, fid, g, fr, warm, evals).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::part_model::Support;

    fn model(name: &str) -> PartModel {
        PartModel::new(&part_from_spec(name).unwrap(), &Support::Uniform).unwrap()
    }

    /// Lynch, Maekawa & Tanie (1992), the ellipsoid's stick motion written out independently:
    /// vx = ((c²+x²)vpx + x y vpy)/(c²+x²+y²), vy = (x y vpx + (c²+y²)vpy)/(c²+x²+y²), ω = (x vy − y vx)/c².
    fn lynch_stick(c: f64, p: Vec2, vp: Vec2) -> [f64; 3] {
        let (x, y) = (p.x, p.y);
        let c2 = c * c;
        let den = c2 + x * x + y * y;
        let vx = ((c2 + x * x) * vp.x + x * y * vp.y) / den;
        let vy = (x * y * vp.x + (c2 + y * y) * vp.y) / den;
        [vx, vy, (x * vy - y * vx) / c2]
    }

    #[test]
    fn ellipsoid_matches_lynch_closed_form() {
        let m = model("tripoly2");
        let c = m.ellipsoid_c();
        let mut ev = 0;
        for (p, n, vp, mu) in [
            (
                Vec2::new(0.5, -0.2),
                Vec2::new(-0.6, 0.8),
                Vec2::new(-1.0, 0.0),
                0.5,
            ),
            (
                Vec2::new(-0.3, 0.4),
                Vec2::new(0.0, -1.0),
                Vec2::new(-0.2, -1.0),
                0.3,
            ),
            (
                Vec2::new(0.7, 0.1),
                Vec2::new(-1.0, 0.0),
                Vec2::new(-1.0, 0.6),
                0.05,
            ),
        ] {
            let n = n.normalized();
            let g = ContactGeom {
                p,
                n,
                v_pin: vp,
                slide_at: None,
            };
            let mut warm = Warm::for_tolerance(1e-6);
            let inst = classify(
                &m,
                Fidelity::Ellipsoid,
                &g,
                Friction::new(mu),
                &mut warm,
                &mut ev,
            )
            .unwrap()
            .unwrap();
            // Lynch: stick if v_pin inside the motion cone; else slide with v_b in place of v_pin.
            let phi = f64::atan(mu);
            let edge_vel = |f: Vec2| {
                // For a force f at p the ellipsoid twist is (c² f, p×f): contact velocity.
                let xi = [c * c * f.x, c * c * f.y, p.cross(f)];
                point_velocity(xi, p)
            };
            let vl = edge_vel(n.rotate(phi));
            let vr = edge_vel(n.rotate(-phi));
            let expected = if vl.cross(vp) > 0.0 {
                let k = n.dot(vp) / n.dot(vl);
                lynch_stick(c, p, vl * k)
            } else if vr.cross(vp) < 0.0 {
                let k = n.dot(vp) / n.dot(vr);
                lynch_stick(c, p, vr * k)
            } else {
                lynch_stick(c, p, vp)
            };
            for i in 0..3 {
                assert!(
                    (inst.twist[i] - expected[i]).abs() < 1e-10,
                    "{:?} vs {:?} ({:?})",
                    inst.twist,
                    expected,
                    inst.mode
                );
            }
        }
    }

    /// A slide on an edge or round a vertex of a model with slide tables is served by them (no
    /// evaluation) and agrees with the solve the table stands for; the same contact without a
    /// place (a fence's feature) is solved.
    #[test]
    fn slides_on_edges_and_vertices_come_from_the_tables() {
        let plain = model("tripoly1");
        let tabled = plain.clone().with_slide_tables(&[0.5]);
        let poly = plain.polygon().clone();
        for k in 0..poly.len() {
            let (na, nb) = (
                poly.inward_normal(k + poly.len() - 1),
                poly.inward_normal(k),
            );
            let phi = na.angle() + 0.4 * na.cross(nb).atan2(na.dot(nb));
            let e = poly.edge_dir(k);
            for (p, n, at) in [
                (
                    poly.vertex(k),
                    Vec2::from_angle(phi),
                    SlideAt::Vertex(k, phi),
                ),
                (
                    poly.vertex(k) + e * (0.3 * poly.edge_len(k)),
                    e.perp(),
                    SlideAt::Edge(k, 0.3 * poly.edge_len(k)),
                ),
            ] {
                // Mostly across the normal: outside the friction cone's motions, a slide.
                let v_pin = n * 0.3 - n.perp() * 1.0;
                let g = ContactGeom {
                    p,
                    n,
                    v_pin,
                    slide_at: Some(at),
                };
                let run = |m: &PartModel, g: &ContactGeom| {
                    let mut ev = 0;
                    let i = classify(
                        m,
                        Fidelity::Exact,
                        g,
                        Friction::new(0.5),
                        &mut Warm::for_tolerance(1e-6),
                        &mut ev,
                    )
                    .unwrap()
                    .unwrap();
                    (i, ev)
                };
                let (solved, ev_solved) = run(&plain, &g);
                let (served, ev_served) = run(&tabled, &g);
                assert!(matches!(solved.mode, Mode::SlideLeft | Mode::SlideRight));
                assert_eq!(solved.mode, served.mode, "{at:?}");
                assert_eq!(ev_served, 0, "{at:?}: the tables serve both cone edges");
                assert!(ev_solved > 0);
                let scale = solved.twist.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                for (a, b) in solved.twist.iter().zip(served.twist) {
                    assert!(
                        (a - b).abs() < 1e-8 * scale,
                        "{at:?}: {solved:?} {served:?}"
                    );
                }
                // Without a place on the part the tabled model solves like the plain one.
                let (_, ev_off) = run(
                    &tabled,
                    &ContactGeom {
                        slide_at: None,
                        ..g
                    },
                );
                assert!(ev_off > 0);
            }
        }
    }

    /// A stick on an edge of a model with tables is served by its stick table (no evaluation)
    /// and agrees with the solve; a stick at a vertex, where no stick table applies, is solved.
    #[test]
    fn sticks_on_edges_come_from_the_tables() {
        let plain = model("lshape");
        let tabled = plain.clone().with_slide_tables(&[0.8]).with_stick_tables();
        let poly = plain.polygon().clone();
        let run = |m: &PartModel, g: &ContactGeom| {
            let mut ev = 0;
            let i = classify(
                m,
                Fidelity::Exact,
                g,
                Friction::new(0.8),
                &mut Warm::for_tolerance(1e-6),
                &mut ev,
            )
            .unwrap()
            .unwrap();
            (i, ev)
        };
        for k in 0..poly.len() {
            let (e, ell) = (poly.edge_dir(k), 0.45 * poly.edge_len(k));
            let n = e.perp();
            // Nearly along the normal: inside the friction cone's motions, a stick.
            let g = ContactGeom {
                p: poly.vertex(k) + e * ell,
                n,
                v_pin: n * 0.9 + e * 0.05,
                slide_at: Some(SlideAt::Edge(k, ell)),
            };
            let (solved, ev_solved) = run(&plain, &g);
            let (served, ev_served) = run(&tabled, &g);
            assert_eq!(solved.mode, Mode::Stick, "edge {k}");
            assert_eq!(served.mode, Mode::Stick, "edge {k}");
            assert!(ev_solved > 0);
            assert_eq!(
                ev_served, 0,
                "edge {k}: slides and stick all from the tables"
            );
            let scale = solved.twist.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in solved.twist.iter().zip(served.twist) {
                assert!(
                    (a - b).abs() < 1e-8 * scale,
                    "edge {k}: {solved:?} {served:?}"
                );
            }
            assert!((solved.force - served.force).norm() < 1e-8 * solved.force.norm());
            // The same stick at the edge's start vertex: no stick table there.
            let at_vertex = ContactGeom {
                p: poly.vertex(k),
                slide_at: Some(SlideAt::Vertex(k, n.angle())),
                ..g
            };
            let mut ev_vertex = 0;
            let stick = solve_in_mode(
                &tabled,
                Fidelity::Exact,
                &at_vertex,
                Friction::new(0.8),
                Mode::Stick,
                &mut Warm::for_tolerance(1e-6),
                &mut ev_vertex,
            )
            .unwrap();
            assert_eq!(stick.mode, Mode::Stick);
            assert!(ev_vertex > 0, "edge {k}");
        }
    }

    #[test]
    fn separation_when_not_pushing() {
        let m = model("square");
        let g = ContactGeom {
            p: Vec2::new(0.5, 0.0),
            n: Vec2::new(1.0, 0.0),
            v_pin: Vec2::new(-1.0, 0.0),
            slide_at: None,
        };
        let mut ev = 0;
        assert!(classify(
            &m,
            Fidelity::Tip,
            &g,
            Friction::new(0.5),
            &mut Warm::for_tolerance(1e-6),
            &mut ev
        )
        .unwrap()
        .is_none());
    }
}
