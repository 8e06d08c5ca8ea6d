//! Exact limit surface of a polygon under uniform pressure (docs/physics.md#limit-surface).
//!
//! Part frame, centroid at the origin, pressure p0 = 1/A (total load 1), μs = 1. For a twist
//! ξ = [vx, vy, ω] the sliding velocity of the material point x is u(x) = v + ω ẑ×x and
//!
//! * D(ξ) = p0 ∫_A |u| dA,
//! * ∇D(ξ) = p0 ∫_A Jᵀ û dA, J(x) = [[1, 0, −y], [0, 1, x]] (the load on the part is −∇D),
//! * H(ξ) = p0 ∫_A Jᵀ (I − ûûᵀ) J / |u| dA (symmetric, positive semidefinite, H ξ = 0).
//!
//! ## Near field: closed form about the centre of rotation
//!
//! For ω ≠ 0, u(x) = ω ẑ×(x − r) with the centre of rotation r = ẑ×v / ω, so |u| = |ω| |x − r| and
//! û = sgn(ω) ẑ×ê, ê = (x − r)/|x − r|. With I0(r) = ∫ |x − r| dA, G(r) = ∫ ê dA and
//! K(r) = ∫ ê êᵀ / |x − r| dA:
//!
//! * D = |ω| p0 I0(r),
//! * ∇D = p0 sgn(ω) [ẑ×G(r), I0(r) + r·G(r)] (the moment uses x·ê = |x − r| + r·ê),
//! * H = (p0/|ω|) L K(r) Lᵀ with L = [[1, 0], [0, 1], [−r_y, r_x]] (because I − ûûᵀ = ê êᵀ and
//!   x×ê = r×ê).
//!
//! These agree with docs/physics.md#limit-surface (whose F, M_c are the load on the part, i.e. −∇D).
//!
//! The three integrals are sums over the directed edges a→b of the signed fan triangles (r, a, b).
//! Per edge, with e the unit edge direction, n = ẑ×e, c = (a − r)·n (signed; h = |c|; the foot of the
//! perpendicular from r is r + c n), u = (x − r)·e, ρ = |x − r| and L(u) = asinh(u/h) = ln((ρ + u)/h),
//! each bracket [·] taken from a to b:
//!
//! * I0 += −c/6 [u ρ + c² L],
//! * G  += −c/2 [c L n + ρ e],
//! * K  += −c [u/ρ] n nᵀ + c² [1/ρ] (n eᵀ + e nᵀ) − c [L − u/ρ] e eᵀ
//!   (polar coordinates about r: ∫ ê êᵀ/ρ dA = ∫ R(φ) ê êᵀ dφ with R = h/cos ψ = ρ_edge,
//!   dφ = h du/ρ², hence h ∫ (h ν + u e)(h ν + u e)ᵀ/ρ³ du).
//!
//! An edge whose line passes through r (h = 0; below 1e-150 of |u| at its ends) adds nothing.
//! End distances are formed as ρ = √(u² + c²) so that ρ ≥ h holds exactly even when r sits on a
//! vertex. The differences are formed without cancellation: ρ_b − ρ_a = ℓ (u_a + u_b)/(ρ_a + ρ_b),
//! u_b ρ_b − u_a ρ_a = u_b (ρ_b − ρ_a) + ρ_a ℓ, and `[L]` = ln1p((Δρ + ℓ)/(ρ_a + u_a)) when both
//! ends have u ≥ 0, ln1p((ℓ − Δρ)/(ρ_b − u_b)) when both have u ≤ 0, and ln((ρ_b + u_b)/h) +
//! ln((ρ_a − u_a)/h) when the foot of the perpendicular lies inside the edge (ℓ = |b − a|). This is
//! valid for any r: outside, inside, on an edge or at a vertex.
//!
//! ## Far field: quadrature in twist form
//!
//! Far from the part (|r| ≫ a) the fan terms are O(|r|² a) while the moment is O(a⁴/|r|), so the
//! closed form loses accuracy like ε (|r|/a)³ in ∇D; at pure translation (ω = 0) it does not exist.
//! There the integrands of D, ∇D and H are smooth on the part (the singularity x = r lies at
//! distance ≥ |r| − a from it), so we integrate them directly in twist form with a collapsed
//! (Duffy) tensor Gauss–Legendre rule, x = A + s (B − A + t (C − B)), dA = 2|ABC| s ds dt, on each
//! triangle of an ear-clipping triangulation of the polygon (convex or concave; all weights
//! positive, so the rule's rounding is not amplified). Nodes and weights (times p0) are precomputed
//! in [`UniformSurface::new`]. The far field is used when |v| > R·a·|ω| (|r| > R a), which includes
//! ω = 0, so D, ∇D and H are smooth through pure translation from both signs of ω. The rule
//! integrates polynomials of degree ≤ 1 exactly, so at ω = 0 the moment is zero to rounding.
//!
//! Chosen numbers (by measurement): R = [`FAR_FIELD_RATIO`] = 5 and N = [`FAR_FIELD_ORDER`] = 8
//! Gauss points per direction on each triangle of an ear-clipping triangulation (N² = 64 nodes per
//! triangle, 64 (m − 2) for m edges). Measured at |r| = R a over 720 twists per part (360
//! directions of r, both signs of ω) on TriPoly2, a square, a 2×1 rectangle, the L-shape, a 10×1
//! sliver and a 12-gon, with a 48×48-point rule as reference; relative errors in D, ‖∇D‖ and ‖H‖
//! (Frobenius):
//!
//! | at the switch                | D          | ∇D                     | H                        |
//! |------------------------------|------------|------------------------|--------------------------|
//! | 8-point rule vs 48-point rule | ≤ 1e-14   | ≤ 1.4e-14              | ≤ 1.5e-14                |
//! | closed form vs 8-point rule  | ≤ 1.1e-14  | ≤ 5e-14 (sliver 6e-13) | ≤ 9e-13 (sliver 2.5e-11) |
//!
//! The moment alone, relative to itself (it is only O(a/R) of the force), agrees to 3e-12 on the
//! triangle and 1.6e-10 on the sliver. The disagreement is the closed form's rounding, which grows
//! like ε (|r|/a)³ in ∇D (vertices seen from r are rotated into each edge's frame with O(ε |r|)
//! error, and the fan terms are O(|r|² a)): at |r| = 20 a it reaches 2e-12 (triangle) to 2e-11
//! (sliver) in ∇D and 1e-9 in H. The rule, in turn, is converged to rounding (≤ 1e-14) for
//! |r| ≥ 4 a with N = 8 (N = 6 at 5 a: up to 1e-12 in ∇D and 1e-10 in H). Hence the switch at 5 a rather
//! than 20–40 a.
//!
//! Cost (release build, shared 2-core machine, value + gradient / with Hessian): triangle near
//! field 85–110 ns / 100–135 ns, far field (64 nodes) 250–320 ns / 385–480 ns; far-field cost
//! grows with the node count (L-shape: 256 nodes ≈ 0.9–1.1 µs; 12-gon: 640 nodes ≈ 2.3–2.6 µs). A compressed
//! (Tchakaloff) rule would cut that for many-sided parts. No heap allocation in any evaluation.

use super::Dissipation;
use crate::geometry::{Polygon, Vec2};

/// Far-field switch: quadrature is used when the centre of rotation is farther than this many part
/// radii `a` from the centroid (|v| > R a |ω|).
pub const FAR_FIELD_RATIO: f64 = 5.0;
/// Gauss–Legendre points per direction of the collapsed far-field rule (N² nodes per triangle).
pub const FAR_FIELD_ORDER: usize = 8;

/// Edges whose line passes closer to r than this fraction of |u| at their ends add nothing.
const DEGENERATE_EDGE: f64 = 1e-150;

/// Per-edge data for the closed forms.
#[derive(Debug, Clone, Copy)]
struct Edge {
    a: Vec2,
    b: Vec2,
    /// Unit direction a→b.
    e: Vec2,
    /// |b − a|.
    len: f64,
    /// n nᵀ, n eᵀ + e nᵀ, e eᵀ as [xx, xy, yy] with n = ẑ×e.
    nn: [f64; 3],
    ne: [f64; 3],
    ee: [f64; 3],
}

/// Uniform-pressure limit surface of one polygon (normalised: total load 1, μs = 1).
#[derive(Debug, Clone)]
pub struct UniformSurface {
    edges: Vec<Edge>,
    area: f64,
    /// Uniform pressure 1/A.
    p0: f64,
    /// a: largest centroid–vertex distance.
    radius: f64,
    /// R·a: the far-field switch radius.
    switch_radius: f64,
    /// Far-field nodes (structure of arrays): positions and weights·p0.
    node_x: Vec<f64>,
    node_y: Vec<f64>,
    node_w: Vec<f64>,
    ellipsoid_c: f64,
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the three-term recurrence).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0, 0.0); n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for iter in 0..100 {
            let (mut p_prev, mut p) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                let p_next = ((2.0 * kf - 1.0) * x * p - (kf - 1.0) * p_prev) / kf;
                p_prev = p;
                p = p_next;
            }
            dp = nf * (x * p - p_prev) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-15 && iter > 0 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out[i] = (-x, w);
        out[n - 1 - i] = (x, w);
    }
    if n % 2 == 1 {
        out[n / 2].0 = 0.0;
    }
    out
}

/// Ear-clipping triangulation of a simple counter-clockwise polygon (indices into `verts`).
/// Falls back to the fan from vertex 0 (signed areas, still exact for the integrals) if no ear is
/// found, which only happens for numerically degenerate input.
fn triangulate(verts: &[Vec2]) -> Vec<[usize; 3]> {
    let mut ring: Vec<usize> = (0..verts.len()).collect();
    let mut out = Vec::with_capacity(verts.len().saturating_sub(2));
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).find(|&k| {
            let (i, j, l) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
            let (a, b, c) = (verts[i], verts[j], verts[l]);
            if (b - a).cross(c - b) <= 0.0 {
                return false;
            }
            // No other vertex inside or on the candidate triangle.
            ring.iter().all(|&q| {
                if q == i || q == j || q == l {
                    return true;
                }
                let p = verts[q];
                let inside = (b - a).cross(p - a) >= 0.0
                    && (c - b).cross(p - b) >= 0.0
                    && (a - c).cross(p - c) >= 0.0;
                !inside
            })
        });
        match ear {
            Some(k) => {
                out.push([ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]]);
                ring.remove(k);
            }
            None => {
                for k in 1..m - 1 {
                    out.push([ring[0], ring[k], ring[k + 1]]);
                }
                return out;
            }
        }
    }
    out.push([ring[0], ring[1], ring[2]]);
    out
}

impl UniformSurface {
    /// Precompute the per-edge data and the far-field rule with the default switch
    /// ([`FAR_FIELD_RATIO`]) and order ([`FAR_FIELD_ORDER`]).
    pub fn new(poly: &Polygon) -> Self {
        Self::with_far_field(poly, FAR_FIELD_RATIO, FAR_FIELD_ORDER)
    }

    /// As [`UniformSurface::new`] with an explicit far-field switch ratio R (quadrature when
    /// |r| > R a) and Gauss order per direction. For accuracy studies; `new` uses measured
    /// defaults.
    pub fn with_far_field(poly: &Polygon, ratio: f64, order: usize) -> Self {
        let verts = poly.vertices();
        let m = verts.len();
        let edges: Vec<Edge> = (0..m)
            .map(|i| {
                let a = verts[i];
                let b = verts[(i + 1) % m];
                let d = b - a;
                let len = d.norm();
                let e = d / len;
                let n = e.perp();
                Edge {
                    a,
                    b,
                    e,
                    len,
                    nn: [n.x * n.x, n.x * n.y, n.y * n.y],
                    ne: [2.0 * n.x * e.x, n.x * e.y + n.y * e.x, 2.0 * n.y * e.y],
                    ee: [e.x * e.x, e.x * e.y, e.y * e.y],
                }
            })
            .collect();
        let area = poly.area();
        let p0 = 1.0 / area;
        let radius = poly.radius();
        let gl = gauss_legendre(order.max(1));
        let triangles = triangulate(verts);
        let count = triangles.len() * gl.len() * gl.len();
        let (mut node_x, mut node_y, mut node_w) = (
            Vec::with_capacity(count),
            Vec::with_capacity(count),
            Vec::with_capacity(count),
        );
        for [i, j, k] in triangles {
            // Collapsed rule on triangle (A, B, C): x = A + s (B − A + t (C − B)), dA = s |2 area|
            // ds dt.
            let (pa, pb, pc) = (verts[i], verts[j], verts[k]);
            let twice_area = (pb - pa).cross(pc - pa);
            for &(xs, ws) in &gl {
                let s = 0.5 * (1.0 + xs);
                for &(xt, wt) in &gl {
                    let t = 0.5 * (1.0 + xt);
                    let x = pa + (pb - pa + (pc - pb) * t) * s;
                    node_x.push(x.x);
                    node_y.push(x.y);
                    node_w.push(0.25 * ws * wt * s * twice_area * p0);
                }
            }
        }
        let mut surface = UniformSurface {
            edges,
            area,
            p0,
            radius,
            switch_radius: ratio * radius,
            node_x,
            node_y,
            node_w,
            ellipsoid_c: 0.0,
        };
        surface.ellipsoid_c = p0 * surface.i0_g(Vec2::ZERO).0;
        surface
    }

    /// Area A of the polygon.
    pub fn area(&self) -> f64 {
        self.area
    }
    /// a: largest centroid–vertex distance.
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// Distance from the centroid beyond which a centre of rotation is handled by quadrature.
    pub fn switch_radius(&self) -> f64 {
        self.switch_radius
    }
    /// Number of far-field quadrature nodes.
    pub fn far_field_nodes(&self) -> usize {
        self.node_w.len()
    }

    /// Closed-form fan sums about `r`; K only when `WITH_K`.
    #[inline]
    fn fan_sums<const WITH_K: bool>(&self, r: Vec2) -> (f64, Vec2, [f64; 3]) {
        let mut i0 = 0.0;
        let mut g = Vec2::ZERO;
        let mut k = [0.0; 3];
        let Some(first) = self.edges.first() else {
            return (i0, g, k);
        };
        let mut da = first.a - r;
        for ed in &self.edges {
            let db = ed.b - r;
            let n = ed.e.perp();
            let c = da.dot(n);
            let h = c.abs();
            let ua = da.dot(ed.e);
            let ub = db.dot(ed.e);
            if h > DEGENERATE_EDGE * ua.abs().max(ub.abs()) {
                let len = ed.len;
                let c2 = c * c;
                // End distances from (u, c) rather than |a − r|, so that ρ ≥ h > 0 exactly.
                let ra = (ua * ua + c2).sqrt();
                let rb = (ub * ub + c2).sqrt();
                let drho = len * (ua + ub) / (ra + rb);
                let dl = if ua >= 0.0 {
                    ((drho + len) / (ra + ua)).ln_1p()
                } else if ub <= 0.0 {
                    ((len - drho) / (rb - ub)).ln_1p()
                } else {
                    ((rb + ub) / h).ln() + ((ra - ua) / h).ln()
                };
                i0 -= c / 6.0 * (ub * drho + ra * len + c2 * dl);
                g -= (n * (c * dl) + ed.e * drho) * (0.5 * c);
                if WITH_K {
                    let dq = ub / rb - ua / ra;
                    let dinv = -drho / (ra * rb);
                    let cnn = -c * dq;
                    let cne = c2 * dinv;
                    let cee = -c * (dl - dq);
                    for (j, kj) in k.iter_mut().enumerate() {
                        *kj += cnn * ed.nn[j] + cne * ed.ne[j] + cee * ed.ee[j];
                    }
                }
            }
            da = db;
        }
        (i0, g, k)
    }

    /// I0(r) = ∫_A |x − r| dA and G(r) = ∫_A (x − r)/|x − r| dA (part frame, unnormalised, closed
    /// form; any r: outside, inside, on an edge or at a vertex).
    pub fn i0_g(&self, r: Vec2) -> (f64, Vec2) {
        let (i0, g, _) = self.fan_sums::<false>(r);
        (i0, g)
    }

    /// K(r) = ∫_A ê êᵀ / |x − r| dA, ê = (x − r)/|x − r|, as [kxx, kxy, kyy] (unnormalised, closed
    /// form).
    pub fn k_matrix(&self, r: Vec2) -> [f64; 3] {
        self.fan_sums::<true>(r).2
    }

    /// D, ∇D and (if `hessian`) H at twist ξ = [vx, vy, ω] (part frame), normalised pressure.
    /// ξ must not be zero (a zero twist returns [`Dissipation::ZERO`]).
    pub fn eval(&self, xi: [f64; 3], hessian: bool) -> Dissipation {
        let speed = (xi[0] * xi[0] + xi[1] * xi[1]).sqrt();
        let omega = xi[2];
        if speed > self.switch_radius * omega.abs() {
            self.eval_quadrature(xi, hessian)
        } else if omega != 0.0 {
            self.eval_closed_form(xi, hessian)
        } else if speed == 0.0 {
            Dissipation::ZERO
        } else {
            // Only reachable for a non-finite switch radius.
            self.eval_quadrature(xi, hessian)
        }
    }

    /// The near-field branch of [`UniformSurface::eval`] at any twist with ω ≠ 0 (closed form about
    /// the centre of rotation r = ẑ×v/ω). Exposed for accuracy studies; ω = 0 gives non-finite
    /// output.
    pub fn eval_closed_form(&self, xi: [f64; 3], hessian: bool) -> Dissipation {
        let v = Vec2::new(xi[0], xi[1]);
        let omega = xi[2];
        let r = v.perp() / omega;
        let (i0, g, k) = if hessian {
            self.fan_sums::<true>(r)
        } else {
            self.fan_sums::<false>(r)
        };
        let p0 = self.p0;
        let sp = omega.signum() * p0;
        let f = g.perp() * sp;
        let mut out = Dissipation {
            value: omega.abs() * p0 * i0,
            grad: [f.x, f.y, sp * (i0 + r.dot(g))],
            hess: [[0.0; 3]; 3],
        };
        if hessian {
            let s = p0 / omega.abs();
            let l = r.perp();
            let (kxx, kxy, kyy) = (k[0], k[1], k[2]);
            let kl = Vec2::new(kxx * l.x + kxy * l.y, kxy * l.x + kyy * l.y);
            let hxx = s * kxx;
            let hxy = s * kxy;
            let hyy = s * kyy;
            let hxw = s * kl.x;
            let hyw = s * kl.y;
            let hww = s * l.dot(kl);
            out.hess = [[hxx, hxy, hxw], [hxy, hyy, hyw], [hxw, hyw, hww]];
        }
        out
    }

    /// The far-field branch of [`UniformSurface::eval`] at any twist: the collapsed Gauss rule
    /// applied to the twist-form integrands. Exact only when the centre of rotation is far from the
    /// part.
    pub fn eval_quadrature(&self, xi: [f64; 3], hessian: bool) -> Dissipation {
        if hessian {
            self.quadrature::<true>(xi)
        } else {
            self.quadrature::<false>(xi)
        }
    }

    #[inline]
    fn quadrature<const HESSIAN: bool>(&self, xi: [f64; 3]) -> Dissipation {
        let (vx, vy, om) = (xi[0], xi[1], xi[2]);
        // Blocks: first the speeds and w/|u| (an element-wise map that vectorises: the square roots
        // and divisions dominate), then the sums in node order.
        const BLOCK: usize = 32;
        let mut d = 0.0;
        let (mut gx, mut gy, mut gm) = (0.0, 0.0, 0.0);
        let mut h = [0.0; 6];
        let mut speed = [0.0; BLOCK];
        let mut w_over = [0.0; BLOCK];
        let xs = self.node_x.chunks(BLOCK);
        let ys = self.node_y.chunks(BLOCK);
        let ws = self.node_w.chunks(BLOCK);
        for ((x, y), w) in xs.zip(ys).zip(ws) {
            let m = x.len();
            let (y, w) = (&y[..m], &w[..m]);
            for i in 0..m {
                let ux = vx - om * y[i];
                let uy = vy + om * x[i];
                let s = (ux * ux + uy * uy).sqrt();
                speed[i] = s;
                w_over[i] = w[i] / s;
            }
            for i in 0..m {
                let ux = vx - om * y[i];
                let uy = vy + om * x[i];
                let wsp = w_over[i];
                d += w[i] * speed[i];
                gx += wsp * ux;
                gy += wsp * uy;
                gm += wsp * (x[i] * uy - y[i] * ux);
                if HESSIAN {
                    // Jᵀu⊥ with u⊥ = ẑ×u is (−uy, ux, x ux + y uy); H += w/|u|³ (Jᵀu⊥)(Jᵀu⊥)ᵀ.
                    let (a0, a1, a2) = (-uy, ux, x[i] * ux + y[i] * uy);
                    let wh = wsp / (speed[i] * speed[i]);
                    h[0] += wh * a0 * a0;
                    h[1] += wh * a0 * a1;
                    h[2] += wh * a0 * a2;
                    h[3] += wh * a1 * a1;
                    h[4] += wh * a1 * a2;
                    h[5] += wh * a2 * a2;
                }
            }
        }
        Dissipation {
            value: d,
            grad: [gx, gy, gm],
            hess: [[h[0], h[1], h[2]], [h[1], h[3], h[4]], [h[2], h[4], h[5]]],
        }
    }

    /// c = m_max / f_max of the ellipsoid approximation: (1/A) ∫_A |x| dA (length units).
    pub fn ellipsoid_c(&self) -> f64 {
        self.ellipsoid_c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn l_shape() -> Polygon {
        Polygon::from_xy(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ])
        .unwrap()
    }

    fn comb() -> Polygon {
        // Three teeth: strongly concave (two notches).
        Polygon::from_xy(&[
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 3.0),
            (4.0, 3.0),
            (4.0, 1.0),
            (3.0, 1.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ])
        .unwrap()
    }

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in [1, 2, 5, 8, 13] {
            let rule = gauss_legendre(n);
            for k in 0..2 * n {
                let q: f64 = rule.iter().map(|&(x, w)| w * x.powi(k as i32)).sum();
                let exact = if k % 2 == 1 {
                    0.0
                } else {
                    2.0 / (k as f64 + 1.0)
                };
                assert!((q - exact).abs() < 1e-14, "n {n} k {k}: {q} vs {exact}");
            }
            // and not beyond (degree 2n, even), visibly so for small n
            if n <= 5 {
                let q: f64 = rule.iter().map(|&(x, w)| w * x.powi(2 * n as i32)).sum();
                assert!((q - 2.0 / (2.0 * n as f64 + 1.0)).abs() > 1e-6);
            }
        }
    }

    #[test]
    fn ear_clipping_covers_concave_parts_with_positive_triangles() {
        for poly in [l_shape(), comb()] {
            let v = poly.vertices();
            let tris = triangulate(v);
            assert_eq!(tris.len(), v.len() - 2);
            let mut total = 0.0;
            for [i, j, k] in tris {
                let a2 = (v[j] - v[i]).cross(v[k] - v[i]);
                assert!(a2 > 0.0);
                total += 0.5 * a2;
            }
            assert!((total - poly.area()).abs() < 1e-13 * poly.area());
        }
    }

    #[test]
    fn far_field_rule_reproduces_mass_properties() {
        for poly in [l_shape(), comb()] {
            let s = UniformSurface::new(&poly);
            let (mut m0, mut mx, mut my, mut j) = (0.0, 0.0, 0.0, 0.0);
            for i in 0..s.far_field_nodes() {
                let (x, y, w) = (s.node_x[i], s.node_y[i], s.node_w[i]);
                m0 += w;
                mx += w * x;
                my += w * y;
                j += w * (x * x + y * y);
            }
            assert!((m0 - 1.0).abs() < 1e-14);
            assert!(mx.abs() < 1e-14 && my.abs() < 1e-14);
            assert!((j - poly.polar_moment() / poly.area()).abs() < 1e-13);
        }
    }

    /// ∇_r I0 = −G and ∇_r G = −(tr K · I − K): the three closed forms are consistent.
    #[test]
    fn closed_forms_are_mutually_consistent_derivatives() {
        for poly in [l_shape(), comb()] {
            let s = UniformSurface::new(&poly);
            let h = 1e-6;
            for r in [
                Vec2::new(0.13, -0.21),
                Vec2::new(3.0, 2.5),
                Vec2::new(-0.4, 0.9),
                Vec2::new(10.0, -4.0),
            ] {
                let (i0, g) = s.i0_g(r);
                let k = s.k_matrix(r);
                let tr = k[0] + k[2];
                let (ixp, gxp) = s.i0_g(r + Vec2::new(h, 0.0));
                let (ixm, gxm) = s.i0_g(r - Vec2::new(h, 0.0));
                let (iyp, gyp) = s.i0_g(r + Vec2::new(0.0, h));
                let (iym, gym) = s.i0_g(r - Vec2::new(0.0, h));
                let scale = poly.area();
                assert!(((ixp - ixm) / (2.0 * h) + g.x).abs() < 1e-8 * scale);
                assert!(((iyp - iym) / (2.0 * h) + g.y).abs() < 1e-8 * scale);
                let dgx = (gxp - gxm) / (2.0 * h);
                let dgy = (gyp - gym) / (2.0 * h);
                // ∂G/∂x = −(tr K e_x − K e_x), ∂G/∂y = −(tr K e_y − K e_y).
                let tol = 1e-7 * tr;
                assert!((dgx.x + (tr - k[0])).abs() < tol, "{r:?}");
                assert!((dgx.y - k[1]).abs() < tol, "{r:?}");
                assert!((dgy.x - k[1]).abs() < tol, "{r:?}");
                assert!((dgy.y + (tr - k[2])).abs() < tol, "{r:?}");
                assert!(i0 > 0.0);
            }
        }
    }

    /// At a vertex and on an edge the closed forms are finite and equal to their limits.
    #[test]
    fn vertices_and_edges_are_continuous_limits() {
        let poly = comb();
        let s = UniformSurface::new(&poly);
        let v = poly.vertices();
        for i in 0..v.len() {
            let mid = (v[i] + v[(i + 1) % v.len()]) * 0.5;
            for r in [v[i], mid] {
                let (i0, g) = s.i0_g(r);
                let k = s.k_matrix(r);
                assert!(i0.is_finite() && g.is_finite() && k.iter().all(|x| x.is_finite()));
                for dir in [Vec2::new(1.0, 0.3), Vec2::new(-0.2, -1.0)] {
                    let (i1, g1) = s.i0_g(r + dir * 1e-9);
                    let k1 = s.k_matrix(r + dir * 1e-9);
                    // I0 is C¹ with ∇I0 = −G, also at a vertex or on an edge.
                    assert!(
                        (i1 - i0 + g.dot(dir) * 1e-9).abs() < 1e-14 * poly.area(),
                        "{r:?}"
                    );
                    // G is Lipschitz-continuous only up to a log: 1e-9 ln(1e9) scale.
                    assert!((g1 - g).norm() < 1e-7 * poly.area(), "{r:?}");
                    // K has a logarithmic singularity in its derivative: continuity, coarse.
                    for j in 0..3 {
                        assert!((k1[j] - k[j]).abs() < 1e-3 * (k[0] + k[2]), "{r:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn eval_branches_follow_the_switch() {
        let poly = l_shape();
        let s = UniformSurface::new(&poly);
        assert_eq!(s.switch_radius(), FAR_FIELD_RATIO * poly.radius());
        let far = [1.0, 0.0, 0.9 / s.switch_radius()];
        let near = [1.0, 0.0, 1.1 / s.switch_radius()];
        assert_eq!(s.eval(far, true), s.eval_quadrature(far, true));
        assert_eq!(s.eval(near, true), s.eval_closed_form(near, true));
        assert_eq!(
            s.eval([1.0, 0.0, 0.0], false),
            s.eval_quadrature([1.0, 0.0, 0.0], false)
        );
        // The concave part's closed form agrees with the quadrature at the switch.
        let a = s.eval_closed_form(near, true);
        let b = s.eval_quadrature(near, true);
        let gn = a.grad.iter().map(|x| x * x).sum::<f64>().sqrt();
        for j in 0..3 {
            assert!((a.grad[j] - b.grad[j]).abs() < 1e-12 * gn);
        }
    }
}
