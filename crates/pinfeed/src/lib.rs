#![warn(missing_docs)]
//! # pinfeed
//!
//! A simulator and planner for orienting planar parts on a conveyor belt with overhead pins and
//! fences. Data flows one way: a scenario is compiled into an immutable scene (part geometry with its
//! limit-surface data, obstacles, settings); a seeded stream of randomly posed parts runs through a
//! discrete-event engine, which calls the contact model — a pure function from (part, pose, obstacle,
//! settings) to a `ContactOutcome` — for each pin or fence encounter; metrics and reports come out
//! the other end. Physics and conventions are described in `docs/physics.md` (quasi-static pushing with Coulomb
//! friction; x along belt travel, y to the left, angles counter-clockwise, degrees at interfaces).
//!
//! Modules, from the bottom layer up:
//!
//! | module | what it holds |
//! |---|---|
//! | [`random`], [`statistics`], [`input`], [`output`], [`progress`] | seeded streams, intervals, bounded file reads, whole-or-nothing file writes, progress callbacks |
//! | [`geometry`] | polygons, named parts, stable states, first contact |
//! | [`mechanics`] | the contact model: limit surfaces, one pin or fence pass |
//! | [`dynamics`] | the dynamic tier: a part with inertia, impacts and sustained contact with a pin |
//! | [`maps`] | configuration maps θ0 → θf, their bands, ensembles, the map tier |
//! | [`contact_case`] | one fully specified pass, as `pinfeed contact` runs it, batches of them, and the maps of a case as `pinfeed map` computes them ([`contact_case::maps::run`]) |
//! | [`sensing`] | force/torque readings, classifiers, sense experiments |
//! | [`scenario`] | TOML scenarios compiled to an immutable scene |
//! | [`engine`] | the discrete-event feeder line, its controller and metrics |
//! | [`validate`] | measured bands against the model; calibration |
//! | [`plan`] | designing a line (pins, fences, a sensor with moving pins), checked on the line |
//! | [`study`] | Monte Carlo studies, comparisons, cost and accuracy studies, the fuzzing driver |
//! | [`report`] | tables, reports and figures |
//!
//! This crate is the library; the `pinfeed` command is the workspace's other package,
//! `pinfeed-cli` (`src/main.rs` and `src/cli/` at the workspace's top), which depends on it, maps
//! its arguments to these modules and prints. The workspace's `examples/` holds one push, a line
//! run, a plan and a sensing evaluation written against this API.

pub mod contact_case;
pub mod dynamics;
pub mod engine;
pub mod geometry;
pub mod input;
pub mod maps;
pub mod mechanics;
pub mod output;
pub mod plan;
pub mod progress;
pub mod random;
pub mod report;
pub mod scenario;
pub mod sensing;
pub mod statistics;
pub mod study;
pub mod validate;

/// The version of the layout of every JSON document pinfeed prints (`--json`) or writes
/// (`summary.json`, `report.json`, `map.json`, …), stored in each as `"schema_version"`; it grows
/// when a field is removed, renamed or changes meaning (docs/outputs.md).
pub const SCHEMA_VERSION: u32 = 1;

/// The version of pinfeed that produced a JSON document, stored in each as `"pinfeed_version"`.
pub const PINFEED_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The folder under which every command writes by default (`pinfeed-out/runs/<scenario>/`,
/// `pinfeed-out/mc/<study>/`, …): relative to the working folder, and ignored by git in the
/// repository. An explicit `--out` (or a scenario's `[output] dir`) is used exactly as given.
pub const DEFAULT_OUT_ROOT: &str = "pinfeed-out";

/// `rel` under the workspace's top folder (scenarios/, studies/, tests/fixtures/), where the unit
/// tests read the project's files (they run in crates/pinfeed/).
#[cfg(test)]
pub(crate) fn project_path(rel: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

/// `pinfeed-out/<parts…>`: a command's default output folder.
pub fn default_out(parts: &[&str]) -> std::path::PathBuf {
    let mut p = std::path::PathBuf::from(DEFAULT_OUT_ROOT);
    for s in parts {
        p.push(s);
    }
    p
}
