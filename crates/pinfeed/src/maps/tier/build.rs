//! Building a map: exact samples on a lattice, base cells refined as quadtrees where the
//! interpolation does not certify (see the module docs of [`super`]).
//!
//! Every sample sits on a lattice of 2^(max_depth + 2) points per base cell and axis, so a point
//! shared by neighbouring cells is computed once. Each refinement level computes all its missing
//! points in one parallel, order-preserving batch (sorted lattice keys), then decides every cell in
//! order: the result does not depend on the thread count.

use super::{Node, Sample, TierInputs, TierMap};
use crate::geometry::{Pose, Vec2};
use crate::mechanics::{push_path, ContactFeature, PinPath};
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};

/// A cell being decided: lower-left lattice point, side (lattice units), its node.
#[derive(Debug, Clone, Copy)]
struct Cell {
    i: u64,
    j: u64,
    size: u64,
    node: usize,
}

/// The lattice geometry of a map.
#[derive(Debug, Clone, Copy)]
struct Lattice {
    /// Lattice points along θ0 over the whole map.
    theta_points: u64,
    /// Lattice points along d over the whole map.
    d_points: u64,
    /// Half-width r of the d range (units of a).
    reach: f64,
}

impl Lattice {
    fn theta(&self, i: u64) -> f64 {
        std::f64::consts::TAU * i as f64 / self.theta_points as f64
    }
    fn d(&self, j: u64) -> f64 {
        -self.reach + 2.0 * self.reach * j as f64 / self.d_points as f64
    }
}

fn lattice_key(i: u64, j: u64) -> u64 {
    (i << 32) | j
}

/// The half-width r of the d range (units of a): beyond |d| > r the pin cannot touch the part.
pub fn reach(inputs: &TierInputs) -> f64 {
    let r = inputs
        .model
        .polygon()
        .vertices()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.norm()));
    r + inputs.radius / inputs.model.scale()
}

/// One exact push at (θ0, d): the part at the origin, the pin well clear upstream.
pub fn exact_sample(inputs: &TierInputs, reach: f64, theta: f64, d: f64) -> Sample {
    let k = inputs.model.scale();
    let start = Vec2::new((reach + 1.0) * k, d * k);
    let path = PinPath::constant(0.0);
    let out = push_path(
        inputs.model,
        Pose::new(0.0, 0.0, theta),
        start,
        inputs.radius,
        &path,
        &inputs.settings,
        None,
    );
    let last = out.segments.last();
    let span = last.map_or(0.0, |s| s.s_end - out.travel_to_contact) / k;
    let single = out.contact && out.contacts == 1 && out.status.is_ok();
    // The line takes the contact's end from the last segment; a single contact's length is that.
    let consistent = (span - out.contact_length / k).abs() <= 1e-9;
    Sample {
        servable: single && consistent && last.is_some(),
        feature: last.map_or(u32::MAX, |s| feature_code(s.feature)),
        rotation: out.rotation_rad,
        dx: out.pose_final.x / k,
        dy: out.pose_final.y / k,
        span,
    }
}

fn feature_code(f: ContactFeature) -> u32 {
    let kind = match f {
        ContactFeature::Edge(_) => 0,
        ContactFeature::Vertex(_) => 1,
        ContactFeature::FenceVertex(_) => 2,
        ContactFeature::FenceEdge(_) => 3,
    };
    (kind << 16) | (f.index() as u32 & 0xffff)
}

/// Quadratic Lagrange weights on the nodes 0, ½, 1 at `u`.
fn quadratic(u: f64) -> [f64; 3] {
    [
        2.0 * (u - 0.5) * (u - 1.0),
        -4.0 * u * (u - 1.0),
        2.0 * u * (u - 0.5),
    ]
}

/// Biquadratic interpolation through the cell's 3 × 3 nodes (θ-major within each d row: node
/// a + 3b sits at (a/2, b/2)) at (u, v) ∈ [0, 1]²: [rotation, Δx, Δy, span].
pub fn interpolate(nodes: [&Sample; 9], u: f64, v: f64) -> [f64; 4] {
    let (wu, wv) = (quadratic(u), quadratic(v));
    let mut out = [0.0; 4];
    for (k, s) in nodes.iter().enumerate() {
        let w = wu[k % 3] * wv[k / 3];
        out[0] += w * s.rotation;
        out[1] += w * s.dx;
        out[2] += w * s.dy;
        out[3] += w * s.span;
    }
    out
}

impl Cell {
    /// The 3 × 3 interpolation nodes (see [`interpolate`]).
    fn nodes(&self) -> [(u64, u64); 9] {
        let h = self.size / 2;
        std::array::from_fn(|k| (self.i + (k as u64 % 3) * h, self.j + (k as u64 / 3) * h))
    }
    /// Check points with their local coordinates: the four quarter points inside and the two
    /// quarter points of each edge (the nodes of the children that are not the cell's own).
    fn checks(&self) -> [(u64, u64, f64, f64); 12] {
        const AT: [(u64, u64); 12] = [
            (1, 1),
            (3, 1),
            (1, 3),
            (3, 3),
            (1, 0),
            (3, 0),
            (1, 4),
            (3, 4),
            (0, 1),
            (0, 3),
            (4, 1),
            (4, 3),
        ];
        let q = self.size / 4;
        AT.map(|(a, b)| {
            let (u, v) = (a as f64 / 4.0, b as f64 / 4.0);
            (self.i + a * q, self.j + b * q, u, v)
        })
    }
    fn points(&self) -> impl Iterator<Item = (u64, u64)> {
        let checks = self.checks().map(|(i, j, ..)| (i, j));
        self.nodes().into_iter().chain(checks)
    }
}

/// Is the cell certified, given every sample it needs?
fn certified(cell: &Cell, at: &BTreeMap<u64, Sample>, inputs: &TierInputs) -> bool {
    let get = |(i, j): (u64, u64)| &at[&lattice_key(i, j)];
    let c = cell.nodes().map(get);
    let feature = c[0].feature;
    let same = |s: &Sample| s.servable && s.feature == feature;
    if !c.iter().all(|s| same(s)) {
        return false;
    }
    let (tol_rot, tol_pos) = (inputs.spec.check_deg.to_radians(), inputs.spec.check_pos);
    cell.checks().iter().all(|&(i, j, u, v)| {
        let s = get((i, j));
        let p = interpolate(c, u, v);
        same(s)
            && (p[0] - s.rotation).abs() <= tol_rot
            && (p[1] - s.dx).abs() <= tol_pos
            && (p[2] - s.dy).abs() <= tol_pos
            && (p[3] - s.span).abs() <= tol_pos
    })
}

/// How far a cell is from certifying at its first level, to order cells by how deep they will
/// refine: a cell whose points differ in contact feature or servability (a jump of θf crosses it)
/// ranks above any smooth one, by how many of its points differ from its first node; a smooth one
/// by its largest interpolation error at a check point, relative to the tolerance.
fn shortfall(cell: &Cell, at: &BTreeMap<u64, Sample>, inputs: &TierInputs) -> f64 {
    let get = |(i, j): (u64, u64)| &at[&lattice_key(i, j)];
    let c = cell.nodes().map(get);
    let (feature, servable) = (c[0].feature, c[0].servable);
    let differ = cell
        .points()
        .filter(|&p| {
            let s = get(p);
            s.feature != feature || s.servable != servable
        })
        .count();
    if differ > 0 || !servable {
        return 1e9 + differ as f64;
    }
    let (tol_rot, tol_pos) = (inputs.spec.check_deg.to_radians(), inputs.spec.check_pos);
    cell.checks()
        .iter()
        .map(|&(i, j, u, v)| {
            let s = get((i, j));
            let p = interpolate(c, u, v);
            ((p[0] - s.rotation).abs() / tol_rot)
                .max((p[1] - s.dx).abs() / tol_pos)
                .max((p[2] - s.dy).abs() / tol_pos)
                .max((p[3] - s.span).abs() / tol_pos)
        })
        .fold(0.0, f64::max)
}

/// Does any of the cell's points push the part once and pass (else there is nothing to
/// tabulate in it: a miss is answered by the ray cast, anything else by the exact model)?
fn any_servable(cell: &Cell, at: &BTreeMap<u64, Sample>) -> bool {
    cell.points().any(|(i, j)| at[&lattice_key(i, j)].servable)
}

/// Compute, in parallel and in key order, every lattice point the cells need that is not known;
/// returns the thread time they took (seconds, summed over threads).
fn fill(
    cells: &[Cell],
    at: &mut BTreeMap<u64, Sample>,
    inputs: &TierInputs,
    lat: &Lattice,
    parallel: bool,
) -> f64 {
    let missing: BTreeSet<(u64, u64)> = cells
        .iter()
        .flat_map(|c| c.points())
        .filter(|&(i, j)| !at.contains_key(&lattice_key(i, j)))
        .collect();
    let missing: Vec<(u64, u64)> = missing.into_iter().collect();
    let sample = |&(i, j): &(u64, u64)| {
        let started = std::time::Instant::now();
        let s = exact_sample(inputs, lat.reach, lat.theta(i), lat.d(j));
        (s, started.elapsed().as_secs_f64())
    };
    let computed: Vec<(Sample, f64)> = if parallel {
        missing.par_iter().map(sample).collect()
    } else {
        missing.iter().map(sample).collect()
    };
    let mut seconds = 0.0;
    for ((i, j), (s, t)) in missing.into_iter().zip(computed) {
        at.insert(lattice_key(i, j), s);
        seconds += t;
    }
    seconds
}

/// Build the whole map of `inputs` (deterministic; parallel over samples).
pub fn build(inputs: &TierInputs) -> TierMap {
    let mut map = TierMap::unbuilt(inputs);
    let roots: Vec<usize> = map.unbuilt_cells().collect();
    extend(&mut map, inputs, &roots);
    map
}

/// Build the base cells `roots` of `map` (the map of `inputs`) that are not built yet, in
/// parallel over samples. A base cell's quadtree and samples depend on that cell alone (every
/// sample sits on the lattice, and a cell is decided by its own points), so a map answers every
/// query in a built cell the same way whichever other cells were built, in whatever order.
pub fn extend(map: &mut TierMap, inputs: &TierInputs, roots: &[usize]) {
    extend_observed(map, inputs, roots, &crate::progress::silent);
}

/// Base cells built per batch by [`extend_observed`]: enough for the samples of a refinement
/// level to fill both cores, few enough for the progress to move.
const CELLS_PER_BATCH: usize = 24;

/// [`extend`], telling `progress` the base cells built of those asked for. The cells are built in
/// batches of consecutive cells (θ-major), one after another, each batch in parallel. A build of
/// more than one batch first computes the first level of every cell it builds (its nine nodes and
/// twelve check points), which decides which cells refine and roughly how deep, then builds a
/// probe of the refining cells (see [`probe_cells`]) in full, and tells `progress` a
/// [`BuildForecast`] of the rest (also returned) before building it.
pub fn extend_observed(
    map: &mut TierMap,
    inputs: &TierInputs,
    roots: &[usize],
    progress: crate::progress::Report,
) -> Option<BuildForecast> {
    let todo: Vec<usize> = roots
        .iter()
        .copied()
        .filter(|&r| map.nodes.get(r) == Some(&Node::Unbuilt))
        .collect::<BTreeSet<usize>>()
        .into_iter()
        .collect();
    if todo.is_empty() {
        return None;
    }
    let model = tabled_model(inputs);
    let inputs = &TierInputs {
        model: &model,
        ..*inputs
    };
    let tally = crate::progress::Tally::new(todo.len() as u64, progress);
    let mut first = BTreeMap::new();
    let mut forecast = None;
    let mut rest = todo.clone();
    if todo.len() > CELLS_PER_BATCH {
        let (probe, told) = probe_and_forecast(map, inputs, &todo, &mut first);
        tally.add(probe.len() as u64);
        progress.forecast(&crate::progress::Forecast {
            seconds_left: told.seconds_left,
            said: told.describe(),
        });
        forecast = Some(told);
        rest.retain(|r| !probe.contains(r));
    }
    for batch in rest.chunks(CELLS_PER_BATCH) {
        build_cells(map, inputs, batch, true, &first);
        tally.add(batch.len() as u64);
    }
    forecast
}

/// The start of a build of the base cells `todo`: the first level of every cell (its samples
/// left in `first`), the refining cells ranked by [`shortfall`], the probe among them built in
/// full; returns the probe's cells and the forecast for the other refining cells.
fn probe_and_forecast(
    map: &mut TierMap,
    inputs: &TierInputs,
    todo: &[usize],
    first: &mut BTreeMap<u64, Sample>,
) -> (Vec<usize>, BuildForecast) {
    let spec = inputs.spec;
    let cells: Vec<Cell> = todo.iter().map(|&r| base_cell(r, spec)).collect();
    let started = std::time::Instant::now();
    fill(&cells, first, inputs, &lattice(map.reach, spec), true);
    let first_seconds = started.elapsed().as_secs_f64();
    map.stats.exact_samples += first.len() as u64;
    let mut refining: Vec<(f64, usize)> = cells
        .iter()
        .filter(|c| refines(c, first, inputs))
        .map(|c| (shortfall(c, first, inputs), c.node))
        .collect();
    refining.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let ranked: Vec<usize> = refining.iter().map(|&(_, r)| r).collect();
    let mut probe = probe_cells(&ranked);
    probe.sort_unstable();
    let started = std::time::Instant::now();
    let tables_before = inputs.model.table_build_seconds();
    let built = build_cells(map, inputs, &probe, true, first);
    let seconds = started.elapsed().as_secs_f64();
    let tables = inputs.model.table_build_seconds() - tables_before;
    let probed = Probe {
        cells: probe.len() as u64,
        pushes: built.computed,
        seconds,
        tables_share: (tables / built.thread_seconds.max(1e-12)).clamp(0.0, 1.0),
    };
    let told = BuildForecast::of(
        (todo.len(), first.len() as u64, first_seconds),
        ranked.len() as u64,
        probed,
    );
    (probe, told)
}

/// Does a base cell refine, given its first level's samples (as [`build_cells`] decides)?
fn refines(cell: &Cell, at: &BTreeMap<u64, Sample>, inputs: &TierInputs) -> bool {
    !certified(cell, at, inputs) && cell.size > 4 && any_servable(cell, at)
}

/// The cells of `ranked` (the base cells whose first level does not certify, in increasing
/// shortfall: the smooth ones by their largest interpolation error at a check point, then those a
/// jump of θf crosses; roughly, how deep they will refine) that a build refines first, to forecast the
/// rest: a sixteenth of them, at least eight and at most 24, one batch (all of them when
/// there are no more), picked at even strides through the ranking, so that the probe holds
/// shallow and deep cells in their proportions. A cell's quadtree depends on that cell alone, so
/// building these first changes no answer.
pub fn probe_cells(ranked: &[usize]) -> Vec<usize> {
    let n = ranked.len();
    let k = n.div_ceil(16).clamp(8, CELLS_PER_BATCH).min(n);
    (0..k).map(|i| ranked[(2 * i + 1) * n / (2 * k)]).collect()
}

/// What a build's probe measured.
#[derive(Debug, Clone, Copy)]
struct Probe {
    /// The probed base cells.
    cells: u64,
    /// The exact pushes (lattice samples) their refinement took (their first level was known).
    pushes: u64,
    /// Their wall time.
    seconds: f64,
    /// The share of the samples' thread time that went into the model's slide and stick tables
    /// (built as the first pushes ask for them; later cells mostly find them built).
    tables_share: f64,
}

/// How long the rest of a map build should take, told before the rest starts. The first level
/// of every cell is computed first: it decides which cells refine. The probe then refines some of
/// those (see [`probe_cells`]); the others are forecast to take as many pushes each as the
/// probe's cells did on average, at the probe's wall time per push less the share of it that
/// built the model's slide and stick tables (which the build's first pushes mostly pay for).
/// Cells that certify at their first level need nothing more.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildForecast {
    /// Base cells of the build.
    pub cells: u64,
    /// Exact pushes of the first level of every cell.
    pub first_pushes: u64,
    /// Wall time of the first level.
    pub first_seconds: f64,
    /// Base cells whose first level does not certify: they refine.
    pub refining: u64,
    /// Refining cells probed (built in full).
    pub probe_cells: u64,
    /// Exact pushes the probe's refinement took.
    pub probe_pushes: u64,
    /// Wall time of the probe.
    pub probe_seconds: f64,
    /// Exact pushes forecast for the other refining cells.
    pub pushes_left: u64,
    /// Wall time forecast for them.
    pub seconds_left: f64,
}

impl BuildForecast {
    fn of(
        (cells, first_pushes, first_seconds): (usize, u64, f64),
        refining: u64,
        probe: Probe,
    ) -> BuildForecast {
        let left = refining - probe.cells;
        let per_cell = probe.pushes as f64 / probe.cells.max(1) as f64;
        let pushes_left = (per_cell * left as f64).round() as u64;
        let per_push = probe.seconds * (1.0 - probe.tables_share) / probe.pushes.max(1) as f64;
        BuildForecast {
            cells: cells as u64,
            first_pushes,
            first_seconds,
            refining,
            probe_cells: probe.cells,
            probe_pushes: probe.pushes,
            probe_seconds: probe.seconds,
            pushes_left,
            seconds_left: pushes_left as f64 * per_push,
        }
    }

    /// Wall time forecast for the whole build, what was measured before the forecast included.
    pub fn seconds_in_all(&self) -> f64 {
        self.first_seconds + self.probe_seconds + self.seconds_left
    }

    /// The forecast in words.
    pub fn describe(&self) -> String {
        format!(
            "map tier: {} base cells to build; their first level ({} exact pushes, {:.2} s) certifies {} and leaves {} to refine; {} of those took {} pushes in {:.2} s, so the other {} should take about {} pushes, {:.1} s",
            self.cells,
            self.first_pushes,
            self.first_seconds,
            self.cells - self.refining,
            self.refining,
            self.probe_cells,
            self.probe_pushes,
            self.probe_seconds,
            self.refining - self.probe_cells,
            self.pushes_left,
            self.seconds_left
        )
    }
}

/// The lattice of a map of half-width `reach` on the grid `spec`.
fn lattice(reach: f64, spec: super::TierSpec) -> Lattice {
    let per_cell = 1u64 << (spec.max_depth + 2);
    Lattice {
        theta_points: u64::from(spec.theta_cells) * per_cell,
        d_points: u64::from(spec.d_cells) * per_cell,
        reach,
    }
}

/// Base cell `root` of a map on the grid `spec`, as a cell of its lattice.
fn base_cell(root: usize, spec: super::TierSpec) -> Cell {
    let per_cell = 1u64 << (spec.max_depth + 2);
    let nd = u64::from(spec.d_cells);
    Cell {
        i: (root as u64 / nd) * per_cell,
        j: (root as u64 % nd) * per_cell,
        size: per_cell,
        node: root,
    }
}

/// The model a map is built with: the inputs' model with stick tables. A map's build is a batch
/// of ~10⁵ exact pushes over one part, whose sticks pay for the tables; a map built cell by cell
/// ([`super::LazyMap`]) keeps one such model for all its cells.
pub fn tabled_model(inputs: &TierInputs) -> crate::mechanics::PartModel {
    inputs.model.clone().with_stick_tables()
}

/// Build the unbuilt base cell `root` of `map` (`inputs.model` already the [`tabled_model`]):
/// the same cell as [`extend`] builds, for a cell built while a query waits
/// ([`super::LazyMap`]). Its samples are computed in parallel only when this thread is not one
/// of rayon's workers: a worker waiting for its helpers runs other queued tasks meanwhile, and
/// one of those could ask for the cell being built (a line of a study run in parallel), which
/// would wait on itself. A thread outside the pool just blocks until its helpers are done.
pub fn build_cell_here(map: &mut TierMap, inputs: &TierInputs, root: usize) {
    if map.nodes.get(root) == Some(&Node::Unbuilt) {
        let parallel = rayon::current_thread_index().is_none();
        build_cells(map, inputs, &[root], parallel, &BTreeMap::new());
    }
}

/// What [`build_cells`] did.
#[derive(Debug, Clone, Copy)]
struct Built {
    /// Exact pushes computed (samples not known before).
    computed: u64,
    /// Their thread time (seconds, summed over threads).
    thread_seconds: f64,
}

/// Build the unbuilt base cells `todo` of `map` (the model of `inputs` already has its tables),
/// their samples computed in parallel or on this thread; the samples in `known` (the lattice
/// points computed earlier, counted then) are not computed again.
fn build_cells(
    map: &mut TierMap,
    inputs: &TierInputs,
    todo: &[usize],
    parallel: bool,
    known: &BTreeMap<u64, Sample>,
) -> Built {
    let spec = inputs.spec;
    let per_cell = 1u64 << (spec.max_depth + 2);
    let (nt, nd) = (u64::from(spec.theta_cells), u64::from(spec.d_cells));
    let lat = lattice(map.reach, spec);
    let mut cells: Vec<Cell> = todo.iter().map(|&r| base_cell(r, spec)).collect();
    for &r in todo {
        map.nodes[r] = Node::Fallback;
    }
    let mut at: BTreeMap<u64, Sample> = cells
        .iter()
        .flat_map(|c| c.points())
        .filter_map(|(i, j)| {
            let key = lattice_key(i, j);
            known.get(&key).map(|s| (key, *s))
        })
        .collect();
    let seeded = at.len() as u64;
    let mut index: BTreeMap<u64, u32> = BTreeMap::new();
    let stats = &mut map.stats;
    let (nodes, samples) = (&mut map.nodes, &mut map.samples);
    let mut area = 0.0;
    let mut thread_seconds = 0.0;
    while !cells.is_empty() {
        thread_seconds += fill(&cells, &mut at, inputs, &lat, parallel);
        let mut next = Vec::new();
        for cell in &cells {
            if certified(cell, &at, inputs) {
                let points = cell.nodes().map(|(i, j)| {
                    let key = lattice_key(i, j);
                    *index.entry(key).or_insert_with(|| {
                        samples.push(at[&key]);
                        (samples.len() - 1) as u32
                    })
                });
                nodes[cell.node] = Node::Certified { points };
                stats.certified_cells += 1;
                area += (cell.size as f64 / per_cell as f64).powi(2);
            } else if cell.size > 4 && any_servable(cell, &at) {
                let first = nodes.len();
                nodes.extend([Node::Fallback; 4]);
                nodes[cell.node] = Node::Split {
                    first: first as u32,
                };
                let h = cell.size / 2;
                for (k, (di, dj)) in [(0, 0), (h, 0), (0, h), (h, h)].into_iter().enumerate() {
                    next.push(Cell {
                        i: cell.i + di,
                        j: cell.j + dj,
                        size: h,
                        node: first + k,
                    });
                }
            } else {
                stats.fallback_cells += 1;
            }
        }
        cells = next;
    }
    let computed = at.len() as u64 - seeded;
    stats.exact_samples += computed;
    stats.certified_area += area / (nt * nd) as f64;
    stats.built_cells += todo.len() as u64;
    Built {
        computed,
        thread_seconds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sixteenth of the ranked cells, 8 to 24 of them (all when fewer), at even strides from
    /// the shallowest to the deepest, each once.
    #[test]
    fn a_probe_spans_the_ranking_in_proportion() {
        assert!(probe_cells(&[]).is_empty());
        let five: Vec<usize> = (10..15).collect();
        assert_eq!(probe_cells(&five), five);
        for n in [9usize, 40, 129, 384, 1000] {
            let ranked: Vec<usize> = (0..n).rev().collect();
            let probe = probe_cells(&ranked);
            let k = n.div_ceil(16).clamp(8, CELLS_PER_BATCH);
            assert_eq!(probe.len(), k, "n {n}");
            let mut unique = probe.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(unique.len(), k, "n {n}: each once");
            // Positions in the ranking: one in each of k equal strides.
            let pos: Vec<usize> = probe.iter().map(|c| n - 1 - c).collect();
            let stride = n as f64 / k as f64;
            for (i, &p) in pos.iter().enumerate() {
                let (lo, hi) = (i as f64 * stride, (i + 1) as f64 * stride);
                assert!(
                    lo.floor() <= p as f64 && (p as f64) < hi,
                    "n {n}: pick {i} at {p}"
                );
            }
        }
    }
}
