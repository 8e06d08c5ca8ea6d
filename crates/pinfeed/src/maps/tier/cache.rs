//! Maps on disk: one file per key, `<dir>/<key>.pfmap`, written atomically (temp + rename).
//!
//! Layout (little-endian): magic `PINFEED-MAPTIER\n` (16 bytes), format version (u32), key (16
//! bytes), payload length (u64), payload, FNV-1a 64 checksum of everything before it (u64). The
//! payload is the grid (spec, reach), the build statistics, the nodes (a base cell not built yet is
//! an `Unbuilt` root) and the corner samples. A
//! file whose magic, version, key, length or checksum does not match is refused with a message
//! naming the file and the reason, and the map is rebuilt and written again.
//!
//! The directory: `--cache-dir`, else `$PINFEED_CACHE`, else `$XDG_CACHE_HOME/pinfeed/maps`, else
//! `$HOME/.cache/pinfeed/maps`, else `target/pinfeed-cache` ([`default_cache_dir`]).

use super::key::{fnv1a64, TierKey, BASIS, FORMAT_VERSION};
use super::{BuildStats, Node, Sample, TierInputs, TierMap, TierSpec};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

const MAGIC: &[u8; 16] = b"PINFEED-MAPTIER\n";

/// Why a cache file was not used.
#[derive(Debug, thiserror::Error)]
pub enum CacheError {
    /// The file exists but is corrupted, stale, or for another map; it is not used.
    #[error(
        "map cache file {path} is corrupted or stale ({reason}); it is refused and the map rebuilt"
    )]
    Refused {
        /// The cache file.
        path: PathBuf,
        /// What is wrong with it.
        reason: DecodeError,
    },
    /// The file could not be read or written.
    /// (The cause is in the message, not a `source`, so that it is printed once.)
    #[error("map cache file {path}: {error}")]
    Io {
        /// The cache file.
        path: PathBuf,
        /// Why it could not be read or written.
        error: std::io::Error,
    },
}

/// Why a cache file's bytes are refused ([`decode`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    /// Too short, or the magic bytes are not ours.
    #[error("not a pinfeed map file")]
    NotAMapFile,
    /// The stored checksum is not that of the bytes before it.
    #[error("checksum mismatch")]
    Checksum,
    /// Written by another format version.
    #[error("format version {found}, expected {expected}")]
    Version {
        /// The version in the file.
        found: u32,
        /// The version this build reads and writes.
        expected: u32,
    },
    /// The key in the file is not that of the inputs.
    #[error("its key does not match its inputs")]
    KeyMismatch,
    /// The stated payload length is not the number of bytes that follow.
    #[error("payload length mismatch")]
    PayloadLength,
    /// Bytes after the payload.
    #[error("trailing bytes")]
    TrailingBytes,
    /// The file ends before what it announces.
    #[error("truncated")]
    Truncated,
    /// A node tag that is none of split, certified, fallback, unbuilt.
    #[error("unknown node tag {0}")]
    NodeTag(u8),
    /// The grid is empty, has fewer nodes than base cells, or its reach is not positive.
    #[error("inconsistent grid")]
    Grid,
    /// A node or corner index points outside the map.
    #[error("a node points outside the map")]
    Link,
}

/// Where a map came from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// Already in this process.
    Memory,
    /// Read from a cache file.
    Disk(PathBuf),
    /// Built now (`cells` base cells, added to those a cache file held), in `seconds`.
    Built {
        /// Wall time of the build (s).
        seconds: f64,
        /// Base cells built now.
        cells: u64,
        /// What was forecast for the build after its probe (none for a build of one batch).
        forecast: Option<super::build::BuildForecast>,
    },
}

/// A map ready for use, where it came from, and what went wrong on the way (a refused file, a
/// file that could not be written): never fatal.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The map.
    pub map: Arc<TierMap>,
    /// Where it came from.
    pub source: Source,
    /// Its cache file (None without a cache folder).
    pub file: Option<PathBuf>,
    /// What went wrong on the way (a refused or unwritable file), in words; never fatal.
    pub warnings: Vec<String>,
}

/// The default cache directory (see the module docs).
pub fn default_cache_dir() -> PathBuf {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(d) = env("PINFEED_CACHE") {
        return d;
    }
    if let Some(d) = env("XDG_CACHE_HOME") {
        return d.join("pinfeed").join("maps");
    }
    if let Some(d) = env("HOME") {
        return d.join(".cache").join("pinfeed").join("maps");
    }
    PathBuf::from("target").join("pinfeed-cache")
}

/// The file of a key in `dir`.
pub fn file_of(dir: &Path, key: &TierKey) -> PathBuf {
    dir.join(format!("{key}.pfmap"))
}

/// Read the map of `inputs` from `dir` if a valid file is there, else build it and write it
/// (`dir` None: build, no file). The whole map: every base cell.
pub fn load_or_build(inputs: &TierInputs, dir: Option<&Path>) -> Loaded {
    load_or_build_cells(inputs, dir, None, &crate::progress::silent)
}

/// [`load_or_build`] for the base cells `cells` only (None: all): a file that holds them is
/// used as it is; otherwise the missing ones are built into the map the file holds (or into an
/// empty map) and the file is written again. A query in a built cell gets the same answer
/// whichever other cells are built ([`super::build::extend`]). `progress` is told the base cells
/// built of those missing.
pub fn load_or_build_cells(
    inputs: &TierInputs,
    dir: Option<&Path>,
    cells: Option<&[usize]>,
    progress: crate::progress::Report,
) -> Loaded {
    let key = TierKey::of(inputs);
    let mut warnings = Vec::new();
    let file = dir.map(|d| file_of(d, &key));
    let mut map = None;
    if let Some(path) = &file {
        if path.exists() {
            match read(path, &key) {
                Ok(m) => map = Some((m, path.clone())),
                Err(e) => warnings.push(e.to_string()),
            }
        }
    }
    let (mut map, from) = match map {
        Some((m, path)) => (m, Some(path)),
        None => (TierMap::unbuilt(inputs), None),
    };
    // Each cell once, however many queries fall in it.
    let wanted: Vec<usize> = match cells {
        Some(c) => c
            .iter()
            .copied()
            .filter(|&r| map.nodes.get(r) == Some(&Node::Unbuilt))
            .collect::<BTreeSet<usize>>()
            .into_iter()
            .collect(),
        None => map.unbuilt_cells().collect(),
    };
    if let (true, Some(path)) = (wanted.is_empty(), from) {
        return Loaded {
            map: Arc::new(map),
            source: Source::Disk(path),
            file,
            warnings,
        };
    }
    let started = Instant::now();
    let forecast = super::build::extend_observed(&mut map, inputs, &wanted, progress);
    let seconds = started.elapsed().as_secs_f64();
    if let Some(path) = &file {
        if let Err(e) = write(path, &map) {
            warnings.push(e.to_string());
        }
    }
    Loaded {
        map: Arc::new(map),
        source: Source::Built {
            seconds,
            cells: wanted.len() as u64,
            forecast,
        },
        file,
        warnings,
    }
}

/// [`load_or_build`], remembered in this process by key (a map is built or read once per run).
pub fn shared(inputs: &TierInputs, dir: Option<&Path>) -> Loaded {
    shared_observed(inputs, dir, &crate::progress::silent)
}

/// [`shared`], telling `progress` the base cells built of those missing.
pub fn shared_observed(
    inputs: &TierInputs,
    dir: Option<&Path>,
    progress: crate::progress::Report,
) -> Loaded {
    static MEMO: OnceLock<Mutex<BTreeMap<TierKey, Arc<TierMap>>>> = OnceLock::new();
    let memo = MEMO.get_or_init(|| Mutex::new(BTreeMap::new()));
    let key = TierKey::of(inputs);
    if let Some(map) = memo.lock().expect("map memo").get(&key) {
        return Loaded {
            map: map.clone(),
            source: Source::Memory,
            file: dir.map(|d| file_of(d, &key)),
            warnings: Vec::new(),
        };
    }
    let loaded = load_or_build_cells(inputs, dir, None, progress);
    memo.lock()
        .expect("map memo")
        .insert(key, loaded.map.clone());
    loaded
}

/// Write `map` to `path` atomically.
pub fn write(path: &Path, map: &TierMap) -> Result<(), CacheError> {
    let io = |error| CacheError::Io {
        path: path.to_path_buf(),
        error,
    };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    // Whole or not at all; a failed write leaves no temporary file behind.
    crate::output::write_atomic(path, encode(map)).map_err(io)
}

/// Read the map with key `key` from `path`, refusing anything that does not check out.
pub fn read(path: &Path, key: &TierKey) -> Result<TierMap, CacheError> {
    let bytes = crate::input::read_bounded(path, crate::input::MAP_CAP).map_err(|error| {
        CacheError::Io {
            path: path.to_path_buf(),
            error,
        }
    })?;
    decode(&bytes, key).map_err(|reason| CacheError::Refused {
        path: path.to_path_buf(),
        reason,
    })
}

/// The file's bytes.
pub fn encode(map: &TierMap) -> Vec<u8> {
    let mut p = Writer(Vec::new());
    let s = &map.spec;
    p.u32(s.theta_cells);
    p.u32(s.d_cells);
    p.u32(s.max_depth);
    p.f64(s.check_deg);
    p.f64(s.check_pos);
    p.f64(map.reach);
    let st = &map.stats;
    p.u64(st.exact_samples);
    p.u64(st.certified_cells);
    p.u64(st.fallback_cells);
    p.f64(st.certified_area);
    p.u64(st.built_cells);
    p.u64(map.nodes.len() as u64);
    for n in &map.nodes {
        let (tag, v) = match *n {
            Node::Split { first } => (0u8, [first, 0, 0, 0, 0, 0, 0, 0, 0]),
            Node::Certified { points } => (1, points),
            Node::Fallback => (2, [0; 9]),
            Node::Unbuilt => (3, [0; 9]),
        };
        p.0.push(tag);
        v.iter().for_each(|&x| p.u32(x));
    }
    p.u64(map.samples.len() as u64);
    for s in &map.samples {
        p.0.push(u8::from(s.servable));
        p.u32(s.feature);
        [s.rotation, s.dx, s.dy, s.span]
            .iter()
            .for_each(|&x| p.f64(x));
    }
    let payload = p.0;
    let mut out = Writer(MAGIC.to_vec());
    out.u32(FORMAT_VERSION);
    out.0.extend_from_slice(&map.key.0);
    out.u64(payload.len() as u64);
    out.0.extend_from_slice(&payload);
    let sum = fnv1a64(&out.0, BASIS);
    out.u64(sum);
    out.0
}

/// Parse a file's bytes (the reason it is refused, if it is).
pub fn decode(bytes: &[u8], key: &TierKey) -> Result<TierMap, DecodeError> {
    if bytes.len() < 16 + 4 + 16 + 8 + 8 || &bytes[..16] != MAGIC {
        return Err(DecodeError::NotAMapFile);
    }
    let (body, sum) = bytes.split_at(bytes.len() - 8);
    if fnv1a64(body, BASIS).to_le_bytes() != sum {
        return Err(DecodeError::Checksum);
    }
    let mut r = Reader(&body[16..]);
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(DecodeError::Version {
            found: version,
            expected: FORMAT_VERSION,
        });
    }
    if r.take(16)? != key.0 {
        return Err(DecodeError::KeyMismatch);
    }
    let len = r.u64()? as usize;
    if len != r.0.len() {
        return Err(DecodeError::PayloadLength);
    }
    let map = payload(&mut r, *key)?;
    if !r.0.is_empty() {
        return Err(DecodeError::TrailingBytes);
    }
    Ok(map)
}

fn payload(r: &mut Reader, key: TierKey) -> Result<TierMap, DecodeError> {
    let spec = TierSpec {
        theta_cells: r.u32()?,
        d_cells: r.u32()?,
        max_depth: r.u32()?,
        check_deg: r.f64()?,
        check_pos: r.f64()?,
    };
    let reach = r.f64()?;
    let stats = BuildStats {
        exact_samples: r.u64()?,
        certified_cells: r.u64()?,
        fallback_cells: r.u64()?,
        certified_area: r.f64()?,
        built_cells: r.u64()?,
    };
    let n_nodes = r.count(37)?;
    let mut nodes = Vec::with_capacity(n_nodes);
    for _ in 0..n_nodes {
        let tag = r.take(1)?[0];
        let mut v = [0u32; 9];
        for x in &mut v {
            *x = r.u32()?;
        }
        nodes.push(match tag {
            0 => Node::Split { first: v[0] },
            1 => Node::Certified { points: v },
            2 => Node::Fallback,
            3 => Node::Unbuilt,
            t => return Err(DecodeError::NodeTag(t)),
        });
    }
    let n_samples = r.count(37)?;
    let mut samples = Vec::with_capacity(n_samples);
    for _ in 0..n_samples {
        let servable = r.take(1)?[0] != 0;
        let feature = r.u32()?;
        let [rotation, dx, dy, span] = [r.f64()?, r.f64()?, r.f64()?, r.f64()?];
        samples.push(Sample {
            servable,
            feature,
            rotation,
            dx,
            dy,
            span,
        });
    }
    let map = TierMap {
        key,
        spec,
        reach,
        nodes,
        samples,
        stats,
    };
    check_links(&map)?;
    Ok(map)
}

/// Every node and corner index points inside the map, and the base grid is there.
fn check_links(map: &TierMap) -> Result<(), DecodeError> {
    let roots = map.spec.theta_cells as usize * map.spec.d_cells as usize;
    if roots == 0 || map.nodes.len() < roots || !(map.reach > 0.0 && map.reach.is_finite()) {
        return Err(DecodeError::Grid);
    }
    let ok = map.nodes.iter().enumerate().all(|(i, n)| match *n {
        Node::Split { first } => (first as usize) > i && first as usize + 4 <= map.nodes.len(),
        Node::Certified { points } => points.iter().all(|&c| (c as usize) < map.samples.len()),
        Node::Fallback => true,
        Node::Unbuilt => i < roots,
    });
    if ok {
        Ok(())
    } else {
        Err(DecodeError::Link)
    }
}

struct Writer(Vec<u8>);

impl Writer {
    fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }
}

struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], DecodeError> {
        if self.0.len() < n {
            return Err(DecodeError::Truncated);
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }
    fn u32(&mut self) -> Result<u32, DecodeError> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64, DecodeError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64(&mut self) -> Result<f64, DecodeError> {
        Ok(f64::from_bits(self.u64()?))
    }
    /// A count of items of `size` bytes each that must fit in what is left.
    fn count(&mut self, size: usize) -> Result<usize, DecodeError> {
        let n = self.u64()? as usize;
        if n.checked_mul(size).is_none_or(|b| b > self.0.len()) {
            return Err(DecodeError::Truncated);
        }
        Ok(n)
    }
}
