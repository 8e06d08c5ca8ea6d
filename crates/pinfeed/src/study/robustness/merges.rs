//! Merge tampering: the three shards of a small study (studies/quickstart_mu_tripod.toml, 3
//! samples per point, run once per fuzzing run with `mc --shard K/3`'s code), with one or two
//! edits ([`Tamper`]): a number or a string of the JSON changed (outcome counts, contacts,
//! latency histograms, sample ranges, hashes, the version, the checksum, …), two values swapped
//! between points or shards, a field deleted or added, a shard left out or given twice, the text
//! truncated or replaced. The shards are written to a folder and merged as `pinfeed merge`
//! does ([`crate::study::mc::shard::read`], [`crate::study::mc::shard::merge`]). A merge that
//! succeeds though the content differs from what was written counts as an accepted edit; an
//! untouched set must merge.

use super::{refused, CaseReport, Class};
use crate::random::ChaCha8Rng;
use crate::study::mc::{self, shard};
use rand::RngExt;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// What a case of the merges target is (in the fuzz report).
pub const DESCRIPTION: &str = "the three shards of studies/quickstart_mu_tripod.toml (3 samples per point) with 1–2 edits: a number or string of the JSON changed (counts, contacts, histograms, sample ranges, hashes, version, checksum), values swapped between points or shards, a field deleted or added, a shard left out or given twice, the text truncated or replaced; written to disk and merged as `pinfeed merge` does";

/// Shards of the study.
pub const SHARDS: u64 = 3;

/// Why the study's shards could not be made ([`make_shards`]).
#[derive(Debug, thiserror::Error)]
pub enum ShardsError {
    /// The study could not be loaded or run.
    #[error(transparent)]
    Study(#[from] mc::StudyError),
    /// A shard could not be written as JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// The shards of the study: (file name, JSON text).
pub fn make_shards(root: &Path) -> Result<Vec<(String, String)>, ShardsError> {
    let path = root.join("studies/quickstart_mu_tripod.toml");
    let study = mc::load(&path, Some(3))?;
    let header = mc::report::StudyHeader::of(&study);
    let total = study.total_samples();
    (0..SHARDS)
        .map(|k| {
            let spec = shard::ShardSpec {
                index: k,
                count: SHARDS,
            };
            let range = spec.range(total);
            let tallies = mc::run::run_range_with_threads(&study, range.clone(), Some(1), &|| {})?;
            let file = shard::ShardFile::new(&header, spec, range, &tallies);
            let text = serde_json::to_string_pretty(&file)? + "\n";
            Ok((spec.file_name(), text))
        })
        .collect()
}

/// One edit of the shard set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tamper {
    /// Change leaf `leaf` (numbers and strings, in document order) of shard `shard`.
    Leaf {
        /// Index of the shard (modulo their number).
        shard: usize,
        /// Index of the leaf in document order (modulo their number).
        leaf: usize,
        /// Picks the change.
        how: usize,
    },
    /// Swap leaves `a` and `b` (of shards `sa` and `sb`).
    Swap {
        /// Shard of the first leaf.
        sa: usize,
        /// First leaf, in document order.
        a: usize,
        /// Shard of the second leaf.
        sb: usize,
        /// Second leaf, in document order.
        b: usize,
    },
    /// Delete the object member holding leaf `leaf`.
    Delete {
        /// Index of the shard (modulo their number).
        shard: usize,
        /// Index of the leaf in document order (modulo their number).
        leaf: usize,
    },
    /// Add a member `extra` next to leaf `leaf`.
    Add {
        /// Index of the shard (modulo their number).
        shard: usize,
        /// Index of the leaf in document order (modulo their number).
        leaf: usize,
    },
    /// Leave shard `shard` out.
    Missing {
        /// Index of the shard (modulo their number).
        shard: usize,
    },
    /// Give shard `shard` twice.
    Twice {
        /// Index of the shard (modulo their number).
        shard: usize,
    },
    /// Keep the first `permille`/1000 of shard `shard`'s text.
    Truncate {
        /// Index of the shard (modulo their number).
        shard: usize,
        /// Thousandths of the text kept, in [0, 1000).
        permille: u32,
    },
    /// Replace shard `shard`'s text by `{}` or an empty file.
    Replace {
        /// Index of the shard (modulo their number).
        shard: usize,
        /// An empty file rather than `{}`.
        empty: bool,
    },
}

impl Tamper {
    fn random(rng: &mut ChaCha8Rng) -> Tamper {
        let shard = rng.random_range(0..SHARDS as usize);
        let leaf = rng.random_range(0..100_000usize);
        match rng.random_range(0..16u32) {
            0..=7 => Tamper::Leaf {
                shard,
                leaf,
                how: rng.random_range(0..16),
            },
            8 | 9 => Tamper::Swap {
                sa: shard,
                a: leaf,
                sb: rng.random_range(0..SHARDS as usize),
                b: rng.random_range(0..100_000),
            },
            10 => Tamper::Delete { shard, leaf },
            11 => Tamper::Add { shard, leaf },
            12 => Tamper::Missing { shard },
            13 => Tamper::Twice { shard },
            14 => Tamper::Truncate {
                shard,
                permille: rng.random_range(0..1000),
            },
            _ => Tamper::Replace {
                shard,
                empty: rng.random::<bool>(),
            },
        }
    }
}

/// Paths (JSON pointers) of the number and string leaves of `v`, in document order.
fn leaves(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                leaves(
                    x,
                    format!("{at}/{}", k.replace('~', "~0").replace('/', "~1")),
                    out,
                );
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                leaves(x, format!("{at}/{i}"), out);
            }
        }
        Value::Number(_) | Value::String(_) | Value::Bool(_) => out.push(at),
        Value::Null => {}
    }
}

/// A changed value for a leaf (`how` picks the change).
fn changed(v: &Value, how: usize) -> Value {
    match v {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(0.0);
            let options = [
                serde_json::json!(x + 1.0),
                serde_json::json!(x - 1.0),
                serde_json::json!(0),
                serde_json::json!(1e12),
                serde_json::json!(-1),
                serde_json::json!(x * 2.0),
                serde_json::json!(u64::MAX),
                serde_json::json!(0.5),
                serde_json::json!("7"),
                Value::Null,
            ];
            options[how % options.len()].clone()
        }
        Value::String(s) => {
            let mut flipped = s.clone();
            if let Some(c) = flipped.pop() {
                flipped.push(if c == 'a' { 'b' } else { 'a' });
            }
            let options = [
                Value::String(flipped),
                Value::String(String::new()),
                Value::String(format!("{s}0")),
                serde_json::json!(0),
                Value::String("0.0.0".into()),
            ];
            options[how % options.len()].clone()
        }
        Value::Bool(b) => Value::Bool(!b),
        _ => Value::Null,
    }
}

/// The shard set after the edits: (file name, text, content as JSON when it is JSON).
fn tampered(shards: &[(String, String)], edits: &[Tamper]) -> Vec<(String, String, Option<Value>)> {
    let mut set: Vec<(String, String, Option<Value>)> = shards
        .iter()
        .map(|(n, t)| (n.clone(), t.clone(), serde_json::from_str(t).ok()))
        .collect();
    let leaf_of = |set: &Vec<(String, String, Option<Value>)>, s: usize, leaf: usize| {
        let v = set.get(s)?.2.as_ref()?;
        let mut l = Vec::new();
        leaves(v, String::new(), &mut l);
        (!l.is_empty()).then(|| l[leaf % l.len()].clone())
    };
    for &e in edits {
        let n = set.len().max(1);
        match e {
            Tamper::Leaf { shard, leaf, how } => {
                let s = shard % n;
                if let Some(p) = leaf_of(&set, s, leaf) {
                    if let Some(x) = set[s].2.as_mut().and_then(|v| v.pointer_mut(&p)) {
                        *x = changed(x, how);
                    }
                }
            }
            Tamper::Swap { sa, a, sb, b } => {
                let (sa, sb) = (sa % n, sb % n);
                if let (Some(pa), Some(pb)) = (leaf_of(&set, sa, a), leaf_of(&set, sb, b)) {
                    let va = set[sa].2.as_ref().and_then(|v| v.pointer(&pa)).cloned();
                    let vb = set[sb].2.as_ref().and_then(|v| v.pointer(&pb)).cloned();
                    if let (Some(va), Some(vb)) = (va, vb) {
                        if let Some(x) = set[sa].2.as_mut().and_then(|v| v.pointer_mut(&pa)) {
                            *x = vb;
                        }
                        if let Some(x) = set[sb].2.as_mut().and_then(|v| v.pointer_mut(&pb)) {
                            *x = va;
                        }
                    }
                }
            }
            Tamper::Delete { shard, leaf } | Tamper::Add { shard, leaf } => {
                let s = shard % n;
                if let Some(p) = leaf_of(&set, s, leaf) {
                    let (parent, key) = p.rsplit_once('/').unwrap_or(("", ""));
                    let add = matches!(e, Tamper::Add { .. });
                    match set[s].2.as_mut().and_then(|v| v.pointer_mut(parent)) {
                        Some(Value::Object(m)) => {
                            if add {
                                m.insert("extra".into(), serde_json::json!(1));
                            } else {
                                m.remove(&key.replace("~1", "/").replace("~0", "~"));
                            }
                        }
                        Some(Value::Array(a)) => {
                            if add {
                                a.push(serde_json::json!(1));
                            } else if let Ok(i) = key.parse::<usize>() {
                                if i < a.len() {
                                    a.remove(i);
                                }
                            }
                        }
                        _ => {}
                    }
                }
            }
            Tamper::Missing { shard } => {
                if set.len() > 1 {
                    set.remove(shard % n);
                }
            }
            Tamper::Twice { shard } => {
                let mut c = set[shard % n].clone();
                c.0 = format!("copy-{}", c.0);
                set.push(c);
            }
            Tamper::Truncate { shard, permille } => {
                let s = shard % n;
                let t = &set[s].1;
                let mut cut = t.len() * permille as usize / 1000;
                while !t.is_char_boundary(cut) {
                    cut -= 1;
                }
                set[s].1 = t[..cut].to_string();
                set[s].2 = None;
            }
            Tamper::Replace { shard, empty } => {
                let s = shard % n;
                set[s].1 = if empty { String::new() } else { "{}".into() };
                set[s].2 = None;
            }
        }
    }
    // Re-render the edited JSON (texts already replaced keep their text).
    for e in &mut set {
        if let Some(v) = &e.2 {
            e.1 = serde_json::to_string_pretty(v).unwrap_or_default() + "\n";
        }
    }
    set
}

/// A case: 1–2 edits (none a tenth of the time: the untouched set must merge).
pub fn edits(rng: &mut ChaCha8Rng) -> Vec<Tamper> {
    if rng.random_range(0..10u32) == 0 {
        return Vec::new();
    }
    (0..rng.random_range(1..=2usize))
        .map(|_| Tamper::random(rng))
        .collect()
}

/// Run a case: write the (edited) shards into `scratch`, read and merge them.
pub fn run(shards: &[(String, String)], edits: &[Tamper], scratch: &Path) -> CaseReport {
    let set = tampered(shards, edits);
    let _ = std::fs::create_dir_all(scratch);
    let mut files: Vec<PathBuf> = Vec::new();
    for (name, text, _) in &set {
        let p = scratch.join(name);
        if let Err(e) = std::fs::write(&p, text) {
            return CaseReport::with(Class::Named, format!("cannot write a shard: {e}"));
        }
        files.push(p);
    }
    // The same content as written (the same shard files, whatever the order or the spelling)?
    let parse = |t: &str| serde_json::from_str::<shard::ShardFile>(t).ok();
    let original: Vec<shard::ShardFile> = shards.iter().filter_map(|(_, t)| parse(t)).collect();
    let now: Vec<Option<shard::ShardFile>> = set.iter().map(|(_, t, _)| parse(t)).collect();
    let untouched = now.len() == original.len()
        && original
            .iter()
            .all(|o| now.iter().any(|v| v.as_ref() == Some(o)));
    let merged = (|| {
        let mut read = Vec::new();
        for p in &files {
            read.push((p.clone(), shard::read(p)?));
        }
        shard::merge(&read)
    })();
    let mut r = match (merged, untouched) {
        (Ok(_), true) => CaseReport::new(Class::Success),
        (Ok(_), false) => CaseReport::with(
            Class::Accepted,
            format!("merge accepted the edited shards ({edits:?})"),
        ),
        (Err(e), true) => CaseReport::with(
            Class::Unlocated,
            format!("merge refused the shards as written: {e}"),
        ),
        (Err(e), false) => {
            let msg = e.to_string();
            if files.iter().any(|f| msg.contains(&f.display().to_string())) || msg.contains("shard")
            {
                CaseReport::new(Class::Named)
            } else {
                let mut r = refused(&msg);
                if r.class.is_problem() {
                    r.detail = format!("{edits:?}: {msg}");
                }
                r
            }
        }
    };
    r.kind = Some(
        match edits.first() {
            None => "untouched",
            Some(Tamper::Leaf { .. }) => "a value changed",
            Some(Tamper::Swap { .. }) => "values swapped",
            Some(Tamper::Delete { .. }) | Some(Tamper::Add { .. }) => "a field deleted or added",
            Some(Tamper::Missing { .. }) | Some(Tamper::Twice { .. }) => "a shard missing or twice",
            Some(Tamper::Truncate { .. }) | Some(Tamper::Replace { .. }) => {
                "text truncated or replaced"
            }
        }
        .into(),
    );
    r
}
