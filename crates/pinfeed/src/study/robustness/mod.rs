//! Fuzzing the simulator's inputs in-process: generated and mutated scenario and study
//! files, random contacts and random polygons, each run under `catch_unwind` with a per-case
//! watchdog, tallied into clean errors, successes, panics, hangs, non-finite outputs and contact
//! self-check disagreements (`pinfeed fuzz`, results/robustness.md).
//!
//! * [`files`]: scenario and study files mutated from the bundled ones and the test fixtures;
//! * [`contacts`]: random star polygons pushed by point and disc pins at two tolerances;
//! * [`polygons`]: vertex lists at extreme magnitudes, near-degenerate and self-intersecting;
//! * [`pairs`], [`merges`]: scenarios with pairs of keys set together, edited shard files;
//! * [`compares`]: `pinfeed compare` of two or three designs in both orders and each alone.
//!
//! The plans and csvs targets fuzz `pinfeed` command lines through the command's own argument
//! parser: their cases come from the command line, given to the driver as [`CommandCases`].
//!
//! Determinism: case i of a target draws only from `random::stream(seed ^ tag, i)` and the results
//! are tallied in index order, so the counts and the listed reproducers do not depend on the
//! thread count. Only hangs depend on the machine (a case slower than the time budget counts as a
//! hang); the report says so.
//!
//! A case runs on its own thread: a panic is caught there (the panic hook is silenced while
//! fuzzing, and the message and location are recorded), and a case still running after the budget
//! is reported as a hang and left to finish in the background (after [`MAX_HANGS`] hangs the run
//! stops, so runaway threads cannot pile up).

pub mod commands;
pub mod compares;
pub mod contacts;
pub mod counts;
pub mod files;
pub mod measured_csv;
pub mod merges;
pub mod pairs;
pub mod polygons;

use crate::random::ChaCha8Rng;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// What a case of the plans target is (its cases are [`CommandCases`]).
pub const PLANS_DESCRIPTION: &str = "`pinfeed plan` argument sets: one of 12 parts (named parts, ngon:500, random and degenerate vertex lists, an unknown name), a time limit of 0.05–1 s, line checks of at most 200 parts, one thread, no files, and 0–4 more of 36 flags with values inside, at the ends of and beyond their ranges; parsed and checked as the command does, designed, and the design's numbers and the scenario and policy it would write checked (parsed and run for 3 parts); the searches stop at a wall-time limit, so these counts can depend on the machine";
/// What a case of the csvs target is (its cases are [`CommandCases`]).
pub const CSVS_DESCRIPTION: &str = "measured-band CSV files (1–6 rows of the bundled data sets, with and without the part column, with 0–3 mutations: fields set to extreme numbers, input states, parts or trial counts, fields dropped or added, rows duplicated, the header dropped or swapped, a byte-order mark, CRLF, an open quote, truncation) with random `validate` (three in four, at most 5 members) or `calibrate` (10 members) flags (μc, pin radius, --uncertain, --part, the score's settings, members); read from disk, checked and run as the commands do, every number of an accepted report finite";

/// Hung cases after which a target stops generating new ones.
pub const MAX_HANGS: u64 = 8;
/// Problems of each kind listed in the report.
pub const LISTED: usize = 5;

/// What to fuzz.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Target {
    /// Scenario files: the bundled and fixture scenarios, mutated.
    Scenarios,
    /// Study files: the bundled and fixture studies, mutated.
    Studies,
    /// Single contacts: random star polygons pushed by random pins.
    Contacts,
    /// Vertex lists at extreme magnitudes and near-degenerate shapes.
    Polygons,
    /// Sensing, actuator and controller scenarios with two keys moved together.
    Pairs,
    /// `pinfeed plan` argument sets (cases supplied by the command line, [`CommandCases`]).
    Plans,
    /// Measured-band CSV files with `validate` or `calibrate` flags (cases supplied by the command
    /// line).
    Csvs,
    /// Edited Monte Carlo shard sets given to `merge`.
    Merges,
    /// `compare` of bundled designs in both orders and each alone.
    Compares,
}

impl Target {
    /// Every target, in report order.
    pub const ALL: [Target; 9] = [
        Target::Scenarios,
        Target::Studies,
        Target::Contacts,
        Target::Polygons,
        Target::Pairs,
        Target::Plans,
        Target::Csvs,
        Target::Merges,
        Target::Compares,
    ];
    /// The target's name on the command line and in the report (`scenarios`, `contacts`, …).
    pub fn name(self) -> &'static str {
        match self {
            Target::Scenarios => "scenarios",
            Target::Studies => "studies",
            Target::Contacts => "contacts",
            Target::Polygons => "polygons",
            Target::Pairs => "pairs",
            Target::Plans => "plans",
            Target::Csvs => "csvs",
            Target::Merges => "merges",
            Target::Compares => "compares",
        }
    }
    /// Mixed into the seed so that the targets draw different streams.
    fn tag(self) -> u64 {
        match self {
            Target::Scenarios => 0x1000_0001,
            Target::Studies => 0x1000_0002,
            Target::Contacts => 0x1000_0003,
            Target::Polygons => 0x1000_0004,
            Target::Pairs => 0x1000_0005,
            Target::Plans => 0x1000_0006,
            Target::Csvs => 0x1000_0007,
            Target::Merges => 0x1000_0008,
            Target::Compares => 0x1000_0009,
        }
    }
    /// What a case of this target is.
    pub fn describe(self) -> &'static str {
        match self {
            Target::Scenarios => files::SCENARIO_DESCRIPTION,
            Target::Studies => files::STUDY_DESCRIPTION,
            Target::Contacts => contacts::DESCRIPTION,
            Target::Polygons => polygons::DESCRIPTION,
            Target::Pairs => pairs::DESCRIPTION,
            Target::Plans => PLANS_DESCRIPTION,
            Target::Csvs => CSVS_DESCRIPTION,
            Target::Merges => merges::DESCRIPTION,
            Target::Compares => compares::DESCRIPTION,
        }
    }
}

/// How one case ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Class {
    /// Refused with an error pointing at the input (file:line:column and an excerpt).
    Located,
    /// Refused with an error that names its cause (a key, a parameter, a sample) but not a place.
    Named,
    /// Refused with an error that says neither where nor why.
    Unlocated,
    /// Accepted and run, every output finite (a contact: status `ok` at both tolerances, agreeing).
    Success,
    /// A contact that ended with a named status other than `ok` (at the default tolerance).
    Status,
    /// Accepted, but an output is NaN or infinite.
    NonFinite,
    /// A contact `ok` at both tolerances whose rotations differ by more than 1°.
    Disagreement,
    /// A contact `ok` at the default tolerance but not at the tighter one.
    OkThenFailed,
    /// `merge` accepted shards whose content was edited.
    Accepted,
    /// The case panicked.
    Panic,
    /// The case ran longer than [`Options::budget`].
    Hang,
}

impl Class {
    /// Every class, in report column order.
    pub const ALL: [Class; 11] = [
        Class::Located,
        Class::Named,
        Class::Unlocated,
        Class::Success,
        Class::Status,
        Class::Panic,
        Class::Hang,
        Class::NonFinite,
        Class::Disagreement,
        Class::OkThenFailed,
        Class::Accepted,
    ];
    /// The column heading of the class in the report.
    pub fn label(self) -> &'static str {
        match self {
            Class::Located => "located errors",
            Class::Named => "errors naming the cause",
            Class::Unlocated => "unlocated errors",
            Class::Success => "successes",
            Class::Status => "other statuses",
            Class::NonFinite => "non-finite outputs",
            Class::Disagreement => "self-check disagreements",
            Class::OkThenFailed => "ok, then failed at 1000× tighter tol",
            Class::Accepted => "edited shards accepted",
            Class::Panic => "panics",
            Class::Hang => "hangs",
        }
    }
}

impl Class {
    /// Problems: listed in the report with their reproducers.
    pub fn is_problem(self) -> bool {
        matches!(
            self,
            Class::Unlocated
                | Class::NonFinite
                | Class::Disagreement
                | Class::OkThenFailed
                | Class::Accepted
                | Class::Panic
                | Class::Hang
        )
    }
}

/// The result of one case.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseReport {
    /// How the case ended.
    pub class: Class,
    /// Contacts: the status at the default tolerance.
    pub status: Option<String>,
    /// For problems: what happened and how to reproduce it.
    pub detail: String,
    /// The kind of case within its target (a contact's pin motion, a file's seed, …), counted
    /// apart in the report.
    pub kind: Option<String>,
}

impl CaseReport {
    /// A report of class `class` with no status, detail or kind.
    pub fn new(class: Class) -> CaseReport {
        CaseReport {
            class,
            status: None,
            detail: String::new(),
            kind: None,
        }
    }
    /// A report of class `class` with `detail` (what happened and how to reproduce it).
    pub fn with(class: Class, detail: impl Into<String>) -> CaseReport {
        CaseReport {
            class,
            status: None,
            detail: detail.into(),
            kind: None,
        }
    }
}

/// Per-target counts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tally {
    /// Cases generated and run.
    pub generated: u64,
    /// Cases per class (a class with none may be absent; read with [`Tally::count`]).
    pub counts: BTreeMap<Class, u64>,
    /// Contacts: statuses at the default tolerance, by name.
    pub statuses: BTreeMap<String, u64>,
    /// Counts by the kind of case ([`CaseReport::kind`]), then by class.
    pub kinds: BTreeMap<String, BTreeMap<Class, u64>>,
    /// The first few problems of each class, in case order: (case index, detail).
    pub problems: BTreeMap<Class, Vec<(u64, String)>>,
    /// The run stopped early after too many hangs.
    pub stopped_early: bool,
    /// Wall time of the target's run (s).
    pub seconds: f64,
}

impl Tally {
    /// Cases of class `c` (0 when none).
    pub fn count(&self, c: Class) -> u64 {
        self.counts.get(&c).copied().unwrap_or(0)
    }
    fn add(&mut self, index: u64, r: &CaseReport) {
        self.generated += 1;
        *self.counts.entry(r.class).or_insert(0) += 1;
        if let Some(s) = &r.status {
            *self.statuses.entry(s.clone()).or_insert(0) += 1;
        }
        if let Some(k) = &r.kind {
            *self
                .kinds
                .entry(k.clone())
                .or_default()
                .entry(r.class)
                .or_insert(0) += 1;
        }
        if r.class.is_problem() {
            let list = self.problems.entry(r.class).or_default();
            if list.len() < LISTED {
                list.push((index, r.detail.clone()));
            }
        }
    }
}

/// Settings of a fuzzing run.
#[derive(Debug, Clone)]
pub struct Options {
    /// Seed of the cases: case i of a target draws from a stream derived from (seed, target, i), so
    /// the same seed gives the same cases on any thread count.
    pub seed: u64,
    /// Worker threads running cases in parallel (the counts do not depend on it, hangs aside).
    pub threads: usize,
    /// A case running longer than this is a hang.
    pub budget: Duration,
    /// The project root (bundled scenarios, studies and test fixtures are read from it).
    pub root: PathBuf,
}

/// The cases of a target whose inputs are `pinfeed` command lines (plans, csvs): they go
/// through the command's own argument parser, so the command line supplies them (`pinfeed fuzz`
/// loads them into its corpus with [`Corpus::with_commands`]).
#[derive(Debug, Clone, Copy)]
pub struct CommandCases {
    /// Run the case drawn from the case's stream, with a fresh folder for the files it writes.
    pub run: fn(&mut ChaCha8Rng, &Path) -> CaseReport,
    /// The input of the case drawn from the case's stream, as text (its command line, and the
    /// file it reads).
    pub input: fn(&mut ChaCha8Rng) -> String,
}

/// Everything the generators need, shared by the case threads.
pub struct Corpus {
    /// The seed scenario and study files.
    pub files: files::Seeds,
    /// The seed scenarios of the pairs target.
    pub pair_seeds: Vec<(PathBuf, String)>,
    /// The seed scenarios of the compares target.
    pub compare_seeds: Vec<(PathBuf, String)>,
    root: PathBuf,
    /// The merges target's shards, made on first use.
    shards: std::sync::OnceLock<Result<Vec<(String, String)>, merges::ShardsError>>,
    /// The command-line targets' cases ([`Corpus::with_commands`]).
    commands: Vec<(Target, CommandCases)>,
}

impl Corpus {
    /// Read the seed files under the project root `root`; Err names the file or folder that could
    /// not be read.
    pub fn load(root: &Path) -> Result<Corpus, files::SeedsError> {
        let files = files::Seeds::load(root)?;
        Ok(Corpus {
            pair_seeds: pairs::seeds(&files),
            compare_seeds: compares::seeds(&files),
            files,
            root: root.to_path_buf(),
            shards: std::sync::OnceLock::new(),
            commands: Vec::new(),
        })
    }

    /// The corpus with `cases` as the cases of the command-line target `target`; without them a
    /// case of that target is an unlocated error saying so.
    pub fn with_commands(mut self, target: Target, cases: CommandCases) -> Corpus {
        self.commands.retain(|(t, _)| *t != target);
        self.commands.push((target, cases));
        self
    }

    /// The cases of the command-line target `target`, if given.
    fn command(&self, target: Target) -> Option<&CommandCases> {
        self.commands
            .iter()
            .find(|(t, _)| *t == target)
            .map(|(_, c)| c)
    }

    /// The shards of the merges target (run once; a failure is kept and given to every case).
    pub fn shards(&self) -> Result<&[(String, String)], &merges::ShardsError> {
        self.shards
            .get_or_init(|| merges::make_shards(&self.root))
            .as_ref()
            .map(|v| v.as_slice())
    }
}

/// A fresh folder for case `index` of `target` (removed when the case ends).
struct Scratch(PathBuf);

impl Scratch {
    /// The folder for case `index` of `target` in a run seeded with `seed`, under the system's
    /// temporary folder (emptied if left over; not created).
    fn new(target: Target, seed: u64, index: u64) -> Scratch {
        let d = std::env::temp_dir().join(format!(
            "pinfeed-fuzz-{}-{}-{seed}-{index}",
            std::process::id(),
            target.name()
        ));
        let _ = std::fs::remove_dir_all(&d);
        Scratch(d)
    }
    /// The folder's path.
    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Run case `index` of `target` (no guard): a pure function of (corpus, seed, index).
pub fn run_case(target: Target, corpus: &Corpus, seed: u64, index: u64) -> CaseReport {
    let mut rng = crate::random::stream(seed ^ target.tag(), index);
    let scratch = || Scratch::new(target, seed, index);
    match target {
        Target::Scenarios => files::scenario_case(&corpus.files, &mut rng).1,
        Target::Studies => files::study_case(&corpus.files, &mut rng).1,
        Target::Contacts => contacts::case(&mut rng),
        Target::Polygons => polygons::case(&mut rng),
        Target::Pairs => {
            let c = pairs::PairCase::random(&corpus.pair_seeds, &mut rng);
            pairs::run(&c, &corpus.pair_seeds, scratch().path())
        }
        Target::Plans | Target::Csvs => match corpus.command(target) {
            Some(c) => (c.run)(&mut rng, scratch().path()),
            None => no_commands(target),
        },
        Target::Merges => match corpus.shards() {
            Ok(shards) => merges::run(shards, &merges::edits(&mut rng), scratch().path()),
            Err(e) => CaseReport::with(Class::Unlocated, format!("cannot make the shards: {e}")),
        },
        Target::Compares => {
            let c = compares::CompareCase::random(&corpus.compare_seeds, &mut rng);
            compares::run(&c, &corpus.compare_seeds, scratch().path())
        }
    }
}

/// The input of case `index` as text (a scenario or study file, a contact or part command line).
pub fn case_input(target: Target, corpus: &Corpus, seed: u64, index: u64) -> String {
    let mut rng = crate::random::stream(seed ^ target.tag(), index);
    match target {
        Target::Scenarios => files::scenario_input(&corpus.files, &mut rng),
        Target::Studies => files::study_input(&corpus.files, &mut rng),
        Target::Contacts => contacts::input(&mut rng),
        Target::Polygons => polygons::input(&mut rng),
        Target::Pairs => {
            let c = pairs::PairCase::random(&corpus.pair_seeds, &mut rng);
            match corpus.pair_seeds.get(c.seed) {
                Some((path, text)) => {
                    let (scenario, policy) = pairs::texts(&c, text);
                    let mut s = format!("# {}\n{scenario}", c.describe(path));
                    if let Some(p) = policy {
                        s.push_str(&format!("\n# {}:\n{p}", pairs::POLICY_NAME));
                    }
                    s
                }
                None => "no seed scenario".into(),
            }
        }
        Target::Plans | Target::Csvs => match corpus.command(target) {
            Some(c) => (c.input)(&mut rng),
            None => no_commands(target).detail,
        },
        Target::Merges => format!(
            "shards of {} with edits {:?}",
            "studies/quickstart_mu_tripod.toml (3 samples)",
            merges::edits(&mut rng)
        ),
        Target::Compares => {
            let c = compares::CompareCase::random(&corpus.compare_seeds, &mut rng);
            let mut s = format!("{}\n", c.command(&corpus.compare_seeds));
            for &k in &c.files {
                if let Some((path, text)) = corpus.compare_seeds.get(k) {
                    s.push_str(&format!("# {}:\n{text}", path.display()));
                }
            }
            s
        }
    }
}

/// A case of a command-line target whose cases the corpus was not given.
fn no_commands(target: Target) -> CaseReport {
    CaseReport::with(
        Class::Unlocated,
        format!(
            "{}: the corpus has no cases for this command-line target (Corpus::with_commands)",
            target.name()
        ),
    )
}

thread_local! {
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// The message of a caught panic, with its location when the hook recorded it.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let msg = if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(non-string panic payload)".to_string()
    };
    match LAST_PANIC.with(|p| p.borrow_mut().take()) {
        Some(at) => format!("panicked at {at}: {msg}"),
        None => format!("panicked: {msg}"),
    }
}

/// Run one case on its own thread, catching a panic and giving up after `budget`.
fn guarded(
    target: Target,
    corpus: &Arc<Corpus>,
    seed: u64,
    index: u64,
    budget: Duration,
) -> CaseReport {
    let (tx, rx) = mpsc::channel();
    let c = Arc::clone(corpus);
    let spawned = std::thread::Builder::new()
        .name(format!("fuzz-{}-{index}", target.name()))
        .stack_size(16 << 20)
        .spawn(move || {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                run_case(target, &c, seed, index)
            }));
            let report = match r {
                Ok(r) => r,
                Err(payload) => CaseReport::with(Class::Panic, panic_message(payload.as_ref())),
            };
            let _ = tx.send(report);
        });
    let handle = match spawned {
        Ok(h) => h,
        Err(e) => return CaseReport::with(Class::Hang, format!("cannot start a thread: {e}")),
    };
    match rx.recv_timeout(budget) {
        Ok(mut r) => {
            let _ = handle.join();
            if r.class.is_problem() {
                r.detail = format!("{} (case {index}): {}", target.name(), r.detail);
            }
            r
        }
        Err(mpsc::RecvTimeoutError::Timeout) => CaseReport::with(
            Class::Hang,
            format!(
                "{} (case {index}): still running after {:.0} s",
                target.name(),
                budget.as_secs_f64()
            ),
        ),
        Err(mpsc::RecvTimeoutError::Disconnected) => {
            CaseReport::with(Class::Panic, "the case thread ended without a result")
        }
    }
}

/// Run `count` cases of `target`; `progress` is called with the number of finished cases.
pub fn run_target(
    target: Target,
    count: u64,
    corpus: &Arc<Corpus>,
    opts: &Options,
    progress: &(dyn Fn(u64) + Sync),
) -> Tally {
    let start = Instant::now();
    let next = AtomicU64::new(0);
    let done = AtomicU64::new(0);
    let hangs = AtomicU64::new(0);
    let stop = AtomicBool::new(false);
    let results: Mutex<Vec<Option<CaseReport>>> = Mutex::new(vec![None; count as usize]);
    let previous_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|info| {
        let at = info
            .location()
            .map(|l| format!("{}:{}:{}", l.file(), l.line(), l.column()))
            .unwrap_or_else(|| "an unknown place".into());
        LAST_PANIC.with(|p| *p.borrow_mut() = Some(at));
    }));
    std::thread::scope(|s| {
        for _ in 0..opts.threads.max(1) {
            s.spawn(|| loop {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= count {
                    break;
                }
                let r = guarded(target, corpus, opts.seed, i, opts.budget);
                if r.class == Class::Hang && hangs.fetch_add(1, Ordering::Relaxed) + 1 >= MAX_HANGS
                {
                    stop.store(true, Ordering::Relaxed);
                }
                results.lock().expect("results lock")[i as usize] = Some(r);
                let d = done.fetch_add(1, Ordering::Relaxed) + 1;
                if d % 1000 == 0 {
                    progress(d);
                }
            });
        }
    });
    std::panic::set_hook(previous_hook);
    let mut tally = Tally::default();
    for (i, r) in results
        .into_inner()
        .expect("results lock")
        .into_iter()
        .enumerate()
    {
        match r {
            Some(r) => tally.add(i as u64, &r),
            None => tally.stopped_early = true,
        }
    }
    tally.seconds = start.elapsed().as_secs_f64();
    tally
}

/// The report (results/robustness.md): headed by `command`, one row per target, the contact
/// statuses and the first problems of each kind.
pub fn report(command: &str, opts: &Options, tallies: &[(Target, Tally)]) -> String {
    let mut s = String::new();
    s.push_str("# Robustness: fuzzing the inputs\n\nRegenerate with:\n\n");
    s.push_str(&format!("    {command}\n\n"));
    s.push_str(&format!(
        "Seed {}, time budget {:.0} s per case (a slower case counts as a hang). The counts and the \
listed cases do not depend on the thread count; hangs and times depend on the machine. \
Re-run one case with `pinfeed fuzz TARGET --seed {} --case N` (prints its input and how it ended).\n\n",
        opts.seed,
        opts.budget.as_secs_f64(),
        opts.seed
    ));
    s.push_str("## What was generated\n\n");
    for (t, _) in tallies {
        s.push_str(&format!("* **{}**: {}\n", t.name(), t.describe()));
    }
    s.push_str(&totals(tallies));
    s.push_str("\n## Counts\n\n");
    s.push_str(
        "Each case ends in one class: a *located error* points at the input (file, line and \
column, or a CSV file and line); an *error naming the cause* names a key, flag, field, shard or \
sample and why; an *unlocated error* says neither (a problem); a *success* ran and every output \
is finite (a contact: `ok` at both tolerances and agreeing within 1°); *other statuses* are \
contacts that ended with a named status other than `ok` at the default tolerance; *panics*, \
*hangs* (slower than the budget) and *non-finite outputs* are problems; a *self-check \
disagreement* is a contact `ok` at both tolerances whose rotations differ by more than 1°, or a \
plan whose written scenario the parser refuses, or a design whose row of a comparison depends on \
the order of the files or on the other designs; *ok, then failed* is a contact `ok` at the \
default tolerance that ends in another status at the 1000× tighter one (listed, not a wrong \
answer); an *edited shard accepted* is a merge that succeeded though a shard's content was \
changed.\n\n",
    );
    s.push_str(&counts_table(
        "target",
        tallies.iter().map(|(t, y)| {
            let name = if y.stopped_early {
                format!("{} (stopped early)", t.name())
            } else {
                t.name().to_string()
            };
            (name, y.generated, &y.counts, Some(y.seconds))
        }),
    ));
    for (t, y) in tallies {
        if y.kinds.is_empty() {
            continue;
        }
        s.push_str(&format!("\n## {} by kind\n\n", t.name()));
        s.push_str(&counts_table(
            "kind",
            y.kinds
                .iter()
                .map(|(k, c)| (k.clone(), c.values().sum(), c, None)),
        ));
    }
    for (t, y) in tallies {
        if y.statuses.is_empty() {
            continue;
        }
        s.push_str(&format!(
            "\n## {} statuses (default tolerance)\n\n| status | count |\n|---|---:|\n",
            t.name()
        ));
        for (name, n) in &y.statuses {
            s.push_str(&format!("| `{name}` | {n} |\n"));
        }
    }
    let mut any = false;
    for (t, y) in tallies {
        for (class, list) in &y.problems {
            if !any {
                s.push_str("\n## Problems (the first few of each kind)\n\n");
                any = true;
            }
            s.push_str(&format!(
                "* {} — {:?} ({}):\n",
                t.name(),
                class,
                y.count(*class)
            ));
            for (_, d) in list {
                s.push_str(&format!("  * `{}`\n", d.replace('`', "'")));
            }
        }
    }
    if !any {
        s.push_str("\nNo problems: no panic, hang, non-finite output, unlocated error, self-check disagreement or accepted edited shard.\n");
    }
    s
}

/// The totals the acceptance targets are stated in: the new surface's cases and their problems,
/// and the contacts (with moving pins apart) and their disagreements.
fn totals(tallies: &[(Target, Tally)]) -> String {
    let surface = [
        Target::Pairs,
        Target::Plans,
        Target::Csvs,
        Target::Merges,
        Target::Compares,
    ];
    let of = |ts: &[Target], c: Option<Class>| -> u64 {
        tallies
            .iter()
            .filter(|(t, _)| ts.contains(t))
            .map(|(_, y)| c.map_or(y.generated, |c| y.count(c)))
            .sum()
    };
    let mut s = String::from("\n## Totals\n\n");
    if tallies.iter().any(|(t, _)| surface.contains(t)) {
        s.push_str(&format!(
            "* sensing/actuator/controller/policy key pairs, plan argument sets, validate/calibrate CSV files, edited merge shards and compared designs: **{}** generated; {} panics, {} hangs, {} non-finite outputs, {} unlocated errors, {} self-check disagreements, {} edited shards accepted\n",
            of(&surface, None),
            of(&surface, Some(Class::Panic)),
            of(&surface, Some(Class::Hang)),
            of(&surface, Some(Class::NonFinite)),
            of(&surface, Some(Class::Unlocated)),
            of(&surface, Some(Class::Disagreement)),
            of(&surface, Some(Class::Accepted)),
        ));
    }
    if let Some((_, y)) = tallies.iter().find(|(t, _)| *t == Target::Contacts) {
        let moving = |c: Option<Class>| -> u64 {
            y.kinds
                .iter()
                .filter(|(k, _)| k.starts_with("moving pin"))
                .map(|(_, m)| match c {
                    Some(c) => m.get(&c).copied().unwrap_or(0),
                    None => m.values().sum(),
                })
                .sum()
        };
        s.push_str(&format!(
            "* contacts: **{}** generated, **{}** of them with moving pins; {} `ok` at both the default and the 1000× tighter tolerance with rotations more than 1° apart ({} with moving pins); {} panics, {} hangs, {} non-finite outputs; {} `ok` at the default tolerance only\n",
            y.generated,
            moving(None),
            y.count(Class::Disagreement),
            moving(Some(Class::Disagreement)),
            y.count(Class::Panic),
            y.count(Class::Hang),
            y.count(Class::NonFinite),
            y.count(Class::OkThenFailed),
        ));
    }
    s
}

/// A Markdown table of counts by class, one row per (name, generated, counts, seconds); the
/// columns are every class, and the seconds when given.
fn counts_table<'a>(
    first: &str,
    rows: impl Iterator<Item = (String, u64, &'a BTreeMap<Class, u64>, Option<f64>)>,
) -> String {
    let rows: Vec<_> = rows.collect();
    let timed = rows.iter().any(|r| r.3.is_some());
    let mut s = format!("| {first} | generated |");
    let mut rule = String::from("|---|---:|");
    for c in Class::ALL {
        s.push_str(&format!(" {} |", c.label()));
        rule.push_str("---:|");
    }
    if timed {
        s.push_str(" seconds |");
        rule.push_str("---:|");
    }
    s.push_str(&format!("\n{rule}\n"));
    for (name, generated, counts, seconds) in rows {
        s.push_str(&format!("| {name} | {generated} |"));
        for c in Class::ALL {
            s.push_str(&format!(" {} |", counts.get(&c).copied().unwrap_or(0)));
        }
        if let Some(t) = seconds {
            s.push_str(&format!(" {t:.0} |"));
        }
        s.push('\n');
    }
    s
}

/// Does a Debug rendering show a NaN or an infinity (Rust prints them `NaN`, `inf`)?
pub fn shows_non_finite(debug: &str) -> bool {
    debug
        .split(|c: char| !c.is_ascii_alphanumeric())
        .any(|w| w == "NaN" || w == "inf")
}

/// A refusal given as a message: located when it points at a file and line (`….csv:LINE`),
/// naming its cause when it names a flag, a field, a column, a file, a part or a range, else
/// unlocated (listed in the report).
pub fn refused(message: &str) -> CaseReport {
    let located = message
        .split(".csv:")
        .nth(1)
        .is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_digit()));
    if located {
        return CaseReport::new(Class::Located);
    }
    let names = [
        "--", "field", "column", ".csv", ".json", "part", "must", "range", "expected", "shard",
        "member",
    ];
    if names.iter().any(|n| message.contains(n)) {
        CaseReport::new(Class::Named)
    } else {
        CaseReport::with(Class::Unlocated, message.to_string())
    }
}

/// Does every number in `values` lie in f64's finite range?
pub fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}
