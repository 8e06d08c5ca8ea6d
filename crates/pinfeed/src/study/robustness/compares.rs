//! The compares target: `pinfeed compare` ([`crate::study::compare`]) in both orders. A case
//! draws two or three of the bundled scenarios (mostly for one part, now and then for two: the
//! comparison must refuse those), always `--parts` 1–6 and, at random, `--seed`, `--headway`
//! (inside, at the ends of and beyond its range, NaN) and `--uniform-orientation`, writes the
//! scenarios into the case's folder (online controllers with their smallest belief, as the
//! scenarios target has them) and compares them in the order drawn, reversed, and each design
//! alone. A design's row must be the same in every order and alone: its numbers are its own
//! (issue 57 item 1: a design scored 0.9995 in one order and 0.3903 in the other); a difference,
//! or a comparison refused in one order and not in the other, is a self-check disagreement.

use super::files::{classify_scenario_error, engine_error, Seeds};
use super::{shows_non_finite, CaseReport, Class};
use crate::random::ChaCha8Rng;
use crate::scenario::FeedOverrides;
use crate::study::compare::{compare, designs, ComparisonRow, DesignsError};
use rand::RngExt;
use std::path::{Path, PathBuf};

/// What a case of the compares target is (in the fuzz report).
pub const DESCRIPTION: &str = "two or three bundled scenarios (mostly for one part; one case in eight draws from any part, which the comparison must refuse), online controllers with their smallest belief, with --parts 1–6 and at random --seed, --headway (inside, at the ends of and beyond its range, NaN, inf) and --uniform-orientation; compared in the order drawn, reversed, and each design alone: every design's row must be the same each time (a difference, or a refusal in one order only, is a self-check disagreement) and every number finite";

/// Headways (s) a case imposes: inside, at the ends of and beyond [1e-6, 1e6], not a number.
pub const HEADWAYS: [f64; 9] = [
    0.5,
    3.0,
    1e-6,
    1e6,
    9.9e-7,
    1.1e6,
    0.0,
    f64::NAN,
    f64::INFINITY,
];

/// A case: the seed scenarios compared (indices into the seeds, in the order drawn) and what is
/// imposed on every feed.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareCase {
    /// Indices of the seed scenarios, in the order drawn.
    pub files: Vec<usize>,
    /// What the case imposes on every feed (`parts` always).
    pub overrides: FeedOverrides,
}

/// The seed scenarios of this target: the bundled ones (not the test fixtures), as the scenarios
/// target has them (online controllers with their smallest belief).
pub fn seeds(files: &Seeds) -> Vec<(PathBuf, String)> {
    files
        .scenarios
        .iter()
        .filter(|(p, _)| !p.components().any(|c| c.as_os_str() == "fixtures"))
        .cloned()
        .collect()
}

/// The `shape = …` value of a scenario's text (how a case finds designs for the same part).
fn shape_of(text: &str) -> &str {
    text.lines()
        .find_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == "shape").then(|| v.split('#').next().unwrap_or("").trim())
        })
        .unwrap_or("")
}

impl CompareCase {
    /// Draw a case for the seeds `seeds`.
    pub fn random(seeds: &[(PathBuf, String)], rng: &mut ChaCha8Rng) -> CompareCase {
        let n = seeds.len().max(1);
        let first = rng.random_range(0..n);
        let same_part: Vec<usize> = (0..seeds.len())
            .filter(|&k| {
                k != first
                    && seeds
                        .get(first)
                        .is_some_and(|(_, t)| shape_of(&seeds[k].1) == shape_of(t))
            })
            .collect();
        let any_part = same_part.is_empty() || rng.random_range(0..8) == 0;
        let mut files = vec![first];
        for _ in 0..rng.random_range(1..=2) {
            let k = if any_part {
                rng.random_range(0..n)
            } else {
                same_part[rng.random_range(0..same_part.len())]
            };
            if !files.contains(&k) {
                files.push(k);
            }
        }
        let overrides = FeedOverrides {
            parts: Some(rng.random_range(1..=6)),
            seed: rng.random::<bool>().then(|| rng.random_range(0..1000)),
            headway: (rng.random_range(0..3) == 0)
                .then(|| HEADWAYS[rng.random_range(0..HEADWAYS.len())]),
            uniform_orientation: rng.random_range(0..4) == 0,
        };
        CompareCase { files, overrides }
    }

    /// The command lines of the case: `pinfeed compare A B … --parts N …` in the order drawn.
    pub fn command(&self, seeds: &[(PathBuf, String)]) -> String {
        let mut words = vec!["pinfeed compare".to_string()];
        for &k in &self.files {
            words.push(
                seeds
                    .get(k)
                    .map_or("?".into(), |(p, _)| p.display().to_string()),
            );
        }
        let o = &self.overrides;
        if let Some(n) = o.parts {
            words.push(format!("--parts {n}"));
        }
        if let Some(s) = o.seed {
            words.push(format!("--seed {s}"));
        }
        if let Some(h) = o.headway {
            words.push(format!("--headway {h}"));
        }
        if o.uniform_orientation {
            words.push("--uniform-orientation".into());
        }
        words.join(" ")
    }
}

/// How one comparison ended: its rows, or how the refusal is classed.
fn compared(paths: &[PathBuf], overrides: FeedOverrides) -> Result<Vec<ComparisonRow>, CaseReport> {
    let d = designs(paths, overrides).map_err(|e| match &e {
        DesignsError::Scenario(se) => classify_scenario_error(se),
        DesignsError::Empty | DesignsError::Override(_) | DesignsError::Stream { .. } => {
            CaseReport::new(Class::Named)
        }
    })?;
    compare(&d.scenes, &d.files, &d.online).map_err(|e| engine_error(&e))
}

/// Run a case: write its scenarios into `scratch`, compare them in the order drawn, reversed and
/// each alone, and check that every design's row is the same each time.
pub fn run(c: &CompareCase, seeds: &[(PathBuf, String)], scratch: &Path) -> CaseReport {
    let _ = std::fs::create_dir_all(scratch);
    let mut paths = Vec::new();
    for &k in &c.files {
        let Some((path, text)) = seeds.get(k) else {
            return CaseReport::with(Class::Unlocated, "no seed scenario");
        };
        let to = scratch.join(path.file_name().unwrap_or_default());
        if let Err(e) = std::fs::write(&to, text) {
            return CaseReport::with(Class::Named, format!("cannot write the scenario: {e}"));
        }
        paths.push(to);
    }
    let mut r = check(&paths, c.overrides);
    if r.class.is_problem() {
        r.detail = format!("{}: {}", c.command(seeds), r.detail);
    }
    r.kind = Some(format!("{} designs", paths.len()));
    r
}

fn check(paths: &[PathBuf], overrides: FeedOverrides) -> CaseReport {
    let forward = compared(paths, overrides);
    let reversed_paths: Vec<PathBuf> = paths.iter().rev().cloned().collect();
    let reversed = compared(&reversed_paths, overrides);
    let rows = match (forward, reversed) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(a), Err(b)) if a.class == b.class => return a,
        (a, b) => {
            let said = |r: &Result<Vec<ComparisonRow>, CaseReport>| match r {
                Ok(_) => "ran".to_string(),
                Err(e) => format!("{:?}", e.class),
            };
            return CaseReport::with(
                Class::Disagreement,
                format!(
                    "the comparison {} in the order given but {} reversed",
                    said(&a),
                    said(&b)
                ),
            );
        }
    };
    let (forward, reversed) = rows;
    if shows_non_finite(&format!("{forward:?} {reversed:?}")) {
        return CaseReport::with(Class::NonFinite, "a row holds NaN or inf");
    }
    for row in &forward {
        let file = &row.file;
        let other = reversed.iter().find(|r| &r.file == file);
        if other != Some(row) {
            return CaseReport::with(
                Class::Disagreement,
                format!("{file}: its row differs when the files are given in reverse order: {row:?} against {other:?}"),
            );
        }
        if paths.len() > 1 {
            match compared(&[PathBuf::from(file)], overrides) {
                Ok(alone) if alone.first() == Some(row) => {}
                alone => {
                    return CaseReport::with(
                        Class::Disagreement,
                        format!("{file}: its row differs when it is compared alone: {row:?} against {alone:?}"),
                    )
                }
            }
        }
    }
    CaseReport::new(Class::Success)
}
