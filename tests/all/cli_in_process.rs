//! The command line in process, through its library `pinfeed_cli` (the other modules run the built
//! binary): every command shown in README.md and docs/ parses, the recorded command line parses
//! back to itself, the units table of docs/commands.md matches `--help`, random and mutated
//! argument vectors never panic, the `pinfeed fuzz` targets that drive commands run clean on any
//! number of threads, and a map report's default folder is per part.

use crate::argv::{contact_args, part_args};
use crate::doc_commands::{commands, documents, root, shell_words};
use pinfeed::study::robustness::{self, Class, Options, Target};
use pinfeed_cli::{fuzz, Cli};
use proptest::prelude::*;
use std::sync::Arc;
use std::time::Duration;

/// Parse and run in-process; a panic fails, an error (or a clap refusal) is fine.
fn check_in_process(args: &[String]) -> Result<(), TestCaseError> {
    let argv: Vec<String> = std::iter::once("pinfeed".to_string())
        .chain(args.iter().cloned())
        .collect();
    let result = std::panic::catch_unwind(|| match Cli::try_parse_from(&argv) {
        Ok(cli) => pinfeed_cli::run(cli).err().map(|e| format!("{e:#}")),
        Err(e) => Some(e.to_string()),
    });
    match result {
        Err(_) => Err(TestCaseError::fail(format!("{args:?} panicked"))),
        Ok(Some(msg)) => {
            prop_assert!(!msg.trim().is_empty(), "{args:?}: empty error");
            Ok(())
        }
        Ok(None) => Ok(()),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, rng_seed: proptest::test_runner::RngSeed::Fixed(20261130), .. ProptestConfig::default() })]

    #[test]
    fn part_and_contact_argv_in_process(args in prop_oneof![part_args(), contact_args()]) {
        check_in_process(&args)?;
    }
}

#[test]
fn every_documented_command_parses() {
    let mut seen = 0;
    let mut bad = Vec::new();
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        for cmd in commands(&text) {
            // Output redirection and pipes are the shell's, not pinfeed's.
            let cmd = cmd.split(['>', '|']).next().unwrap().to_string();
            let words = shell_words(&cmd);
            seen += 1;
            if let Err(e) = Cli::try_parse_from(&words) {
                bad.push(format!(
                    "{}: `{cmd}`: {}",
                    doc.display(),
                    e.to_string().lines().next().unwrap_or("")
                ));
            }
        }
    }
    assert!(seen > 40, "only {seen} commands found");
    assert!(
        bad.is_empty(),
        "commands that do not parse:\n{}",
        bad.join("\n")
    );
}

/// The flags that take a length (or a ratio of lengths): each is in docs/commands.md's table of
/// units with the unit its `--help` names, and no command has one the table leaves out.
#[test]
fn every_length_flag_names_its_unit_as_the_units_table_does() {
    use clap::CommandFactory;
    const LENGTH_FLAGS: [&str; 14] = [
        "pin-radius",
        "pin-radius-max",
        "pin-radius-sd",
        "lateral",
        "belt-width",
        "spacing",
        "scale",
        "d",
        "pin-stop-after",
        "pin-stop-at",
        "pin-stop-after-touch",
        "d-jitter",
        "fence-overhang",
        "tail-max",
    ];
    const UNITS: [&str; 3] = ["part units", "metres", "units of a"];
    let text = std::fs::read_to_string(root().join("docs/commands.md")).unwrap();
    let section = text
        .split("## Units of length")
        .nth(1)
        .expect("docs/commands.md has a section on units")
        .split("\n## ")
        .next()
        .unwrap();
    // (command, flag) → unit, from the table's rows of plain flags.
    let mut table = std::collections::BTreeMap::new();
    for row in section.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = row.trim_matches('|').split(" | ").map(str::trim).collect();
        let unit = UNITS
            .iter()
            .find(|u| cells[2].to_lowercase().starts_with(*u))
            .unwrap_or_else(|| panic!("no unit in {row}"));
        let ticked = |cell: &str| -> Vec<String> {
            cell.split('`')
                .skip(1)
                .step_by(2)
                .map(str::to_string)
                .collect()
        };
        for flag in ticked(cells[0]).iter().filter(|f| !f.contains(' ')) {
            for cmd in ticked(cells[1]) {
                table.insert((cmd, flag.trim_start_matches("--").to_string()), *unit);
            }
        }
    }
    let mut seen = 0;
    let cli = Cli::command();
    for sub in cli.get_subcommands() {
        for arg in sub.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            if !LENGTH_FLAGS.contains(&long) {
                continue;
            }
            seen += 1;
            let key = (sub.get_name().to_string(), long.to_string());
            let unit = table
                .get(&key)
                .unwrap_or_else(|| panic!("{key:?} is not in docs/commands.md's table of units"));
            let help = arg
                .get_help()
                .map(|h| h.to_string().to_lowercase())
                .unwrap_or_default();
            assert!(
                help.contains(unit),
                "{key:?}: the table says {unit}, --help says: {help}"
            );
        }
    }
    assert_eq!(
        seen,
        table.len(),
        "rows of the table that no command has: {table:?}"
    );
}

/// `pinfeed ARGS` parsed: the command line it records.
fn recorded(args: &[&str]) -> String {
    Cli::try_parse_from(std::iter::once("pinfeed").chain(args.iter().copied()))
        .unwrap()
        .recorded
}

#[test]
fn records_what_was_given_in_definition_order_and_quotes_it() {
    let r = recorded(&[
        "map",
        "--threads",
        "2",
        "--mu-c",
        "0.7",
        "--part",
        "vertices:0,0 2,0 0,1",
        "--d=-0.5,0.25",
        "--quiet",
    ]);
    assert_eq!(
        r,
        "pinfeed map --part 'vertices:0,0 2,0 0,1' --d=-0.5,0.25 --mu-c 0.7"
    );
}

#[test]
fn the_recorded_command_parses_back_to_itself() {
    for args in [
        &[
            "sense", "--part", "tripoly2", "--d=-0.3", "--tripod", "--noise", "0,1,2",
        ][..],
        &["validate", "my file.csv", "--members", "3", "--seed", "9"],
        &["bench", "designs", "--random", "2", "--tripod"],
        &[
            "plan",
            "--part",
            "lshape",
            "--fences",
            "--mu-c-range",
            "0.3:0.7",
        ],
    ] {
        let r = recorded(args);
        let words = shell_words(&r);
        let again = recorded(&words.iter().skip(1).map(String::as_str).collect::<Vec<_>>());
        assert_eq!(again, r);
        assert!(!r.contains("--threads") && !r.contains("--quiet"), "{r}");
    }
}

/// Driver settings for a test: seed, threads, a budget no case reaches.
fn options(seed: u64, threads: usize) -> Options {
    Options {
        seed,
        threads,
        budget: Duration::from_secs(600),
        root: root(),
    }
}

/// The targets of the new surface run clean and their counts do not depend on the thread count:
/// pairs of sensing/actuator/controller/policy keys, measured-band CSVs with validate and
/// calibrate arguments, edited merge shards, contacts with moving pins, and designs compared in
/// both orders.
#[test]
fn new_surface_targets_run_clean_on_any_number_of_threads() {
    let corpus = Arc::new(fuzz::corpus(&root()).unwrap());
    let opts = |threads| options(11, threads);
    for (target, n) in [
        (Target::Pairs, 24),
        (Target::Csvs, 80),
        (Target::Merges, 80),
        (Target::Contacts, 200),
        (Target::Compares, 8),
    ] {
        let mut one = robustness::run_target(target, n, &corpus, &opts(1), &|_| {});
        let mut two = robustness::run_target(target, n, &corpus, &opts(2), &|_| {});
        one.seconds = 0.0;
        two.seconds = 0.0;
        assert_eq!(one, two, "{}", target.name());
        assert_eq!(one.generated, n);
        assert!(
            one.problems.is_empty(),
            "{}: {:?}",
            target.name(),
            one.problems
        );
        // Each target reaches its work, not only the parsers.
        assert!(one.count(Class::Success) > 0, "{}: {one:?}", target.name());
    }
    // Half the contacts move, in each of the three ways.
    let contacts = robustness::run_target(Target::Contacts, 200, &corpus, &opts(1), &|_| {});
    let moving: u64 = contacts
        .kinds
        .iter()
        .filter(|(k, _)| k.starts_with("moving pin"))
        .map(|(_, c)| c.values().sum::<u64>())
        .sum();
    assert!((60..=140).contains(&moving), "{:?}", contacts.kinds);
    assert_eq!(contacts.kinds.len(), 4, "{:?}", contacts.kinds);
}

/// `pinfeed plan` arguments for a test: part, time limit, check parts, then `extra`.
fn plan_args(part: &str, time: &str, check: &str, extra: &[&str]) -> Vec<String> {
    let mut a = pinfeed::study::robustness::commands::base_arguments(part, time, check, "50");
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

/// A plan argument set runs through the command's checks and the design, and the scenario the
/// design would write is accepted and runs; a refused argument names its flag.
#[test]
fn plan_argument_sets_design_and_their_written_scenario_runs() {
    use pinfeed_cli::fuzz::plans;
    let dir = std::env::temp_dir().join(format!("pinfeed-plan-fuzz-{}", std::process::id()));
    let args = |extra: &[&str]| plan_args("tripoly1", "1", "50", extra);
    let r = plans::run(&args(&[]), &dir.join("a"));
    assert_eq!(r.class, Class::Success, "{}", r.detail);
    let r = plans::run(&args(&["--jitter-samples=2001"]), &dir.join("b"));
    assert_eq!(r.class, Class::Named, "{}", r.detail);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `plan --fewest-sets --check-parts 0` for a square wrote a belt 0.02 m wide for a part with
/// 2a = 0.028 m fed within ±2 mm, which the scenario parser refuses: the written width is now at
/// least 2(a + lateral).
#[test]
fn a_planned_scenario_has_a_belt_at_least_as_wide_as_the_part() {
    use pinfeed_cli::fuzz::plans;
    let dir = std::env::temp_dir().join(format!("pinfeed-plan-width-{}", std::process::id()));
    let args = plan_args("square", "0.2", "0", &["--fewest-sets"]);
    let r = plans::run(&args, &dir);
    assert_eq!(r.class, Class::Success, "{}", r.detail);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn default_report_directory_is_per_part() {
    use pinfeed_cli::map::default_out_dir;
    use std::path::Path;
    assert_eq!(
        default_out_dir("tripoly1"),
        Path::new("pinfeed-out/maps/tripoly1")
    );
    assert_eq!(
        default_out_dir("rect:2:1"),
        Path::new("pinfeed-out/maps/rect_2_1")
    );
    // Issue 57 item 11: each vertex list its own folder (as `plan` names its designs), so a second
    // part never replaces the first's figures; the same list (up to spacing) the same folder.
    let a = default_out_dir("vertices:0,0 1,0 0,1");
    let b = default_out_dir("vertices:0,0 2,0 0,1");
    assert_ne!(a, b);
    assert_eq!(a, default_out_dir("vertices:0,0  1,0 0,1"));
    let name = pinfeed::plan::design::design_name("vertices:0,0 1,0 0,1");
    assert!(name.starts_with("custom-"), "{name}");
    assert_eq!(a, Path::new("pinfeed-out/maps").join(&name));
    assert_eq!(
        pinfeed_cli::sense::default_out_dir("vertices:0,0 2,0 0,1"),
        Path::new("pinfeed-out/sensing").join(b.file_name().unwrap())
    );
}
