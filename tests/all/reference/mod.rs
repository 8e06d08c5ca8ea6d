//! An independent, deliberately slow reference for the contact model (docs/physics.md#one-instant), used only by tests.
//!
//! It computes the same physics as `pinfeed::mechanics::push` by a different algorithm, sharing no
//! code with `crates/pinfeed/src/mechanics` (only the caller's vertex list):
//!
//! * **Dissipation** D(ξ) = (1/A)∫_A |v + ω ẑ×x| dA by its own quadrature, not the library's closed
//!   form. For a centre of rotation (COR) r within 20·a of the centroid, the divergence theorem
//!   (div((x−r)|x−r|) = 3|x−r|) turns I0(r) = ∫_A |x − r| dA into (1/3)Σ_k h_k ∫_{edge k} |x − r| dℓ
//!   (h_k the signed distance of r from edge k's line), each edge integral done by Gauss–Legendre on
//!   panels graded towards the foot of the perpendicular from r. Farther away (and for pure
//!   translation) the integrand is smooth over the part and a collapsed-product Gauss rule on the fan
//!   triangles from the centroid is used instead.
//! * **One instant** follows the steps of docs/physics.md#one-instant, but every minimisation is brute force (function values
//!   only, no gradient, no Newton on the limit surface): the friction-cone edge twists
//!   ξ_e = argmin D(ξ) subject to w(f_e)·ξ = 1 are found over the COR plane, where the problem is
//!   J(r) = I0(r) / (A |(p − r)×f|) (ω = 1/((p − r)×f), v = −ω ẑ×r), by a log-polar grid
//!   (|r| from 0.05·a to 1100·a, 36 directions) on a fresh contact, then from the previous
//!   instant's COR, a stencil search with quadratic-fit jumps in (ln|r|, arg r) (function values
//!   only, monotone descent); pure translation along f (J = 1/|f|) is the point at infinity,
//!   compared explicitly. When the COR is far (beyond 30·a), ω may be about to change sign (the
//!   minimiser passes through infinity), so the search restarts on both sides from 30·a. The stick
//!   problem, the 1-D convex minimisation over ω with v_c = v_pin, is
//!   solved by golden-section search. Stick iff v_pin lies in the cone of v_R, v_L; otherwise slide on
//!   the violated side scaled by κ = (n·v_pin)/(n·v_b); μc = 0 slides along the normal.
//! * **Integration** in the world frame, on the pose (x, y, θ) itself, with classical RK4 steps of
//!   fixed pin travel h. The mode is decided afresh at every stage (the twist is continuous across
//!   stick/slide switches, so they need no event location). After each step the contact is re-found
//!   geometrically: the part is translated along the edge normal so that the pin lies on the edge line
//!   again (no drift). When the pin passes an edge end, the step is shortened (secant on the step
//!   fraction) to land on the vertex, and the point pin passes onto the next edge if that edge faces
//!   the pin's motion (n·v_pin > 0), else the contact separates. The contact also separates when the
//!   pin stops pushing (n·v_pin ≤ 0), located within the step in the same way.
//! * **Own accuracy**: [`push_with_error`] runs a push at h and at h/2 and returns the h/2 result with
//!   the difference as its error estimate.
//!
//! Scope: convex polygons, point pins (ρ = 0), fixed pins (lateral speed 0), uniform pressure.
//! The CLI's convention places the part's centroid at the origin at θ0 and the pin at
//! (1.01·a, d·a), moving along −x relative to the belt.
#![allow(dead_code)]

use std::f64::consts::PI;
use std::ops::{Add, Mul, Neg, Sub};

/// A plane vector (own type: nothing shared with the library).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct V {
    pub x: f64,
    pub y: f64,
}

impl V {
    pub const fn new(x: f64, y: f64) -> V {
        V { x, y }
    }
    pub fn dot(self, o: V) -> f64 {
        self.x * o.x + self.y * o.y
    }
    pub fn cross(self, o: V) -> f64 {
        self.x * o.y - self.y * o.x
    }
    /// ẑ × self.
    pub fn perp(self) -> V {
        V::new(-self.y, self.x)
    }
    pub fn norm(self) -> f64 {
        self.x.hypot(self.y)
    }
    pub fn rot(self, a: f64) -> V {
        let (s, c) = a.sin_cos();
        V::new(c * self.x - s * self.y, s * self.x + c * self.y)
    }
    pub fn unit(self) -> V {
        self * (1.0 / self.norm())
    }
}

impl Add for V {
    type Output = V;
    fn add(self, o: V) -> V {
        V::new(self.x + o.x, self.y + o.y)
    }
}
impl Sub for V {
    type Output = V;
    fn sub(self, o: V) -> V {
        V::new(self.x - o.x, self.y - o.y)
    }
}
impl Mul<f64> for V {
    type Output = V;
    fn mul(self, k: f64) -> V {
        V::new(self.x * k, self.y * k)
    }
}
impl Neg for V {
    type Output = V;
    fn neg(self) -> V {
        V::new(-self.x, -self.y)
    }
}

/// A twist: centroid velocity and angular rate (part frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    pub v: V,
    pub w: f64,
}

impl Twist {
    pub fn scaled(self, k: f64) -> Twist {
        Twist {
            v: self.v * k,
            w: self.w * k,
        }
    }
    /// Velocity of the material point p.
    pub fn at(self, p: V) -> V {
        self.v + p.perp() * self.w
    }
}

/// Gauss–Legendre nodes per panel of the boundary quadrature.
const GL_NODES: usize = 6;
/// Panel length in units of the panel start's distance from the nearest singularity of the
/// integrand √(h² + t²) (at t = ±ih).
const PANEL: f64 = 2.0;
/// Gauss nodes per direction of the collapsed product rule on each fan triangle (far field).
const FAR_NODES: usize = 4;

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on the Legendre recurrence).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((0.5 * (1.0 - x), 0.5 * w));
    }
    out
}

/// A convex part for the reference: CCW vertices with the area centroid at the origin.
#[derive(Debug, Clone)]
pub struct Part {
    pub verts: Vec<V>,
    pub area: f64,
    /// Largest centroid-to-vertex distance.
    pub a: f64,
    gl: Vec<(f64, f64)>,
    /// Per edge: start, unit direction, length, outward unit normal.
    edges: Vec<(V, V, f64, V)>,
    /// Area quadrature (points, weights summing to the area) for far CORs and translations.
    far: Vec<(V, f64)>,
}

/// Why a vertex list is not a part the reference handles.
#[derive(Debug, Clone, PartialEq)]
pub enum PartError {
    TooFew,
    NotConvexCcw,
}

impl Part {
    /// Build from any CCW convex vertex list; recentres on its own area centroid.
    pub fn new(pts: &[V]) -> Result<Part, PartError> {
        let n = pts.len();
        if n < 3 {
            return Err(PartError::TooFew);
        }
        for i in 0..n {
            let (a, b, c) = (pts[i], pts[(i + 1) % n], pts[(i + 2) % n]);
            if (b - a).cross(c - b) <= 0.0 {
                return Err(PartError::NotConvexCcw);
            }
        }
        // Area and centroid by the fan from vertex 0.
        let (mut area, mut cx) = (0.0, V::new(0.0, 0.0));
        for i in 1..n - 1 {
            let t = 0.5 * (pts[i] - pts[0]).cross(pts[i + 1] - pts[0]);
            area += t;
            cx = cx + (pts[0] + pts[i] + pts[i + 1]) * (t / 3.0);
        }
        let c = cx * (1.0 / area);
        let verts: Vec<V> = pts.iter().map(|&p| p - c).collect();
        let a = verts.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let gl = gauss_legendre(GL_NODES);
        let g6 = gauss_legendre(FAR_NODES);
        let edges = (0..n)
            .map(|k| {
                let (a, b) = (verts[k], verts[(k + 1) % n]);
                let l = (b - a).norm();
                let e = (b - a) * (1.0 / l);
                (a, e, l, -e.perp())
            })
            .collect();
        let mut far = Vec::new();
        for i in 0..n {
            let (p, q) = (verts[i], verts[(i + 1) % n]);
            let jac = p.cross(q); // twice the triangle (0, p, q)'s area
            for &(s, ws) in &g6 {
                for &(t, wt) in &g6 {
                    // x = s·(p + t(q − p)), dA = s·|p×q| ds dt.
                    far.push(((p + (q - p) * t) * s, ws * wt * s * jac));
                }
            }
        }
        Ok(Part {
            verts,
            area,
            a,
            gl,
            edges,
            far,
        })
    }

    pub fn n(&self) -> usize {
        self.verts.len()
    }
    /// Edge k: (start, unit direction, length).
    pub fn edge(&self, k: usize) -> (V, V, f64) {
        let n = self.n();
        let (a, b) = (self.verts[k % n], self.verts[(k + 1) % n]);
        let l = (b - a).norm();
        (a, (b - a) * (1.0 / l), l)
    }
    /// Inward unit normal of edge k.
    pub fn normal(&self, k: usize) -> V {
        self.edge(k).1.perp()
    }

    /// ∫ sqrt(h² + t²) dt over [t0, t1], 0 ≤ t0 ≤ t1, on panels graded away from t = 0.
    fn hyp_integral(&self, h2: f64, t0: f64, t1: f64) -> f64 {
        let mut s = 0.0;
        let mut lo = t0;
        let mut guard = 0;
        while lo < t1 && guard < 200 {
            guard += 1;
            let reach = (h2 + lo * lo).sqrt().max(1e-300);
            let hi = (lo + PANEL * reach).min(t1);
            let w = hi - lo;
            for &(x, wx) in &self.gl {
                let t = lo + w * x;
                s += wx * w * (h2 + t * t).sqrt();
            }
            lo = hi;
        }
        s
    }

    /// I0(r) = ∫_A |x − r| dA: boundary form near the part, area quadrature far from it.
    pub fn i0(&self, r: V) -> f64 {
        if r.norm() > 20.0 * self.a {
            return self.far.iter().map(|&(x, w)| w * (x - r).norm()).sum();
        }
        let mut total = 0.0;
        for &(a, e, l, out) in &self.edges {
            let h = (a - r).dot(out);
            if h == 0.0 {
                continue;
            }
            let l0 = (r - a).dot(e);
            let h2 = h * h;
            let int = if l0 <= 0.0 {
                self.hyp_integral(h2, -l0, l - l0)
            } else if l0 >= l {
                self.hyp_integral(h2, l0 - l, l0)
            } else {
                self.hyp_integral(h2, 0.0, l0) + self.hyp_integral(h2, 0.0, l - l0)
            };
            total += h * int;
        }
        total / 3.0
    }

    /// D(ξ) = (1/A)∫_A |v + ω ẑ×x| dA (uniform pressure, normalised to total load 1).
    pub fn dissipation(&self, xi: Twist) -> f64 {
        let vn = xi.v.norm();
        if xi.w == 0.0 || vn > 20.0 * self.a * xi.w.abs() {
            let s: f64 = self
                .far
                .iter()
                .map(|&(x, w)| w * (xi.v + x.perp() * xi.w).norm())
                .sum();
            return s / self.area;
        }
        // COR r = ẑ×v/ω.
        let r = xi.v.perp() * (1.0 / xi.w);
        xi.w.abs() * self.i0(r) / self.area
    }
}

/// Warm starts of the searches, carried from instant to instant within one push.
#[derive(Debug, Clone, Copy, Default)]
pub struct Warm {
    /// (ln(|r|/a), arg r) of the last COR found for each cone edge (None: translation or unknown).
    pub left: Option<(f64, f64)>,
    pub right: Option<(f64, f64)>,
    pub normal: Option<(f64, f64)>,
    pub stick: Option<f64>,
}

fn cor_of(part: &Part, q: (f64, f64)) -> V {
    V::new(q.1.cos(), q.1.sin()) * (part.a * q.0.exp())
}

/// Largest ln(|r|/a) searched.
const T_MAX: f64 = 13.8;

/// J(r) = D of the twist about COR r normalised by w(f)·ξ = 1.
fn j_cor(part: &Part, p: V, f: V, q: (f64, f64)) -> f64 {
    // COR between 3e-4·a and 1e6·a; beyond that the point at infinity stands for it.
    if !(-8.0..=T_MAX).contains(&q.0) {
        return f64::INFINITY;
    }
    let r = cor_of(part, q);
    let g = (p - r).cross(f);
    if g.abs() < 1e-300 {
        return f64::INFINITY;
    }
    part.i0(r) / (part.area * g.abs())
}

/// Derivative-free search from q0 with initial stencil step `step`: at each stencil (centre and
/// six neighbours) a quadratic model is fitted and its minimiser tried; the best point seen is kept
/// (monotone descent); the stencil moves to a better neighbour (growing) or shrinks.
fn refine(jf: &dyn Fn((f64, f64)) -> f64, q0: (f64, f64), step: f64) -> ((f64, f64), f64) {
    const FLOOR: f64 = 1e-6;
    let mut q = q0;
    let mut j0 = jf(q);
    let mut s = step;
    for _ in 0..200 {
        let at = |dt: f64, dp: f64| (q.0 + dt, q.1 + dp);
        let pts = [
            at(s, 0.0),
            at(-s, 0.0),
            at(0.0, s),
            at(0.0, -s),
            at(s, s),
            at(-s, -s),
        ];
        let vals: Vec<f64> = pts.iter().map(|&x| jf(x)).collect();
        let (ib, &jb) = vals
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .expect("six points");
        let (jpt, jmt, jpp, jmp, jpd, jmd) = (vals[0], vals[1], vals[2], vals[3], vals[4], vals[5]);
        let gt = (jpt - jmt) / (2.0 * s);
        let gp = (jpp - jmp) / (2.0 * s);
        let htt = (jpt - 2.0 * j0 + jmt) / (s * s);
        let hpp = (jpp - 2.0 * j0 + jmp) / (s * s);
        let htp = (jpd + jmd - jpt - jmt - jpp - jmp + 2.0 * j0) / (2.0 * s * s);
        let det = htt * hpp - htp * htp;
        let mut newton = None;
        if htt > 0.0 && det > 0.0 && det.is_finite() {
            let dt = -(hpp * gt - htp * gp) / det;
            let dp = -(htt * gp - htp * gt) / det;
            let dn = dt.abs().max(dp.abs());
            if dn <= 8.0 * s {
                let cand = (q.0 + dt, q.1 + dp);
                let jc = jf(cand);
                if jc <= j0 && jc <= jb {
                    newton = Some((cand, jc, dn));
                }
            }
        }
        let at_floor = s <= FLOOR;
        if let Some((cand, jc, dn)) = newton {
            q = cand;
            j0 = jc;
            // Quadratic convergence: the remaining error is about dn².
            s = (4.0 * dn * dn).clamp(FLOOR, (s / 2.0).max(FLOOR));
            if at_floor || dn <= FLOOR {
                break;
            }
        } else if jb < j0 {
            q = pts[ib];
            j0 = jb;
            s = (s * 2.0).min(1.0);
        } else {
            if at_floor {
                break;
            }
            s = (s / 4.0).max(FLOOR);
        }
    }
    (q, j0)
}

/// The twist normal to the limit surface at the wrench of force `f` applied at `p`, normalised so
/// that w(f)·ξ = 1: brute-force search over the COR plane (see the module doc).
pub fn edge_twist(part: &Part, p: V, f: V, warm: &mut Option<(f64, f64)>) -> Twist {
    let jf = |q: (f64, f64)| j_cor(part, p, f, q);
    let far = (30.0f64).ln();
    let from_far = |psi: f64| {
        let a = refine(&jf, (far, psi), 0.25);
        let b = refine(&jf, (far, psi + PI), 0.25);
        if a.1 <= b.1 {
            a
        } else {
            b
        }
    };
    let (q, jq) = match *warm {
        None => {
            let mut best = ((0.0, 0.0), f64::INFINITY);
            for it in 0..21 {
                let t = -3.0 + 0.5 * it as f64;
                for ip in 0..36 {
                    let q = (t, ip as f64 * PI / 18.0);
                    let j = jf(q);
                    if j < best.1 {
                        best = (q, j);
                    }
                }
            }
            refine(&jf, best.0, 0.25)
        }
        // A far COR: ω may be changing sign (the minimiser passes through infinity), so search
        // both sides afresh.
        Some(q0) if q0.0 > far => from_far(q0.1),
        Some(q0) => {
            let res = refine(&jf, q0, 0.02);
            if res.0 .0 > far {
                from_far(res.0 .1)
            } else {
                res
            }
        }
    };
    let j_inf = 1.0 / f.norm();
    if j_inf <= jq {
        // Pure translation along f: v = f/|f|², ω = 0 (the point at infinity). Warm-start the next
        // search far out, perpendicular to f, on either side (the antipode is also tried).
        *warm = Some(((1e4f64).ln(), f.perp().y.atan2(f.perp().x)));
        return Twist {
            v: f * (1.0 / (f.norm() * f.norm())),
            w: 0.0,
        };
    }
    *warm = Some((q.0, q.1.rem_euclid(2.0 * PI)));
    let r = cor_of(part, q);
    let w = 1.0 / (p - r).cross(f);
    Twist {
        v: r.perp() * (-w),
        w,
    }
}

/// The stick twist: v_c(ξ) = v_pin at p, ω by golden-section search on D.
pub fn stick_twist(part: &Part, p: V, v_pin: V, warm: &mut Option<f64>) -> Twist {
    let tw = |w: f64| Twist {
        v: v_pin - p.perp() * w,
        w,
    };
    let fd = |w: f64| part.dissipation(tw(w));
    let scale = 1.0 / part.a;
    let w0 = warm.unwrap_or(0.0);
    // Bracket: expand until both ends exceed the middle.
    let mut d = 0.05 * scale;
    let (mut lo, mut mid, mut hi) = (w0 - d, w0, w0 + d);
    let (mut flo, mut fmid, mut fhi) = (fd(lo), fd(mid), fd(hi));
    for _ in 0..80 {
        if fmid <= flo && fmid <= fhi {
            break;
        }
        d *= 2.0;
        if flo < fmid {
            hi = mid;
            fhi = fmid;
            mid = lo;
            fmid = flo;
            lo = mid - d;
            flo = fd(lo);
        } else {
            lo = mid;
            flo = fmid;
            mid = hi;
            fmid = fhi;
            hi = mid + d;
            fhi = fd(hi);
        }
    }
    let _ = (flo, fhi);
    // Golden section on [lo, hi].
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let (mut f1, mut f2) = (fd(x1), fd(x2));
    while b - a > 1e-9 * scale {
        if f1 <= f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = fd(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = fd(x2);
        }
    }
    let w = 0.5 * (a + b);
    *warm = Some(w);
    tw(w)
}

/// Contact mode found by the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefMode {
    Stick,
    SlideLeft,
    SlideRight,
    Slide,
}

/// One instant (part frame): contact point p, inward unit normal n, pin velocity v_pin. Returns the
/// twist scaled so that the contact's normal velocity equals the pin's, or None (separation).
pub fn instant(
    part: &Part,
    p: V,
    n: V,
    v_pin: V,
    mu: f64,
    warm: &mut Warm,
) -> Option<(Twist, RefMode)> {
    if n.dot(v_pin) <= 1e-12 * v_pin.norm() {
        return None;
    }
    let scale_to = |xi: Twist| {
        let vb = xi.at(p);
        xi.scaled(n.dot(v_pin) / n.dot(vb))
    };
    if mu == 0.0 {
        let xi = edge_twist(part, p, n, &mut warm.normal);
        return Some((scale_to(xi), RefMode::Slide));
    }
    let phi = mu.atan();
    let xl = edge_twist(part, p, n.rot(phi), &mut warm.left);
    let xr = edge_twist(part, p, n.rot(-phi), &mut warm.right);
    let (vl, vr) = (xl.at(p), xr.at(p));
    let vp = v_pin.unit();
    let eps = 1e-9;
    let sl = vl.cross(vp) / vl.norm();
    let sr = -vr.cross(vp) / vr.norm();
    let left = n.dot(vl) > eps * vl.norm() && sl > 0.0;
    let right = n.dot(vr) > eps * vr.norm() && sr > 0.0;
    if left && (!right || sl >= sr) {
        return Some((scale_to(xl), RefMode::SlideLeft));
    }
    if right {
        return Some((scale_to(xr), RefMode::SlideRight));
    }
    Some((stick_twist(part, p, v_pin, &mut warm.stick), RefMode::Stick))
}

/// Where a pin at height y moving along −x first meets the part at rest at orientation θ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// Edge index (part frame).
    pub edge: usize,
    /// Contact point (world).
    pub point: V,
    /// Distance along the edge from its start vertex, and the edge length.
    pub ell: f64,
    pub len: f64,
}

/// First touch of the pin line y = y_pin (pin coming from +x) with the part at (0, 0, θ).
pub fn first_touch(part: &Part, theta: f64, y_pin: f64) -> Option<Touch> {
    let mut best: Option<Touch> = None;
    for k in 0..part.n() {
        let (a, e, l) = part.edge(k);
        let (aw, ew) = (a.rot(theta), e.rot(theta));
        // Edge facing +x: inward normal with negative x.
        if ew.perp().x >= 0.0 || ew.y == 0.0 {
            continue;
        }
        let t = (y_pin - aw.y) / ew.y;
        if !(0.0..=l).contains(&t) {
            continue;
        }
        let pt = aw + ew * t;
        if best.is_none_or(|b| pt.x > b.point.x) {
            best = Some(Touch {
                edge: k,
                point: pt,
                ell: t,
                len: l,
            });
        }
    }
    best
}

/// How a reference push ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefStatus {
    /// The pin passed the part.
    Separated,
    /// The pin never touched the part.
    NoContact,
    /// Contact travel exceeded the limit (the part rides on the pin).
    TravelLimit,
    /// The pin went back and forth over one vertex without advancing (a case the reference does
    /// not model: a point pin hooked on a vertex).
    VertexCycle,
}

/// Result of one reference push (world frame, the caller's units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefOutcome {
    pub status: RefStatus,
    pub x: f64,
    pub y: f64,
    /// Final orientation, unwrapped (radians).
    pub theta: f64,
    /// Pin travel while in contact.
    pub contact_length: f64,
    /// Edge changes of the pin during the contact.
    pub edge_changes: u32,
    pub steps: u32,
    /// RK stages that were in stick mode / in total (a rough mode profile).
    pub stick_stages: u32,
    pub stages: u32,
}

#[derive(Debug, Clone, Copy)]
struct Pose {
    c: V,
    th: f64,
}

struct Run<'a> {
    part: &'a Part,
    mu: f64,
    /// Pin at travel 0 (world).
    start: V,
    warm: Warm,
    stick_stages: u32,
    stages: u32,
}

impl Run<'_> {
    fn pin(&self, s: f64) -> V {
        self.start + V::new(-s, 0.0)
    }
    /// Pin in the part frame, relative to edge k: (ℓ along the edge, depth δ along the inward
    /// normal, contact point on the edge line).
    fn on_edge(&self, pose: Pose, s: f64, k: usize) -> (f64, f64, V) {
        let praw = (self.pin(s) - pose.c).rot(-pose.th);
        let (a, e, _) = self.part.edge(k);
        let ell = (praw - a).dot(e);
        (ell, (praw - a).dot(e.perp()), a + e * ell)
    }
    fn v_pin(&self, pose: Pose) -> V {
        V::new(-1.0, 0.0).rot(-pose.th)
    }
    /// d(pose)/ds on edge k.
    fn rhs(&mut self, pose: Pose, s: f64, k: usize) -> (V, f64) {
        let (_, _, p) = self.on_edge(pose, s, k);
        let n = self.part.normal(k);
        let vp = self.v_pin(pose);
        self.stages += 1;
        match instant(self.part, p, n, vp, self.mu, &mut self.warm) {
            None => (V::new(0.0, 0.0), 0.0),
            Some((xi, mode)) => {
                if mode == RefMode::Stick {
                    self.stick_stages += 1;
                }
                (xi.v.rot(pose.th), xi.w)
            }
        }
    }
    fn rk4(&mut self, y: Pose, s: f64, h: f64, k: usize) -> Pose {
        let add = |y: Pose, d: (V, f64), t: f64| Pose {
            c: y.c + d.0 * t,
            th: y.th + d.1 * t,
        };
        let k1 = self.rhs(y, s, k);
        let k2 = self.rhs(add(y, k1, h / 2.0), s + h / 2.0, k);
        let k3 = self.rhs(add(y, k2, h / 2.0), s + h / 2.0, k);
        let k4 = self.rhs(add(y, k3, h), s + h, k);
        Pose {
            c: y.c + (k1.0 + k2.0 * 2.0 + k3.0 * 2.0 + k4.0) * (h / 6.0),
            th: y.th + (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1) * (h / 6.0),
        }
    }
    /// Translate the part along edge k's normal so that the pin lies on the edge's line.
    fn project(&self, pose: Pose, s: f64, k: usize) -> Pose {
        let (_, depth, _) = self.on_edge(pose, s, k);
        Pose {
            c: pose.c + self.part.normal(k).rot(pose.th) * depth,
            th: pose.th,
        }
    }
}

/// One reference push with fixed step `h` (pin travel, caller's units) and contact-travel limit
/// `max_travel` (units of a).
pub fn push(part: &Part, theta0: f64, d: f64, mu: f64, h: f64, max_travel: f64) -> RefOutcome {
    let a = part.a;
    let start = V::new(1.01 * a, d * a);
    let mut out = RefOutcome {
        status: RefStatus::NoContact,
        x: 0.0,
        y: 0.0,
        theta: theta0,
        contact_length: 0.0,
        edge_changes: 0,
        steps: 0,
        stick_stages: 0,
        stages: 0,
    };
    let Some(touch) = first_touch(part, theta0, d * a) else {
        return out;
    };
    let mut run = Run {
        part,
        mu,
        start,
        warm: Warm::default(),
        stick_stages: 0,
        stages: 0,
    };
    let s0 = start.x - touch.point.x;
    let mut s = s0;
    let mut k = touch.edge;
    let mut pose = Pose {
        c: V::new(0.0, 0.0),
        th: theta0,
    };
    let n_edges = part.n();
    let mut stalls = 0;
    out.status = loop {
        if s - s0 > max_travel * a {
            break RefStatus::TravelLimit;
        }
        if part.normal(k).dot(run.v_pin(pose)) <= 0.0 {
            break RefStatus::Separated;
        }
        let len = part.edge(k).2;
        // Event functions, positive while the contact goes on along edge k: the pin's distance
        // from the edge's two ends, and n·v_pin (the pin pushes).
        let events = |run: &Run, p: Pose, s: f64| -> [f64; 3] {
            let (ell, _, _) = run.on_edge(p, s, k);
            [ell, len - ell, part.normal(k).dot(run.v_pin(p)) * a]
        };
        let ev0 = events(&run, pose, s);
        let next = run.rk4(pose, s, h, k);
        let ev1 = events(&run, next, s + h);
        out.steps += 1;
        if ev1.iter().all(|&e| e >= 0.0) {
            pose = run.project(next, s + h, k);
            s += h;
            stalls = 0;
            continue;
        }
        // An event within this step: land on the earliest one by the Illinois method on the
        // fraction τ of a real step.
        let mut first: Option<(f64, Pose, usize)> = None;
        for i in (0..3).filter(|&i| ev1[i] < 0.0) {
            let (mut ta, mut fa) = (0.0, ev0[i]);
            let (mut tb, mut fb) = (1.0, ev1[i]);
            let mut land = (1.0, next);
            if fa <= 1e-13 * a {
                land = (0.0, pose);
            } else {
                let mut side = 0;
                for _ in 0..60 {
                    let mut t = (ta * fb - tb * fa) / (fb - fa);
                    if !t.is_finite() || t <= ta || t >= tb {
                        t = 0.5 * (ta + tb);
                    }
                    let pt = run.rk4(pose, s, t * h, k);
                    let ft = events(&run, pt, s + t * h)[i];
                    land = (t, pt);
                    if ft.abs() <= 1e-12 * a || (tb - ta) < 1e-14 {
                        break;
                    }
                    if ft < 0.0 {
                        tb = t;
                        fb = ft;
                        if side == -1 {
                            fa *= 0.5;
                        }
                        side = -1;
                    } else {
                        ta = t;
                        fa = ft;
                        if side == 1 {
                            fb *= 0.5;
                        }
                        side = 1;
                    }
                }
            }
            if first.is_none_or(|f| land.0 < f.0) {
                first = Some((land.0, land.1, i));
            }
        }
        let (tau, p_land, which) = first.expect("an event is negative");
        s += tau * h;
        if which == 2 {
            // The pin stops pushing: the contact separates here.
            pose = p_land;
            break RefStatus::Separated;
        }
        pose = run.project(p_land, s, k);
        if tau * h <= 1e-9 * a {
            stalls += 1;
            if stalls > 4 {
                break RefStatus::VertexCycle;
            }
        } else {
            stalls = 0;
        }
        // The pin reached a vertex: it passes onto the neighbouring edge if that edge faces the
        // pin's motion, else the contact separates.
        let nk = if which == 1 {
            (k + 1) % n_edges
        } else {
            (k + n_edges - 1) % n_edges
        };
        if part.normal(nk).dot(run.v_pin(pose)) <= 1e-12 {
            break RefStatus::Separated;
        }
        k = nk;
        out.edge_changes += 1;
        pose = run.project(pose, s, k);
    };
    if out.status == RefStatus::Separated || out.status == RefStatus::TravelLimit {
        out.x = pose.c.x;
        out.y = pose.c.y;
        out.theta = pose.th;
        out.contact_length = s - s0;
    }
    out.stick_stages = run.stick_stages;
    out.stages = run.stages;
    out
}

/// A push at step h and at h/2: the h/2 result and the differences (orientation in radians,
/// centroid distance) as the reference's own error estimate. `None` for the estimate when the two
/// runs end differently.
pub fn push_with_error(
    part: &Part,
    theta0: f64,
    d: f64,
    mu: f64,
    h: f64,
    max_travel: f64,
) -> (RefOutcome, Option<(f64, f64)>) {
    let coarse = push(part, theta0, d, mu, h, max_travel);
    let fine = push(part, theta0, d, mu, h / 2.0, max_travel);
    let err = if coarse.status == fine.status {
        Some((
            (coarse.theta - fine.theta).abs(),
            (coarse.x - fine.x).hypot(coarse.y - fine.y),
        ))
    } else {
        None
    };
    (fine, err)
}

/// Mason's vote computed from scratch: the sign of the median of the signed distances of the
/// centroid from the lines through p along v_pin, f_L and f_R (+1 CCW, −1 CW), with that median.
pub fn vote_median(p: V, n: V, v_pin: V, mu: f64) -> f64 {
    let phi = mu.atan();
    let c = -p;
    let mut m = [
        v_pin.unit().cross(c),
        n.rot(phi).cross(c),
        n.rot(-phi).cross(c),
    ];
    m.sort_by(|a, b| a.total_cmp(b));
    m[1]
}

/// A small deterministic generator (SplitMix64) for the tests' random cases.
#[derive(Debug, Clone)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }
}
