//! The part as the contact model sees it: geometry normalised to unit size plus its support
//! (friction) model, and the two convex sub-problems every instant reduces to (docs/physics.md#one-instant):
//!
//! * [`PartModel::twist_for_wrench`]: the twist ξ normal to the limit surface at a contact wrench w,
//!   ξ = argmin D(ξ) subject to w·ξ = 1;
//! * [`PartModel::stick_twist`]: the twist whose velocity at a contact point p equals a given v,
//!   ξ(ω) = (v − ω ẑ×p, ω) with ω minimising D (zero support moment about p).
//!
//! Units: the polygon is scaled so that `a` (largest centroid-to-vertex distance) is 1, the support
//! load is normalised to μs m g = 1, and twists are in the part frame (centroid origin, part axes).
//! Lengths are converted back by [`PartModel::scale`]. μs only scales forces and never enters a
//! motion, so μs invariance holds by construction (and is tested).
//!
//! Fidelity levels:
//! * `exact`: the dissipation D(ξ) = ∫ p|u| dA of the real pressure distribution (uniform: closed
//!   form per edge; points: exact sums), minimised by Newton's method with the analytic Hessian and
//!   a backtracking line search, warm-started from the previous instant.
//! * `ellipsoid`: H(w) = |f|²/f_max² + m²/m_max² (Lynch, Maekawa & Tanie 1992), normal map
//!   ξ ∝ (c² f, m) with c = m_max/f_max = (1/mg)∫p|x|dA: closed forms.
//! * `tip`: Peshkin & Sanderson's COR-locus tip. For a force line at distance q from the centroid the
//!   COR sits on the perpendicular through the centroid at a²/q on the far side; this is exactly the
//!   normal map ξ ∝ (a² f, m), i.e. the ellipsoid formulas with c = a. It is the slowest-rotating
//!   motion any pressure distribution allows, kept as the thesis's baseline.

use super::limit_surface::points::PointSupport;
use super::limit_surface::uniform::UniformSurface;
use super::limit_surface::Dissipation;
use super::slide_table::{Place, Side, SlideTables, Table, TableStats};
use super::stick_table::{StickStats, StickTables};
use crate::geometry::{Polygon, Vec2};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;

/// A twist (vx, vy, ω) in the part frame: centroid velocity and angular rate.
pub type Twist = [f64; 3];
/// A wrench (fx, fy, m) in the part frame: force and moment about the centroid.
pub type Wrench = [f64; 3];

#[inline]
pub(crate) fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
fn scale3(a: [f64; 3], k: f64) -> [f64; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}
#[inline]
fn axpy3(a: [f64; 3], k: f64, b: [f64; 3]) -> [f64; 3] {
    [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]]
}
#[inline]
fn norm3(a: [f64; 3]) -> f64 {
    dot3(a, a).sqrt()
}
#[inline]
fn quad3(h: &[[f64; 3]; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += a[i] * h[i][j] * b[j];
        }
    }
    s
}

/// Contact wrench of a force `f` applied at part-frame point `p`.
#[inline]
pub fn wrench_of(f: Vec2, p: Vec2) -> Wrench {
    [f.x, f.y, p.cross(f)]
}

/// Velocity of the material point `p` (part frame) under twist `xi`.
#[inline]
pub fn point_velocity(xi: Twist, p: Vec2) -> Vec2 {
    Vec2::new(xi[0], xi[1]) + p.perp() * xi[2]
}

/// Which model of the support friction to use (docs/physics.md#fidelity-tiers).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// The thesis's COR-locus tip (Peshkin & Sanderson): slowest possible rotation.
    Tip,
    /// Ellipsoidal limit surface (Lynch et al. 1992).
    Ellipsoid,
    /// The limit surface of the actual pressure distribution.
    #[default]
    Exact,
}

impl Fidelity {
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Tip => "tip",
            Fidelity::Ellipsoid => "ellipsoid",
            Fidelity::Exact => "exact",
        }
    }
    pub fn parse(s: &str) -> Option<Fidelity> {
        match s {
            "tip" => Some(Fidelity::Tip),
            "ellipsoid" => Some(Fidelity::Ellipsoid),
            "exact" => Some(Fidelity::Exact),
            _ => None,
        }
    }
}

impl fmt::Display for Fidelity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How the part's weight is carried by the belt.
#[derive(Debug, Clone, PartialEq)]
pub enum Support {
    /// Uniform pressure over the footprint (the thesis's assumption).
    Uniform,
    /// Weighted support points in the part frame of the *caller's* units (e.g. a tripod).
    Points {
        points: Vec<Vec2>,
        weights: Vec<f64>,
    },
}

impl Support {
    /// A random tripod (docs/physics.md#support): three points drawn uniformly inside the part whose triangle
    /// contains the centroid; each carries the centroid's barycentric weight (static equilibrium).
    /// Points are in the polygon's part frame (centroid origin). Each weight is at least 2%, so the
    /// tripod is never degenerate.
    pub fn random_tripod(poly: &Polygon, rng: &mut impl rand::Rng) -> Result<Support, String> {
        use rand::RngExt;
        let v = poly.vertices();
        let (mut lo, mut hi) = (v[0], v[0]);
        for p in v {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        let draw = |rng: &mut dyn FnMut() -> f64| -> Option<Vec2> {
            for _ in 0..10_000 {
                let p = Vec2::new(lo.x + (hi.x - lo.x) * rng(), lo.y + (hi.y - lo.y) * rng());
                if poly.contains(p) {
                    return Some(p);
                }
            }
            None
        };
        let mut uni = || rng.random::<f64>();
        for _ in 0..100_000 {
            let (Some(a), Some(b), Some(c)) = (draw(&mut uni), draw(&mut uni), draw(&mut uni))
            else {
                break;
            };
            let area = (b - a).cross(c - a);
            if area.abs() < 1e-12 {
                continue;
            }
            // Barycentric coordinates of the centroid (origin).
            let o = Vec2::ZERO;
            let wa = (b - o).cross(c - o) / area;
            let wb = (c - o).cross(a - o) / area;
            let wc = (a - o).cross(b - o) / area;
            if wa >= 0.02 && wb >= 0.02 && wc >= 0.02 {
                return Ok(Support::Points {
                    points: vec![a, b, c],
                    weights: vec![wa, wb, wc],
                });
            }
        }
        Err("could not draw a tripod inside the part that carries its centroid".into())
    }

    /// Parse a support specification: `uniform` or `tripod:SEED`.
    pub fn parse(spec: &str, poly: &Polygon) -> Result<Support, String> {
        let s = spec.trim();
        if s == "uniform" {
            return Ok(Support::Uniform);
        }
        if let Some(seed) = s.strip_prefix("tripod:") {
            let seed: u64 = seed
                .trim()
                .parse()
                .map_err(|_| format!("support '{s}': the tripod seed must be a whole number"))?;
            let mut rng = crate::random::stream(seed, 0);
            return Support::random_tripod(poly, &mut rng);
        }
        Err(format!(
            "unknown support '{s}'; expected 'uniform' or 'tripod:SEED'"
        ))
    }
}

#[derive(Clone)]
enum SupportData {
    Uniform(UniformSurface),
    Points(PointSupport),
}

/// Why a convex sub-problem could not be solved.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SolveFailure {
    /// Newton's method stopped before reaching the tolerance; `residual` is the relative optimality gap.
    NoConvergence { iterations: u32, residual: f64 },
    /// A non-finite number appeared.
    NonFinite,
}

impl fmt::Display for SolveFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveFailure::NoConvergence {
                iterations,
                residual,
            } => write!(
                f,
                "limit-surface solve did not converge ({iterations} iterations, residual {residual:.2e})"
            ),
            SolveFailure::NonFinite => write!(f, "limit-surface solve produced a non-finite number"),
        }
    }
}

/// A solved twist with the contact wrench on the limit surface it corresponds to
/// (in units of μs m g; the friction load on the part is its negative).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solved {
    pub twist: Twist,
    pub wrench: Wrench,
}

/// What a twist solve leaves behind for the next one: the solution, the wrench it answered, the
/// multiplier λ (∇D = λ w at the optimum) and the Hessian of D there. With these the next solve
/// starts from a first-order prediction (implicit function theorem on ∇D(ξ) = λ w, w·ξ = 1):
/// [H −w; wᵀ 0] [dξ; dλ] = [λ dw; −dw·ξ].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmTwist {
    pub twist: Twist,
    pub wrench: Wrench,
    pub lambda: f64,
    pub hess: Option<[[f64; 3]; 3]>,
}

/// What a stick solve leaves behind for the next one: the solution, its wrench and the Hessian of
/// D there (`None` for the closed forms).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmStick {
    pub twist: Twist,
    pub wrench: Wrench,
    pub hess: Option<[[f64; 3]; 3]>,
}

impl WarmStick {
    fn without_hessian(s: Solved) -> WarmStick {
        WarmStick {
            twist: s.twist,
            wrench: s.wrench,
            hess: None,
        }
    }

    /// The first-order prediction of the next stick solve's ω: the new problem's twist at the
    /// previous ω is `xi`, the new constraint direction `e`; one Newton step on D linearised about
    /// the previous solution (∇D(ξ) ≈ ∇D₀ + H₀ (ξ − ξ₀)). Without a Hessian, or when the step
    /// is not defined, the previous ω; likewise when the previous ω already meets the solve's
    /// tolerance to first order (so that a state the solve holds exactly, e.g. the pure
    /// translation of a push through the centroid, is not moved by rounding).
    fn predict(&self, e: [f64; 3], xi: Twist) -> f64 {
        let om = self.twist[2];
        let Some(h) = self.hess else {
            return om;
        };
        let grad = linear_grad(self.wrench, &h, self.twist, xi);
        let g = dot3(e, grad);
        if g.abs() <= NEWTON_TOL * norm3(grad) * norm3(e) {
            return om;
        }
        let hss = quad3(&h, e, e);
        let next = om - g / hss;
        if hss > 0.0 && next.is_finite() {
            next
        } else {
            om
        }
    }
}

/// The compiled part: normalised geometry and support data. Immutable; shared by all contacts.
#[derive(Clone)]
pub struct PartModel {
    poly: Polygon,
    /// The convex hull as a polygon (what a straight fence can touch), normalised units.
    hull: Polygon,
    scale: f64,
    support: SupportData,
    /// m_max / f_max of the ellipsoid approximation (normalised units).
    c_ellipsoid: f64,
    /// The exact model's slide tables, for the μc values given to
    /// [`PartModel::with_slide_tables`] (shared by clones: their content depends only on the part).
    slide_tables: Option<Arc<SlideTables>>,
    /// The exact model's stick tables (any μc), when asked for ([`PartModel::with_stick_tables`]).
    stick_tables: Option<Arc<StickTables>>,
}

impl fmt::Debug for PartModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PartModel")
            .field("vertices", &self.poly.len())
            .field("scale", &self.scale)
            .field("c_ellipsoid", &self.c_ellipsoid)
            .finish()
    }
}

/// Relative optimality gap at which a Newton solve stops (see also the rounding-floor test).
const NEWTON_TOL: f64 = 1e-12;
const NEWTON_MAX: u32 = 60;

/// The `final_gap` of the exact solves for integration tolerance `tol`: below this relative
/// optimality gap a solve takes its last Newton step without evaluating D at its end (see
/// `linearised`), since the gap after that step is O(gap²). Measured over 10⁶ solves on the
/// reference parts, a step from a gap g left at most ≈ 100 g², so √(1e-6 tol) leaves a gap below
/// 1e-4 tol: far below what the integration needs (`pinfeed bench contact`: the self-error at
/// tol 1e-6 is the same to three digits as with every step evaluated). A larger gap would save a
/// few more evaluations (8% at √(1e-4 tol)) but makes the answer jump by up to 100 g² where a
/// solve's last evaluation decides between one step and two: rounding-level changes of the input
/// (a part scaled by 10⁻⁶) would then move a grazing separation by more than 1e-6 a.
pub fn final_gap(tol: f64) -> f64 {
    (1e-6 * tol).sqrt().clamp(1e-9, 1e-4)
}

impl PartModel {
    /// Compile a part: normalise to a = 1 and precompute the support's limit-surface data.
    pub fn new(poly: &Polygon, support: &Support) -> Result<PartModel, String> {
        let scale = poly.radius();
        let unit = poly.scaled(1.0 / scale);
        let data = match support {
            Support::Uniform => SupportData::Uniform(UniformSurface::new(&unit)),
            Support::Points { points, weights } => {
                let pts: Vec<Vec2> = points.iter().map(|&p| p / scale).collect();
                SupportData::Points(PointSupport::new(pts, weights.clone())?)
            }
        };
        let c = match &data {
            SupportData::Uniform(u) => u.ellipsoid_c(),
            SupportData::Points(p) => p.ellipsoid_c(),
        };
        let hull = Polygon::new(unit.hull()).map_err(|e| e.to_string())?;
        Ok(PartModel {
            hull,
            poly: unit,
            scale,
            support: data,
            c_ellipsoid: c,
            slide_tables: None,
            stick_tables: None,
        })
    }

    /// Serve the exact model's slides from tables (`mechanics::slide_table`) for contacts with
    /// these μc values: for a model that many contacts share (a scene's, a planner's, a map's). Only uniform
    /// pressure is tabulated; a model with point supports (a part's own tripod, used for a few
    /// contacts) is returned unchanged. Slides at another μc, and the tip and ellipsoid
    /// fidelities, solve as before.
    pub fn with_slide_tables(mut self, mu_values: &[f64]) -> PartModel {
        if matches!(self.support, SupportData::Uniform(_)) {
            let tables = SlideTables::new(self.poly.len(), mu_values);
            self.slide_tables = (!tables.is_empty()).then(|| Arc::new(tables));
        }
        self
    }

    /// Also serve the exact model's sticks on edges from tables at any μc
    /// (`mechanics::stick_table`): for a batch of contacts large enough to pay for the cells it
    /// visits (a map tier's build). A stick cell costs ~10³ evaluations to build and saves ~1.7 per
    /// stick it serves, so a line of a few thousand parts, or of a part with many edges, runs
    /// slower with them (`results/line-speed.md`, "Stick tables"); scenes and the planner do not
    /// use them. Only uniform pressure is tabulated, as for [`PartModel::with_slide_tables`].
    pub fn with_stick_tables(mut self) -> PartModel {
        if matches!(self.support, SupportData::Uniform(_)) {
            self.stick_tables = Some(Arc::new(StickTables::new(self.poly.len())));
        }
        self
    }

    /// The exact stick solve on edge `k` at ℓ for pin velocity `v` (part frame) from the model's
    /// stick tables (`mechanics::stick_table`), where they serve it.
    #[inline]
    pub fn tabled_stick(&self, k: usize, ell: f64, v: Vec2) -> Option<(Solved, WarmStick)> {
        self.stick_tables.as_ref()?.at(self, k, ell, v)
    }

    /// What the stick tables hold so far (`None`: the model has none).
    pub fn stick_table_stats(&self) -> Option<StickStats> {
        self.stick_tables.as_ref().map(|t| t.stats())
    }

    /// A stick solve converged as far as the solver goes, for the stick tables' nodes.
    pub(crate) fn converged_stick(
        &self,
        p: Vec2,
        v: Vec2,
        warm: Option<&WarmStick>,
        evals: &mut u64,
    ) -> Result<(Solved, WarmStick), SolveFailure> {
        self.exact_stick(p, v, warm, 0.0, evals)
    }

    /// The slide table of (μc, edge or vertex, side), built on first use; `None` when the model
    /// has none for that μc.
    #[inline]
    pub fn slide_table(&self, mu_c: f64, place: Place, side: Side) -> Option<&Table> {
        self.slide_tables.as_ref()?.table(self, mu_c, place, side)
    }

    /// Build every slide table (all μc values, edges and sides) and every stick table's cells now
    /// rather than on first use: for timing contacts without their tables' build.
    pub fn build_all_tables(&self) {
        if let Some(t) = &self.slide_tables {
            t.build_all(self);
        }
        if let Some(t) = &self.stick_tables {
            t.build_all(self);
        }
    }

    /// What the slide tables hold so far (`None`: the model has none).
    pub fn slide_table_stats(&self) -> Option<TableStats> {
        self.slide_tables.as_ref().map(|t| t.stats())
    }

    /// A slide solve converged as far as the solver goes (no unevaluated last step), for the slide
    /// tables' nodes: the normalised twist and what a warm start needs (λ, Hessian).
    pub(crate) fn converged_slide(
        &self,
        w: Wrench,
        warm: Option<&WarmTwist>,
        evals: &mut u64,
    ) -> Result<(Twist, WarmTwist), SolveFailure> {
        self.exact_twist_for_wrench(w, warm, 0.0, evals)
            .map(|(solved, next)| (solved.twist, next))
    }

    /// The polygon in normalised units (a = 1).
    pub fn polygon(&self) -> &Polygon {
        &self.poly
    }
    /// The convex hull in normalised units (fence contacts index its vertices and edges).
    pub fn hull(&self) -> &Polygon {
        &self.hull
    }
    /// Length of one normalised unit in the caller's units (the part's `a`).
    pub fn scale(&self) -> f64 {
        self.scale
    }
    /// m_max/f_max of the ellipsoidal approximation (normalised units).
    pub fn ellipsoid_c(&self) -> f64 {
        self.c_ellipsoid
    }

    /// The c of the closed-form normal map for a non-exact fidelity.
    fn closed_form_c(&self, fid: Fidelity) -> f64 {
        match fid {
            Fidelity::Tip => 1.0,
            _ => self.c_ellipsoid,
        }
    }

    /// Exact dissipation, gradient and optionally Hessian at twist `xi`.
    #[inline]
    pub fn dissipation(&self, xi: Twist, hessian: bool) -> Dissipation {
        match &self.support {
            SupportData::Uniform(u) => u.eval(xi, hessian),
            SupportData::Points(p) => p.eval(xi, hessian),
        }
    }

    /// Contact wrench on the limit surface whose normal is `xi` (units of μs m g).
    pub fn wrench_for_twist(&self, fid: Fidelity, xi: Twist, evals: &mut u64) -> Wrench {
        match fid {
            Fidelity::Exact => {
                *evals += 1;
                self.dissipation(xi, false).grad
            }
            _ => {
                let c = self.closed_form_c(fid);
                // On H(w) = |f|² + m²/c² = 1 with normal ∝ (f, m/c²) ∝ ξ: f = kξv, m = k c² ξω.
                let k = 1.0 / (xi[0] * xi[0] + xi[1] * xi[1] + c * c * xi[2] * xi[2]).sqrt();
                [k * xi[0], k * xi[1], k * c * c * xi[2]]
            }
        }
    }

    /// ξ normal to the limit surface at wrench direction `w`, normalised so that w·ξ = 1.
    /// `warm` is what the previous solve of the same kind left (see [`WarmTwist`]); `gap` is the
    /// relative optimality gap below which the exact solve takes its last Newton step unevaluated
    /// ([`final_gap`]; 0 always evaluates).
    pub fn twist_for_wrench(
        &self,
        fid: Fidelity,
        w: Wrench,
        warm: Option<&WarmTwist>,
        gap: f64,
        evals: &mut u64,
    ) -> Result<(Solved, WarmTwist), SolveFailure> {
        match fid {
            Fidelity::Exact => self.exact_twist_for_wrench(w, warm, gap, evals),
            _ => {
                *evals += 1;
                let c2 = self.closed_form_c(fid).powi(2);
                let xi = [c2 * w[0], c2 * w[1], w[2]];
                let d = dot3(w, xi);
                if d.is_nan() || d <= 0.0 || !d.is_finite() {
                    return Err(SolveFailure::NonFinite);
                }
                let xi = scale3(xi, 1.0 / d);
                let solved = Solved {
                    twist: xi,
                    wrench: self.wrench_for_twist(fid, xi, evals),
                };
                let next = WarmTwist {
                    twist: xi,
                    wrench: w,
                    lambda: 0.0,
                    hess: None,
                };
                Ok((solved, next))
            }
        }
    }

    /// The twist whose velocity at part-frame point `p` equals `v`, minimising D (stick at p).
    /// `warm` and `gap` as for [`PartModel::twist_for_wrench`].
    pub fn stick_twist(
        &self,
        fid: Fidelity,
        p: Vec2,
        v: Vec2,
        warm: Option<&WarmStick>,
        gap: f64,
        evals: &mut u64,
    ) -> Result<(Solved, WarmStick), SolveFailure> {
        match fid {
            Fidelity::Exact => self.exact_stick(p, v, warm, gap, evals),
            _ => {
                // ξ = A w(f) with A = diag(c², c², 1); v_c = B f, B = c² I + q qᵀ, q = ẑ×p (Lynch 1992).
                *evals += 1;
                let c2 = self.closed_form_c(fid).powi(2);
                let q = p.perp();
                let denom = c2 + q.norm2();
                // B⁻¹ v = (v − q (q·v)/(c²+|q|²)) / c²
                let f = (v - q * (q.dot(v) / denom)) / c2;
                let w = wrench_of(f, p);
                let xi = [c2 * w[0], c2 * w[1], w[2]];
                if !norm3(xi).is_finite() {
                    return Err(SolveFailure::NonFinite);
                }
                let solved = Solved {
                    twist: xi,
                    wrench: self.wrench_for_twist(fid, xi, evals),
                };
                Ok((solved, WarmStick::without_hessian(solved)))
            }
        }
    }

    fn ellipsoid_guess(&self, w: Wrench) -> Twist {
        let c2 = self.c_ellipsoid * self.c_ellipsoid;
        [c2 * w[0], c2 * w[1], w[2]]
    }

    fn exact_twist_for_wrench(
        &self,
        w: Wrench,
        warm: Option<&WarmTwist>,
        gap: f64,
        evals: &mut u64,
    ) -> Result<(Solved, WarmTwist), SolveFailure> {
        let wn = norm3(w);
        if wn.is_nan() || wn <= 0.0 || !wn.is_finite() {
            return Err(SolveFailure::NonFinite);
        }
        let wh = scale3(w, 1.0 / wn);
        let (e1, e2) = orthonormal_complement(wh);
        let xi0 = scale3(wh, 1.0 / wn);
        let predicted = warm.and_then(|p| predict_twist(p, w));
        let start = match (predicted, warm) {
            (Some(x), _) => x,
            (None, Some(p)) if dot3(w, p.twist) > 0.0 => scale3(p.twist, 1.0 / dot3(w, p.twist)),
            _ => {
                let g = self.ellipsoid_guess(w);
                scale3(g, 1.0 / dot3(w, g))
            }
        };
        let done = |xi: Twist, d: &Dissipation| {
            let solved = Solved {
                twist: xi,
                wrench: d.grad,
            };
            let next = WarmTwist {
                twist: xi,
                wrench: w,
                lambda: dot3(d.grad, w) / dot3(w, w),
                hess: Some(d.hess),
            };
            (solved, next)
        };
        let mut z = [dot3(e1, start), dot3(e2, start)];
        let at = |z: [f64; 2]| axpy3(axpy3(xi0, z[0], e1), z[1], e2);
        let mut xi = at(z);
        *evals += 1;
        let mut d = self.dissipation(xi, true);
        let mut residual = f64::INFINITY;
        for it in 0..NEWTON_MAX {
            let prev_residual = residual;
            let gr = [dot3(e1, d.grad), dot3(e2, d.grad)];
            let gnorm = norm3(d.grad);
            residual = (gr[0] * gr[0] + gr[1] * gr[1]).sqrt() / gnorm.max(1e-300);
            if !residual.is_finite() {
                return Err(SolveFailure::NonFinite);
            }
            // Converged, or at the rounding floor of the gradient (small and no longer improving).
            if residual <= NEWTON_TOL || (residual <= 1e-9 && residual > 0.5 * prev_residual) {
                return Ok(done(xi, &d));
            }
            let h11 = quad3(&d.hess, e1, e1);
            let h12 = quad3(&d.hess, e1, e2);
            let h22 = quad3(&d.hess, e2, e2);
            let det = h11 * h22 - h12 * h12;
            let solvable = det > 0.0 && h11 > 0.0 && det.is_finite();
            let mut dz = if solvable {
                [
                    -(h22 * gr[0] - h12 * gr[1]) / det,
                    -(-h12 * gr[0] + h11 * gr[1]) / det,
                ]
            } else {
                [-gr[0], -gr[1]]
            };
            let slope = gr[0] * dz[0] + gr[1] * dz[1];
            if solvable && slope < 0.0 && residual <= gap {
                let xin = at([z[0] + dz[0], z[1] + dz[1]]);
                let dn = linearised(&d, xi, xin);
                return Ok(done(xin, &dn));
            }
            if slope >= 0.0 {
                dz = [-gr[0], -gr[1]];
            }
            let slope0 = gr[0] * dz[0] + gr[1] * dz[1];
            // Converged to rounding: the Newton step no longer moves the twist.
            let step_len = (dz[0] * dz[0] + dz[1] * dz[1]).sqrt();
            if step_len <= 1e-14 * norm3(xi) {
                return Ok(done(xi, &d));
            }
            // Line search on the directional derivative φ'(t) = ∇D(ξ(z + t dz))·dz, which is
            // monotone for convex D. Unlike the value of D it stays informative near the optimum,
            // where decreases fall below the rounding of D on ill-conditioned (needle-like) parts.
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..40 {
                let zn = [z[0] + t * dz[0], z[1] + t * dz[1]];
                let xin = at(zn);
                *evals += 1;
                let dn = self.dissipation(xin, true);
                let slope_t = dot3(e1, dn.grad) * dz[0] + dot3(e2, dn.grad) * dz[1];
                if !slope_t.is_finite() {
                    return Err(SolveFailure::NonFinite);
                }
                if slope_t <= 0.9 * slope0.abs() {
                    z = zn;
                    xi = xin;
                    d = dn;
                    accepted = true;
                    break;
                }
                // Overshot: secant on φ' between 0 (slope0 < 0) and t (slope_t > 0), safeguarded.
                let tn = t * (-slope0) / (slope_t - slope0);
                t = tn.clamp(0.1 * t, 0.7 * t);
            }
            if !accepted {
                if residual <= 1e-9 {
                    return Ok(done(xi, &d));
                }
                return Err(SolveFailure::NoConvergence {
                    iterations: it + 1,
                    residual,
                });
            }
        }
        if residual <= 1e-9 {
            return Ok(done(xi, &d));
        }
        Err(SolveFailure::NoConvergence {
            iterations: NEWTON_MAX,
            residual,
        })
    }

    fn exact_stick(
        &self,
        p: Vec2,
        v: Vec2,
        warm: Option<&WarmStick>,
        gap: f64,
        evals: &mut u64,
    ) -> Result<(Solved, WarmStick), SolveFailure> {
        // ξ(ω) = (v + ω q, ω), q = −ẑ×p, so that the velocity at p is v for every ω.
        let q = -p.perp();
        let e = [q.x, q.y, 1.0];
        let xi_of = |om: f64| [v.x + om * q.x, v.y + om * q.y, om];
        let mut om = match warm {
            Some(w) if w.twist[2].is_finite() => w.predict(e, xi_of(w.twist[2])),
            _ => {
                let mut dummy = 0;
                self.stick_twist(Fidelity::Ellipsoid, p, v, None, 0.0, &mut dummy)
                    .map(|(s, _)| {
                        s.twist[2] / point_velocity(s.twist, p).norm().max(1e-300) * v.norm()
                    })
                    .unwrap_or(0.0)
            }
        };
        let done = |xi: Twist, d: &Dissipation| {
            let solved = Solved {
                twist: xi,
                wrench: d.grad,
            };
            (
                solved,
                WarmStick {
                    twist: xi,
                    wrench: d.grad,
                    hess: Some(d.hess),
                },
            )
        };
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let vscale = v.norm() / (1.0 + q.norm());
        let mut residual = f64::INFINITY;
        let mut last_step = f64::INFINITY;
        for it in 0..200u32 {
            let xi = xi_of(om);
            *evals += 1;
            let d = self.dissipation(xi, true);
            let g = dot3(e, d.grad);
            let hss = quad3(&d.hess, e, e);
            if !g.is_finite() {
                return Err(SolveFailure::NonFinite);
            }
            residual = g.abs() / (norm3(d.grad) * norm3(e)).max(1e-300);
            if residual <= NEWTON_TOL {
                return Ok(done(xi, &d));
            }
            if residual <= gap && hss > 0.0 && hss.is_finite() {
                let xin = xi_of(om - g / hss);
                return Ok(done(xin, &linearised(&d, xi, xin)));
            }
            if g > 0.0 {
                hi = hi.min(om);
            } else {
                lo = lo.max(om);
            }
            // A bracket closed to rounding: the minimum sits on a kink (a point support) or is found.
            if hi - lo <= 1e-15 * (1.0 + om.abs()) {
                return Ok(done(xi, &d));
            }
            let mut next = if hss > 0.0 && hss.is_finite() {
                om - g / hss
            } else {
                f64::NAN
            };
            // Safeguard (as in Numerical Recipes' rtsafe): bisect when the Newton step leaves the
            // bracket or fails to halve the step before it (a stiff, kink-like minimum, e.g. a
            // support patch, makes Newton bounce between the bracket's ends).
            let newton_step = (next - om).abs();
            let slow = newton_step > 0.5 * last_step && lo.is_finite() && hi.is_finite();
            last_step = if newton_step.is_finite() {
                newton_step
            } else {
                f64::INFINITY
            };
            if slow {
                next = f64::NAN;
            }
            if !(next > lo && next < hi && next.is_finite()) {
                next = if lo.is_finite() && hi.is_finite() {
                    0.5 * (lo + hi)
                } else if lo.is_finite() {
                    lo + vscale.max(1.0) * 2f64.powi(it as i32)
                } else {
                    hi - vscale.max(1.0) * 2f64.powi(it as i32)
                };
            }
            om = next;
        }
        Err(SolveFailure::NoConvergence {
            iterations: 200,
            residual,
        })
    }
}

/// First-order prediction of the twist for wrench `w` from the previous solution (see
/// [`WarmTwist`]), normalised to w·ξ = 1; `None` without a Hessian or if the system is singular.
fn predict_twist(p: &WarmTwist, w: Wrench) -> Option<Twist> {
    let dw = [w[0] - p.wrench[0], w[1] - p.wrench[1], w[2] - p.wrench[2]];
    let (dxi, _) = kkt_delta(p, dw)?;
    let xi = [
        p.twist[0] + dxi[0],
        p.twist[1] + dxi[1],
        p.twist[2] + dxi[2],
    ];
    let c = dot3(w, xi);
    (c > 0.0 && c.is_finite()).then(|| scale3(xi, 1.0 / c))
}

/// The first-order change (dξ, dλ) of a solution `p` of ∇D(ξ) = λ w, w·ξ = 1 when its wrench
/// changes by `dw`: [H −w; wᵀ 0] [dξ; dλ] = [λ dw; −dw·ξ] (Gaussian elimination with pivoting);
/// `None` without a Hessian or if the system is singular. The predictor of the warm starts and the
/// derivatives of the slide tables (`mechanics::slide_table`).
pub(crate) fn kkt_delta(p: &WarmTwist, dw: [f64; 3]) -> Option<(Twist, f64)> {
    let h = p.hess?;
    let w0 = p.wrench;
    let mut a = [
        [h[0][0], h[0][1], h[0][2], -w0[0], p.lambda * dw[0]],
        [h[1][0], h[1][1], h[1][2], -w0[1], p.lambda * dw[1]],
        [h[2][0], h[2][1], h[2][2], -w0[2], p.lambda * dw[2]],
        [w0[0], w0[1], w0[2], 0.0, -dot3(dw, p.twist)],
    ];
    for col in 0..4 {
        let piv = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        let pivot_row = a[col];
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / pivot_row[col];
                for (x, p) in row.iter_mut().zip(pivot_row).skip(col) {
                    *x -= f * p;
                }
            }
        }
    }
    let dxi = [a[0][4] / a[0][0], a[1][4] / a[1][1], a[2][4] / a[2][2]];
    Some((dxi, a[3][4] / a[3][3]))
}

/// D, ∇D and H at `to`, to first order from their values `d` at `from`: ∇D(to) ≈ ∇D(from) +
/// H (to − from); H is kept.
fn linearised(d: &Dissipation, from: Twist, to: Twist) -> Dissipation {
    let dx = [to[0] - from[0], to[1] - from[1], to[2] - from[2]];
    Dissipation {
        value: d.value + dot3(d.grad, dx),
        grad: linear_grad(d.grad, &d.hess, from, to),
        hess: d.hess,
    }
}

/// ∇D at `to` to first order from ∇D = `grad` and H = `hess` at `from`.
fn linear_grad(grad: Wrench, hess: &[[f64; 3]; 3], from: Twist, to: Twist) -> Wrench {
    let dx = [to[0] - from[0], to[1] - from[1], to[2] - from[2]];
    [
        grad[0] + dot3(hess[0], dx),
        grad[1] + dot3(hess[1], dx),
        grad[2] + dot3(hess[2], dx),
    ]
}

/// Two unit vectors orthogonal to the unit vector `w` and to each other.
fn orthonormal_complement(w: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    // Pick the coordinate axis least aligned with w.
    let a = if w[0].abs() <= w[1].abs() && w[0].abs() <= w[2].abs() {
        [1.0, 0.0, 0.0]
    } else if w[1].abs() <= w[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let e1 = axpy3(a, -dot3(a, w), w);
    let e1 = scale3(e1, 1.0 / norm3(e1));
    let e2 = [
        w[1] * e1[2] - w[2] * e1[1],
        w[2] * e1[0] - w[0] * e1[2],
        w[0] * e1[1] - w[1] * e1[0],
    ];
    (e1, e2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;

    #[test]
    fn ellipsoid_normal_map_is_linear() {
        let poly = part_from_spec("tripoly2").unwrap();
        let m = PartModel::new(&poly, &Support::Uniform).unwrap();
        let mut ev = 0;
        let w = [0.3, -1.0, 0.2];
        let (s, _) = m
            .twist_for_wrench(Fidelity::Ellipsoid, w, None, 0.0, &mut ev)
            .unwrap();
        assert!((dot3(w, s.twist) - 1.0).abs() < 1e-14);
        let c2 = m.ellipsoid_c().powi(2);
        assert!((s.twist[0] / s.twist[2] - c2 * w[0] / w[2]).abs() < 1e-12);
        // The wrench returned lies on the ellipsoid.
        let wr = s.wrench;
        let h = wr[0] * wr[0] + wr[1] * wr[1] + wr[2] * wr[2] / c2;
        assert!((h - 1.0).abs() < 1e-12);
    }

    #[test]
    fn closed_form_stick_matches_target_velocity() {
        let poly = part_from_spec("square").unwrap();
        let m = PartModel::new(&poly, &Support::Uniform).unwrap();
        let mut ev = 0;
        let p = Vec2::new(0.7, 0.2);
        let v = Vec2::new(-1.0, 0.3);
        for fid in [Fidelity::Tip, Fidelity::Ellipsoid] {
            let (s, _) = m.stick_twist(fid, p, v, None, 0.0, &mut ev).unwrap();
            assert!((point_velocity(s.twist, p) - v).norm() < 1e-13);
        }
    }

    fn rel_diff(a: Twist, b: Twist) -> f64 {
        let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        norm3(d) / norm3(b)
    }

    /// A path of solves as an integration makes them: a wrench (or a stick velocity) turning in
    /// small steps, each solve warm-started by the one before. With the final Newton step taken
    /// unevaluated (`final_gap` of tol 1e-6) every twist and wrench agrees with the fully
    /// converged solve (gap 0) to 1e-8 relative, and the path costs fewer evaluations.
    #[test]
    fn an_unevaluated_final_step_keeps_the_solves_within_a_hundredth_of_the_tolerance() {
        for name in ["tripoly1", "square", "lshape"] {
            let m = PartModel::new(&part_from_spec(name).unwrap(), &Support::Uniform).unwrap();
            let p = Vec2::new(0.45, -0.2);
            let (mut ev_fast, mut ev_full) = (0u64, 0u64);
            let (mut wf, mut wc): (Option<WarmTwist>, Option<WarmTwist>) = (None, None);
            let (mut sf, mut sc): (Option<WarmStick>, Option<WarmStick>) = (None, None);
            for k in 0..200 {
                let a = 0.01 * k as f64;
                let f = Vec2::new(-a.cos(), 0.3 * a.sin() - 0.4);
                let w = wrench_of(f, p);
                let gap = final_gap(1e-6);
                let (fast, nf) = m
                    .twist_for_wrench(Fidelity::Exact, w, wf.as_ref(), gap, &mut ev_fast)
                    .unwrap();
                let (full, nc) = m
                    .twist_for_wrench(Fidelity::Exact, w, wc.as_ref(), 0.0, &mut ev_full)
                    .unwrap();
                (wf, wc) = (Some(nf), Some(nc));
                assert!(rel_diff(fast.twist, full.twist) < 1e-8, "{name} {k}");
                assert!(rel_diff(fast.wrench, full.wrench) < 1e-8, "{name} {k}");
                let v = Vec2::new(-1.0, 0.0).rotate(-a);
                let (fast, nf) = m
                    .stick_twist(Fidelity::Exact, p, v, sf.as_ref(), gap, &mut ev_fast)
                    .unwrap();
                let (full, nc) = m
                    .stick_twist(Fidelity::Exact, p, v, sc.as_ref(), 0.0, &mut ev_full)
                    .unwrap();
                (sf, sc) = (Some(nf), Some(nc));
                assert!(rel_diff(fast.twist, full.twist) < 1e-8, "{name} stick {k}");
                assert!((point_velocity(fast.twist, p) - v).norm() < 1e-12);
            }
            assert!(ev_fast < ev_full, "{name}: {ev_fast} vs {ev_full}");
        }
    }

    /// A stick solve warm-started from the solve before it is predicted to first order: along
    /// a slowly turning velocity it needs fewer evaluations than one started from the previous ω
    /// alone, and the same answer.
    #[test]
    fn the_stick_prediction_saves_evaluations() {
        let m = PartModel::new(&part_from_spec("tripoly2").unwrap(), &Support::Uniform).unwrap();
        let p = Vec2::new(0.3, 0.35);
        let (mut ev_pred, mut ev_plain) = (0u64, 0u64);
        let mut warm: Option<WarmStick> = None;
        let mut plain: Option<WarmStick> = None;
        for k in 0..100 {
            let v = Vec2::new(-1.0, 0.2).rotate(-0.02 * k as f64);
            let (a, next) = m
                .stick_twist(Fidelity::Exact, p, v, warm.as_ref(), 0.0, &mut ev_pred)
                .unwrap();
            warm = Some(next);
            // The previous ω alone: a warm start without its Hessian.
            let (b, next) = m
                .stick_twist(Fidelity::Exact, p, v, plain.as_ref(), 0.0, &mut ev_plain)
                .unwrap();
            plain = Some(WarmStick { hess: None, ..next });
            assert!(rel_diff(a.twist, b.twist) < 1e-10, "{k}");
        }
        assert!(ev_pred < ev_plain, "{ev_pred} vs {ev_plain}");
    }

    #[test]
    fn orthonormal_basis() {
        let w = [0.2, -0.5, 0.84];
        let n = norm3(w);
        let w = scale3(w, 1.0 / n);
        let (a, b) = orthonormal_complement(w);
        assert!(dot3(a, w).abs() < 1e-15 && dot3(b, w).abs() < 1e-15 && dot3(a, b).abs() < 1e-15);
        assert!((norm3(a) - 1.0).abs() < 1e-15 && (norm3(b) - 1.0).abs() < 1e-15);
    }
}
