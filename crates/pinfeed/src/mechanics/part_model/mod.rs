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
//!
//! Files:
//! * `mod.rs` (here): [`PartModel`] — compiling a part, its tables, and the front API that
//!   dispatches each solve by fidelity; the twist and wrench conventions; the quadratic form of
//!   the Hessian the solves share.
//! * `fidelity.rs`: [`Fidelity`], the three tiers and their names.
//! * `support.rs`: [`Support`] (uniform pressure, weighted points, random tripods) and the compiled
//!   limit-surface data.
//! * `closed_form.rs`: the `tip` and `ellipsoid` normal maps.
//! * `solve.rs`: the exact slide solve (Newton on the plane w·ξ = 1), [`Solved`], [`SolveFailure`],
//!   [`final_gap`].
//! * `stick.rs`: the exact stick solve (safeguarded Newton in ω).
//! * `warm.rs`: the warm starts [`WarmTwist`], [`WarmStick`] and their first-order predictions.
//!
//! The solves' small vectors and matrices (twists, wrenches, directions, Hessians) are nalgebra's
//! [`Vector3`] and [`Matrix3`]; the public [`Twist`] and [`Wrench`] stay plain `[f64; 3]` arrays,
//! as the limit surfaces and the tables hold them.

mod closed_form;
mod fidelity;
mod solve;
mod stick;
mod support;
mod warm;

pub use fidelity::Fidelity;
pub use solve::{final_gap, SolveFailure, Solved};
pub use support::{Support, SupportSpecError, TripodError};
pub(crate) use warm::kkt_delta;
pub use warm::{WarmStick, WarmTwist};

use super::limit_surface::Dissipation;
use super::slide_table::{Place, Side, SlideTables, Table, TableStats};
use super::stick_table::{StickStats, StickTables};
use crate::geometry::{Polygon, Vec2};
use nalgebra::{Matrix3, Vector3};
use std::fmt;
use std::sync::Arc;
use support::SupportData;

/// A twist (vx, vy, ω) in the part frame: centroid velocity and angular rate.
pub type Twist = [f64; 3];
/// A wrench (fx, fy, m) in the part frame: force and moment about the centroid.
pub type Wrench = [f64; 3];

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

/// The Hessian `h` of D (row-major, as [`Dissipation::hess`] holds it) as a matrix.
fn hessian(h: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| h[i][j])
}

/// The quadratic form aᵀ H b, summed term by term in row order (nalgebra's `a.dot(&(h * b))`
/// would add in another order, and every solve's last bits depend on this one).
fn quad_form(h: &Matrix3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += a[i] * h[(i, j)] * b[j];
        }
    }
    s
}

/// The compiled part: normalised geometry and support data. Immutable; shared by all contacts.
#[derive(Clone)]
pub struct PartModel {
    poly: Polygon,
    /// The convex hull as a polygon (what a straight fence can touch), normalised units, in the
    /// part's frame (`Polygon::hull_polygon`).
    hull: Polygon,
    /// Per hull vertex, the polygon's vertex at the same point (a hull vertex is one of the
    /// polygon's convex vertices): a fence on hull vertex k slides on the same vertex tables as a
    /// pin on that polygon vertex.
    hull_in_poly: Vec<Option<usize>>,
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

/// Why a part's contact model cannot be built ([`PartModel::new`]), or a part with a random
/// tripod cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PartModelError {
    /// The support's points or weights are refused.
    #[error(transparent)]
    Support(#[from] super::limit_surface::points::PointSupportError),
    /// The part's convex hull is not a valid polygon.
    #[error(transparent)]
    Hull(#[from] crate::geometry::PolygonError),
    /// No random tripod could be drawn for the part.
    #[error(transparent)]
    Tripod(#[from] TripodError),
}

impl PartModel {
    /// Compile a part: normalise to a = 1 and precompute the support's limit-surface data.
    pub fn new(poly: &Polygon, support: &Support) -> Result<PartModel, PartModelError> {
        let scale = poly.radius();
        let unit = poly.scaled(1.0 / scale);
        let data = SupportData::new(&unit, scale, support)?;
        let c = data.ellipsoid_c();
        // In the part's frame: a fence's contact point is a point of the part, about its centroid.
        let hull = unit.hull_polygon()?;
        let hull_in_poly = (0..hull.len())
            .map(|k| {
                let v = hull.vertex(k);
                (0..unit.len()).find(|&i| unit.vertex(i) == v && unit.vertex_is_convex(i))
            })
            .collect();
        Ok(PartModel {
            hull,
            hull_in_poly,
            poly: unit,
            scale,
            support: data,
            c_ellipsoid: c,
            slide_tables: None,
            stick_tables: None,
        })
    }

    /// Serve the exact model's slides from tables (`mechanics::slide_table`) for contacts with
    /// these μc values: for a model that many contacts share (a scene's, a planner's or one of
    /// its physics samples', a map's, an ensemble member's). Every support is tabulated: uniform
    /// pressure and point supports alike (a tripod's limit surface is smooth, its patches
    /// rounding the pivots, and its tables are certified to the same tolerance). A table costs
    /// about 10⁴ limit-surface evaluations to build, so a model used for a few hundred contacts
    /// is better left without. Slides at another μc, and the tip and ellipsoid fidelities, solve
    /// as before.
    pub fn with_slide_tables(self, mu_values: &[f64]) -> PartModel {
        self.with_slide_tables_to(mu_values, super::slide_table::TABLE_TOL)
    }

    /// [`PartModel::with_slide_tables`] with tables certified to `tol` relative instead of
    /// `slide_table::TABLE_TOL`: for a model standing for one sample of uncertain physics, whose
    /// tables are built for it alone (`slide_table::sampled_table_tol`).
    pub fn with_slide_tables_to(mut self, mu_values: &[f64], tol: f64) -> PartModel {
        let tables = SlideTables::certified_to(self.poly.len(), mu_values, tol);
        self.slide_tables = (!tables.is_empty()).then(|| Arc::new(tables));
        self
    }

    /// Also serve the exact model's sticks on edges from tables at any μc
    /// (`mechanics::stick_table`): for a batch of contacts large enough to pay for the cells it
    /// visits (a map tier's build). A stick cell costs ~10³ evaluations to build and saves ~1.7 per
    /// stick it serves, so a line of a few thousand parts, or of a part with many edges, runs
    /// slower with them (`results/line-speed.md`, "Stick tables and where they pay"); scenes and the planner do not
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

    /// Thread time (seconds, summed over threads) spent building the model's slide and stick
    /// tables so far (both are built as pushes first ask for them; 0 without tables). A timing,
    /// for forecasts: the tables' content never depends on it.
    pub fn table_build_seconds(&self) -> f64 {
        let slides = self
            .slide_tables
            .as_ref()
            .map_or(0.0, |t| t.build_seconds());
        slides
            + self
                .stick_tables
                .as_ref()
                .map_or(0.0, |t| t.build_seconds())
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

    /// Does the model serve slides from tables at some μc ([`PartModel::with_slide_tables`])?
    pub fn has_slide_tables(&self) -> bool {
        self.slide_tables.is_some()
    }

    /// The polygon vertex at hull vertex `k`, if the hull's vertex is one of the polygon's convex
    /// vertices (always, unless rounding moved it): where a fence touching hull vertex k slides
    /// in the slide tables.
    pub fn hull_vertex_in_polygon(&self, k: usize) -> Option<usize> {
        self.hull_in_poly.get(k).copied().flatten()
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
    /// The convex hull in normalised units, in the part's frame (fence contacts index its vertices and edges).
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
            _ => self.closed_form_wrench(fid, xi),
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
            _ => self.closed_form_twist_for_wrench(fid, w, evals),
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
            _ => self.closed_form_stick(fid, p, v, evals),
        }
    }
}
