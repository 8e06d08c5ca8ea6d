//! pinfeed's integration tests, built as one test binary (`cargo test --release --test all`): one
//! module per area, and the shared helpers (`support`: running the built `pinfeed`; `common`: the
//! contact-model helpers; `plan_cli`: the `pinfeed plan` helpers; `reference`: the independent slow contact
//! reference; `shapes`, random polygons; `argv`, argument-vector strategies; `doc_commands`, the
//! documents' command lines). Most modules run the built `pinfeed`; `cli_in_process` drives the
//! command in process through its library `pinfeed_cli`. One binary links the crates once instead
//! of once per file. A single test is selected by its module path, e.g.
//! `cargo test --release --test all slow_reference::many_cases -- --ignored`.
//!
//! Tests in different modules run in parallel threads of one process: scratch files go under
//! names that no other test uses (every module's folders carry its own name and the process id).
//! The long randomized tests (the file fuzzers, the fuzz driver's determinism across threads, the
//! slow reference) run a bounded number of cases; `PINFEED_DEEP_TESTS=1 cargo test --release`
//! runs their deep form (`support::cases`): the same assertions over more cases of the same seeds.
//! proptest keeps each module's failure seeds in `tests/proptest-regressions/<module>.txt` (its
//! default, `SourceParallel`, for a source file beside a `main.rs`).

mod argv;
mod common;
mod doc_commands;
mod plan_cli;
mod reference;
mod shapes;
mod support;
mod xml;

mod accuracy_study;
mod animate;
mod belief;
mod cad;
mod cli_contact;
mod cli_in_process;
mod cli_part;
mod cli_sense;
mod closed_loop;
mod closed_stdout;
mod compare;
mod contact_invariants;
mod contact_regressions;
mod docs;
mod examples;
mod fence_tail;
mod fences;
mod figures;
mod first_contact;
mod fuzz_cli;
mod fuzz_files;
mod geometry;
mod hard_cases;
mod hardening;
mod input_regressions;
mod invariant_properties;
mod json_versions;
mod layering;
mod limit_surface;
mod line;
mod line_cost;
mod line_fences;
mod map_fence;
mod map_tier;
mod maps;
mod mc;
mod mc_loop;
mod mc_obstacles;
mod mc_precision;
mod mc_sensing;
mod moving_pin;
mod online;
mod plan;
mod plan_certificate;
mod plan_fences;
mod plan_goal;
mod plan_margins;
mod plan_reject;
mod plan_sensing;
mod plan_tails;
mod plan_uncertain;
mod plan_verdict;
mod readme_tutorial;
mod run_precision;
mod scenario_errors;
mod sensing_classify;
mod sensing_evaluate;
mod sensing_signal;
mod sensor_scenario;
mod slide_tables;
mod slow_reference;
mod slurm_example;
mod trace;
mod validate;
