//! Sharding a study over machines (docs/cluster.md).
//!
//! * `--shard k/n` (k 0-based) runs global samples [⌊k·T/n⌋, ⌊(k+1)·T/n⌋) of T. With `--shard /n`
//!   (or `auto/n`) k comes from the batch scheduler: `SLURM_ARRAY_TASK_ID` (minus
//!   `SLURM_ARRAY_TASK_MIN` when set, so `--array=1-8` works too), else `JOB_COMPLETION_INDEX`
//!   (Kubernetes Indexed Jobs).
//! * A shard file is self-describing JSON: format tag and version, the study header (name, study
//!   and scenario hashes, seed, samples per point, sweep grid, pinfeed version), the shard's index
//!   and sample range, and per touched point the integer counts and the latency histogram
//!   serialised as HdrHistogram V2 (base64).
//! * It is written atomically ([`crate::output`]), so a killed job leaves either no shard file or a
//!   complete one.
//! * [`merge`] checks that the shards fit together (same format, pinfeed version, study hash, seed
//!   and grid; sample ranges that cover [0, T) exactly once; counts that add up to each range) and
//!   adds them exactly.

use super::tally::{add_count, latency_histogram, PointTally};
use super::{report::StudyHeader, StudyError};
use crate::engine::{OutcomeCounts, PartOutcome};
use base64::Engine as _;
use hdrhistogram::serialization::{Deserializer, Serializer, V2Serializer};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The format tag of a shard file.
pub const FORMAT: &str = "pinfeed-mc-shard";
/// The shard file format version.
pub const FORMAT_VERSION: u32 = 1;

/// Which shard to run: index k of n.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShardSpec {
    /// k, the 0-based index of this shard (k < n).
    pub index: u64,
    /// n, the number of shards.
    pub count: u64,
}

impl ShardSpec {
    /// Parse `k/n`, `/n` or `auto/n`; a missing k is read with `env` (the process environment in
    /// the CLI) from SLURM_ARRAY_TASK_ID (− SLURM_ARRAY_TASK_MIN) or JOB_COMPLETION_INDEX.
    pub fn parse(
        text: &str,
        env: &dyn Fn(&str) -> Option<String>,
    ) -> Result<ShardSpec, ShardSpecError> {
        let fail = |why: ShardWhy| ShardSpecError {
            text: text.to_string(),
            why,
        };
        let (k, n) = text.split_once('/').ok_or_else(|| fail(ShardWhy::Form))?;
        let count: u64 = n.trim().parse().map_err(|_| fail(ShardWhy::N))?;
        if count == 0 {
            return Err(fail(ShardWhy::NoShards));
        }
        let k = k.trim();
        let index = if k.is_empty() || k == "auto" {
            from_scheduler(env).map_err(fail)?
        } else {
            k.parse().map_err(|_| fail(ShardWhy::K))?
        };
        if index >= count {
            return Err(fail(ShardWhy::Index { index, count }));
        }
        Ok(ShardSpec { index, count })
    }

    /// The global sample range of this shard out of `total`.
    pub fn range(&self, total: u64) -> Range<u64> {
        let at = |k: u64| (k as u128 * total as u128 / self.count as u128) as u64;
        at(self.index)..at(self.index + 1)
    }

    /// The shard file's name: `shard-0003-of-0008.json`.
    pub fn file_name(&self) -> String {
        format!("shard-{:04}-of-{:04}.json", self.index, self.count)
    }
}

fn from_scheduler(env: &dyn Fn(&str) -> Option<String>) -> Result<u64, ShardWhy> {
    let num = |var: &'static str| -> Result<Option<u64>, ShardWhy> {
        match env(var) {
            None => Ok(None),
            Some(v) if v.trim().is_empty() => Ok(None),
            Some(v) => v
                .trim()
                .parse()
                .map(Some)
                .map_err(|_| ShardWhy::Variable { var, value: v }),
        }
    };
    if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
        let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
        return id.checked_sub(min).ok_or(ShardWhy::BelowMin { id, min });
    }
    if let Some(k) = num("JOB_COMPLETION_INDEX")? {
        return Ok(k);
    }
    Err(ShardWhy::NoIndex)
}

const SHARD_USAGE: &str = "write --shard K/N with 0 ≤ K < N (K 0-based), or --shard /N to take K from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX";

/// A `--shard` value that is refused ([`ShardSpec::parse`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--shard '{text}': {why}")]
pub struct ShardSpecError {
    /// The value given.
    pub text: String,
    /// What is wrong with it.
    pub why: ShardWhy,
}

/// What is wrong with a `--shard` value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShardWhy {
    /// No `/`.
    #[error("{SHARD_USAGE}")]
    Form,
    /// N is not a whole number.
    #[error("N must be a whole number; {SHARD_USAGE}")]
    N,
    /// N = 0.
    #[error("N must be at least 1")]
    NoShards,
    /// K is not a whole number.
    #[error("K must be a whole number; {SHARD_USAGE}")]
    K,
    /// K ≥ N.
    #[error("shard index {index} is out of range for {count} shards (K is 0-based: 0 to {})", count - 1)]
    Index {
        /// K.
        index: u64,
        /// N.
        count: u64,
    },
    /// A scheduler's variable that is not a whole number.
    #[error("{var}='{value}' is not a whole number")]
    Variable {
        /// The variable.
        var: &'static str,
        /// Its value.
        value: String,
    },
    /// SLURM_ARRAY_TASK_ID below SLURM_ARRAY_TASK_MIN.
    #[error("SLURM_ARRAY_TASK_ID ({id}) is below SLURM_ARRAY_TASK_MIN ({min})")]
    BelowMin {
        /// SLURM_ARRAY_TASK_ID.
        id: u64,
        /// SLURM_ARRAY_TASK_MIN.
        min: u64,
    },
    /// K left out and no scheduler's index set.
    #[error(
        "no shard index given and neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set"
    )]
    NoIndex,
}

/// One point's counts in a shard file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardPoint {
    /// Index of the sweep point (0-based).
    pub point: usize,
    /// Samples of this point run in this shard.
    pub samples: u64,
    /// Count per outcome class (every class listed).
    pub outcomes: BTreeMap<String, u64>,
    /// Pin encounters, summed over the samples.
    pub contacts: u64,
    /// Perturbed polygons redrawn because they were invalid.
    pub shape_redraws: u64,
    /// Other values redrawn because they left their domain.
    pub other_redraws: u64,
    /// Latency histogram (µs), HdrHistogram V2 serialisation, base64.
    pub latency_us_hdr_v2: String,
    /// Sensor readings and correct decisions; left out when 0 (a line without sensors writes
    /// the same shard files as before sensors existed).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sensor_readings: u64,
    /// Of those readings, the ones decided correctly.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub sensor_correct: u64,
    /// An online controller's counts; left out without decisions.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub online: super::online::OnlineTally,
    /// A closed loop: the passes its parts made, summed (left out on an open line).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub passes: u64,
}

fn is_zero<T: Default + PartialEq>(n: &T) -> bool {
    *n == T::default()
}

/// Which shard a file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardId {
    /// 0-based index of the shard (less than `count`).
    pub index: u64,
    /// Number of shards the study was split into.
    pub count: u64,
}

/// A shard file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardFile {
    /// [`crate::SCHEMA_VERSION`] and the version of the binary that wrote the shard (absent from
    /// shards written before they were added: such a file keeps its checksum and merges as before).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub schema_version: u32,
    /// Version of the binary that wrote the shard (empty in older shards).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub pinfeed_version: String,
    /// Always [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`] of the writer.
    pub format_version: u32,
    /// The study the shard belongs to: every shard of a merge must have the same one.
    pub header: StudyHeader,
    /// Which shard this file holds.
    pub shard: ShardId,
    /// Global sample range [start, end).
    pub samples: [u64; 2],
    /// Counts of each sweep point the shard's range touches.
    pub points: Vec<ShardPoint>,
    /// The study file's absolute path where the shard ran (empty when unknown, as in shards
    /// written before it was added): `merge`'s rerun commands name the study from wherever they
    /// are printed, not as the shard job named it (relative to its own folder).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub study_path: String,
    /// FNV-1a of the file's content with this field empty ([`ShardFile::content_checksum`]):
    /// `merge` refuses a shard whose content was edited or damaged. Not cryptographic: it catches
    /// hand edits and corruption, not a forger who recomputes it.
    #[serde(default)]
    pub checksum: String,
}

impl ShardFile {
    /// Build a shard file from the tallies of the points its range touches.
    pub fn new(
        header: &StudyHeader,
        spec: ShardSpec,
        range: Range<u64>,
        tallies: &BTreeMap<usize, PointTally>,
    ) -> ShardFile {
        let points = tallies
            .iter()
            .map(|(&point, t)| {
                let mut bytes = Vec::new();
                V2Serializer::new()
                    .serialize(&t.latency_us, &mut bytes)
                    .expect("serialising a histogram to memory cannot fail");
                ShardPoint {
                    point,
                    samples: t.samples,
                    // Every class of a line; `rejected` (a closed loop's) only when it happened,
                    // so that an open line's shard reads as before.
                    outcomes: PartOutcome::EVERY
                        .iter()
                        .filter(|&&c| c != PartOutcome::Rejected || t.outcomes.rejected > 0)
                        .map(|&c| (c.name().to_string(), t.outcomes.get(c)))
                        .collect(),
                    contacts: t.contacts,
                    shape_redraws: t.shape_redraws,
                    other_redraws: t.other_redraws,
                    latency_us_hdr_v2: base64::engine::general_purpose::STANDARD.encode(bytes),
                    sensor_readings: t.sensor_readings,
                    sensor_correct: t.sensor_correct,
                    online: t.online.clone(),
                    passes: t.passes,
                }
            })
            .collect();
        ShardFile {
            schema_version: crate::SCHEMA_VERSION,
            pinfeed_version: header.pinfeed_version.clone(),
            format: FORMAT.to_string(),
            format_version: FORMAT_VERSION,
            header: header.clone(),
            shard: ShardId {
                index: spec.index,
                count: spec.count,
            },
            samples: [range.start, range.end],
            points,
            study_path: String::new(),
            checksum: String::new(),
        }
        .sealed()
    }

    /// The same file recording where its study file is: `study` made absolute (symbolic links
    /// resolved when it exists), so that rerun commands work from any folder.
    pub fn with_study_path(mut self, study: &Path) -> ShardFile {
        let abs = std::fs::canonicalize(study)
            .or_else(|_| std::path::absolute(study))
            .unwrap_or_else(|_| study.to_path_buf());
        self.study_path = abs.display().to_string();
        self.sealed()
    }

    /// The study file as a path that works from the current folder: the recorded absolute path
    /// (relative when it lies under the current folder), else the study file as the shard job
    /// named it.
    pub fn study_path_here(&self) -> String {
        if self.study_path.is_empty() {
            return self.header.study_file.clone();
        }
        let abs = Path::new(&self.study_path);
        let here = std::env::current_dir().and_then(std::fs::canonicalize);
        match here.as_deref().map(|h| abs.strip_prefix(h)) {
            Ok(Ok(rel)) if !rel.as_os_str().is_empty() => rel.display().to_string(),
            _ => self.study_path.clone(),
        }
    }

    /// The checksum of the file's content: its JSON with `checksum` empty.
    pub fn content_checksum(&self) -> String {
        let bare = ShardFile {
            checksum: String::new(),
            ..self.clone()
        };
        let json = serde_json::to_string(&bare).expect("a shard serialises");
        super::hash::hex(super::hash::fnv1a(&[b"pinfeed-mc-shard", json.as_bytes()]))
    }

    /// The same file with its checksum set.
    fn sealed(mut self) -> ShardFile {
        self.checksum = self.content_checksum();
        self
    }
}

impl ShardPoint {
    /// The exact tally this point carries.
    fn tally(&self) -> Result<PointTally, ShardPointError> {
        let point = self.point;
        let mut outcomes = OutcomeCounts::default();
        for (name, &n) in &self.outcomes {
            let c = PartOutcome::EVERY
                .into_iter()
                .find(|c| c.name() == name)
                .ok_or_else(|| ShardPointError::UnknownOutcome(name.clone()))?;
            add_count(&mut outcomes, c, n);
        }
        if outcomes.total() != self.samples {
            return Err(ShardPointError::OutcomeTotal {
                point,
                total: outcomes.total(),
                samples: self.samples,
            });
        }
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(&self.latency_us_hdr_v2)
            .map_err(|error| ShardPointError::NotBase64 { point, error })?;
        let h: hdrhistogram::Histogram<u64> = Deserializer::new()
            .deserialize(&mut bytes.as_slice())
            .map_err(|error| ShardPointError::NotHdrHistogram { point, error })?;
        let mut latency_us = latency_histogram();
        latency_us
            .add(&h)
            .map_err(|error| ShardPointError::LatencyRange { point, error })?;
        if self.sensor_correct > self.sensor_readings {
            return Err(ShardPointError::SensorCorrect {
                point,
                correct: self.sensor_correct,
                readings: self.sensor_readings,
            });
        }
        self.online
            .check()
            .map_err(|error| ShardPointError::Online { point, error })?;
        if self.online.decisions > self.samples {
            return Err(ShardPointError::OnlineDecisions {
                point,
                decisions: self.online.decisions,
                samples: self.samples,
            });
        }
        Ok(PointTally {
            samples: self.samples,
            outcomes,
            contacts: self.contacts,
            shape_redraws: self.shape_redraws,
            other_redraws: self.other_redraws,
            latency_us,
            sensor_readings: self.sensor_readings,
            sensor_correct: self.sensor_correct,
            online: self.online.clone(),
            passes: self.passes,
        })
    }
}

/// Why a point of a shard file gives no tally: its counts do not hang together. Every message
/// but the unknown class's starts with `point N: `; the causes are in the messages, not sources,
/// so that they are printed once.
#[derive(Debug, thiserror::Error)]
pub enum ShardPointError {
    /// An outcome class no pinfeed outcome is named (holds the name).
    #[error("unknown outcome class `{0}`")]
    UnknownOutcome(String),
    /// The outcome counts do not add up to the point's samples.
    #[error("point {point}: the outcome counts add up to {total}, not to its {samples} samples")]
    OutcomeTotal {
        /// Index of the sweep point.
        point: usize,
        /// The sum of the outcome counts.
        total: u64,
        /// The point's samples.
        samples: u64,
    },
    /// The latency histogram is not base64.
    #[error("point {point}: latency histogram is not base64: {error}")]
    NotBase64 {
        /// Index of the sweep point.
        point: usize,
        /// The decoder's error.
        error: base64::DecodeError,
    },
    /// The latency histogram is not an HdrHistogram V2 serialisation.
    #[error("point {point}: latency histogram is not HdrHistogram V2: {error:?}")]
    NotHdrHistogram {
        /// Index of the sweep point.
        point: usize,
        /// The deserialiser's error.
        error: hdrhistogram::serialization::DeserializeError,
    },
    /// The latency histogram holds values outside the study's latency range.
    #[error("point {point}: latency histogram out of range: {error:?}")]
    LatencyRange {
        /// Index of the sweep point.
        point: usize,
        /// The histogram's error.
        error: hdrhistogram::errors::AdditionError,
    },
    /// More correct sensor decisions than readings.
    #[error("point {point}: {correct} correct sensor decisions out of {readings} readings")]
    SensorCorrect {
        /// Index of the sweep point.
        point: usize,
        /// Correct sensor decisions.
        correct: u64,
        /// Sensor readings.
        readings: u64,
    },
    /// The online controller's counts do not hang together.
    #[error("point {point}: {error}")]
    Online {
        /// Index of the sweep point.
        point: usize,
        /// What is wrong with them.
        error: super::online::OnlineTallyError,
    },
    /// More online decisions than samples.
    #[error("point {point}: {decisions} online decisions out of {samples} samples")]
    OnlineDecisions {
        /// Index of the sweep point.
        point: usize,
        /// The online controller's decisions.
        decisions: u64,
        /// The point's samples.
        samples: u64,
    },
}

/// Read a shard file.
pub fn read(path: &Path) -> Result<ShardFile, StudyError> {
    let text = crate::input::read_text(path)
        .map_err(|e| StudyError::Shard(format!("{}: cannot read: {e}", path.display())))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        StudyError::Shard(format!(
            "{}: not a pinfeed shard file (not JSON: {e})",
            path.display()
        ))
    })?;
    if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
        return Err(StudyError::Shard(format!(
            "{}: not a pinfeed shard file (no \"format\": \"{FORMAT}\")",
            path.display()
        )));
    }
    let v = value.get("format_version").and_then(|v| v.as_u64());
    if v != Some(FORMAT_VERSION as u64) {
        return Err(StudyError::Shard(format!(
            "{}: shard format version {} is not supported (this pinfeed reads version {FORMAT_VERSION})",
            path.display(),
            v.map_or("missing".to_string(), |v| v.to_string())
        )));
    }
    let stated = value.get("checksum").is_some();
    let file: ShardFile = serde_json::from_value(value)
        .map_err(|e| StudyError::Shard(format!("{}: malformed shard file: {e}", path.display())))?;
    check_checksum(path, &text, stated, &file)?;
    Ok(file)
}

/// Refuse a shard whose `checksum` field is missing, blank or not its content's
/// ([`ShardFile::content_checksum`]): every shard pinfeed writes carries it, so any of these means
/// the file was edited (its counts perhaps) or damaged after it was written. `text` is the file's
/// text, to give the field's line; `stated` says whether the field is there at all.
fn check_checksum(
    path: &Path,
    text: &str,
    stated: bool,
    file: &ShardFile,
) -> Result<(), StudyError> {
    let expected = file.content_checksum();
    if stated && file.checksum == expected {
        return Ok(());
    }
    // The checksum is the file's last top-level field: its line is the last `"checksum"` key.
    let at = match text.rfind("\"checksum\"") {
        Some(i) if stated => format!("{}:{}", path.display(), text[..i].matches('\n').count() + 1),
        _ => path.display().to_string(),
    };
    let what = if !stated {
        "is missing".to_string()
    } else if file.checksum.trim().is_empty() {
        "is blank".to_string()
    } else {
        format!("is {:?} but the content gives {expected}", file.checksum)
    };
    Err(StudyError::Shard(format!(
        "{at}: field `checksum` {what}: every shard pinfeed writes carries the checksum of its content, so the shard was edited or damaged after it was written (rerun it: {})",
        rerun_command(file, file.shard.index, file.shard.count, path)
    )))
}

/// The command that rewrites shard `k` of `n` of `file`'s study into the folder of `path`, from the
/// current folder.
fn rerun_command(file: &ShardFile, k: u64, n: u64, path: &Path) -> String {
    let h = &file.header;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    format!(
        "pinfeed mc {} --samples {} --shard {k}/{n} --out {} --quiet",
        file.study_path_here(),
        h.samples_per_point,
        dir.display()
    )
}

/// What to run when shards are missing: each missing shard of `n` (by the indices the given
/// files do not hold) as a `--shard K/N` command, and the Slurm `--array=` list of them.
fn missing_shards_help(files: &[(PathBuf, ShardFile)], total: u64) -> String {
    let (first_path, first) = &files[0];
    let n = first.shard.count;
    let have: std::collections::BTreeSet<u64> = files
        .iter()
        .filter(|(_, f)| f.shard.count == n)
        .map(|(_, f)| f.shard.index)
        .collect();
    let missing: Vec<u64> = (0..n)
        .filter(|k| !have.contains(k))
        .filter(|&k| {
            let r = ShardSpec { index: k, count: n }.range(total);
            r.start < r.end
        })
        .collect();
    if missing.is_empty() {
        return String::new();
    }
    let mut s = format!("\nrerun only the missing shards of {n}:\n");
    for &k in &missing {
        s += &format!("  {}\n", rerun_command(first, k, n, first_path));
    }
    let list: Vec<String> = missing.iter().map(u64::to_string).collect();
    // The array's task ids are the shard indices themselves (`--shard /N` would subtract
    // SLURM_ARRAY_TASK_MIN and run shard 0).
    let each = rerun_command(first, 0, n, first_path).replace(
        &format!("--shard 0/{n}"),
        &format!("--shard \\$SLURM_ARRAY_TASK_ID/{n}"),
    );
    s += &format!(
        "or as one Slurm array job:\n  sbatch --array={} --wrap \"{each}\"",
        list.join(",")
    );
    s
}

/// Check that the shards fit together and add them: the common header and each point's tally.
pub fn merge(files: &[(PathBuf, ShardFile)]) -> Result<(StudyHeader, Vec<PointTally>), StudyError> {
    let bad = |m: String| Err(StudyError::Shard(m));
    let Some((first_path, first)) = files.first() else {
        return bad("no shard files given".into());
    };
    let h0 = &first.header;
    let p0 = first_path.display();
    for (path, f) in &files[1..] {
        let h = &f.header;
        let p = path.display();
        for (field, a, b, why) in [
            (
                "scenario_hash",
                &h.scenario_hash,
                &h0.scenario_hash,
                ": they ran different scenarios or policy files",
            ),
            ("fidelity", &h.fidelity, &h0.fidelity, ""),
        ] {
            if a != b {
                return bad(format!(
                    "{p} and {p0} differ in field `{field}` ({a} vs {b}){why}"
                ));
            }
        }
        if h.pinfeed_version != h0.pinfeed_version {
            return bad(format!(
                "{p} was written by pinfeed {} but {p0} by pinfeed {}: shards must come from the same version",
                h.pinfeed_version, h0.pinfeed_version
            ));
        }
        if h.study_hash != h0.study_hash {
            return bad(format!(
                "{p} belongs to a different study than {p0} (study hash {} vs {}: the study file, its scenario or --samples differ)",
                h.study_hash, h0.study_hash
            ));
        }
        if h.seed != h0.seed || h.samples_per_point != h0.samples_per_point || h.points != h0.points
        {
            return bad(format!(
                "{p} and {p0} have the same study hash but a different seed, sample count or sweep grid"
            ));
        }
    }
    let total = h0.total_samples();
    let mut order: Vec<&(PathBuf, ShardFile)> = files.iter().collect();
    order.sort_by_key(|(_, f)| (f.samples[0], f.samples[1]));
    let mut covered = 0u64;
    let mut last: Option<&Path> = None;
    for (path, f) in &order {
        let [a, b] = f.samples;
        if a > b || b > total {
            return bad(format!(
                "{}: sample range [{a}, {b}) does not lie within the study's {total} samples",
                path.display()
            ));
        }
        if a == b {
            continue;
        }
        if a < covered {
            return bad(format!(
                "shards overlap: {} covers samples [{a}, {b}) but {} already covers up to {covered}",
                path.display(),
                last.map_or("another shard".into(), |p| p.display().to_string())
            ));
        }
        if a > covered {
            return bad(format!(
                "samples [{covered}, {a}) are missing: no shard covers them (the study has {total} samples; did a shard job fail?){}",
                missing_shards_help(files, total)
            ));
        }
        covered = b;
        last = Some(path);
    }
    if covered < total {
        return bad(format!(
            "samples [{covered}, {total}) are missing: no shard covers them (the study has {total} samples; did a shard job fail?){}",
            missing_shards_help(files, total)
        ));
    }
    let mut tallies: Vec<PointTally> = (0..h0.points.len())
        .map(|_| PointTally::default())
        .collect();
    let n = h0.samples_per_point;
    for (path, f) in &order {
        let [a, b] = f.samples;
        for sp in &f.points {
            let t = sp.tally().map_err(|error| StudyError::ShardPoint {
                path: path.clone(),
                error,
            })?;
            // The samples of this point inside the shard's range.
            let (lo, hi) = (sp.point as u64 * n, (sp.point as u64 + 1) * n);
            let expected = b.min(hi).saturating_sub(a.max(lo));
            if sp.point >= tallies.len() || t.samples != expected {
                return bad(format!(
                    "{}: point {} holds {} samples but the shard's range [{a}, {b}) gives it {expected}",
                    path.display(),
                    sp.point,
                    t.samples
                ));
            }
            tallies[sp.point]
                .merge(&t)
                .map_err(|error| StudyError::ShardMerge {
                    path: path.clone(),
                    error,
                })?;
        }
    }
    for (j, t) in tallies.iter().enumerate() {
        if t.samples != n {
            return bad(format!(
                "point {j} has {} samples after merging, expected {n}: a shard lacks the counts of its range",
                t.samples
            ));
        }
    }
    Ok((h0.clone(), tallies))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_of(vars: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let v: Vec<(String, String)> = vars
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
        move |k| v.iter().find(|(a, _)| a == k).map(|(_, b)| b.clone())
    }

    #[test]
    fn shard_spec_parses_and_takes_index_from_schedulers() {
        let none = env_of(&[]);
        assert_eq!(
            ShardSpec::parse("2/4", &none).unwrap(),
            ShardSpec { index: 2, count: 4 }
        );
        assert!(ShardSpec::parse("4/4", &none)
            .unwrap_err()
            .to_string()
            .contains("0-based"));
        assert!(ShardSpec::parse("1/0", &none).is_err());
        assert!(ShardSpec::parse("3", &none).is_err());
        assert!(ShardSpec::parse("/4", &none)
            .unwrap_err()
            .to_string()
            .contains("SLURM_ARRAY_TASK_ID"));
        let slurm = env_of(&[("SLURM_ARRAY_TASK_ID", "5"), ("SLURM_ARRAY_TASK_MIN", "1")]);
        assert_eq!(ShardSpec::parse("/8", &slurm).unwrap().index, 4);
        let k8s = env_of(&[("JOB_COMPLETION_INDEX", "3")]);
        assert_eq!(ShardSpec::parse("auto/8", &k8s).unwrap().index, 3);
        let junk = env_of(&[("JOB_COMPLETION_INDEX", "x")]);
        assert_eq!(
            ShardSpec::parse("/8", &junk).unwrap_err().to_string(),
            "--shard '/8': JOB_COMPLETION_INDEX='x' is not a whole number"
        );
        assert_eq!(
            ShardSpec::parse("3", &none).unwrap_err().to_string(),
            format!("--shard '3': {SHARD_USAGE}")
        );
    }

    #[test]
    fn ranges_partition_the_samples() {
        for total in [0u64, 1, 7, 1000, 1001] {
            for n in 1..=9u64 {
                let mut next = 0;
                for k in 0..n {
                    let r = ShardSpec { index: k, count: n }.range(total);
                    assert_eq!(r.start, next);
                    next = r.end;
                }
                assert_eq!(next, total);
            }
        }
    }
}
