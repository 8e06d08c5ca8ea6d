//! The certified map tier: a pin's whole push, tabulated over initial
//! orientation θ0 × contact parameter d for one (part, support, pin radius, μc, tolerance, travel
//! and evaluation budgets, grid), answered by interpolation where the table is certified and by the
//! exact model everywhere else, so that every answer is within 0.05° of exact or is exact.
//!
//! What a push gives the line (see `engine::contact`): whether it touched, its status class, the
//! final pose (rotation and centroid displacement), the travel before first touch, the travel to
//! the end of contact, and — only when something looks — the path. The tier tabulates, per sample
//! of (θ0, d), in units of a: the signed rotation, the centroid displacement (Δx, Δy) and the
//! contact span (pin travel from first touch to separation). The travel to first touch is not
//! tabulated: it is the exact first-contact ray cast ([`crate::mechanics::pin_first_touch`]),
//! cheap and kinked where the touching vertex changes. A query whose ray cast misses is answered
//! exactly (no contact) without the table.
//!
//! Grid and refinement ([`mod@build`]): θ0 ∈ [0, 2π) in `theta_cells` base cells, d ∈ [−r, r] with
//! r = (largest vertex radius + ρ)/a in `d_cells` base cells. A cell is **certified** when its 3 × 3
//! nodes (corners, edge midpoints, centre) and twelve check points (the quarter points inside and
//! on its edges) are all single, ok contacts ending on the same feature, and biquadratic
//! interpolation through the nodes reproduces the exact model at each check point within
//! `check_deg` (rotation) and `check_pos` (Δx, Δy, span, units of a) — a quarter of the promised
//! 0.05° by default. Otherwise the cell splits in four, down to `max_depth`; an
//! uncertified cell at the floor is a **fallback** cell, where the exact model answers. This is a
//! sampled certificate (a discontinuity island smaller than a cell and missed by all nine points
//! would go unseen by all 21 points), not a proof.
//!
//! Base cells are built on demand ([`build::extend`], [`load_or_build_cells`]): a single query
//! needs only its own cell, a scene the whole map ([`build()`]). A cell's quadtree and samples depend
//! on that cell alone, so an answer does not depend on which other cells are built; a query in a
//! cell not built yet is answered by the exact model ([`Fallback::Unbuilt`]).
//!
//! Cached on disk ([`cache`]) under a 128-bit hash of a canonical encoding of every input and of
//! the contact model's version ([`key`], [`crate::mechanics::MODEL_VERSION`]: a map an older
//! model built is rebuilt, not reused); the file carries a magic, a format version, the key and a checksum, so a stale or
//! corrupted file is refused and rebuilt. Building is deterministic (rayon, order-preserving) and
//! independent of the thread count.

pub mod build;
pub mod cache;
pub mod key;
pub mod lazy;
pub mod query;
pub mod report;

pub use build::{build, BuildForecast};
pub use cache::{
    default_cache_dir, load_or_build, load_or_build_cells, shared, shared_observed, CacheError,
    Loaded, Source,
};
pub use key::TierKey;
pub use lazy::LazyMap;

pub use query::{cell_of_query, push_with_map, Fallback};

use crate::mechanics::{ContactSettings, PartModel, Support};

/// Grid and certification settings of a map (part of its key).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TierSpec {
    /// Base cells over θ0 ∈ [0, 360°).
    pub theta_cells: u32,
    /// Base cells over d ∈ [−r, r].
    pub d_cells: u32,
    /// Largest number of halvings of a base cell.
    pub max_depth: u32,
    /// Largest interpolation error of the rotation at a check point (degrees).
    pub check_deg: f64,
    /// Largest interpolation error of Δx, Δy and span at a check point (units of a).
    pub check_pos: f64,
}

impl Default for TierSpec {
    fn default() -> Self {
        TierSpec {
            theta_cells: 36,
            d_cells: 12,
            max_depth: 4,
            check_deg: 0.0125,
            check_pos: 1e-3,
        }
    }
}

/// Everything a map depends on: the part (normalised polygon and support), the pin radius (the
/// caller's units, as the model takes it), the contact settings (μc, tolerance, budgets; μs and
/// the fidelity do not enter: μs scales forces only and the table is always of the exact model)
/// and the grid.
#[derive(Debug, Clone, Copy)]
pub struct TierInputs<'a> {
    /// The part's contact model (its normalised polygon and support).
    pub model: &'a PartModel,
    /// The part's support.
    pub support: &'a Support,
    /// Pin radius (the caller's units, as the model takes it).
    pub radius: f64,
    /// Contact settings (μc, tolerance, budgets).
    pub settings: ContactSettings,
    /// The map's grid.
    pub spec: TierSpec,
}

/// One exact sample of the push, in units of a.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Servable: an ok push with exactly one contact.
    pub servable: bool,
    /// The feature of the last segment (kind · 2¹⁶ + index), for servable samples.
    pub feature: u32,
    /// Signed rotation (radians).
    pub rotation: f64,
    /// Centroid displacement along the belt (units of a).
    pub dx: f64,
    /// Centroid displacement across the belt (units of a).
    pub dy: f64,
    /// Pin travel from first touch to separation (units of a).
    pub span: f64,
}

/// A node of a base cell's quadtree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Node {
    /// Split in four: children at `first`..`first + 4` (θ-low d-low, θ-high d-low, θ-low d-high,
    /// θ-high d-high).
    Split {
        /// Index of the first child in `TierMap::nodes`.
        first: u32,
    },
    /// Certified: interpolate through these 3 × 3 node samples (θ-major within each d row).
    Certified {
        /// Indices into `TierMap::samples`.
        points: [u32; 9],
    },
    /// Not certified at the finest level: the exact model answers here.
    Fallback,
    /// A base cell not built yet ([`build::extend`] builds base cells on demand: a single query
    /// needs only its own); the exact model answers a query here.
    Unbuilt,
}

/// How a map was built.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BuildStats {
    /// Exact pushes computed.
    pub exact_samples: u64,
    /// Certified leaves.
    pub certified_cells: u64,
    /// Fallback leaves (uncertified at the finest level).
    pub fallback_cells: u64,
    /// Fraction of the (θ0, d) rectangle covered by certified cells.
    pub certified_area: f64,
    /// Base cells built (of `theta_cells · d_cells`).
    pub built_cells: u64,
}

/// A built map: the base grid, the quadtrees (roots first, θ-major), the corner samples.
#[derive(Debug, Clone, PartialEq)]
pub struct TierMap {
    /// Hash of everything the map depends on (names its cache file).
    pub key: TierKey,
    /// The grid it was built on.
    pub spec: TierSpec,
    /// Half-width r of the d range (units of a).
    pub reach: f64,
    /// The quadtree nodes, roots first (θ-major).
    pub nodes: Vec<Node>,
    /// The exact samples the certified cells interpolate.
    pub samples: Vec<Sample>,
    /// How it was built.
    pub stats: BuildStats,
}

/// The base cell (θ-major index) holding (θ0 ∈ [0, 2π), d ∈ [−r, r]) on a grid of `spec` with
/// half-width `reach`, and the local coordinates (u, v) ∈ [0, 1]² in it; None outside the d range.
pub fn base_cell(spec: &TierSpec, reach: f64, theta: f64, d: f64) -> Option<(usize, f64, f64)> {
    let (nt, nd) = (spec.theta_cells as usize, spec.d_cells as usize);
    let ft = theta / std::f64::consts::TAU * nt as f64;
    let fd = (d + reach) / (2.0 * reach) * nd as f64;
    if !(ft >= 0.0 && fd >= 0.0 && fd <= nd as f64 && ft <= nt as f64) {
        return None;
    }
    let (it, id) = ((ft as usize).min(nt - 1), (fd as usize).min(nd - 1));
    Some((it * nd + id, ft - it as f64, fd - id as f64))
}

impl TierMap {
    /// An empty map of `inputs`: every base cell unbuilt.
    pub fn unbuilt(inputs: &TierInputs) -> TierMap {
        let roots = inputs.spec.theta_cells as usize * inputs.spec.d_cells as usize;
        TierMap {
            key: TierKey::of(inputs),
            spec: inputs.spec,
            reach: build::reach(inputs),
            nodes: vec![Node::Unbuilt; roots],
            samples: Vec::new(),
            stats: BuildStats::default(),
        }
    }

    /// Every base cell is built.
    pub fn is_complete(&self) -> bool {
        self.unbuilt_cells().next().is_none()
    }

    /// The base cells not built yet.
    pub fn unbuilt_cells(&self) -> impl Iterator<Item = usize> + '_ {
        let roots = self.spec.theta_cells as usize * self.spec.d_cells as usize;
        (0..roots).filter(|&r| self.nodes[r] == Node::Unbuilt)
    }

    /// Base cell `root` on its own ([`CellTree`]); None if it is not built.
    pub fn cell(&self, root: usize) -> Option<CellTree> {
        if self.nodes.get(root).is_none_or(|n| *n == Node::Unbuilt) {
            return None;
        }
        let mut cell = CellTree {
            nodes: vec![Node::Unbuilt],
            samples: Vec::new(),
            stats: BuildStats::default(),
        };
        copy_tree(
            (&self.nodes, &self.samples, root),
            (&mut cell.nodes, &mut cell.samples, 0),
        );
        // A cell's own statistics are known only when the map holds that cell alone.
        if self.stats.built_cells == 1 {
            cell.stats = self.stats;
        }
        Some(cell)
    }

    /// Take base cell `root` as `cell` holds it, if this map has not built it yet: its quadtree
    /// and samples are copied in (indices renumbered) and its build statistics added. Every query
    /// in the cell is then answered as `cell` answers it.
    pub fn adopt(&mut self, root: usize, cell: &CellTree) {
        if self.nodes.get(root) != Some(&Node::Unbuilt) || cell.nodes[0] == Node::Unbuilt {
            return;
        }
        copy_tree(
            (&cell.nodes, &cell.samples, 0),
            (&mut self.nodes, &mut self.samples, root),
        );
        let (st, add) = (&mut self.stats, &cell.stats);
        st.exact_samples += add.exact_samples;
        st.certified_cells += add.certified_cells;
        st.fallback_cells += add.fallback_cells;
        st.certified_area += add.certified_area;
        st.built_cells += 1;
    }

    /// The leaf holding (θ0 ∈ [0, 2π), d ∈ [−r, r]) and the local coordinates (u, v) ∈ [0, 1]² in
    /// it; None outside the d range.
    pub fn leaf(&self, theta: f64, d: f64) -> Option<(Node, f64, f64)> {
        let (root, u, v) = base_cell(&self.spec, self.reach, theta, d)?;
        Some(self.leaf_in(root, u, v))
    }

    /// The leaf of base cell `root` holding its local coordinates (u, v) ∈ [0, 1]², and the
    /// leaf's own.
    pub fn leaf_in(&self, root: usize, u: f64, v: f64) -> (Node, f64, f64) {
        descend(&self.nodes, root, u, v)
    }
}

/// One base cell of a map on its own: its quadtree (root first) and the samples its certified
/// leaves interpolate, with the statistics of its build. What a lazy map builds when a query first
/// falls in a cell ([`LazyMap`]), and what [`TierMap::adopt`] copies in.
#[derive(Debug, Clone, PartialEq)]
pub struct CellTree {
    /// The quadtree, root at 0.
    pub nodes: Vec<Node>,
    /// The samples of its certified leaves.
    pub samples: Vec<Sample>,
    /// How it was built.
    pub stats: BuildStats,
}

impl CellTree {
    /// The leaf holding the local coordinates (u, v) ∈ [0, 1]² of the cell, and the leaf's own.
    pub fn leaf(&self, u: f64, v: f64) -> (Node, f64, f64) {
        descend(&self.nodes, 0, u, v)
    }
}

/// From node `at` of a quadtree down to the leaf holding the local coordinates (u, v) ∈ [0, 1]²,
/// and the leaf's own coordinates.
fn descend(nodes: &[Node], at: usize, mut u: f64, mut v: f64) -> (Node, f64, f64) {
    let mut node = nodes[at];
    while let Node::Split { first } = node {
        let (hu, hv) = (usize::from(u >= 0.5), usize::from(v >= 0.5));
        u = 2.0 * u - hu as f64;
        v = 2.0 * v - hv as f64;
        node = nodes[first as usize + hu + 2 * hv];
    }
    (node, u, v)
}

/// Copy the quadtree under node `from.2` of (`from.0` nodes, `from.1` samples) into node `to.2` of
/// (`to.0`, `to.1`): children appended, samples appended once each, indices renumbered.
fn copy_tree(from: (&[Node], &[Sample], usize), to: (&mut Vec<Node>, &mut Vec<Sample>, usize)) {
    let ((src_nodes, src_samples, root), (nodes, samples, at)) = (from, to);
    let mut renumbered = std::collections::BTreeMap::new();
    // Depth-first: (node in the source, its slot here).
    let mut stack = vec![(root, at)];
    while let Some((src, dst)) = stack.pop() {
        nodes[dst] = match src_nodes[src] {
            Node::Split { first } => {
                let here = nodes.len();
                nodes.extend([Node::Fallback; 4]);
                for k in 0..4 {
                    stack.push((first as usize + k, here + k));
                }
                Node::Split { first: here as u32 }
            }
            Node::Certified { points } => Node::Certified {
                points: points.map(|i| {
                    *renumbered.entry(i).or_insert_with(|| {
                        samples.push(src_samples[i as usize]);
                        (samples.len() - 1) as u32
                    })
                }),
            },
            leaf => leaf,
        };
    }
}
