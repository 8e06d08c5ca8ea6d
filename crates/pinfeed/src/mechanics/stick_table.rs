//! Tabulated sticking twists: the exact model's stick solves on an edge without solving (
//! the companion of `mechanics::slide_table`).
//!
//! While a pin sticks on edge k at ℓ, the contact point p = a_k + ℓ e_k moves with the pin: its
//! velocity in the part frame is the pin's, v. The part's twist is the one of least dissipation
//! among those giving p that velocity (docs/physics.md#one-instant, stick):
//!
//!   ξ(ω) = (v + ω q, ω),  q = −ẑ×p,   ω* = argmin D(ξ(ω)),  i.e.  ∇D(ξ)·(q, 1) = 0,
//!
//! and the contact force is the force part F of ∇D(ξ*) (its moment is p × F). D is 1-homogeneous,
//! so ω* = |v| Ω(ℓ, b) and F = F(ℓ, b), with b the angle of v from the edge's inward normal. Ω
//! and F depend neither on μc nor on the part's orientation or the belt: one table per edge serves
//! every stick on it, at any μc.
//!
//! **Who builds them.** A cell costs about 10³ evaluations and saves about 1.7 per stick it serves;
//! a map tier's build (about 10⁵ exact pushes of one part) pays for them many times over, a line
//! of a few thousand parts or of a part with many edges does not (`results/line-speed.md`). They
//! are made by [`PartModel::with_stick_tables`], which the map tier's build calls.
//!
//! **The table** covers ℓ from [`EDGE_REACH`] of the edge's length before its start to as much
//! past its end (the integrator's stages overshoot an edge's end inside the step that lands there)
//! and |b| ≤ [`B_REACH`] (the pin pushing, n·v > 0, and a margin for stages beyond). It is a grid
//! of [`CELLS_L`] × [`CELLS_B`] cells, each built on the first query that lands in it. A cell
//! holds the tensor-product Chebyshev interpolant of degree [`DEGREE`] in ℓ and in b of (Ω, Fx, Fy)
//! through full solves at the (DEGREE+1)² Chebyshev–Lobatto points (Trefethen, *Approximation
//! Theory and Approximation Practice*, ch. 3–8: for a function analytic near the cell the
//! coefficients and the error fall geometrically with the degree). Ω and F are analytic in (ℓ, b)
//! except where the centre of rotation crosses the part's boundary (there the third derivative of
//! D is singular, as for the slide tables).
//!
//! **Certified refinement.** A cell's interpolant is accepted when (a) its highest coefficients
//! (the last row and column of the table of coefficients, whose size bounds the truncation error
//! of a geometrically converging series to within a small factor) and (b) its disagreement with
//! full solves (converged to the solver's own limit) at the four points (±½, ±½) of the cell — not
//! interpolation points — are both below [`STICK_TOL`] relative to the cell's smallest twist and
//! force. Otherwise the cell is split in four, down to [`MAX_DEPTH`] levels, as long as each
//! halving cuts the tail by [`SPLIT_GAIN`] or more: the tail falls geometrically where the
//! function is analytic, only algebraically across a kink, where halving further would cost 125
//! solves a piece for answers the solver gives anyway (stopping there halves the build of a
//! planner's tables, at no cost in a line's speed). A piece not certified, a query outside the
//! table's range, and a piece whose points cannot all be solved are left to the solver.
//! [`STICK_TOL`] is the accuracy of a live stick solve at the default tolerance (its last Newton
//! step is taken unevaluated: `part_model::final_gap`), as for the slide tables.
//!
//! **Pure translations are solved.** A stick whose Ω is within [`TRANSLATION_BAND`] of zero (a push
//! through the centroid, an equilibrium the part may ride) is left to the solver: there the sign
//! of the interpolant's Ω is rounding, and the solver holds the exact state (`WarmStick::predict`).
//!
//! **Deterministic.** A cell's content is a fixed function of (part, edge, cell): its points are
//! solved in a fixed order from fixed warm starts, so which contact or thread builds it first
//! changes nothing, and the evaluations a build spends are the table's ([`StickTables::stats`]),
//! not the contact's that needed it first.

use super::part_model::{PartModel, Solved, WarmStick};
use super::slide_table::EDGE_REACH;
use crate::geometry::Vec2;
use std::f64::consts::{PI, TAU};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// Relative agreement (twist and force) a piece must show.
pub const STICK_TOL: f64 = 1e-10;
/// |Ω|·max(1, |q|) below which a query is left to the solver (see `EdgeTable::at`): ten times
/// the table's accuracy.
pub const TRANSLATION_BAND: f64 = 10.0 * STICK_TOL;
/// Cells of the grid along ℓ (over the edge and its reach).
pub const CELLS_L: usize = 12;
/// Cells of the grid along b (over ±[`B_REACH`]).
pub const CELLS_B: usize = 24;
/// How far from the edge's inward normal (radians) the pin's velocity may point for the table to
/// serve it: the pushing half-plane (|b| < π/2) and 0.1π beyond.
pub const B_REACH: f64 = 0.6 * PI;
/// The degree of a piece's interpolant in each variable.
pub const DEGREE: usize = 10;
/// Levels of four-way splitting below a grid cell before a piece is left to the solver.
pub const MAX_DEPTH: u32 = 3;

/// How much halving a piece must cut its tail for its halves to be halved again (see
/// `Builder::refine`).
pub const SPLIT_GAIN: f64 = 16.0;

const NP: usize = DEGREE + 1;

/// One piece: its lower corner and sides in (ℓ, b), the Chebyshev coefficients of (Ω, Fx, Fy)
/// (`coef[i][j]` multiplies T_i in ℓ and T_j in b, on the piece mapped to [−1, 1]²), and the
/// Hessian of D at its centre (for unit pin speed), which a served solve hands on as the warm
/// start of a later solve the table does not serve.
#[derive(Debug)]
struct Piece {
    l0: f64,
    b0: f64,
    hl: f64,
    hb: f64,
    coef: Box<[[[f64; 3]; NP]; NP]>,
    hess: [[f64; 3]; 3],
}

/// A grid cell: a piece, four sub-cells (quadrants: low ℓ low b, high ℓ low b, low ℓ high b,
/// high ℓ high b), or nothing the table serves.
#[derive(Debug)]
enum Cell {
    Piece(Piece),
    /// Split at (ℓ, b) = `mid`.
    Split {
        mid: (f64, f64),
        quads: Box<[Cell; 4]>,
    },
    Open,
}

/// T_0(x) … T_DEGREE(x).
#[inline]
fn chebyshev(x: f64) -> [f64; NP] {
    let mut t = [0.0; NP];
    t[0] = 1.0;
    t[1] = x;
    for n in 2..NP {
        t[n] = 2.0 * x * t[n - 1] - t[n - 2];
    }
    t
}

/// The Chebyshev–Lobatto points cos(πk/DEGREE), k = 0 … DEGREE.
fn lobatto() -> [f64; NP] {
    std::array::from_fn(|k| (PI * k as f64 / DEGREE as f64).cos())
}

impl Piece {
    /// The piece's coordinates (x, y) ∈ [−1, 1]² of (ℓ, b).
    fn local(&self, ell: f64, b: f64) -> (f64, f64) {
        (
            (2.0 * (ell - self.l0) / self.hl - 1.0).clamp(-1.0, 1.0),
            (2.0 * (b - self.b0) / self.hb - 1.0).clamp(-1.0, 1.0),
        )
    }

    /// (Ω, Fx, Fy) at local coordinates (x, y): the coefficients contracted with T_i(x) first
    /// (33 independent sums, which vectorise), then with T_j(y).
    #[inline]
    fn eval(&self, x: f64, y: f64) -> [f64; 3] {
        let (tx, ty) = (chebyshev(x), chebyshev(y));
        let mut g = [0.0; 3 * NP];
        for (row, txi) in self.coef.iter().zip(tx) {
            for (gk, ck) in g.iter_mut().zip(row.as_flattened()) {
                *gk += ck * txi;
            }
        }
        let mut out = [0.0; 3];
        for (gj, tyj) in g.chunks_exact(3).zip(ty) {
            out[0] += gj[0] * tyj;
            out[1] += gj[1] * tyj;
            out[2] += gj[2] * tyj;
        }
        out
    }
}

/// The table of one edge.
#[derive(Debug)]
struct EdgeTable {
    /// The edge's start, unit direction and inward normal's angle.
    a: Vec2,
    e: Vec2,
    psi: f64,
    l_lo: f64,
    cell_l: f64,
    cell_b: f64,
    cells: Vec<OnceLock<Cell>>,
}

/// A served stick solve: the twist for the pin's velocity with the wrench, and a warm start.
pub type Served = (Solved, WarmStick);

impl EdgeTable {
    fn new(model: &PartModel, k: usize) -> EdgeTable {
        let poly = model.polygon();
        let (e, len) = (poly.edge_dir(k), poly.edge_len(k));
        EdgeTable {
            a: poly.vertex(k),
            e,
            psi: e.perp().angle(),
            l_lo: -EDGE_REACH * len,
            cell_l: (1.0 + 2.0 * EDGE_REACH) * len / CELLS_L as f64,
            cell_b: 2.0 * B_REACH / CELLS_B as f64,
            cells: (0..CELLS_L * CELLS_B).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The grid cell of (ℓ, b), if inside the table's range.
    fn cell_index(&self, ell: f64, b: f64) -> Option<usize> {
        let x = (ell - self.l_lo) / self.cell_l;
        let y = (b + B_REACH) / self.cell_b;
        if !(x >= 0.0 && x <= CELLS_L as f64 && y >= 0.0 && y <= CELLS_B as f64) {
            return None;
        }
        let i = (x as usize).min(CELLS_L - 1);
        let j = (y as usize).min(CELLS_B - 1);
        Some(i * CELLS_B + j)
    }

    /// Cell `idx`, built on first use (its evaluations and time added to `spent`).
    fn cell(&self, model: &PartModel, idx: usize, spent: &Spent) -> &Cell {
        self.cells[idx].get_or_init(|| {
            let started = std::time::Instant::now();
            let (i, j) = (idx / CELLS_B, idx % CELLS_B);
            let mut builder = Builder {
                model,
                table: self,
                evaluations: 0,
            };
            let l0 = self.l_lo + i as f64 * self.cell_l;
            let b0 = -B_REACH + j as f64 * self.cell_b;
            let cell = builder.refine(l0, b0, self.cell_l, self.cell_b, 0, f64::INFINITY);
            spent
                .evaluations
                .fetch_add(builder.evaluations, Ordering::Relaxed);
            let nanos = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
            spent.nanos.fetch_add(nanos, Ordering::Relaxed);
            cell
        })
    }

    /// The certified piece holding (ℓ, b), its cell built on first use; `None` outside the range
    /// or in a piece left to the solver.
    fn piece_at(&self, model: &PartModel, ell: f64, b: f64, spent: &Spent) -> Option<&Piece> {
        let mut cell = self.cell(model, self.cell_index(ell, b)?, spent);
        loop {
            match cell {
                Cell::Piece(p) => return Some(p),
                Cell::Open => return None,
                Cell::Split { mid, quads } => {
                    let hi_l = usize::from(ell >= mid.0);
                    let hi_b = usize::from(b >= mid.1);
                    cell = &quads[hi_l + 2 * hi_b];
                }
            }
        }
    }

    /// The stick at ℓ for pin velocity `v` (part frame) from the table, where it serves.
    fn at(&self, model: &PartModel, ell: f64, v: Vec2, spent: &Spent) -> Option<Served> {
        let speed = v.norm();
        if !(speed > 0.0 && speed.is_finite()) {
            return None;
        }
        // Both angles lie in (−π, π]: one turn at most brings the difference there.
        let mut b = v.y.atan2(v.x) - self.psi;
        if b > PI {
            b -= TAU;
        } else if b <= -PI {
            b += TAU;
        }
        let piece = self.piece_at(model, ell, b, spent)?;
        let (x, y) = piece.local(ell, b);
        let [om, fx, fy] = piece.eval(x, y);
        let p = self.a + self.e * ell;
        let q = -p.perp();
        // Within the table's accuracy of a pure translation (a push through the centroid) the
        // sense of rotation would be the interpolant's rounding: the solver, which holds such a
        // state exactly, decides it.
        if om.abs() * q.norm().max(1.0) <= TRANSLATION_BAND {
            return None;
        }
        let omega = om * speed;
        let twist = [v.x + omega * q.x, v.y + omega * q.y, omega];
        let force = Vec2::new(fx, fy);
        let wrench = [fx, fy, p.cross(force)];
        // D is 1-homogeneous: its Hessian at the twist for speed |v| is the unit one over |v|.
        let inv = 1.0 / speed;
        let hess = piece.hess.map(|row| row.map(|h| h * inv));
        Some((
            Solved { twist, wrench },
            WarmStick {
                twist,
                wrench,
                hess: Some(hess),
            },
        ))
    }
}

/// Builds one cell of one edge's table, counting the evaluations it spends.
struct Builder<'a> {
    model: &'a PartModel,
    table: &'a EdgeTable,
    evaluations: u64,
}

/// A converged solve at one point: (Ω, Fx, Fy), the twist's largest component, and the warm start
/// (with the Hessian) it leaves.
struct Point {
    f: [f64; 3],
    twist_scale: f64,
    warm: WarmStick,
}

impl Builder<'_> {
    /// The converged stick solve at (ℓ, b) for unit pin speed.
    fn solve(&mut self, ell: f64, b: f64, warm: Option<&WarmStick>) -> Option<Point> {
        let t = self.table;
        let p = t.a + t.e * ell;
        let u = Vec2::from_angle(t.psi + b);
        let (s, next) = self
            .model
            .converged_stick(p, u, warm, &mut self.evaluations)
            .ok()?;
        next.hess?;
        let f = [s.twist[2], s.wrench[0], s.wrench[1]];
        f.iter().all(|x| x.is_finite()).then(|| Point {
            f,
            twist_scale: s.twist.iter().fold(0.0f64, |m, x| m.max(x.abs())),
            warm: next,
        })
    }

    /// The piece over [l0, l0 + hl] × [b0, b0 + hb], or its refinement. `parent_tail` is the
    /// tail of the piece this one halves (relative to the certificate's bound; infinite for a
    /// grid cell).
    fn refine(&mut self, l0: f64, b0: f64, hl: f64, hb: f64, depth: u32, parent_tail: f64) -> Cell {
        match self.piece(l0, b0, hl, hb) {
            Some((piece, true, _)) => Cell::Piece(piece),
            None => Cell::Open,
            Some((_, false, _)) if depth >= MAX_DEPTH => Cell::Open,
            // Where the function is analytic, halving a piece cuts its tail by far more than
            // SPLIT_GAIN (geometric convergence in the degree, faster as the piece shrinks);
            // across a kink the tail falls only algebraically, and halving further would spend
            // 125 solves a piece on what the solver answers anyway.
            Some((_, false, tail)) if tail * SPLIT_GAIN > parent_tail => Cell::Open,
            Some((_, false, tail)) => {
                let (hl2, hb2) = (0.5 * hl, 0.5 * hb);
                let quads = [
                    (l0, b0),
                    (l0 + hl2, b0),
                    (l0, b0 + hb2),
                    (l0 + hl2, b0 + hb2),
                ];
                Cell::Split {
                    mid: (l0 + hl2, b0 + hb2),
                    quads: Box::new(
                        quads.map(|(l, b)| self.refine(l, b, hl2, hb2, depth + 1, tail)),
                    ),
                }
            }
        }
    }

    /// The interpolant over the rectangle, whether it is certified, and its tail (its largest
    /// highest coefficient over the certificate's bound); `None` when a point cannot be solved.
    fn piece(&mut self, l0: f64, b0: f64, hl: f64, hb: f64) -> Option<(Piece, bool, f64)> {
        let xs = lobatto();
        let at = |x: f64, h: f64, o: f64| o + 0.5 * (x + 1.0) * h;
        let mut vals = [[[0.0; 3]; NP]; NP];
        let (mut twist_min, mut force_min) = (f64::INFINITY, f64::INFINITY);
        let mut warm_row: Option<WarmStick> = None;
        let mut centre: Option<WarmStick> = None;
        // Solved row by row in a fixed order, each from its neighbour's warm start.
        for (i, &x) in xs.iter().enumerate() {
            let mut warm = warm_row;
            for (j, &y) in xs.iter().enumerate() {
                let pt = self.solve(at(x, hl, l0), at(y, hb, b0), warm.as_ref())?;
                if j == 0 {
                    warm_row = Some(pt.warm);
                }
                if i == DEGREE / 2 && j == DEGREE / 2 {
                    centre = Some(pt.warm);
                }
                twist_min = twist_min.min(pt.twist_scale);
                force_min = force_min.min(pt.f[1].hypot(pt.f[2]));
                warm = Some(pt.warm);
                vals[i][j] = pt.f;
            }
        }
        let piece = Piece {
            l0,
            b0,
            hl,
            hb,
            coef: Box::new(coefficients(&vals)),
            hess: centre.and_then(|w| w.hess).unwrap_or([[0.0; 3]; 3]),
        };
        // The twist differs by ΔΩ (q, 1): |q| ≤ the farthest corner's distance from the centroid.
        let q_max = [l0, l0 + hl]
            .iter()
            .map(|&l| (self.table.a + self.table.e * l).norm())
            .fold(1.0f64, f64::max);
        // A difference (ΔΩ, ΔFx, ΔFy) over the certificate's bound (≤ 1 passes).
        let ratio = |d: [f64; 3]| {
            (d[0].abs() * q_max / (STICK_TOL * twist_min))
                .max(d[1].hypot(d[2]) / (STICK_TOL * force_min))
        };
        let within = |d: [f64; 3]| ratio(d) <= 1.0;
        let tail = (0..NP)
            .map(|k| ratio(piece.coef[k][DEGREE]).max(ratio(piece.coef[DEGREE][k])))
            .fold(0.0f64, f64::max);
        let mut ok = tail <= 1.0;
        if ok {
            for (x, y) in [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)] {
                let pt = self.solve(at(x, hl, l0), at(y, hb, b0), centre.as_ref())?;
                let v = piece.eval(x, y);
                ok &= within([v[0] - pt.f[0], v[1] - pt.f[1], v[2] - pt.f[2]]);
            }
        }
        Some((piece, ok, tail))
    }
}

/// The coefficients of the tensor Chebyshev interpolant through values at the Lobatto points
/// (the discrete cosine transform of type I along each variable).
fn coefficients(vals: &[[[f64; 3]; NP]; NP]) -> [[[f64; 3]; NP]; NP] {
    let n = DEGREE as f64;
    // cos(π j k / n) and the end weights ½.
    let cos: [[f64; NP]; NP] =
        std::array::from_fn(|j| std::array::from_fn(|k| (PI * (j * k) as f64 / n).cos()));
    let w = |k: usize| if k == 0 || k == DEGREE { 0.5 } else { 1.0 };
    let transform = |get: &dyn Fn(usize) -> [f64; 3], j: usize| -> [f64; 3] {
        let mut s = [0.0; 3];
        for (k, ck) in cos[j].iter().enumerate() {
            let v = get(k);
            for c in 0..3 {
                s[c] += w(k) * v[c] * ck;
            }
        }
        let scale = w(j) * 2.0 / n;
        s.map(|x| x * scale)
    };
    // Along b (second index) for every ℓ point, then along ℓ.
    let rows: [[[f64; 3]; NP]; NP] =
        std::array::from_fn(|i| std::array::from_fn(|j| transform(&|k| vals[i][k], j)));
    std::array::from_fn(|i| std::array::from_fn(|j| transform(&|k| rows[k][j], i)))
}

/// A model's stick tables, one per edge (see the module docs).
#[derive(Debug)]
pub struct StickTables {
    edges: Vec<OnceLock<EdgeTable>>,
    spent: Spent,
}

/// What building the tables' cells has cost so far, from whichever threads built them.
#[derive(Debug, Default)]
struct Spent {
    /// Dissipation evaluations.
    evaluations: AtomicU64,
    /// Thread time (ns), summed over the threads.
    nanos: AtomicU64,
}

/// What a model's stick tables hold so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StickStats {
    /// Grid cells built.
    pub cells: usize,
    /// Certified pieces in them.
    pub pieces: usize,
    /// Pieces left to the solver (not certified at the deepest level, or not solvable).
    pub open: usize,
    /// Dissipation evaluations spent building them.
    pub evaluations: u64,
}

impl StickTables {
    /// Empty tables for a part with `edges` edges.
    pub fn new(edges: usize) -> StickTables {
        StickTables {
            edges: (0..edges).map(|_| OnceLock::new()).collect(),
            spent: Spent::default(),
        }
    }

    /// The stick solve on edge `k` at ℓ for pin velocity `v` (part frame), from the table where it
    /// serves; `None` where it does not (the caller solves).
    #[inline]
    pub fn at(&self, model: &PartModel, k: usize, ell: f64, v: Vec2) -> Option<Served> {
        let table = self.edges.get(k)?.get_or_init(|| EdgeTable::new(model, k));
        table.at(model, ell, v, &self.spent)
    }

    /// Build every cell of every edge now (for timing contacts without their tables' build).
    pub fn build_all(&self, model: &PartModel) {
        for (k, slot) in self.edges.iter().enumerate() {
            let table = slot.get_or_init(|| EdgeTable::new(model, k));
            for idx in 0..table.cells.len() {
                table.cell(model, idx, &self.spent);
            }
        }
    }

    /// The thread time (seconds, summed over threads) spent building cells so far: a timing, kept
    /// out of [`StickStats`], whose counts are deterministic.
    pub fn build_seconds(&self) -> f64 {
        self.spent.nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// What has been built so far.
    pub fn stats(&self) -> StickStats {
        fn count(c: &Cell, s: &mut StickStats) {
            match c {
                Cell::Piece(_) => s.pieces += 1,
                Cell::Open => s.open += 1,
                Cell::Split { quads, .. } => quads.iter().for_each(|c| count(c, s)),
            }
        }
        let mut s = StickStats {
            evaluations: self.spent.evaluations.load(Ordering::Relaxed),
            ..StickStats::default()
        };
        for t in self.edges.iter().filter_map(OnceLock::get) {
            for c in t.cells.iter().filter_map(OnceLock::get) {
                s.cells += 1;
                count(c, &mut s);
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

    fn plain(name: &str) -> PartModel {
        PartModel::new(&part_from_spec(name).unwrap(), &Support::Uniform).unwrap()
    }

    /// The pin velocity at angle `b` from edge k's inward normal, of length `speed`.
    fn velocity(m: &PartModel, k: usize, b: f64, speed: f64) -> Vec2 {
        Vec2::from_angle(m.polygon().edge_dir(k).perp().angle() + b) * speed
    }

    /// (ℓ, b) off any grid: irrational fractions of the edge with its reach, and of ±0.55π.
    fn probes(len: f64, n: usize) -> impl Iterator<Item = (f64, f64)> {
        (0..n).map(move |j| {
            let x = (j as f64 * 0.618_033_988_7 + 0.0123) % 1.0;
            let y = (j as f64 * 0.754_877_666_2 + 0.0371) % 1.0;
            let ell = len * (-EDGE_REACH + (1.0 + 2.0 * EDGE_REACH) * x);
            (ell, 0.55 * PI * (2.0 * y - 1.0))
        })
    }

    /// The interpolant through the Lobatto points reproduces any polynomial of degree ≤ DEGREE in
    /// each variable (to rounding), and its coefficients are the polynomial's Chebyshev ones.
    #[test]
    fn the_interpolant_reproduces_tensor_polynomials() {
        let f = |x: f64, y: f64| {
            let (tx, ty) = (chebyshev(x), chebyshev(y));
            [
                0.5 + tx[3] * ty[7],
                -2.0 * tx[DEGREE] * ty[1] + x * y,
                tx[5] * ty[DEGREE] - 0.25 * y,
            ]
        };
        let xs = lobatto();
        let vals: [[[f64; 3]; NP]; NP] =
            std::array::from_fn(|i| std::array::from_fn(|j| f(xs[i], xs[j])));
        let coef = coefficients(&vals);
        assert!((coef[0][0][0] - 0.5).abs() < 1e-14 && (coef[3][7][0] - 1.0).abs() < 1e-14);
        assert!((coef[DEGREE][1][1] + 2.0).abs() < 1e-14 && (coef[1][1][1] - 1.0).abs() < 1e-14);
        assert!((coef[5][DEGREE][2] - 1.0).abs() < 1e-14 && (coef[0][1][2] + 0.25).abs() < 1e-14);
        let piece = Piece {
            l0: 2.0,
            b0: -1.0,
            hl: 0.5,
            hb: 0.25,
            coef: Box::new(coef),
            hess: [[0.0; 3]; 3],
        };
        for k in 0..50 {
            let (x, y) = (
                ((k as f64 * 0.618_033_988_7) % 1.0) * 2.0 - 1.0,
                ((k as f64 * 0.754_877_666_2) % 1.0) * 2.0 - 1.0,
            );
            let (ell, b) = (2.0 + 0.5 * (x + 1.0) * 0.5, -1.0 + 0.5 * (y + 1.0) * 0.25);
            let (lx, ly) = piece.local(ell, b);
            let (got, want) = (piece.eval(lx, ly), f(x, y));
            for c in 0..3 {
                assert!((got[c] - want[c]).abs() < 1e-13, "{k}: {got:?} {want:?}");
            }
        }
    }

    /// Mirror symmetry: tripoly1 is symmetric about the y axis, which maps edge 1 onto edge 2 (ℓ
    /// measured from the other end) and a pin velocity at angle b from edge 1's normal onto one at
    /// −b from edge 2's. The mirrored stick has vx, ω and Fx reversed, vy and Fy kept.
    #[test]
    fn mirrored_sticks_have_mirrored_tables() {
        let m = plain("tripoly1")
            .with_slide_tables(&[0.5])
            .with_stick_tables();
        let poly = m.polygon().clone();
        let l1 = poly.edge_len(1);
        assert!((l1 - poly.edge_len(2)).abs() < 1e-12);
        let mut compared = 0;
        for (ell, b) in probes(l1, 60) {
            let mirror = |v: Vec2| Vec2::new(-v.x, v.y);
            let v = velocity(&m, 1, b, 0.7);
            let (Some((a, _)), Some((c, _))) = (
                m.tabled_stick(1, ell, v),
                m.tabled_stick(2, l1 - ell, mirror(v)),
            ) else {
                continue;
            };
            compared += 1;
            let (sa, sc) = (a.twist, c.twist);
            assert!((sa[0] + sc[0]).abs() < 1e-9, "{a:?} {c:?}");
            assert!((sa[1] - sc[1]).abs() < 1e-9, "{a:?} {c:?}");
            assert!((sa[2] + sc[2]).abs() < 1e-9, "{a:?} {c:?}");
            assert!((a.wrench[0] + c.wrench[0]).abs() < 1e-9, "{a:?} {c:?}");
            assert!((a.wrench[1] - c.wrench[1]).abs() < 1e-9, "{a:?} {c:?}");
        }
        assert!(compared >= 50, "{compared}");
    }

    /// Where the table serves, its twist and force are those of a converged solve to about
    /// STICK_TOL; and it serves nearly everywhere in its range.
    #[test]
    fn tables_agree_with_converged_solves_where_they_serve() {
        let (mut worst, mut served, mut asked) = (0.0f64, 0, 0);
        for name in ["tripoly1", "lshape", "ngon:7"] {
            let m = plain(name).with_slide_tables(&[0.5]).with_stick_tables();
            let poly = m.polygon().clone();
            for k in 0..poly.len() {
                for (ell, b) in probes(poly.edge_len(k), 40) {
                    let v = velocity(&m, k, b, 1.3);
                    asked += 1;
                    let Some((got, _)) = m.tabled_stick(k, ell, v) else {
                        continue;
                    };
                    served += 1;
                    let p = poly.vertex(k) + poly.edge_dir(k) * ell;
                    let (want, _) = m.converged_stick(p, v, None, &mut 0).unwrap();
                    let scale = want.twist.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                    for (g, w) in got.twist.iter().zip(want.twist) {
                        worst = worst.max((g - w).abs() / scale);
                    }
                    let f = (want.wrench[0].hypot(want.wrench[1]), want.wrench);
                    for c in 0..3 {
                        worst = worst.max((got.wrench[c] - f.1[c]).abs() / f.0.max(1e-300));
                    }
                }
            }
        }
        // The certificate is STICK_TOL = 1e-10 on the coefficients' tail and at four checkpoints
        // per piece; the reference solve itself is converged to about 1e-12.
        assert!(worst < 1e-9, "worst relative error {worst:e}");
        assert!(served * 10 >= asked * 9, "served {served} of {asked}");
    }

    /// A served solve is a fixed function of (edge, ℓ, v): the same bits whichever cells were built
    /// first, 1-homogeneous in the pin's speed, and outside the table's range (or for no speed)
    /// nothing is served.
    #[test]
    fn served_sticks_are_pure_functions_of_the_query() {
        let (a, b) = (
            plain("tripoly2")
                .with_slide_tables(&[0.3])
                .with_stick_tables(),
            plain("tripoly2").with_stick_tables(),
        );
        let poly = a.polygon().clone();
        let queries: Vec<(usize, f64, Vec2)> = (0..poly.len())
            .flat_map(|k| {
                let m = &a;
                probes(poly.edge_len(k), 12).map(move |(ell, bb)| (k, ell, velocity(m, k, bb, 0.8)))
            })
            .collect();
        let forward: Vec<_> = queries
            .iter()
            .map(|&(k, l, v)| a.tabled_stick(k, l, v))
            .collect();
        let backward: Vec<_> = queries
            .iter()
            .rev()
            .map(|&(k, l, v)| b.tabled_stick(k, l, v))
            .collect();
        for (f, g) in forward.iter().zip(backward.iter().rev()) {
            assert_eq!(f.map(|s| s.0), g.map(|s| s.0));
        }
        assert_eq!(a.stick_table_stats(), b.stick_table_stats());
        // The same direction at four times the speed (a power of two scales every component
        // exactly, so the direction is the same bit for bit): the same wrench, four times the
        // twist.
        for &(k, l, v) in &queries {
            let (Some((s1, _)), Some((s2, _))) =
                (a.tabled_stick(k, l, v), a.tabled_stick(k, l, v * 4.0))
            else {
                continue;
            };
            for c in 0..3 {
                assert!(
                    (s2.twist[c] - 4.0 * s1.twist[c]).abs() <= 1e-14 * (1.0 + s2.twist[c].abs())
                );
                assert_eq!(s1.wrench[c], s2.wrench[c]);
            }
        }
        let len = poly.edge_len(0);
        let v = velocity(&a, 0, 0.1, 1.0);
        assert!(a.tabled_stick(0, 0.5 * len, v).is_some());
        assert!(a.tabled_stick(0, -0.26 * len, v).is_none());
        assert!(a.tabled_stick(0, 1.26 * len, v).is_none());
        assert!(a
            .tabled_stick(0, 0.5 * len, velocity(&a, 0, 0.61 * PI, 1.0))
            .is_none());
        assert!(a.tabled_stick(0, 0.5 * len, Vec2::new(0.0, 0.0)).is_none());
        assert!(a.tabled_stick(0, f64::NAN, v).is_none());
        assert!(a.tabled_stick(poly.len(), 0.5 * len, v).is_none());
        assert!(plain("tripoly2").tabled_stick(0, 0.5 * len, v).is_none());
        // A scene's model (slide tables only) has none.
        let scene_model = plain("tripoly2").with_slide_tables(&[0.5]);
        assert!(scene_model.tabled_stick(0, 0.5 * len, v).is_none());
    }

    /// Where the centre of rotation crosses the part's boundary the stick twist is not smooth
    /// (docs/physics.md#limit-surface): the refinement stops there and leaves those pieces to the solver, while the rest
    /// of the table is certified.
    #[test]
    fn pieces_across_a_kink_are_left_to_the_solver() {
        let m = plain("tripoly2").with_stick_tables();
        m.build_all_tables();
        let st = m.stick_table_stats().unwrap();
        assert_eq!(st.cells, m.polygon().len() * CELLS_L * CELLS_B);
        assert!(st.open > 0, "{st:?}");
        assert!(st.pieces > 3 * st.open, "{st:?}");
        assert!(st.evaluations > 0);
    }
}
