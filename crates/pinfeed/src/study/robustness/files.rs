//! Scenario and study files for fuzzing: the bundled scenarios/*.toml and studies/*.toml and the
//! test fixtures, mutated as text (so NaN and inf spelled in TOML, wrong types and truncated files
//! are all reachable) and then parsed, compiled and run for a few parts or samples.
//!
//! A mutation ([`Mutation`]) is one of: a number replaced by an extreme (0, negative, 5e-324,
//! 1e-200, 1e308, nan, inf, huge integers, …) or multiplied by a power of ten; a key of a known
//! section set to an extreme (inserted when missing); a line deleted, duplicated or swapped; a key
//! renamed; a value's type changed; a section dropped; the file truncated. Positions are taken
//! modulo the candidates in the file, so any list of mutations applies to any file (the proptest
//! file tests/fuzz_files.rs drives [`apply`] with its own strategies).
//!
//! A case ends [`Class::Located`] (the error points at the file: line, column, excerpt),
//! [`Class::Named`] (the error names a key, a parameter or a sample), [`Class::Unlocated`],
//! [`Class::Success`] (the run's summary and per-part records are finite) or
//! [`Class::NonFinite`].

use super::{all_finite, CaseReport, Class};
use crate::engine::{self, EngineError, RunOptions};
use crate::random::ChaCha8Rng;
use crate::scenario::{InvalidScenario, ScenarioError, Scene};
use crate::study::mc::{self, StudyError};
use rand::RngExt;
use std::path::{Path, PathBuf};

/// What a case of the scenarios target is (in the fuzz report).
pub const SCENARIO_DESCRIPTION: &str = "the bundled scenarios/*.toml and tests/fixtures/scenarios/*.toml, three times in four a bundled one, with 1–4 text mutations (one half the time) (numbers set to extremes: 0, negatives, 5e-324, 1e-200, 1e308, nan, ±inf, huge integers, or scaled by 10^±k; known keys set to extremes or inserted; lines deleted, duplicated or swapped; keys renamed; types changed; sections dropped; truncation; `[controller.belief]` lists with duplicates, empty, unknown or out-of-range entries; `[uncertain.*]` tables of every ranged study parameter at, just inside and just beyond its range's ends), parsed, compiled and run for at most 3 parts";
/// What a case of the studies target is (in the fuzz report).
pub const STUDY_DESCRIPTION: &str = "the bundled studies/*.toml and tests/fixtures/studies/*.toml, mutated as the scenarios are (plus [uncertain.*] tables — each ranged parameter's value at, just inside and just beyond the ends of its documented range, as a fixed value, a uniform's max, a normal's mean or truncation to one value, a triangular's mode — sweeps and the scenario path), parsed, compiled and run for 3 samples at the first and last sweep points";

/// Parts run per accepted scenario (bounded: a case never runs a whole feed).
pub const PARTS_PER_CASE: u64 = 3;
/// Samples run per accepted study, at its first and last sweep points.
pub const SAMPLES_PER_CASE: u64 = 3;

/// Values a mutated number or key takes.
pub const EXTREMES: [&str; 30] = [
    "0",
    "-0.0",
    "-1",
    "-0.05",
    "5e-324",
    "1e-320",
    "1e-300",
    "1e-200",
    "1e-162",
    "1e-150",
    "1e-14",
    "1e-9",
    "1e-3",
    "0.5",
    "1",
    "2",
    "3",
    "90",
    "360",
    "1e9",
    "1e20",
    "1e150",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "18446744073709551615",
    "9223372036854775807",
    "-9223372036854775808",
];

/// Keys the mutator sets by name: (section header, key). An empty section is the top level.
pub const KNOWN_KEYS: [(&str, &str); 44] = [
    ("", "seed"),
    ("", "samples"),
    ("", "scenario"),
    ("belt", "speed"),
    ("belt", "width"),
    ("belt", "length"),
    ("part", "scale"),
    ("part", "mu_c"),
    ("part", "mu_s"),
    ("part", "support"),
    ("feed", "parts"),
    ("feed", "headway"),
    ("feed", "rate"),
    ("feed", "jitter"),
    ("feed", "weights"),
    ("feed.lateral", "sd"),
    ("feed.lateral", "max"),
    ("obstacles", "x"),
    ("obstacles", "y"),
    ("obstacles", "radius"),
    ("obstacles", "mu_c"),
    ("obstacles", "angle"),
    ("obstacles", "length"),
    ("goal.sets", "tolerance"),
    ("goal.sets", "orientations"),
    ("model", "tol"),
    ("model", "max_travel"),
    ("model", "fidelity"),
    ("output", "histogram_bin"),
    ("output", "draw_parts"),
    ("uncertain.belt_speed", "distribution"),
    ("uncertain.belt_speed", "value"),
    ("uncertain.mu_c", "distribution"),
    ("uncertain.mu_c", "max"),
    ("uncertain.shape", "distribution"),
    ("uncertain.shape", "sd"),
    ("uncertain.pin_radius", "distribution"),
    ("uncertain.pin_radius", "mean"),
    ("uncertain.pose_theta", "sd"),
    ("uncertain.support", "model"),
    ("uncertain.support", "points"),
    ("sweep", "parameter"),
    ("sweep", "values"),
    ("sweep", "steps"),
];

/// Values for keys that take words or lists.
fn special_values(key: &str) -> &'static [&'static str] {
    match key {
        "distribution" => &[
            "\"fixed\"",
            "\"uniform\"",
            "\"normal\"",
            "\"triangular\"",
            "\"bogus\"",
        ],
        "model" => &["\"uniform\"", "\"tripod\"", "\"smooth\"", "\"none\""],
        "support" => &["\"uniform\"", "\"tripod\"", "\"smooth\""],
        "fidelity" => &["\"exact\"", "\"ellipsoid\"", "\"tip\"", "\"perfect\""],
        "parameter" => &[
            "\"belt_speed\"",
            "\"mu_c\"",
            "\"mu_c.max\"",
            "\"shape.sd\"",
            "\"pin_radius\"",
            "\"support.points\"",
            "\"nothing\"",
        ],
        "scenario" => &[
            "\"../scenarios/quickstart.toml\"",
            "\"../scenarios/tripoly1_fences.toml\"",
            "\"../scenarios/crowded_belt.toml\"",
            "\"missing.toml\"",
            "\"\"",
        ],
        "values" | "orientations" | "weights" => &[
            "[]",
            "[1e-320]",
            "[0.1, 1e308]",
            "[nan]",
            "[1, 2, 3]",
            "[0, 0, 0]",
            "[-1, 5e-324, 1e300]",
        ],
        _ => &[],
    }
}

/// One text mutation; indices are taken modulo the candidates present.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mutation {
    /// Replace numeric token `which` by `EXTREMES[value]`.
    Number {
        /// Index of the numeric token (modulo their number).
        which: usize,
        /// Index into `EXTREMES` of the new value (modulo their number).
        value: usize,
    },
    /// Multiply numeric token `which` by 10^power (written as `{token}e{power}` when possible).
    Scale {
        /// Index of the numeric token (modulo their number).
        which: usize,
        /// Power of ten to multiply by.
        power: i32,
    },
    /// Set `KNOWN_KEYS[key]` to value `value` (an extreme, or a word or list for such keys).
    SetKey {
        /// Index into `KNOWN_KEYS` of the key.
        key: usize,
        /// Picks the value (modulo the candidates for the key).
        value: usize,
    },
    /// Delete line `which`.
    DeleteLine {
        /// Index of the line (modulo the number of lines).
        which: usize,
    },
    /// Insert a second copy of line `which`.
    DuplicateLine {
        /// Index of the line (modulo the number of lines).
        which: usize,
    },
    /// Swap lines `a` and `b`.
    SwapLines {
        /// Index of the first line (modulo the number of lines).
        a: usize,
        /// Index of the second line (modulo the number of lines).
        b: usize,
    },
    /// Rename the key on key line `which` (`how` picks: a suffix, another known key, upper case).
    RenameKey {
        /// Index of the key line (modulo their number).
        which: usize,
        /// Picks the new name.
        how: usize,
    },
    /// Replace the value on key line `which` by another type (`kind` picks string, bool, list, table).
    ChangeType {
        /// Index of the key line (modulo their number).
        which: usize,
        /// Picks the new type.
        kind: usize,
    },
    /// Drop the section starting at header `which` (the header and its lines).
    DropSection {
        /// Index of the section header (modulo their number).
        which: usize,
    },
    /// Keep the first `permille`/1000 of the file.
    Truncate {
        /// Thousandths of the file kept, in [0, 1000).
        permille: u32,
    },
    /// Replace the study's `[uncertain.P]` table (P = `RANGED[param]`) by one whose value lies
    /// at, just inside or just beyond an end of P's documented range ([`range_value`]), as a
    /// fixed value, a uniform's max, a normal's mean (sd the range's width, or truncated to the
    /// value alone) or a triangular's mode ([`ranged_table`]).
    Ranged {
        /// Index into [`RANGED`] of the parameter (modulo their number).
        param: usize,
        /// Picks the distribution (modulo 5).
        form: usize,
        /// Picks the value (modulo 7).
        at: usize,
    },
    /// Set a `[controller.belief]` list (`support` or `mu_c`) to `BELIEF_LISTS[key].1[list]`:
    /// duplicates, empty, unknown or out-of-range entries, too many values.
    Belief {
        /// Index into [`BELIEF_LISTS`] of the key (modulo their number).
        key: usize,
        /// Index of the list (modulo the key's lists).
        list: usize,
    },
}

/// The study parameters, each with a documented range ([`crate::study::mc::compile::domain`]),
/// that [`Mutation::Ranged`] sets.
pub use crate::study::mc::compile::DISTRIBUTION_PARAMETERS as RANGED;

/// The lists [`Mutation::Belief`] gives a `[controller.belief]` key (issue 57 item 7: a support
/// listed twice ran with the class counted twice).
pub const BELIEF_LISTS: [(&str, &[&str]); 2] = [
    (
        "support",
        &[
            "[\"uniform\"]",
            "[\"tripod\"]",
            "[\"uniform\", \"tripod\"]",
            "[\"uniform\", \"uniform\"]",
            "[\"tripod\", \"uniform\", \"tripod\"]",
            "[]",
            "[\"smooth\"]",
            "[\"bogus\"]",
            "\"uniform\"",
        ],
    ),
    (
        "mu_c",
        &[
            "[0.5]",
            "[0.3, 0.7]",
            "[0.5, 0.5]",
            "[0.3, 0.5, 0.3]",
            "[]",
            "[0, 5]",
            "[-0.1]",
            "[5.01]",
            "[nan]",
            "[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6]",
            "[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7]",
        ],
    ),
];

/// A value for a parameter whose range is [lo, hi]: `at` (modulo 7) picks lo, hi, just below lo,
/// just above hi, just inside lo, just inside hi, or the middle.
pub fn range_value(lo: f64, hi: f64, at: usize) -> f64 {
    let step = |x: f64| (x.abs() * 1e-9).max(1e-12);
    match at % 7 {
        0 => lo,
        1 => hi,
        2 => lo - step(lo),
        3 => hi + step(hi),
        4 => lo + step(lo),
        5 => hi - step(hi),
        _ => 0.5 * (lo + hi),
    }
}

/// The `[uncertain.NAME]` table of [`Mutation::Ranged`]: `v` (a value from [`range_value`]) as a
/// fixed value, a uniform's max (from lo), a normal's mean with the range's width as its sd, a
/// normal truncated to `v` alone, or a triangular's mode over [lo, hi] (`form` modulo 5). Numbers
/// in exponent notation, every digit kept.
pub fn ranged_table(name: &str, form: usize, v: f64) -> Vec<String> {
    let ((lo, hi), _) = crate::study::mc::compile::domain(name);
    let mut t = vec![format!("[uncertain.{name}]")];
    let fields: Vec<(&str, f64)> = match form % 5 {
        0 => vec![("value", v)],
        1 => vec![("min", lo), ("max", v)],
        2 => vec![("mean", v), ("sd", hi - lo)],
        3 => vec![("mean", v), ("sd", 1.0), ("min", v), ("max", v)],
        _ => vec![("min", lo), ("mode", v), ("max", hi)],
    };
    let kind = ["fixed", "uniform", "normal", "normal", "triangular"][form % 5];
    t.push(format!("distribution = \"{kind}\""));
    t.extend(fields.into_iter().map(|(k, x)| format!("{k} = {x:e}")));
    t
}

impl Mutation {
    /// A random mutation.
    pub fn random(rng: &mut ChaCha8Rng) -> Mutation {
        let which = rng.random_range(0..10_000usize);
        match rng.random_range(0..23u32) {
            0..=5 => Mutation::Number {
                which,
                value: rng.random_range(0..EXTREMES.len()),
            },
            6 | 7 => Mutation::Scale {
                which,
                power: rng.random_range(-320..=320),
            },
            8..=11 => Mutation::SetKey {
                key: rng.random_range(0..KNOWN_KEYS.len()),
                value: rng.random_range(0..64),
            },
            12 => Mutation::DeleteLine { which },
            13 => Mutation::DuplicateLine { which },
            14 => Mutation::SwapLines {
                a: which,
                b: rng.random_range(0..10_000),
            },
            15 => Mutation::RenameKey {
                which,
                how: rng.random_range(0..3),
            },
            16 | 17 => Mutation::ChangeType {
                which,
                kind: rng.random_range(0..4),
            },
            18 => Mutation::DropSection { which },
            19 | 20 => Mutation::Ranged {
                param: rng.random_range(0..RANGED.len()),
                form: rng.random_range(0..5),
                at: rng.random_range(0..7),
            },
            21 => Mutation::Belief {
                key: rng.random_range(0..BELIEF_LISTS.len()),
                list: rng.random_range(0..16),
            },
            _ => Mutation::Truncate {
                permille: rng.random_range(0..1000),
            },
        }
    }
}

/// Byte ranges of a line's value (after the first `=` outside quotes, before a comment).
fn value_range(line: &str) -> Option<(usize, usize)> {
    let mut in_str = false;
    let mut eq = None;
    for (i, c) in line.char_indices() {
        match c {
            '"' | '\'' => in_str = !in_str,
            '=' if !in_str && eq.is_none() => eq = Some(i + 1),
            '#' if !in_str => return eq.map(|e| (e, i)),
            _ => {}
        }
    }
    eq.map(|e| (e, line.len()))
}

fn is_header(line: &str) -> bool {
    line.trim_start().starts_with('[')
}

/// The key of a `key = value` line.
fn key_of(line: &str) -> Option<&str> {
    if is_header(line) {
        return None;
    }
    let (start, _) = value_range(line)?;
    let k = line[..start - 1].trim();
    (!k.is_empty() && !k.starts_with('#')).then_some(k)
}

/// Numeric tokens: (line, byte start, byte end).
fn numbers(lines: &[String]) -> Vec<(usize, usize, usize)> {
    let mut out = Vec::new();
    for (li, line) in lines.iter().enumerate() {
        if is_header(line) {
            continue;
        }
        let Some((a, b)) = value_range(line) else {
            continue;
        };
        let bytes = line.as_bytes();
        let mut i = a;
        let mut in_str = false;
        while i < b {
            let c = bytes[i] as char;
            if c == '"' || c == '\'' {
                in_str = !in_str;
                i += 1;
                continue;
            }
            let starts = !in_str
                && (c.is_ascii_digit()
                    || ((c == '-' || c == '+')
                        && i + 1 < b
                        && (bytes[i + 1] as char).is_ascii_alphanumeric()))
                && (i == a || !(bytes[i - 1] as char).is_ascii_alphanumeric());
            let word = !in_str
                && (line[i..b].starts_with("inf") || line[i..b].starts_with("nan"))
                && (i == a || !(bytes[i - 1] as char).is_ascii_alphanumeric());
            if starts || word {
                let mut j = i + 1;
                while j < b {
                    let d = bytes[j] as char;
                    let sign_after_e =
                        (d == '-' || d == '+') && matches!(bytes[j - 1] as char, 'e' | 'E');
                    if d.is_ascii_alphanumeric() || d == '.' || d == '_' || sign_after_e {
                        j += 1;
                    } else {
                        break;
                    }
                }
                out.push((li, i, j));
                i = j;
            } else {
                i += 1;
            }
        }
    }
    out
}

/// Header text without brackets.
pub(crate) fn header_name(line: &str) -> Option<&str> {
    let t = line.split('#').next()?.trim();
    let t = t
        .strip_prefix("[[")
        .and_then(|t| t.strip_suffix("]]"))
        .or_else(|| t.strip_prefix('[').and_then(|t| t.strip_suffix(']')))?;
    Some(t.trim())
}

/// The end (exclusive) of the section whose header is line `h`: the next header, or the end.
fn section_end(lines: &[String], h: usize) -> usize {
    lines[h + 1..]
        .iter()
        .position(|l| is_header(l))
        .map(|p| h + 1 + p)
        .unwrap_or(lines.len())
}

fn set_key(lines: &mut Vec<String>, section: &str, key: &str, value: &str) {
    // The section's line range: top level runs to the first header.
    let (start, end) = if section.is_empty() {
        (
            0,
            lines
                .iter()
                .position(|l| is_header(l))
                .unwrap_or(lines.len()),
        )
    } else {
        match lines.iter().position(|l| header_name(l) == Some(section)) {
            Some(h) => (h + 1, section_end(lines, h)),
            None => {
                lines.push(String::new());
                lines.push(format!("[{section}]"));
                lines.push(format!("{key} = {value}"));
                return;
            }
        }
    };
    for l in lines[start..end].iter_mut() {
        if key_of(l) == Some(key) {
            *l = format!("{key} = {value}");
            return;
        }
    }
    lines.insert(start, format!("{key} = {value}"));
}

/// Apply one mutation to a file's text.
pub fn apply(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let key_lines: Vec<usize> = (0..lines.len())
        .filter(|&i| key_of(&lines[i]).is_some())
        .collect();
    match *m {
        Mutation::Number { which, value } => {
            let nums = numbers(&lines);
            if let Some(&(li, a, b)) = nums.get(which % nums.len().max(1)) {
                lines[li].replace_range(a..b, EXTREMES[value % EXTREMES.len()]);
            }
        }
        Mutation::Scale { which, power } => {
            let nums = numbers(&lines);
            if let Some(&(li, a, b)) = nums.get(which % nums.len().max(1)) {
                let tok = &lines[li][a..b];
                let new = match tok.parse::<f64>() {
                    Ok(v) => format!("{:e}", v * 10f64.powi(power)),
                    Err(_) => format!("{tok}e{power}"),
                };
                let new = if new.contains("inf") || new.contains("NaN") {
                    new.to_lowercase()
                } else {
                    new
                };
                lines[li].replace_range(a..b, &new);
            }
        }
        Mutation::SetKey { key, value } => {
            let (section, k) = KNOWN_KEYS[key % KNOWN_KEYS.len()];
            let special = special_values(k);
            let v = if !special.is_empty() && value % 2 == 0 {
                special[(value / 2) % special.len()]
            } else {
                EXTREMES[value % EXTREMES.len()]
            };
            set_key(&mut lines, section, k, v);
        }
        Mutation::DeleteLine { which } => {
            if !lines.is_empty() {
                let i = which % lines.len();
                lines.remove(i);
            }
        }
        Mutation::DuplicateLine { which } => {
            if !lines.is_empty() {
                let i = which % lines.len();
                let l = lines[i].clone();
                lines.insert(i, l);
            }
        }
        Mutation::SwapLines { a, b } => {
            if !lines.is_empty() {
                let n = lines.len();
                lines.swap(a % n, b % n);
            }
        }
        Mutation::RenameKey { which, how } => {
            if let Some(&li) = key_lines.get(which % key_lines.len().max(1)) {
                let line = lines[li].clone();
                let k = key_of(&line).unwrap_or("").to_string();
                let new = match how % 3 {
                    0 => format!("{k}x"),
                    1 => KNOWN_KEYS[which % KNOWN_KEYS.len()].1.to_string(),
                    _ => k.to_uppercase(),
                };
                lines[li] = line.replacen(&k, &new, 1);
            }
        }
        Mutation::ChangeType { which, kind } => {
            if let Some(&li) = key_lines.get(which % key_lines.len().max(1)) {
                let line = lines[li].clone();
                let k = key_of(&line).unwrap_or("").to_string();
                let v = ["\"text\"", "true", "[1, \"two\"]", "{ a = 1 }"][kind % 4];
                lines[li] = format!("{k} = {v}");
            }
        }
        Mutation::DropSection { which } => {
            let headers: Vec<usize> = (0..lines.len()).filter(|&i| is_header(&lines[i])).collect();
            if let Some(&h) = headers.get(which % headers.len().max(1)) {
                let end = section_end(&lines, h);
                lines.drain(h..end);
            }
        }
        Mutation::Ranged { param, form, at } => {
            let name = RANGED[param % RANGED.len()];
            let ((lo, hi), _) = crate::study::mc::compile::domain(name);
            let header = format!("uncertain.{name}");
            // The table replaces the file's own for the parameter, if it has one.
            if let Some(h) = lines.iter().position(|l| header_name(l) == Some(&header)) {
                let end = section_end(&lines, h);
                lines.drain(h..end);
            }
            lines.push(String::new());
            lines.extend(ranged_table(name, form, range_value(lo, hi, at)));
        }
        Mutation::Belief { key, list } => {
            let (k, lists) = BELIEF_LISTS[key % BELIEF_LISTS.len()];
            set_key(
                &mut lines,
                "controller.belief",
                k,
                lists[list % lists.len()],
            );
        }
        Mutation::Truncate { permille } => {
            let mut cut = text.len() * (permille.min(1000) as usize) / 1000;
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            return text[..cut].to_string();
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// The seed files: (path, text), read from the project root.
#[derive(Debug, Clone)]
pub struct Seeds {
    /// The seed scenarios: (path, text).
    pub scenarios: Vec<(PathBuf, String)>,
    /// The seed studies: (path, text).
    pub studies: Vec<(PathBuf, String)>,
}

/// Why the seed files could not be read ([`Seeds::load`]).
#[derive(Debug, thiserror::Error)]
pub enum SeedsError {
    /// A folder or a file that could not be read.
    /// (The cause is in the message, not a `source`, so that it is printed once.)
    #[error("{}: {error}", path.display())]
    Read {
        /// The folder or file.
        path: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// An entry of a folder that could not be listed.
    #[error(transparent)]
    Entry(std::io::Error),
    /// No seed scenarios or no seed studies under the root.
    #[error(
        "no scenario or study files under {} (run from the project root, or give --root)",
        root.display()
    )]
    Empty {
        /// The project root given.
        root: PathBuf,
    },
}

fn read_dir_toml(dir: &Path) -> Result<Vec<(PathBuf, String)>, SeedsError> {
    let read = |path: &Path| {
        let path = path.to_path_buf();
        move |error| SeedsError::Read { path, error }
    };
    let mut out = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(read(dir))?;
    for e in entries {
        let p = e.map_err(SeedsError::Entry)?.path();
        if p.extension().is_some_and(|x| x == "toml") {
            let text = std::fs::read_to_string(&p).map_err(read(&p))?;
            out.push((p, text));
        }
    }
    out.sort();
    Ok(out)
}

/// An online scenario with its `[controller.belief]` shrunk to the smallest model (one offset
/// bin, one member, two grid positions, one friction value and support): every mutation of it
/// builds a model of its own, and the fuzzer tests the file's handling, not the model's size.
fn smallest_belief(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_belief = false;
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with('[') {
            in_belief = t.starts_with("[controller.belief]");
        }
        let key = t.split(['=', ' ']).next().unwrap_or("");
        let line = match (in_belief, key) {
            (true, "offsets") => "offsets = 1",
            (true, "samples") => "samples = 1",
            (true, "targets") => "targets = 2",
            (true, "mu_c") | (true, "support") => "",
            _ => line,
        };
        out.push_str(line);
        out.push('\n');
    }
    out
}

impl Seeds {
    /// The bundled scenarios and studies and the test fixtures under `root`.
    pub fn load(root: &Path) -> Result<Seeds, SeedsError> {
        let mut scenarios = read_dir_toml(&root.join("scenarios"))?;
        for (_, text) in &mut scenarios {
            *text = smallest_belief(text);
        }
        scenarios.extend(read_dir_toml(&root.join("tests/fixtures/scenarios"))?);
        let mut studies = read_dir_toml(&root.join("studies"))?;
        studies.extend(read_dir_toml(&root.join("tests/fixtures/studies"))?);
        if scenarios.is_empty() || studies.is_empty() {
            return Err(SeedsError::Empty {
                root: root.to_path_buf(),
            });
        }
        Ok(Seeds { scenarios, studies })
    }
}

/// Pick a seed file and 1–4 mutations, and apply them.
fn mutate(files: &[(PathBuf, String)], rng: &mut ChaCha8Rng) -> (PathBuf, String, Vec<Mutation>) {
    // Mostly the bundled files (fixtures are bad files already), mostly one or two mutations, so
    // that many cases get past the parser and reach compilation and the engine.
    let bundled = files
        .iter()
        .position(|(p, _)| p.components().any(|c| c.as_os_str() == "fixtures"))
        .unwrap_or(files.len())
        .max(1);
    let pick = if rng.random::<f64>() < 0.75 {
        rng.random_range(0..bundled)
    } else {
        rng.random_range(0..files.len())
    };
    let (path, text) = &files[pick];
    let n = match rng.random::<f64>() {
        u if u < 0.5 => 1,
        u if u < 0.8 => 2,
        _ => rng.random_range(3..=4),
    };
    let ms: Vec<Mutation> = (0..n).map(|_| Mutation::random(rng)).collect();
    let mut t = text.clone();
    for m in &ms {
        t = apply(&t, m);
    }
    (path.clone(), t, ms)
}

/// Classify a scenario error.
pub fn classify_invalid(i: &InvalidScenario) -> CaseReport {
    if !i.excerpt.is_empty() && i.line > 0 && i.column > 0 {
        CaseReport::new(Class::Located)
    } else if i.key != "(top level)" && !i.message.trim().is_empty() {
        CaseReport::new(Class::Named)
    } else {
        CaseReport::with(Class::Unlocated, i.to_string())
    }
}

pub(crate) fn classify_scenario_error(e: &ScenarioError) -> CaseReport {
    match e.invalid() {
        Some(i) => classify_invalid(i),
        None => CaseReport::new(Class::Named), // I/O: names the path and the reason
    }
}

pub(crate) fn engine_error(e: &EngineError) -> CaseReport {
    match e {
        EngineError::NonFiniteTime { .. } => CaseReport::with(Class::NonFinite, e.to_string()),
        EngineError::OnlineModel(se) => classify_scenario_error(se),
        _ => CaseReport::new(Class::Named),
    }
}

/// The numbers of a run that must be finite.
fn run_numbers(r: &engine::RunResult) -> Vec<f64> {
    let s = &r.summary;
    let mut v = vec![
        s.success_rate,
        s.success_ci95[0],
        s.success_ci95[1],
        s.contacts_per_part,
        s.simulated_time_s,
        s.orientation_histogram.bin_deg,
    ];
    v.extend(
        [
            s.throughput_in_per_min,
            s.throughput_out_per_min,
            s.throughput_ok_per_min,
        ]
        .into_iter()
        .flatten(),
    );
    if let Some(w) = s.steady_window_s {
        v.extend(w);
    }
    if let Some(l) = s.latency_s {
        v.extend([l.p50, l.p90, l.p99, l.max]);
    }
    v.extend(s.obstacles.iter().map(|o| o.busy_fraction));
    for p in &r.records {
        v.extend([
            p.arrival_s,
            p.end_s,
            p.theta_in_deg,
            p.theta_out_deg,
            p.y_in_m,
            p.y_out_m,
        ]);
    }
    for path in &r.paths {
        for (t, pose) in &path.poses {
            v.extend([*t, pose.x, pose.y, pose.theta_rad]);
        }
    }
    v
}

/// Run an accepted scene for a few parts and check its outputs.
pub fn run_scene(scene: &Scene) -> CaseReport {
    let opts = RunOptions {
        parts: scene.feed.parts.min(PARTS_PER_CASE),
        seed: scene.seed,
        sample_paths: 1,
        keep_records: true,
        online: None,
        stop: None,
    };
    match engine::run(scene, &opts, &mut |_| {}) {
        Err(e) => engine_error(&e),
        Ok(r) => {
            if all_finite(&run_numbers(&r)) {
                CaseReport::new(Class::Success)
            } else {
                CaseReport::with(
                    Class::NonFinite,
                    "a run's summary or records hold NaN or inf",
                )
            }
        }
    }
}

/// Parse, compile and run scenario text.
pub fn check_scenario(path: &Path, text: &str) -> CaseReport {
    match crate::scenario::parse(path, text) {
        Err(e) => classify_scenario_error(&e),
        Ok(scene) => run_scene(&scene),
    }
}

/// Parse and compile study text (`path` resolves its scenario) and run a few samples.
pub fn check_study(path: &Path, text: &str) -> CaseReport {
    let study = match mc::parse(path, text, None) {
        Ok(s) => s,
        Err(e) => {
            return match &e {
                StudyError::Invalid(i) => classify_invalid(i),
                StudyError::Scenario(se) => classify_scenario_error(se),
                StudyError::Engine { source, .. } => engine_error(source),
                other if other.to_string().trim().is_empty() => {
                    CaseReport::with(Class::Unlocated, format!("{other:?}"))
                }
                _ => CaseReport::new(Class::Named),
            }
        }
    };
    let last = study.points.len().saturating_sub(1);
    let mut points = vec![0, last];
    points.dedup();
    for point in points {
        for sample in 0..SAMPLES_PER_CASE.min(study.samples) {
            let r = mc::sample::run_sample(
                &study.scene,
                study.online.as_ref(),
                &study.points[point],
                point,
                study.seed,
                sample,
            );
            match r {
                Ok(_) => {}
                Err(StudyError::Engine { source, .. }) => return engine_error(&source),
                Err(e) if e.to_string().trim().is_empty() => {
                    return CaseReport::with(Class::Unlocated, format!("{e:?}"))
                }
                // A sample that cannot be drawn names the sample and why: a clean refusal.
                Err(_) => return CaseReport::new(Class::Named),
            }
        }
    }
    CaseReport::new(Class::Success)
}

fn describe(path: &Path, ms: &[Mutation]) -> String {
    format!(
        "{} with {}",
        path.file_name().and_then(|s| s.to_str()).unwrap_or("?"),
        ms.iter()
            .map(|m| format!("{m:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// One scenario case: (input text, report).
pub fn scenario_case(seeds: &Seeds, rng: &mut ChaCha8Rng) -> (String, CaseReport) {
    let (path, text, ms) = mutate(&seeds.scenarios, rng);
    let mut r = check_scenario(&path, &text);
    if r.class.is_problem() {
        r.detail = format!("{}: {}", describe(&path, &ms), r.detail);
    }
    (text, r)
}

/// One study case: (input text, report).
pub fn study_case(seeds: &Seeds, rng: &mut ChaCha8Rng) -> (String, CaseReport) {
    let (path, text, ms) = mutate(&seeds.studies, rng);
    let mut r = check_study(&path, &text);
    if r.class.is_problem() {
        r.detail = format!("{}: {}", describe(&path, &ms), r.detail);
    }
    (text, r)
}

/// The input of a scenario case, headed by what it was made from.
pub fn scenario_input(seeds: &Seeds, rng: &mut ChaCha8Rng) -> String {
    let (path, text, ms) = mutate(&seeds.scenarios, rng);
    format!("# {}\n{text}", describe(&path, &ms))
}

/// The input of a study case, headed by what it was made from (its scenario path is relative to
/// the seed file's folder).
pub fn study_input(seeds: &Seeds, rng: &mut ChaCha8Rng) -> String {
    let (path, text, ms) = mutate(&seeds.studies, rng);
    format!("# {} (in {})\n{text}", describe(&path, &ms), path.display())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_found_and_replaced() {
        let t = "name = \"a1\"\n[belt]\nspeed = 0.05 # m/s, 3 of them\nlist = [1e-3, -2, inf]\n";
        let lines: Vec<String> = t.lines().map(str::to_string).collect();
        let n = numbers(&lines);
        let toks: Vec<&str> = n.iter().map(|&(l, a, b)| &lines[l][a..b]).collect();
        assert_eq!(toks, vec!["0.05", "1e-3", "-2", "inf"]);
        let m = apply(t, &Mutation::Number { which: 0, value: 4 });
        assert!(m.contains("speed = 5e-324 # m/s"), "{m}");
        let m = apply(
            t,
            &Mutation::SetKey {
                key: KNOWN_KEYS.iter().position(|k| k.1 == "width").unwrap(),
                value: 1,
            },
        );
        assert!(m.contains("[belt]\nwidth = -0.0\nspeed"), "{m}");
    }
}
