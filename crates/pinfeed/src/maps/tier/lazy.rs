//! A map whose base cells are built when a query first falls in them: what a line on the map
//! tier uses, so that it builds only the cells its parts reach.
//!
//! A line's pushes cover a small part of a map's θ0 × d rectangle (the feed's lateral spread, and
//! downstream of the first pin the few orientations the pins before it leave), so building every
//! base cell before the run computes pushes no part will ask for. A [`LazyMap`] starts from the
//! map a cache file holds (or from an empty one) and builds a missing base cell the first time a
//! query falls in it, exactly as a whole-map build would (a cell's quadtree and samples depend on
//! that cell alone, [`super::build::extend`]): every answer is the one the whole map gives, and
//! the line's output does not depend on which cells were built before or by which thread. The
//! cells built are written back to the cache after the run ([`LazyMap::merged`]), so later runs
//! find them.

use super::query::answer_from;
use super::{base_cell, build, CellTree, Fallback, Loaded, Node, TierInputs, TierKey, TierMap};
use crate::geometry::{Pose, Vec2};
use crate::mechanics::{ContactOutcome, PartModel};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

/// A map that builds its missing base cells on first use (see the module docs).
pub struct LazyMap {
    /// The map as loaded (every cell, some, or none built).
    map: Arc<TierMap>,
    /// Its cache file (None: kept in memory only).
    file: Option<PathBuf>,
    /// Base cells built in this process, each on its own (a few kB each, whatever the grid).
    cells: Vec<OnceLock<CellTree>>,
    /// The model the cells are built with (stick tables, shared by every cell).
    tabled: OnceLock<PartModel>,
    /// Cells built in this process, and their build's wall time summed (ns).
    built: AtomicU64,
    build_ns: AtomicU64,
    /// Cells built in this process when the map was last written to its file.
    written: Mutex<u64>,
}

impl LazyMap {
    /// A lazy map over `map`, whose cache file is `file`.
    pub fn new(map: Arc<TierMap>, file: Option<PathBuf>) -> LazyMap {
        let cells = (0..map.spec.theta_cells as usize * map.spec.d_cells as usize)
            .map(|_| OnceLock::new())
            .collect();
        LazyMap {
            map,
            file,
            cells,
            tabled: OnceLock::new(),
            built: AtomicU64::new(0),
            build_ns: AtomicU64::new(0),
            written: Mutex::new(0),
        }
    }

    /// The map as it was loaded (without the cells built since).
    pub fn loaded(&self) -> &TierMap {
        &self.map
    }

    /// Its key.
    pub fn key(&self) -> TierKey {
        self.map.key
    }

    /// Its cache file.
    pub fn file(&self) -> Option<&PathBuf> {
        self.file.as_ref()
    }

    /// Base cells built in this process, and the wall time their builds took (s).
    pub fn built_now(&self) -> (u64, f64) {
        (
            self.built.load(Ordering::Relaxed),
            self.build_ns.load(Ordering::Relaxed) as f64 * 1e-9,
        )
    }

    /// [`TierMap::answer`], building the query's base cell first if neither the loaded map nor
    /// this process has built it (only for a query that reaches a cell: a miss or a pin inside the
    /// part is answered first, once). `inputs` must be the map's (its key is checked in debug
    /// builds).
    pub fn answer(
        &self,
        inputs: &TierInputs,
        pose: Pose,
        pin_start: Vec2,
    ) -> Result<ContactOutcome, Fallback> {
        let map = &*self.map;
        answer_from(inputs.model, pose, pin_start, inputs.radius, |theta, d| {
            let (root, u, v) = base_cell(&map.spec, map.reach, theta, d)?;
            if map.nodes[root] != Node::Unbuilt {
                let (node, u, v) = map.leaf_in(root, u, v);
                return Some((node, u, v, map.samples.as_slice()));
            }
            let cell = self.cells[root].get_or_init(|| self.build_cell(inputs, root));
            let (node, u, v) = cell.leaf(u, v);
            Some((node, u, v, cell.samples.as_slice()))
        })
    }

    /// Base cell `root` built alone.
    fn build_cell(&self, inputs: &TierInputs, root: usize) -> CellTree {
        debug_assert_eq!(TierKey::of(inputs), self.map.key, "inputs of another map");
        let started = Instant::now();
        let model = self.tabled.get_or_init(|| build::tabled_model(inputs));
        let inputs = TierInputs { model, ..*inputs };
        // Built in a map of its own (the build indexes cells by their place in the grid), then
        // kept alone: the map's other roots are not held per cell.
        let mut map = TierMap::unbuilt(&inputs);
        build::build_cell_here(&mut map, &inputs, root);
        let cell = map.cell(root).expect("the cell was just built");
        self.built.fetch_add(1, Ordering::Relaxed);
        self.build_ns
            .fetch_add(started.elapsed().as_nanos() as u64, Ordering::Relaxed);
        cell
    }

    /// The loaded map with every cell built since adopted ([`TierMap::adopt`]); None when no
    /// cell was built.
    pub fn merged(&self) -> Option<TierMap> {
        if self.built.load(Ordering::Relaxed) == 0 {
            return None;
        }
        let mut map = (*self.map).clone();
        for (root, cell) in self.cells.iter().enumerate() {
            if let Some(cell) = cell.get() {
                map.adopt(root, cell);
            }
        }
        Some(map)
    }

    /// Write the map with the cells built in this process to its cache file, if it has one and
    /// cells were built since the last attempt: the file written, or None. A write that fails is
    /// not tried again for the same cells (its error is returned once).
    pub fn persist(&self) -> Result<Option<PathBuf>, super::CacheError> {
        let mut written = self.written.lock().expect("lazy map write");
        let built = self.built.load(Ordering::Relaxed);
        let (Some(path), true) = (&self.file, built > *written) else {
            return Ok(None);
        };
        let Some(merged) = self.merged() else {
            return Ok(None);
        };
        *written = built;
        super::cache::write(path, &merged)?;
        Ok(Some(path.clone()))
    }

    /// Base cells built, in the loaded map or since, of all.
    pub fn cells_built(&self) -> (u64, u64) {
        let roots = self.cells.len();
        let built = (0..roots)
            .filter(|&r| self.map.nodes[r] != Node::Unbuilt || self.cells[r].get().is_some())
            .count();
        (built as u64, roots as u64)
    }
}

/// The lazy maps of this process, by key: a line's map tier and every later line share one.
fn memo() -> &'static Mutex<BTreeMap<TierKey, Arc<LazyMap>>> {
    static MEMO: OnceLock<Mutex<BTreeMap<TierKey, Arc<LazyMap>>>> = OnceLock::new();
    MEMO.get_or_init(|| Mutex::new(BTreeMap::new()))
}

/// The lazy map of `inputs` in this process, if a line or [`lazy_shared`] made one.
pub fn existing(inputs: &TierInputs) -> Option<Arc<LazyMap>> {
    let key = TierKey::of(inputs);
    memo().lock().expect("lazy map memo").get(&key).cloned()
}

/// The lazy map of `inputs` in this process; on first use, over the map the cache folder `dir`
/// holds (read, never built: a file refused is reported in the warnings and the map starts
/// empty), or over an empty map without a folder.
pub fn lazy_shared(
    inputs: &TierInputs,
    dir: Option<&std::path::Path>,
) -> (Arc<LazyMap>, Vec<String>) {
    let key = TierKey::of(inputs);
    let mut memo = memo().lock().expect("lazy map memo");
    if let Some(m) = memo.get(&key) {
        return (m.clone(), Vec::new());
    }
    let file = dir.map(|d| super::cache::file_of(d, &key));
    let mut warnings = Vec::new();
    let map = match &file {
        Some(path) if path.exists() => match super::cache::read(path, &key) {
            Ok(m) => m,
            Err(e) => {
                warnings.push(e.to_string());
                TierMap::unbuilt(inputs)
            }
        },
        _ => TierMap::unbuilt(inputs),
    };
    let lazy = Arc::new(LazyMap::new(Arc::new(map), file));
    memo.insert(key, lazy.clone());
    (lazy, warnings)
}

/// Forget every lazy map of this process (their memory is freed once no line holds them): the
/// cells built and not yet written ([`persist_all`]) are lost. The next line starts from what the
/// cache holds — for a long-running program done with its maps, or a measurement from scratch.
pub fn forget_all() {
    memo().lock().expect("lazy map memo").clear();
}

/// Make `loaded` (a map built or read whole) the lazy map of its key in this process: it
/// replaces one there only if it is complete (a cell's content does not depend on where it was
/// built, so nothing is lost).
pub fn register(loaded: &Loaded) -> Arc<LazyMap> {
    let mut memo = memo().lock().expect("lazy map memo");
    let key = loaded.map.key;
    if let Some(m) = memo.get(&key) {
        if !loaded.map.is_complete() {
            return m.clone();
        }
    }
    let lazy = Arc::new(LazyMap::new(loaded.map.clone(), loaded.file.clone()));
    memo.insert(key, lazy.clone());
    lazy
}

/// [`LazyMap::persist`] for every lazy map of this process (a command's last step, so that the
/// cells its lines built are found by the next): the files that could not be written, in words.
pub fn persist_all() -> Vec<String> {
    let maps: Vec<Arc<LazyMap>> = memo()
        .lock()
        .expect("lazy map memo")
        .values()
        .cloned()
        .collect();
    maps.iter()
        .filter_map(|m| m.persist().err().map(|e| e.to_string()))
        .collect()
}
