//! Tabulated sliding twists on a part's edges: the exact model's slide solves without solving
//! (issue 15, "per-part precomputed" data for the exact contact).
//!
//! While a pin slides on edge k the contact force lies on one edge of the friction cone,
//! f = R(±atan μc) n_k (the normal n_k itself when μc = 0), and the contact point is
//! p = a_k + ℓ e_k (vertex a_k, unit direction e_k; the same for a point pin and a disc, whose
//! contact normal on an edge is the edge's). The contact wrench
//!
//!   w(ℓ) = (f, p × f) = (f, a_k × f + ℓ e_k × f)
//!
//! is therefore a straight line in wrench space, and the sliding twist — the limit surface's normal
//! at w, normalised so that w·ξ = 1, with its multiplier λ (∇D(ξ) = λ w, the force being λ f) — is
//! a function of ℓ alone. It does not depend on the part's orientation, the pin's velocity, its
//! radius or the belt: one table per (μc, edge, side) serves every slide on that edge. The table
//! stores ξ, λ and their derivatives in ℓ at nodes and interpolates with cubic Hermite
//! polynomials. The derivatives come from the optimality conditions ∇D(ξ) = λ w, w·ξ = 1
//! differentiated along the line (dw/dℓ = (0, 0, e_k × f)):
//!
//!   [H −w; wᵀ 0] [dξ; dλ] = [λ dw; −dw·ξ]    (the system [`super::part_model`] warm-starts with).
//!
//! **Certified refinement.** An edge starts with [`START_INTERVALS`] equal intervals; each interval
//! is checked at its midpoint against a full solve (converged to the solver's own limit) and
//! accepted when the interpolated ξ and λ agree with it to [`TABLE_TOL`] relative; otherwise it is
//! split there (the midpoint becomes a node). For a smooth ξ(ℓ) the cubic Hermite error is
//! ∝ t²(1 − t)² ξ'''' h⁴/24 on t ∈ [0, 1], largest at the midpoint, so the midpoint check bounds the
//! interval. Where ξ(ℓ) is less smooth (the centre of rotation crossing the part's boundary makes
//! the third derivative of D singular) the refinement goes on down to [`MIN_INTERVAL`]; an interval
//! not certified there is left to the solver, and so is any ℓ outside [0, |edge|] (a stage of a
//! step that overshoots an edge's end) and any solve that failed while building.
//!
//! The accuracy this gives is that of the live solve: a live slide solve stops at a relative
//! optimality gap g ≤ √(1e-6·tol) and takes an unevaluated last Newton step, which leaves a twist
//! error of about 100 g² ≈ 1e-10 at the default tolerance (see `part_model::final_gap`);
//! [`TABLE_TOL`] is 1e-10.
//!
//! **Opt-in, deterministic.** Tables are built lazily, one (μc, edge, side) at a time, on the first
//! slide that needs one, and only for models that ask for them with the μc values they will see
//! ([`super::PartModel::with_slide_tables`]: a scene's shared model, a planner's, the contact
//! benchmark's). A table's content is a fixed function of (part, μc, edge, side), built in a fixed
//! order, so which thread builds it first changes nothing; and a served solve never depends on
//! what was solved before it. The evaluations a build spends are the table's, not the contact's
//! that happened to need it first ([`SlideTables::stats`]), so a contact's evaluation count is
//! the same on any number of threads.

use super::part_model::{kkt_delta, wrench_of, PartModel, Twist, WarmTwist};
use crate::geometry::Vec2;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// Relative agreement (twist and multiplier) an interval must show at its midpoint.
pub const TABLE_TOL: f64 = 1e-10;
/// Equal intervals an edge starts with.
pub const START_INTERVALS: usize = 8;
/// The shortest interval (units of a) refinement makes; one not certified there is left to the
/// solver.
pub const MIN_INTERVAL: f64 = 1e-5;

/// The slide sides a table exists for: the force on the counter-clockwise cone edge R(+atan μc) n
/// (also the frictionless normal force when μc = 0) and on the clockwise one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Left = 0,
    Right = 1,
}

/// One node of an edge table.
#[derive(Debug, Clone, Copy)]
struct Node {
    ell: f64,
    twist: Twist,
    dtwist: Twist,
    lambda: f64,
    dlambda: f64,
    hess: [[f64; 3]; 3],
}

/// A served slide solve: the normalised twist (w·ξ = 1), the multiplier λ (the force is λ f) and
/// the Hessian of D at the nearer node (for warm-starting a later solve that is not served).
#[derive(Debug, Clone, Copy)]
pub struct TableTwist {
    pub twist: Twist,
    pub lambda: f64,
    pub hess: [[f64; 3]; 3],
}

/// The table of one (μc, edge, side): nodes in increasing ℓ and, per interval, whether it was
/// certified; plus a uniform index over ℓ (the first interval of each of [`INDEX_BUCKETS`] equal
/// pieces of the edge) so that a lookup scans a few intervals instead of bisecting a thousand.
#[derive(Debug)]
pub struct EdgeTable {
    nodes: Vec<Node>,
    certified: Vec<bool>,
    bucket_first: Vec<u32>,
    /// Buckets per unit of ℓ.
    bucket_scale: f64,
}

/// Buckets of the uniform index over an edge's ℓ.
const INDEX_BUCKETS: usize = 512;

impl EdgeTable {
    /// The sliding twist at ℓ (units of a from the edge's first vertex), or `None` where the table
    /// does not serve (outside the edge, or an interval that was not certified).
    #[inline]
    pub fn at(&self, ell: f64) -> Option<TableTwist> {
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
        let hess = if t <= 0.5 { a.hess } else { b.hess };
        Some(TableTwist {
            twist,
            lambda,
            hess,
        })
    }

    /// The table over these nodes and intervals, with its uniform index.
    fn indexed(nodes: Vec<Node>, certified: Vec<bool>) -> EdgeTable {
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
        EdgeTable {
            nodes,
            certified,
            bucket_first,
            bucket_scale,
        }
    }

    /// The nodes' ℓ, in increasing order (for reports and tests).
    pub fn breakpoints(&self) -> Vec<f64> {
        self.nodes.iter().map(|n| n.ell).collect()
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

/// The line of wrenches along one edge for one force direction.
struct EdgeLine {
    a: Vec2,
    e: Vec2,
    f: Vec2,
    len: f64,
}

impl EdgeLine {
    fn wrench(&self, ell: f64) -> [f64; 3] {
        wrench_of(self.f, self.a + self.e * ell)
    }
    /// dw/dℓ.
    fn dwrench(&self) -> [f64; 3] {
        [0.0, 0.0, self.e.cross(self.f)]
    }
}

/// Builds one edge table, counting the evaluations it spends.
struct Builder<'a> {
    model: &'a PartModel,
    line: EdgeLine,
    evaluations: u64,
}

impl Builder<'_> {
    /// A full solve at ℓ (warm-started from a neighbouring node) with its derivatives.
    fn node(&mut self, ell: f64, near: Option<&Node>) -> Option<Node> {
        let w = self.line.wrench(ell);
        let warm = near.map(|n| WarmTwist {
            twist: n.twist,
            wrench: self.line.wrench(n.ell),
            lambda: n.lambda,
            hess: Some(n.hess),
        });
        let solved = self
            .model
            .converged_slide(w, warm.as_ref(), &mut self.evaluations);
        let (twist, warm_next) = solved.ok()?;
        let hess = warm_next.hess?;
        let (dtwist, dlambda) = kkt_delta(&warm_next, self.line.dwrench())?;
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
        if twist_err <= TABLE_TOL && lambda_err <= TABLE_TOL {
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

    fn build(mut self) -> (EdgeTable, u64) {
        let len = self.line.len;
        let mut nodes: Vec<Node> = Vec::new();
        let mut certified = Vec::new();
        let mut prev: Option<Node> = None;
        for j in 0..=START_INTERVALS {
            let ell = len * j as f64 / START_INTERVALS as f64;
            let Some(node) = self.node(ell, prev.as_ref()) else {
                // A node that cannot be solved: the table serves nothing on this edge.
                return (EdgeTable::indexed(Vec::new(), Vec::new()), self.evaluations);
            };
            match prev {
                None => nodes.push(node),
                Some(p) => self.refine(p, node, &mut nodes, &mut certified),
            }
            prev = Some(node);
        }
        (EdgeTable::indexed(nodes, certified), self.evaluations)
    }
}

/// The tables of one μc: per edge, one lazily built table per side.
#[derive(Debug)]
struct MuTables {
    mu_c: f64,
    sin_phi: f64,
    cos_phi: f64,
    edges: Vec<[OnceLock<EdgeTable>; 2]>,
}

/// A model's slide tables for the μc values it was given (see the module docs).
#[derive(Debug)]
pub struct SlideTables {
    by_mu: Vec<MuTables>,
    evaluations: AtomicU64,
}

/// What the tables of a model hold so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TableStats {
    /// (μc, edge, side) tables built.
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
    /// negative values ignored).
    pub fn new(edges: usize, mu_values: &[f64]) -> SlideTables {
        let mut by_mu: Vec<MuTables> = Vec::new();
        for &mu in mu_values {
            if !(mu.is_finite() && mu >= 0.0) || by_mu.iter().any(|t| t.mu_c == mu) {
                continue;
            }
            let c = 1.0 / (1.0 + mu * mu).sqrt();
            by_mu.push(MuTables {
                mu_c: mu,
                sin_phi: mu * c,
                cos_phi: c,
                edges: (0..edges)
                    .map(|_| [OnceLock::new(), OnceLock::new()])
                    .collect(),
            });
        }
        SlideTables {
            by_mu,
            evaluations: AtomicU64::new(0),
        }
    }

    /// Does any μc have tables (is there anything to look up)?
    pub fn is_empty(&self) -> bool {
        self.by_mu.is_empty()
    }

    /// The table of (μc, edge, side), built on first use; `None` for a μc the model was not given.
    pub fn table(
        &self,
        model: &PartModel,
        mu_c: f64,
        edge: usize,
        side: Side,
    ) -> Option<&EdgeTable> {
        let mt = self.by_mu.iter().find(|t| t.mu_c == mu_c)?;
        let slot = mt.edges.get(edge)?;
        Some(slot[side as usize].get_or_init(|| {
            let poly = model.polygon();
            let e = poly.edge_dir(edge);
            let n = e.perp();
            let s = match side {
                Side::Left => mt.sin_phi,
                Side::Right => -mt.sin_phi,
            };
            let builder = Builder {
                model,
                line: EdgeLine {
                    a: poly.vertex(edge),
                    e,
                    f: n.rotate_sc(s, mt.cos_phi),
                    len: poly.edge_len(edge),
                },
                evaluations: 0,
            };
            let (table, evals) = builder.build();
            self.evaluations.fetch_add(evals, Ordering::Relaxed);
            table
        }))
    }

    /// Build every table (each μc, edge and side) now.
    pub fn build_all(&self, model: &PartModel) {
        for mt in &self.by_mu {
            for edge in 0..mt.edges.len() {
                for side in [Side::Left, Side::Right] {
                    self.table(model, mt.mu_c, edge, side);
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
            for t in mt.edges.iter().flatten().filter_map(OnceLock::get) {
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

    /// The converged solve the table stands for, at ℓ on (edge, side).
    fn solved(m: &PartModel, mu: f64, edge: usize, side: Side, ell: f64) -> (Twist, f64) {
        let poly = m.polygon();
        let e = poly.edge_dir(edge);
        let c = 1.0 / (1.0 + mu * mu).sqrt();
        let s = if side == Side::Left { mu * c } else { -mu * c };
        let f = e.perp().rotate_sc(s, c);
        let w = wrench_of(f, poly.vertex(edge) + e * ell);
        let mut ev = 0;
        let (xi, warm) = m.converged_slide(w, None, &mut ev).unwrap();
        (xi, warm.lambda)
    }

    #[test]
    fn tables_agree_with_converged_solves_between_their_nodes() {
        let mut worst: f64 = 0.0;
        for (name, mu) in [
            ("tripoly1", 0.5),
            ("lshape", 0.3),
            ("rect:2:1", 0.0),
            ("ngon:7", 1.2),
        ] {
            let m = tabled(name, mu);
            for edge in 0..m.polygon().len() {
                for side in [Side::Left, Side::Right] {
                    let t = m.slide_table(mu, edge, side).unwrap();
                    let len = m.polygon().edge_len(edge);
                    // Off the nodes: irrational fractions of the edge.
                    for j in 0..23 {
                        let ell = len * ((j as f64 * 0.618_033_988_7 + 0.0123) % 1.0);
                        let got = t.at(ell).expect("certified everywhere on these parts");
                        let (xi, lambda) = solved(&m, mu, edge, side, ell);
                        let scale = xi.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                        for (g, x) in got.twist.iter().zip(xi) {
                            worst = worst.max((g - x).abs() / scale);
                        }
                        worst = worst.max((got.lambda - lambda).abs() / lambda);
                    }
                }
            }
        }
        // The midpoint certificate is TABLE_TOL = 1e-10; between nodes the cubic's error is no
        // larger, and the reference solve itself is converged to about 1e-12.
        assert!(worst < 5e-10, "worst relative error {worst:e}");
    }

    #[test]
    fn a_table_serves_only_its_edge_and_mu() {
        let m = tabled("tripoly2", 0.5);
        let t = m.slide_table(0.5, 1, Side::Right).unwrap();
        let len = m.polygon().edge_len(1);
        assert!(t.at(0.0).is_some() && t.at(len).is_some());
        assert!(t.at(-1e-9).is_none() && t.at(len * (1.0 + 1e-9)).is_none());
        assert!(t.at(f64::NAN).is_none());
        assert!(m.slide_table(0.4, 1, Side::Right).is_none());
        assert!(m.slide_table(0.5, 3, Side::Left).is_none());
        // Without tables, or with point supports, there are none.
        let plain =
            PartModel::new(&part_from_spec("tripoly2").unwrap(), &Support::Uniform).unwrap();
        assert!(plain.slide_table(0.5, 0, Side::Left).is_none());
        assert!(plain.slide_table_stats().is_none());
        let tripod = Support::parse("tripod:3", &part_from_spec("tripoly2").unwrap()).unwrap();
        let pts = PartModel::new(&part_from_spec("tripoly2").unwrap(), &tripod)
            .unwrap()
            .with_slide_tables(&[0.5]);
        assert!(pts.slide_table_stats().is_none());
    }

    #[test]
    fn tables_are_built_lazily_the_same_every_time_and_shared_by_clones() {
        let a = tabled("square", 0.5);
        assert_eq!(a.slide_table_stats().unwrap().tables, 0);
        let b = a.clone();
        let ta = a.slide_table(0.5, 2, Side::Left).unwrap().breakpoints();
        // The clone sees the table its original built.
        let st = b.slide_table_stats().unwrap();
        assert_eq!((st.tables, st.nodes), (1, ta.len()));
        assert!(st.evaluations > 0 && st.uncertified == 0);
        // An independent model builds the same nodes, bit for bit (in another order, too).
        let c = tabled("square", 0.5);
        c.slide_table(0.5, 0, Side::Right).unwrap();
        let tc = c.slide_table(0.5, 2, Side::Left).unwrap();
        assert_eq!(ta, tc.breakpoints());
        let ell = 0.377;
        let (x, y) = (
            a.slide_table(0.5, 2, Side::Left).unwrap().at(ell).unwrap(),
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
        let t1 = m.slide_table(0.5, 1, Side::Left).unwrap();
        let t2 = m.slide_table(0.5, 2, Side::Right).unwrap();
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
