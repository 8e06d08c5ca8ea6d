//! The frame of one contact between the part and a fixed obstacle (docs/physics.md#dynamic-tier):
//! a disc pin (centre P, radius r) touching a vertex or an edge of the part, or a straight fence
//! line touching a vertex.
//!
//! With q = (x, y, θ) and q̇ = (v, ω), the contact point c on the part (ρ = c − x from the
//! centroid), n the unit normal pointing from the obstacle into the part and t = ẑ×n:
//!
//! * gap g: the distance from the pin's disc to the part (negative when they overlap), or a
//!   vertex's distance from the fence line on the part's side;
//! * the normal and tangential velocities of the part's material point at c: u_n = J_n q̇,
//!   u_t = J_t q̇ with J_n = (n, ρ×n), J_t = (t, ρ×t) (ġ = u_n);
//! * their rates u̇ = J q̈ + b(q, q̇), where the velocity-product terms b depend on the feature:
//!   - vertex on a disc (d = |V − P| = r + g): b_n = −ω² n·ρ + u_t²/d, b_t = −ω² t·ρ − u_n u_t/d;
//!   - edge on a disc (c the foot of P on the edge line): b_n = 2ω (t·v) + ω² (P − x)·n,
//!     b_t = −ω (n·v);
//!   - vertex on a line: b_n = −ω² n·ρ, b_t = −ω² t·ρ (the disc's formulas as d → ∞);
//! * the inverse effective mass (Delassus) matrix A = J M⁻¹ Jᵀ relating a contact impulse
//!   (P_n, P_t) to the change of (u_n, u_t).
//!
//! The edge formulas follow from ġ = n·v + ω (P − x)×n and u_t = t·v + ω (ρ×t) with
//! ρ×t = (P − x)×t + r + g, differentiated with ṅ = ω t, ṫ = −ω n; the tests check every b
//! against finite differences along a trajectory.

use super::body::Body;
use crate::geometry::{Polygon, Vec2};

/// A disc pin fixed in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedPin {
    /// Centre (world frame).
    pub centre: Vec2,
    /// Radius r ≥ 0 (0: a point pin).
    pub radius: f64,
}

/// What of the part touches the obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ContactKind {
    /// Vertex `i` of the polygon on a disc pin.
    VertexOnPin(usize),
    /// A point inside edge `i` (vertex i → i + 1) on a disc pin.
    EdgeOnPin(usize),
    /// Vertex `i` on a straight fence line.
    VertexOnLine(usize),
}

/// The frame of a contact at one configuration (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// The touching feature.
    pub kind: ContactKind,
    /// Gap g (L); negative when the part overlaps the obstacle.
    pub gap: f64,
    /// Contact point c on the part (world).
    pub point: Vec2,
    /// Unit normal n from the obstacle into the part (world).
    pub normal: Vec2,
    /// ρ = c − x: the contact point from the centroid (world axes).
    pub rho: Vec2,
    /// P − x: the pin's centre from the centroid (edge contacts; zero otherwise).
    pub pin_from_centroid: Vec2,
    /// Distance d from the pin's centre to the touching vertex (vertex on a pin; ∞ on a line).
    pub reach: f64,
}

/// World position of part-frame point `p` at configuration q.
pub(crate) fn world_point(q: [f64; 3], p: Vec2) -> Vec2 {
    p.rotate(q[2]) + Vec2::new(q[0], q[1])
}

impl ContactFrame {
    /// The frame of the part (polygon `poly`, caller's units) at configuration `q` against `pin`:
    /// the nearest feature of the part's boundary to the pin's centre. A centre inside the part
    /// gives a negative gap.
    pub fn pin(poly: &Polygon, q: [f64; 3], pin: &FixedPin) -> ContactFrame {
        let x = Vec2::new(q[0], q[1]);
        let local = (pin.centre - x).rotate(-q[2]);
        let (dist, edge) = poly.distance_to_boundary(local);
        let inside = poly.contains(local);
        let (a, b) = poly.edge(edge);
        let e = b - a;
        let s = (local - a).dot(e) / e.norm2();
        let (kind, foot) = if s <= 0.0 {
            (ContactKind::VertexOnPin(edge), a)
        } else if s >= 1.0 {
            (ContactKind::VertexOnPin((edge + 1) % poly.len()), b)
        } else {
            (ContactKind::EdgeOnPin(edge), a + e * s)
        };
        let signed = if inside { -dist } else { dist };
        let normal_local = match kind {
            ContactKind::EdgeOnPin(_) => poly.inward_normal(edge),
            _ => {
                let d = (foot - local).normalized();
                if inside {
                    -d
                } else {
                    d
                }
            }
        };
        let normal = normal_local.rotate(q[2]);
        let point = world_point(q, foot);
        ContactFrame {
            kind,
            gap: signed - pin.radius,
            point,
            normal,
            rho: point - x,
            pin_from_centroid: match kind {
                ContactKind::EdgeOnPin(_) => pin.centre - x,
                _ => Vec2::ZERO,
            },
            reach: signed,
        }
    }

    /// The frame of the given feature (a vertex or an edge on the pin) at configuration `q`, the
    /// feature's circle or line extended beyond its own region: the frame a sustained contact
    /// keeps until [`ContactFrame::region`] says another feature touches.
    pub fn pin_feature(
        poly: &Polygon,
        q: [f64; 3],
        pin: &FixedPin,
        kind: ContactKind,
    ) -> ContactFrame {
        let x = Vec2::new(q[0], q[1]);
        match kind {
            ContactKind::EdgeOnPin(k) => {
                let n = poly.inward_normal(k).rotate(q[2]);
                let e0 = world_point(q, poly.vertex(k));
                let depth = (e0 - pin.centre).dot(n);
                let point = pin.centre + n * depth;
                ContactFrame {
                    kind,
                    gap: depth - pin.radius,
                    point,
                    normal: n,
                    rho: point - x,
                    pin_from_centroid: pin.centre - x,
                    reach: depth,
                }
            }
            ContactKind::VertexOnPin(i) | ContactKind::VertexOnLine(i) => {
                let point = world_point(q, poly.vertex(i));
                let d = point - pin.centre;
                let reach = d.norm();
                ContactFrame {
                    kind: ContactKind::VertexOnPin(i),
                    gap: reach - pin.radius,
                    point,
                    normal: d.normalized(),
                    rho: point - x,
                    pin_from_centroid: Vec2::ZERO,
                    reach,
                }
            }
        }
    }

    /// How far (length) the pin's centre lies inside the region where this feature is the part's
    /// nearest to it, and the feature beyond the region's nearer side: for an edge, the distance
    /// of the foot of the centre from the edge's nearer end (then that end's vertex); for a
    /// vertex, the least distance of the centre past the normal lines of its two edges (then that
    /// edge). Negative once another feature is the nearer.
    pub fn region(&self, poly: &Polygon, q: [f64; 3], pin: &FixedPin) -> (f64, ContactKind) {
        let local = (pin.centre - Vec2::new(q[0], q[1])).rotate(-q[2]);
        let m = poly.len();
        match self.kind {
            ContactKind::EdgeOnPin(k) => {
                let (a, len) = (poly.vertex(k), poly.edge_len(k));
                let s = (local - a).dot(poly.edge_dir(k));
                if s < len - s {
                    (s, ContactKind::VertexOnPin(k))
                } else {
                    (len - s, ContactKind::VertexOnPin((k + 1) % m))
                }
            }
            ContactKind::VertexOnPin(i) | ContactKind::VertexOnLine(i) => {
                let d = local - poly.vertex(i);
                let before = d.dot(poly.edge_dir(i + m - 1));
                let after = -d.dot(poly.edge_dir(i));
                if before < after {
                    (before, ContactKind::EdgeOnPin((i + m - 1) % m))
                } else {
                    (after, ContactKind::EdgeOnPin(i))
                }
            }
        }
    }

    /// The frame of vertex `i` of `poly` at configuration `q` against the straight line through
    /// `on_line` with unit normal `line_normal` pointing to the part's side.
    pub fn line(
        poly: &Polygon,
        q: [f64; 3],
        i: usize,
        on_line: Vec2,
        line_normal: Vec2,
    ) -> ContactFrame {
        let x = Vec2::new(q[0], q[1]);
        let point = world_point(q, poly.vertex(i));
        ContactFrame {
            kind: ContactKind::VertexOnLine(i),
            gap: (point - on_line).dot(line_normal),
            point,
            normal: line_normal,
            rho: point - x,
            pin_from_centroid: Vec2::ZERO,
            reach: f64::INFINITY,
        }
    }

    /// The unit tangent t = ẑ×n.
    pub fn tangent(&self) -> Vec2 {
        self.normal.perp()
    }

    /// The rows J_n = (n, ρ×n) and J_t = (t, ρ×t).
    pub fn jacobian(&self) -> ([f64; 3], [f64; 3]) {
        let (n, t) = (self.normal, self.tangent());
        ([n.x, n.y, self.rho.cross(n)], [t.x, t.y, self.rho.cross(t)])
    }

    /// (u_n, u_t): the normal and tangential velocity of the part's material point at the contact.
    pub fn velocity(&self, qd: [f64; 3]) -> (f64, f64) {
        let (jn, jt) = self.jacobian();
        (dot3(jn, qd), dot3(jt, qd))
    }

    /// The velocity-product terms (b_n, b_t) of u̇ = J q̈ + b (see the module docs).
    pub fn bias(&self, qd: [f64; 3]) -> (f64, f64) {
        let (n, t) = (self.normal, self.tangent());
        let v = Vec2::new(qd[0], qd[1]);
        let w = qd[2];
        match self.kind {
            ContactKind::EdgeOnPin(_) => (
                2.0 * w * t.dot(v) + w * w * self.pin_from_centroid.dot(n),
                -w * n.dot(v),
            ),
            ContactKind::VertexOnPin(_) | ContactKind::VertexOnLine(_) => {
                let (un, ut) = self.velocity(qd);
                let curv = if self.reach.is_finite() && self.reach > 0.0 {
                    1.0 / self.reach
                } else {
                    0.0
                };
                (
                    -w * w * n.dot(self.rho) + ut * ut * curv,
                    -w * w * t.dot(self.rho) - un * ut * curv,
                )
            }
        }
    }

    /// The inverse effective mass matrix A = J M⁻¹ Jᵀ at the contact, as (A_nn, A_nt, A_tt).
    pub fn delassus(&self, body: &Body) -> [f64; 3] {
        let (jn, jt) = self.jacobian();
        let mjn = body.inverse_mass_times(jn);
        let mjt = body.inverse_mass_times(jt);
        [dot3(jn, mjn), dot3(jn, mjt), dot3(jt, mjt)]
    }

    /// The generalised force Jᵀ (λn, λt) of a contact force (or impulse) with normal and
    /// tangential components λn, λt.
    pub fn generalised(&self, lambda_n: f64, lambda_t: f64) -> [f64; 3] {
        let (jn, jt) = self.jacobian();
        [
            jn[0] * lambda_n + jt[0] * lambda_t,
            jn[1] * lambda_n + jt[1] * lambda_t,
            jn[2] * lambda_n + jt[2] * lambda_t,
        ]
    }
}

/// The frame of a disc of radius 2 centred at the origin touching a line below it (the point
/// (0, −2), normal +y), for tests.
#[cfg(test)]
pub(crate) fn rim_frame() -> ContactFrame {
    ContactFrame {
        kind: ContactKind::VertexOnLine(0),
        gap: 0.0,
        point: Vec2::new(0.0, -2.0),
        normal: Vec2::new(0.0, 1.0),
        rho: Vec2::new(0.0, -2.0),
        pin_from_centroid: Vec2::ZERO,
        reach: f64::INFINITY,
    }
}

/// The dot product of two 3-vectors.
pub(crate) fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;

    /// q(τ) = q0 + q̇0 τ + ½ q̈ τ² and its rate.
    fn along(q0: [f64; 3], qd0: [f64; 3], qdd: [f64; 3], tau: f64) -> ([f64; 3], [f64; 3]) {
        let mut q = [0.0; 3];
        let mut qd = [0.0; 3];
        for i in 0..3 {
            q[i] = q0[i] + qd0[i] * tau + 0.5 * qdd[i] * tau * tau;
            qd[i] = qd0[i] + qdd[i] * tau;
        }
        (q, qd)
    }

    /// Check ġ = u_n (finite difference of the gap) and u̇ = J q̈ + b (finite differences of u).
    fn check(
        frame_at: &dyn Fn([f64; 3]) -> ContactFrame,
        q0: [f64; 3],
        qd0: [f64; 3],
        qdd: [f64; 3],
    ) {
        let h = 1e-5;
        let f0 = frame_at(q0);
        let (qm, qdm) = along(q0, qd0, qdd, -h);
        let (qp, qdp) = along(q0, qd0, qdd, h);
        let (fm, fp) = (frame_at(qm), frame_at(qp));
        assert_eq!(fm.kind, fp.kind);
        let (un, _) = f0.velocity(qd0);
        let gdot = (fp.gap - fm.gap) / (2.0 * h);
        assert!((gdot - un).abs() < 1e-7, "ġ {gdot} vs u_n {un}");
        let (unp, utp) = fp.velocity(qdp);
        let (unm, utm) = fm.velocity(qdm);
        let (jn, jt) = f0.jacobian();
        let (bn, bt) = f0.bias(qd0);
        let an = dot3(jn, qdd) + bn;
        let at = dot3(jt, qdd) + bt;
        assert!(
            ((unp - unm) / (2.0 * h) - an).abs() < 1e-6,
            "u̇_n {} vs {an}",
            (unp - unm) / (2.0 * h)
        );
        assert!(
            ((utp - utm) / (2.0 * h) - at).abs() < 1e-6,
            "u̇_t {} vs {at}",
            (utp - utm) / (2.0 * h)
        );
    }

    #[test]
    fn contact_rates_match_finite_differences_on_every_feature() {
        let poly = part_from_spec("tripoly2").unwrap();
        let qd = [0.3, -0.7, 1.3];
        let qdd = [0.5, 0.2, -0.9];
        // A disc pin off vertex 1 (nearest point the vertex) and off the middle of edge 0.
        let v1 = world_point([0.1, 0.2, 0.4], poly.vertex(1));
        let pin_v = FixedPin {
            centre: v1 + Vec2::new(0.3, -0.05),
            radius: 0.1,
        };
        let at_v = |q: [f64; 3]| ContactFrame::pin(&poly, q, &pin_v);
        assert!(matches!(
            at_v([0.1, 0.2, 0.4]).kind,
            ContactKind::VertexOnPin(1)
        ));
        check(&at_v, [0.1, 0.2, 0.4], qd, qdd);
        let q = [0.1, 0.2, 0.4];
        let (a, b) = poly.edge(0);
        let mid = world_point(q, (a + b) * 0.5);
        let n_in = poly.inward_normal(0).rotate(q[2]);
        let pin_e = FixedPin {
            centre: mid - n_in * 0.35,
            radius: 0.2,
        };
        let at_e = |q: [f64; 3]| ContactFrame::pin(&poly, q, &pin_e);
        assert!(matches!(at_e(q).kind, ContactKind::EdgeOnPin(0)));
        assert!((at_e(q).gap - 0.15).abs() < 1e-12);
        check(&at_e, q, qd, qdd);
        let at_l = |q: [f64; 3]| {
            ContactFrame::line(&poly, q, 2, Vec2::new(-1.0, 3.0), Vec2::from_angle(-0.3))
        };
        check(&at_l, q, qd, qdd);
    }

    #[test]
    fn the_delassus_matrix_of_a_rim_point_is_the_discs() {
        // A disc of radius R: at a rim point ρ = −R n, so A = diag(1/m, 1/m + R²/I) = diag(1/m, 3/m).
        let frame = rim_frame();
        let body = Body::new(3.0, 0.5 * 3.0 * 4.0).unwrap();
        let a = frame.delassus(&body);
        assert!((a[0] - 1.0 / 3.0).abs() < 1e-15 && a[1].abs() < 1e-15);
        assert!((a[2] - 1.0).abs() < 1e-15, "{a:?}");
    }
}
