//! Tabulated sliding twists: the exact model's slide solves without solving ("per-part
//! precomputed" data for the exact contact).
//!
//! While a pin slides on a part, the contact force lies on one edge of the friction cone,
//! f = R(±atan μc) n (the normal n itself when μc = 0), at the contact point p, and the wrench is
//! w = (f, p × f). Two kinds of slide leave a single free coordinate t:
//!
//! * **on edge k** (point pin or disc): n is the edge's inward normal, p = a_k + ℓ e_k, so
//!   w(ℓ) = (f, a_k × f + ℓ e_k × f) is a straight line in wrench space (t = ℓ, on the edge for
//!   ℓ ∈ [0, |edge|]);
//! * **on vertex k**: p is the vertex and n = (cos φ, sin φ) turns through the vertex's normal cone
//!   (a disc riding round the vertex; for a point pin φ stays where it arrived; a fence on this
//!   vertex of the part's hull, φ its normal in the part's frame), so w(φ) is an arc
//!   (t = φ − φ_a, inside the cone for t ∈ [0, cone angle], φ_a the inward normal of the edge
//!   before the vertex).
//!
//! The tables reach beyond where the pin can physically be: an edge's by [`EDGE_REACH`] of its
//! length past each end, a convex vertex's round the whole turn of normals. The integrator's
//! stages go there within a step that ends on the edge's end or the cone's side (an event); the
//! live solve at such a stage is the same function continued, and serving it from the table
//! saves about a quarter of a line's evaluations.
//!
//! The sliding twist — the limit surface's normal at w, normalised so that w·ξ = 1, with its
//! multiplier λ (∇D(ξ) = λ w, the force being λ f) — is then a function of t alone: it does not
//! depend on the part's orientation, the pin's velocity or the belt, and one table per
//! (μc, edge or vertex, side) serves every such slide. The table stores ξ, λ and their derivatives
//! in t at nodes and interpolates with cubic Hermite polynomials. The derivatives come from the
//! optimality conditions ∇D(ξ) = λ w, w·ξ = 1 differentiated along the path:
//!
//!   [H −w; wᵀ 0] [dξ; dλ] = [λ dw; −dw·ξ]    (the system [`super::part_model`] warm-starts with),
//!
//! with dw/dℓ = (0, 0, e_k × f) on an edge and dw/dφ = (ẑ×f, p × (ẑ×f)) on a vertex.
//!
//! **Certified refinement.** A table starts with [`START_INTERVALS`] equal intervals; each interval
//! is checked at its midpoint against a full solve (converged to the solver's own limit) and
//! accepted when the interpolated ξ and λ agree with it to [`TABLE_TOL`] relative; otherwise it is
//! split there (the midpoint becomes a node). For a smooth ξ(t) the cubic Hermite error on an
//! interval of length h is u²(1 − u)² h⁴/24 times the fourth derivative, at fraction u: largest at
//! the midpoint, so the midpoint check bounds the interval. Where ξ(t) is less smooth (the centre
//! of rotation crossing the part's boundary makes the third derivative of D singular) the
//! refinement goes on down to [`MIN_INTERVAL`]; an interval not certified there is left to the
//! solver, and so is any t outside its range (a stage more than [`EDGE_REACH`] past an edge's
//! end), a reflex vertex (a pin cannot slide there) and any table whose nodes could not be
//! solved.
//!
//! The accuracy this gives is that of the live solve: a live slide solve stops at a relative
//! optimality gap g ≤ √(1e-6·tol) and takes an unevaluated last Newton step, which leaves a twist
//! error of about 100 g² ≈ 1e-10 at the default tolerance (see `part_model::final_gap`);
//! [`TABLE_TOL`] is 1e-10. A model that stands for one sample of uncertain physics (a robust
//! planner's physics sample, an ensemble member) has tables built for it alone, and certifies
//! them to a hundredth of the integration tolerance instead ([`sampled_table_tol`]: 1e-8 at the
//! default), with a third of the nodes.
//!
//! **Opt-in, deterministic.** Tables are built lazily, one (μc, place, side) at a time, on the
//! first slide that needs one, and only for models that ask for them with the μc values they will
//! see ([`super::PartModel::with_slide_tables`]: a scene's shared model, an online controller's
//! model at every μc its belief holds, a planner's and each of its robust physics samples' (its
//! own μc and tripod), an ensemble member's that passes three hundred times or more, a map's, the
//! contact benchmark's). Any support is tabulated: a point support's patches make its limit
//! surface smooth, with regions of high curvature where the centre of rotation nears a support
//! point, which the refinement resolves with more nodes (about 1.5–2× a uniform pressure's). A table's content is a fixed function of (part, μc, place, side), built
//! in a fixed order, so which thread builds it first changes nothing; and a served solve never
//! depends on what was solved before it. The evaluations a build spends are the table's, not the
//! contact's that happened to need it first ([`SlideTables::stats`]), so a contact's evaluation
//! count is the same on any number of threads.

use super::part_model::{kkt_delta, wrench_of, PartModel, Twist, WarmTwist};
use crate::geometry::Vec2;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// Vertices up to which the planner and the ensembles tabulate a part's slides: each
/// limit-surface evaluation is linear in the vertices, and past 64 the tables of a part with
/// hundreds of edges cost more than the passes they serve (ngon:500: seconds per edge).
pub const MAX_TABLED_VERTICES: usize = 64;

/// Relative agreement (twist and multiplier) an interval must show at its midpoint: the live
/// solve's own accuracy at the default integration tolerance (see the module docs), so that a
/// model's answers do not depend on whether it has tables beyond that.
pub const TABLE_TOL: f64 = 1e-10;

/// The certification tolerance of the tables of a model that stands for one *sample* of uncertain
/// physics (an ensemble member, a robust planner's physics sample), integrated at tolerance
/// `tol`: a hundredth of `tol`, never tighter than [`TABLE_TOL`] nor looser than 10⁻⁶ — 10⁻⁸ at
/// the default 10⁻⁶.
///
/// Why this is safe: a table's error is a smooth function of the coordinate (the cubic Hermite
/// interpolant is C¹), so unlike a solve's stopping rule it never jumps with rounding-level
/// changes of the input. A relative error ε of the rates moves a step's end by at most ε times
/// the step's change, which the acceptance guard bounds by 0.5 (θ in radians, ℓ in units of
/// a): at ε = tol/100 that is half a percent of the step's error allowance. What it buys: a
/// cubic Hermite table's nodes grow as ε^(−1/4), so a table at 10⁻⁸ has about a third of the
/// nodes of one at 10⁻¹⁰ and costs a third to build and to hold; a sample's tables are built for
/// it alone, and their build was the larger part of a sample's cost
/// (`results/line-speed.md`). Scenes, maps and contact batches keep [`TABLE_TOL`].
pub fn sampled_table_tol(tol: f64) -> f64 {
    (1e-2 * tol).clamp(TABLE_TOL, 1e-6)
}
/// Equal intervals a table starts with.
pub const START_INTERVALS: usize = 8;
/// The shortest interval (units of a) refinement makes; one not certified there is left to the
/// solver.
pub const MIN_INTERVAL: f64 = 1e-5;

/// How far beyond each end of an edge (as a fraction of its length) its tables reach. The
/// integrator's stages overshoot an edge's end within the step that lands on it; the sliding
/// twist there is the same function of ℓ continued (the live solve computes exactly that), and
/// 25% holds 99% of the overshoots on the bundled lines.
pub const EDGE_REACH: f64 = 0.25;

/// The slide sides a table exists for: the force on the counter-clockwise cone edge R(+atan μc) n
/// (also the frictionless normal force when μc = 0) and on the clockwise one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Force on the counter-clockwise cone edge (also the frictionless normal force).
    Left = 0,
    /// Force on the clockwise cone edge.
    Right = 1,
}

/// Where a slide's force acts, with the coordinate the tables are indexed by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SlideAt {
    /// On edge k at ℓ (units of a from its first vertex).
    Edge(usize, f64),
    /// On vertex k with the contact normal at part-frame angle φ (radians, any turn).
    Vertex(usize, f64),
}

/// A table's place on the part: an edge or a vertex (by index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// Edge k.
    Edge(usize),
    /// Vertex k.
    Vertex(usize),
}

impl SlideAt {
    /// The place and the coordinate along it.
    pub fn split(self) -> (Place, f64) {
        match self {
            SlideAt::Edge(k, ell) => (Place::Edge(k), ell),
            SlideAt::Vertex(k, phi) => (Place::Vertex(k), phi),
        }
    }
}

/// One node of a table.
#[derive(Debug, Clone, Copy)]
struct Node {
    /// The path coordinate from the table's origin (ℓ, or φ − φ_a).
    ell: f64,
    twist: Twist,
    dtwist: Twist,
    lambda: f64,
    dlambda: f64,
    /// The Hessian of D, which every support forms symmetric: its upper triangle, row by row.
    hess: [f64; 6],
}

impl Node {
    /// The Hessian of D at the node.
    fn hessian(&self) -> [[f64; 3]; 3] {
        let h = &self.hess;
        [[h[0], h[1], h[2]], [h[1], h[3], h[4]], [h[2], h[4], h[5]]]
    }
}

/// A served slide solve: the normalised twist (w·ξ = 1), the multiplier λ (the force is λ f) and
/// the Hessian of D at the nearer node (for warm-starting a later solve that is not served).
#[derive(Debug, Clone, Copy)]
pub struct TableTwist {
    /// The normalised twist (w·ξ = 1).
    pub twist: Twist,
    /// The multiplier λ: the force is λ f.
    pub lambda: f64,
    /// The Hessian of D at the nearer node.
    pub hess: [[f64; 3]; 3],
}

/// The table of one (μc, place, side): nodes in increasing path coordinate and, per interval,
/// whether it was certified; plus a uniform index (the first interval of each of `INDEX_BUCKETS`
/// equal pieces of the range) so that a lookup scans a few intervals instead of bisecting a
/// thousand.
#[derive(Debug)]
pub struct Table {
    /// Where the path coordinate starts (0 on an edge, φ_a on a vertex) and whether queries are
    /// angles, taken modulo a turn.
    origin: f64,
    periodic: bool,
    nodes: Vec<Node>,
    certified: Vec<bool>,
    bucket_first: Vec<u32>,
    /// Buckets per unit of ℓ.
    bucket_scale: f64,
}

/// Buckets of the uniform index over a table's range.
const INDEX_BUCKETS: usize = 512;

impl Table {
    /// The sliding twist at the place's coordinate `t` (ℓ on an edge, φ on a vertex), or `None`
    /// where the table does not serve (outside its range, or an interval not certified).
    #[inline]
    pub fn at(&self, t: f64) -> Option<TableTwist> {
        let ell = if self.periodic {
            (t - self.origin).rem_euclid(std::f64::consts::TAU)
        } else {
            t - self.origin
        };
        let n = &self.nodes;
        let (first, last) = (n.first()?, n.last()?);
        if !(ell >= first.ell && ell <= last.ell) || n.len() < 2 {
            return None;
        }
        let bucket = (((ell - first.ell) * self.bucket_scale) as usize).min(INDEX_BUCKETS - 1);
        let mut i = self.bucket_first[bucket] as usize;
        while i + 2 < n.len() && n[i + 1].ell <= ell {
            i += 1;
        }
        if !self.certified[i] {
            return None;
        }
        let (a, b) = (&n[i], &n[i + 1]);
        let h = b.ell - a.ell;
        let t = (ell - a.ell) / h;
        let (twist, lambda) = hermite(a, b, t);
        let hess = if t <= 0.5 { a.hessian() } else { b.hessian() };
        Some(TableTwist {
            twist,
            lambda,
            hess,
        })
    }

    /// The table over these nodes and intervals, with its uniform index.
    fn indexed(path: &WrenchPath, mut nodes: Vec<Node>, mut certified: Vec<bool>) -> Table {
        // Built by pushing: give back the growth's spare capacity (a planner holds thousands).
        nodes.shrink_to_fit();
        certified.shrink_to_fit();
        let (lo, hi) = match (nodes.first(), nodes.last()) {
            (Some(a), Some(b)) if b.ell > a.ell => (a.ell, b.ell),
            _ => (0.0, 1.0),
        };
        let bucket_scale = INDEX_BUCKETS as f64 / (hi - lo);
        // Bucket j starts at ℓ_j = lo + j / scale: its first interval is the last one starting at
        // or before ℓ_j (the lookup scans forward from there).
        let mut bucket_first = Vec::with_capacity(INDEX_BUCKETS);
        let mut i = 0usize;
        for j in 0..INDEX_BUCKETS {
            let start = lo + j as f64 / bucket_scale;
            while i + 2 < nodes.len() && nodes[i + 1].ell <= start {
                i += 1;
            }
            bucket_first.push(i as u32);
        }
        let (origin, periodic) = path.origin();
        Table {
            origin,
            periodic,
            nodes,
            certified,
            bucket_first,
            bucket_scale,
        }
    }

    /// The nodes' place coordinates (ℓ, or φ), in increasing order (for reports and tests).
    pub fn breakpoints(&self) -> Vec<f64> {
        self.nodes.iter().map(|n| self.origin + n.ell).collect()
    }

    /// The range of place coordinates the table covers (`None` when it serves nothing).
    pub fn range(&self) -> Option<(f64, f64)> {
        let (a, b) = (self.nodes.first()?, self.nodes.last()?);
        Some((self.origin + a.ell, self.origin + b.ell))
    }

    /// Nodes and certified intervals (for the build statistics and tests).
    pub fn size(&self) -> (usize, usize) {
        let ok = self.certified.iter().filter(|&&c| c).count();
        (self.nodes.len(), ok)
    }
}

/// Cubic Hermite interpolation of (ξ, λ) between nodes `a` and `b` at fraction `t`.
#[inline]
fn hermite(a: &Node, b: &Node, t: f64) -> (Twist, f64) {
    let h = b.ell - a.ell;
    let t2 = t * t;
    let t3 = t2 * t;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = (t3 - 2.0 * t2 + t) * h;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = (t3 - t2) * h;
    let mut xi = [0.0; 3];
    for (c, x) in xi.iter_mut().enumerate() {
        *x = h00 * a.twist[c] + h10 * a.dtwist[c] + h01 * b.twist[c] + h11 * b.dtwist[c];
    }
    let lambda = h00 * a.lambda + h10 * a.dlambda + h01 * b.lambda + h11 * b.dlambda;
    (xi, lambda)
}

/// The wrenches of one (place, force direction) as its coordinate runs over the table's range.
enum WrenchPath {
    /// Edge from `a` along unit `e`, force `f` fixed.
    Edge { a: Vec2, e: Vec2, f: Vec2, len: f64 },
    /// Vertex `p`; the normal turns from angle `phi0` (the inward normal of the edge before it)
    /// round the whole turn, the force at the cone angle whose sine and cosine are (`s`, `c`)
    /// from it. A reflex vertex (`convex` false: no normal cone, a pin cannot slide there) gets
    /// no table.
    Vertex {
        p: Vec2,
        phi0: f64,
        convex: bool,
        s: f64,
        c: f64,
    },
}

impl WrenchPath {
    /// The coordinates the table covers: the edge and [`EDGE_REACH`] of its length beyond each
    /// end; a convex vertex's whole turn of normals; nothing at a reflex vertex.
    fn range(&self) -> (f64, f64) {
        match self {
            WrenchPath::Edge { len, .. } => (-EDGE_REACH * len, (1.0 + EDGE_REACH) * len),
            WrenchPath::Vertex { convex: true, .. } => (0.0, std::f64::consts::TAU),
            WrenchPath::Vertex { .. } => (0.0, 0.0),
        }
    }
    /// The place coordinate at 0 and whether it is an angle.
    fn origin(&self) -> (f64, bool) {
        match self {
            WrenchPath::Edge { .. } => (0.0, false),
            WrenchPath::Vertex { phi0, .. } => (*phi0, true),
        }
    }
    /// The force on a vertex with the normal at angle `phi` (as the live solve forms it: the cone
    /// edge of that normal).
    fn vertex_force(phi: f64, s: f64, c: f64) -> Vec2 {
        Vec2::from_angle(phi).rotate_sc(s, c)
    }
    fn wrench(&self, t: f64) -> [f64; 3] {
        match self {
            WrenchPath::Edge { a, e, f, .. } => wrench_of(*f, *a + *e * t),
            WrenchPath::Vertex { p, phi0, s, c, .. } => {
                wrench_of(WrenchPath::vertex_force(phi0 + t, *s, *c), *p)
            }
        }
    }
    /// dw/dt.
    fn dwrench(&self, t: f64) -> [f64; 3] {
        match self {
            WrenchPath::Edge { e, f, .. } => [0.0, 0.0, e.cross(*f)],
            WrenchPath::Vertex { p, phi0, s, c, .. } => {
                wrench_of(WrenchPath::vertex_force(phi0 + t, *s, *c).perp(), *p)
            }
        }
    }
}

/// Builds one table, counting the evaluations it spends.
struct Builder<'a> {
    model: &'a PartModel,
    path: WrenchPath,
    /// The relative agreement an interval must show at its midpoint.
    tol: f64,
    evaluations: u64,
}

impl Builder<'_> {
    /// A full solve at ℓ (warm-started from a neighbouring node) with its derivatives.
    fn node(&mut self, ell: f64, near: Option<&Node>) -> Option<Node> {
        let w = self.path.wrench(ell);
        let warm = near.map(|n| WarmTwist {
            twist: n.twist,
            wrench: self.path.wrench(n.ell),
            lambda: n.lambda,
            hess: Some(n.hessian()),
        });
        let solved = self
            .model
            .converged_slide(w, warm.as_ref(), &mut self.evaluations);
        let (twist, warm_next) = solved.ok()?;
        let h = warm_next.hess?;
        // Symmetric by construction (both supports mirror one triangle), so this loses nothing.
        debug_assert!(h[1][0] == h[0][1] && h[2][0] == h[0][2] && h[2][1] == h[1][2]);
        let hess = [h[0][0], h[0][1], h[0][2], h[1][1], h[1][2], h[2][2]];
        let (dtwist, dlambda) = kkt_delta(&warm_next, self.path.dwrench(ell))?;
        Some(Node {
            ell,
            twist,
            dtwist,
            lambda: warm_next.lambda,
            dlambda,
            hess,
        })
    }

    /// Refine [a, b] into `out` (its nodes after `a`, in order) and `certified`.
    fn refine(&mut self, a: Node, b: Node, out: &mut Vec<Node>, certified: &mut Vec<bool>) {
        let mid_ell = 0.5 * (a.ell + b.ell);
        let Some(mid) = self.node(mid_ell, Some(&a)) else {
            out.push(b);
            certified.push(false);
            return;
        };
        let (xi, lambda) = hermite(&a, &b, 0.5);
        let scale = mid.twist.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let twist_err = (0..3).fold(0.0f64, |m, c| m.max((xi[c] - mid.twist[c]).abs())) / scale;
        let lambda_err = (lambda - mid.lambda).abs() / mid.lambda.abs();
        if twist_err <= self.tol && lambda_err <= self.tol {
            out.push(b);
            certified.push(true);
        } else if b.ell - a.ell <= MIN_INTERVAL {
            out.push(b);
            certified.push(false);
        } else {
            self.refine(a, mid, out, certified);
            self.refine(mid, b, out, certified);
        }
    }

    fn build(mut self) -> (Table, u64) {
        let (lo, hi) = self.path.range();
        let len = hi - lo;
        if !(len > 0.0 && len.is_finite()) {
            return (Table::indexed(&self.path, Vec::new(), Vec::new()), 0);
        }
        let mut nodes: Vec<Node> = Vec::new();
        let mut certified = Vec::new();
        let mut prev: Option<Node> = None;
        for j in 0..=START_INTERVALS {
            let ell = lo + len * j as f64 / START_INTERVALS as f64;
            let Some(node) = self.node(ell, prev.as_ref()) else {
                // A node that cannot be solved: the table serves nothing.
                return (
                    Table::indexed(&self.path, Vec::new(), Vec::new()),
                    self.evaluations,
                );
            };
            match prev {
                None => nodes.push(node),
                Some(p) => self.refine(p, node, &mut nodes, &mut certified),
            }
            prev = Some(node);
        }
        (
            Table::indexed(&self.path, nodes, certified),
            self.evaluations,
        )
    }
}

/// The tables of one μc: per edge and per vertex, one lazily built table per side.
#[derive(Debug)]
struct MuTables {
    mu_c: f64,
    sin_phi: f64,
    cos_phi: f64,
    edges: Vec<[OnceLock<Table>; 2]>,
    vertices: Vec<[OnceLock<Table>; 2]>,
}

/// Two empty slots per place.
fn slots(n: usize) -> Vec<[OnceLock<Table>; 2]> {
    (0..n).map(|_| [OnceLock::new(), OnceLock::new()]).collect()
}

/// The wrench path of `place` for the force at the cone angle with sine `s` and cosine `c` from
/// the normal. A reflex vertex (no normal cone) gets an empty path.
fn wrench_path(model: &PartModel, place: Place, s: f64, c: f64) -> WrenchPath {
    let poly = model.polygon();
    match place {
        Place::Edge(k) => {
            let e = poly.edge_dir(k);
            WrenchPath::Edge {
                a: poly.vertex(k),
                e,
                f: e.perp().rotate_sc(s, c),
                len: poly.edge_len(k),
            }
        }
        Place::Vertex(k) => {
            // The cone runs counter-clockwise from the normal of the edge before the vertex (the
            // event functions of a disc at a vertex, `Ctx::feature_events`).
            let na = poly.inward_normal(k + poly.len() - 1);
            WrenchPath::Vertex {
                p: poly.vertex(k),
                phi0: na.angle(),
                convex: poly.vertex_is_convex(k),
                s,
                c,
            }
        }
    }
}

/// A model's slide tables for the μc values it was given (see the module docs).
#[derive(Debug)]
pub struct SlideTables {
    by_mu: Vec<MuTables>,
    /// The certification tolerance of every table ([`TABLE_TOL`] unless asked otherwise).
    tol: f64,
    evaluations: AtomicU64,
    /// Thread time (ns) spent building tables, summed over threads.
    build_nanos: AtomicU64,
}

/// What the tables of a model hold so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TableStats {
    /// (μc, place, side) tables built (a reflex vertex's, which serves nothing, included).
    pub tables: usize,
    /// Nodes over all tables.
    pub nodes: usize,
    /// Intervals not certified (left to the solver).
    pub uncertified: usize,
    /// Dissipation evaluations spent building them.
    pub evaluations: u64,
}

impl SlideTables {
    /// Empty tables for a part with `edges` edges and these μc values (duplicates dropped; NaN or
    /// negative values ignored), certified to [`TABLE_TOL`].
    pub fn new(edges: usize, mu_values: &[f64]) -> SlideTables {
        SlideTables::certified_to(edges, mu_values, TABLE_TOL)
    }

    /// [`SlideTables::new`] with tables certified to `tol` relative (at least [`TABLE_TOL`]; see
    /// [`sampled_table_tol`]).
    pub fn certified_to(edges: usize, mu_values: &[f64], tol: f64) -> SlideTables {
        let mut by_mu: Vec<MuTables> = Vec::new();
        for &mu in mu_values {
            // −0 is 0 (the lookup orders by total_cmp).
            let mu = mu + 0.0;
            if !(mu.is_finite() && mu >= 0.0) || by_mu.iter().any(|t| t.mu_c == mu) {
                continue;
            }
            let c = 1.0 / (1.0 + mu * mu).sqrt();
            by_mu.push(MuTables {
                mu_c: mu,
                sin_phi: mu * c,
                cos_phi: c,
                edges: slots(edges),
                vertices: slots(edges),
            });
        }
        // In increasing μc, for the lookup's bisection (a planner's model can hold dozens).
        by_mu.sort_by(|a, b| a.mu_c.total_cmp(&b.mu_c));
        SlideTables {
            by_mu,
            tol: if tol.is_finite() {
                tol.max(TABLE_TOL)
            } else {
                TABLE_TOL
            },
            evaluations: AtomicU64::new(0),
            build_nanos: AtomicU64::new(0),
        }
    }

    /// Does any μc have tables (is there anything to look up)?
    pub fn is_empty(&self) -> bool {
        self.by_mu.is_empty()
    }

    /// The table of (μc, place, side), built on first use; `None` for a μc the model was not
    /// given or a place the part does not have.
    pub fn table(&self, model: &PartModel, mu_c: f64, place: Place, side: Side) -> Option<&Table> {
        let mu_c = mu_c + 0.0;
        let mt = match self.by_mu.as_slice() {
            [only] if only.mu_c == mu_c => only,
            [_] => return None,
            many => &many[many.binary_search_by(|t| t.mu_c.total_cmp(&mu_c)).ok()?],
        };
        let slot = match place {
            Place::Edge(k) => mt.edges.get(k)?,
            Place::Vertex(k) => mt.vertices.get(k)?,
        };
        Some(slot[side as usize].get_or_init(|| {
            let started = std::time::Instant::now();
            let s = match side {
                Side::Left => mt.sin_phi,
                Side::Right => -mt.sin_phi,
            };
            let builder = Builder {
                model,
                path: wrench_path(model, place, s, mt.cos_phi),
                tol: self.tol,
                evaluations: 0,
            };
            let (table, evals) = builder.build();
            self.evaluations.fetch_add(evals, Ordering::Relaxed);
            let nanos = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
            self.build_nanos.fetch_add(nanos, Ordering::Relaxed);
            table
        }))
    }

    /// The thread time (seconds, summed over threads) spent building tables so far: a timing,
    /// kept out of [`TableStats`], whose counts are deterministic.
    pub fn build_seconds(&self) -> f64 {
        self.build_nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// Build every table (each μc, edge and vertex, and side) now.
    pub fn build_all(&self, model: &PartModel) {
        for mt in &self.by_mu {
            for k in 0..mt.edges.len() {
                for place in [Place::Edge(k), Place::Vertex(k)] {
                    for side in [Side::Left, Side::Right] {
                        self.table(model, mt.mu_c, place, side);
                    }
                }
            }
        }
    }

    /// What has been built so far.
    pub fn stats(&self) -> TableStats {
        let mut s = TableStats {
            evaluations: self.evaluations.load(Ordering::Relaxed),
            ..TableStats::default()
        };
        for mt in &self.by_mu {
            let all = mt.edges.iter().chain(&mt.vertices).flatten();
            for t in all.filter_map(OnceLock::get) {
                let (nodes, ok) = t.size();
                s.tables += 1;
                s.nodes += nodes;
                s.uncertified += nodes.saturating_sub(1) - ok;
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::part_model::Support;

    fn tabled(name: &str, mu: f64) -> PartModel {
        PartModel::new(&part_from_spec(name).unwrap(), &Support::Uniform)
            .unwrap()
            .with_slide_tables(&[mu])
    }

    /// The converged solve the table stands for, at coordinate `t` of (place, side).
    fn solved(m: &PartModel, mu: f64, place: Place, side: Side, t: f64) -> (Twist, f64) {
        let poly = m.polygon();
        let c = 1.0 / (1.0 + mu * mu).sqrt();
        let s = if side == Side::Left { mu * c } else { -mu * c };
        let w = match place {
            Place::Edge(k) => {
                let e = poly.edge_dir(k);
                wrench_of(e.perp().rotate_sc(s, c), poly.vertex(k) + e * t)
            }
            Place::Vertex(k) => wrench_of(Vec2::from_angle(t).rotate_sc(s, c), poly.vertex(k)),
        };
        let mut ev = 0;
        let (xi, warm) = m.converged_slide(w, None, &mut ev).unwrap();
        (xi, warm.lambda)
    }

    /// Worst relative difference, twist and multiplier, between `m`'s tables at `mu` and the
    /// converged solves they stand for, at 23 points of every table off the nodes; also the
    /// number of convex vertices' tables checked and of points the tables left to the solver.
    fn worst_table_error(m: &PartModel, mu: f64) -> (f64, usize, usize) {
        let mut worst: f64 = 0.0;
        let (mut vertices, mut unserved) = (0, 0);
        for k in 0..m.polygon().len() {
            for place in [Place::Edge(k), Place::Vertex(k)] {
                for side in [Side::Left, Side::Right] {
                    let t = m.slide_table(mu, place, side).unwrap();
                    let Some((lo, hi)) = t.range() else {
                        // Only a reflex vertex has no range (the L's inner corner).
                        assert!(matches!(place, Place::Vertex(_)));
                        assert!(!m.polygon().vertex_is_convex(k));
                        continue;
                    };
                    vertices += usize::from(matches!(place, Place::Vertex(_)));
                    // Off the nodes: irrational fractions of the range.
                    for j in 0..23 {
                        let x = lo + (hi - lo) * ((j as f64 * 0.618_033_988_7 + 0.0123) % 1.0);
                        let Some(got) = t.at(x) else {
                            unserved += 1;
                            continue;
                        };
                        let (xi, lambda) = solved(m, mu, place, side, x);
                        let scale = xi.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                        for (g, x) in got.twist.iter().zip(xi) {
                            worst = worst.max((g - x).abs() / scale);
                        }
                        worst = worst.max((got.lambda - lambda).abs() / lambda);
                    }
                }
            }
        }
        (worst, vertices, unserved)
    }

    #[test]
    fn tables_agree_with_converged_solves_between_their_nodes() {
        let mut worst: f64 = 0.0;
        let mut vertices = 0;
        for (name, mu) in [
            ("tripoly1", 0.5),
            ("lshape", 0.3),
            ("rect:2:1", 0.0),
            ("ngon:7", 1.2),
        ] {
            let (w, v, unserved) = worst_table_error(&tabled(name, mu), mu);
            assert_eq!(unserved, 0, "{name}: certified everywhere");
            worst = worst.max(w);
            vertices += v;
        }
        assert_eq!(vertices, 2 * (3 + 5 + 4 + 7));
        // The midpoint certificate is TABLE_TOL = 1e-10; between nodes the cubic's error is no
        // larger, and the reference solve itself is converged to about 1e-12.
        assert!(worst < 5e-10, "worst relative error {worst:e}");
    }

    #[test]
    fn a_tripods_tables_agree_with_its_solves_as_closely() {
        // Point supports: the patches round the limit surface's facets into regions of high
        // curvature (the centre of rotation near a support point), which the refinement resolves
        // with more nodes; the served twists are as accurate as uniform pressure's.
        let mut worst: f64 = 0.0;
        for (name, seed, mu) in [
            ("tripoly2", 1, 0.5),
            ("lshape", 3, 0.2),
            ("random:12", 1, 0.8),
        ] {
            let poly = part_from_spec(name).unwrap();
            let tripod =
                Support::random_tripod(&poly, &mut crate::random::stream(seed, 0)).unwrap();
            let m = PartModel::new(&poly, &tripod)
                .unwrap()
                .with_slide_tables(&[mu]);
            let (w, v, _) = worst_table_error(&m, mu);
            assert_eq!(
                v,
                2 * (0..poly.len())
                    .filter(|&k| poly.vertex_is_convex(k))
                    .count()
            );
            worst = worst.max(w);
            let st = m.slide_table_stats().unwrap();
            // Certified where it serves: at most a few percent of intervals left to the solver.
            assert!(st.uncertified * 20 < st.nodes, "{name}: {st:?}");
        }
        assert!(worst < 5e-10, "worst relative error {worst:e}");
    }

    /// A sample's tables (`sampled_table_tol`: 1e-8 at the default integration tolerance) hold
    /// their own, looser certificate between the nodes, with a fraction of the nodes: a cubic
    /// Hermite table's nodes grow as tol^(−1/4), so about a third (100^(−1/4) ≈ 0.32).
    #[test]
    fn a_samples_tables_hold_their_tolerance_with_fewer_nodes() {
        assert_eq!(sampled_table_tol(1e-6), 1e-8);
        assert_eq!(sampled_table_tol(1e-9), TABLE_TOL);
        assert_eq!(sampled_table_tol(1e-2), 1e-6);
        for (name, tripod, mu) in [("tripoly1", None, 0.5), ("lshape", Some(3), 0.3)] {
            let poly = part_from_spec(name).unwrap();
            let support = match tripod {
                Some(seed) => {
                    Support::random_tripod(&poly, &mut crate::random::stream(seed, 0)).unwrap()
                }
                None => Support::Uniform,
            };
            let plain = PartModel::new(&poly, &support).unwrap();
            let fine = plain.clone().with_slide_tables(&[mu]);
            let coarse = plain.with_slide_tables_to(&[mu], sampled_table_tol(1e-6));
            let (w_fine, _, _) = worst_table_error(&fine, mu);
            let (w_coarse, _, _) = worst_table_error(&coarse, mu);
            assert!(w_fine < 5e-10, "{name}: {w_fine:e}");
            assert!(w_coarse < 5e-8, "{name}: {w_coarse:e}");
            let (n_fine, n_coarse) = (
                fine.slide_table_stats().unwrap().nodes,
                coarse.slide_table_stats().unwrap().nodes,
            );
            let ratio = n_coarse as f64 / n_fine as f64;
            assert!(
                (0.2..0.5).contains(&ratio),
                "{name}: {n_coarse} / {n_fine} nodes"
            );
        }
    }

    #[test]
    fn a_table_serves_only_its_edge_and_mu() {
        let m = tabled("tripoly2", 0.5);
        let t = m.slide_table(0.5, Place::Edge(1), Side::Right).unwrap();
        let len = m.polygon().edge_len(1);
        // The edge and EDGE_REACH of its length past each end (where stages overshoot).
        let r = EDGE_REACH * len;
        assert!(t.at(0.0).is_some() && t.at(len).is_some());
        assert!(t.at(-r).is_some() && t.at(len + r).is_some());
        assert!(t.at(-r * (1.0 + 1e-9)).is_none() && t.at(len + r * (1.0 + 1e-9)).is_none());
        assert!(t.at(f64::NAN).is_none());
        assert!(m.slide_table(0.4, Place::Edge(1), Side::Right).is_none());
        assert!(m.slide_table(0.5, Place::Edge(3), Side::Left).is_none());
        assert!(m.slide_table(0.5, Place::Vertex(3), Side::Left).is_none());
        // A vertex's table starts at the normal of the edge before it and goes round the whole
        // turn (its cone ends at the normal of the edge after it), whichever turn the angle is
        // given in.
        let v = m.slide_table(0.5, Place::Vertex(1), Side::Left).unwrap();
        let na = m.polygon().inward_normal(0);
        let (lo, hi) = v.range().unwrap();
        assert!((lo - na.angle()).abs() < 1e-12);
        assert!((hi - lo - std::f64::consts::TAU).abs() < 1e-12);
        for k in 0..16 {
            let phi = lo + std::f64::consts::TAU * (k as f64 + 0.37) / 16.0;
            let turned = v.at(phi + 2.0 * std::f64::consts::TAU).unwrap();
            let here = v.at(phi).unwrap();
            let back = v.at(phi - 3.0 * std::f64::consts::TAU).unwrap();
            for ((a, b), c) in turned.twist.iter().zip(here.twist).zip(back.twist) {
                assert!(
                    (a - b).abs() < 1e-12 && (c - b).abs() < 1e-12,
                    "{turned:?} {here:?}"
                );
            }
        }
        assert!(v.at(f64::NAN).is_none());
        // Without tables there are none.
        let plain =
            PartModel::new(&part_from_spec("tripoly2").unwrap(), &Support::Uniform).unwrap();
        assert!(plain.slide_table(0.5, Place::Edge(0), Side::Left).is_none());
        assert!(plain.slide_table_stats().is_none());
    }

    #[test]
    fn tables_are_built_lazily_the_same_every_time_and_shared_by_clones() {
        let a = tabled("square", 0.5);
        assert_eq!(a.slide_table_stats().unwrap().tables, 0);
        let b = a.clone();
        let ta = a
            .slide_table(0.5, Place::Edge(2), Side::Left)
            .unwrap()
            .breakpoints();
        // The clone sees the table its original built.
        let st = b.slide_table_stats().unwrap();
        assert_eq!((st.tables, st.nodes), (1, ta.len()));
        assert!(st.evaluations > 0 && st.uncertified == 0);
        // An independent model builds the same nodes, bit for bit (in another order, too).
        let c = tabled("square", 0.5);
        c.slide_table(0.5, Place::Vertex(0), Side::Right).unwrap();
        let tc = c.slide_table(0.5, Place::Edge(2), Side::Left).unwrap();
        assert_eq!(ta, tc.breakpoints());
        let ell = 0.377;
        let (x, y) = (
            a.slide_table(0.5, Place::Edge(2), Side::Left)
                .unwrap()
                .at(ell)
                .unwrap(),
            tc.at(ell).unwrap(),
        );
        assert_eq!((x.twist, x.lambda), (y.twist, y.lambda));
    }

    #[test]
    fn mirrored_edges_have_mirrored_tables() {
        // tripoly1 is symmetric about the y axis: edge 1 slid on the left mirrors edge 2 slid on
        // the right (ℓ measured from the other end), with ω and vx reversed.
        let m = tabled("tripoly1", 0.5);
        let l1 = m.polygon().edge_len(1);
        let t1 = m.slide_table(0.5, Place::Edge(1), Side::Left).unwrap();
        let t2 = m.slide_table(0.5, Place::Edge(2), Side::Right).unwrap();
        for j in 1..10 {
            let ell = l1 * j as f64 / 10.3;
            let a = t1.at(ell).unwrap();
            let b = t2.at(l1 - ell).unwrap();
            assert!((a.twist[0] + b.twist[0]).abs() < 1e-9, "{a:?} {b:?}");
            assert!((a.twist[1] - b.twist[1]).abs() < 1e-9);
            assert!((a.twist[2] + b.twist[2]).abs() < 1e-9);
            assert!((a.lambda - b.lambda).abs() < 1e-9);
        }
    }
}
