//! Property tests over generated and mutated scenario and study files: the bundled
//! scenarios/*.toml and studies/*.toml and the fixtures, with numbers set to extremes (0,
//! negatives, 5e-324, 1e-200, 1e308, nan, ±inf, huge integers), keys set, deleted, duplicated or
//! renamed, types changed, sections dropped and files truncated
//! (`pinfeed::study::robustness::files`). Parsing, compiling and running a few parts or samples
//! must never panic (proptest reports a panic as a failure) and never hang (parts and samples are
//! bounded); an error is located (file:line:column with an excerpt) or names its cause; an
//! accepted file's run has no NaN or inf. The deeper run is `pinfeed fuzz` (README "Fuzzing and
//! robustness"). Failures proptest finds are kept in tests/fuzz_files.proptest-regressions.

use pinfeed::study::robustness::files::{
    self, Mutation, Seeds, BELIEF_LISTS, EXTREMES, KNOWN_KEYS, RANGED,
};
use pinfeed::study::robustness::{self, Class, Corpus, Options, Target};
use proptest::prelude::*;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn seeds() -> &'static Seeds {
    static SEEDS: OnceLock<Seeds> = OnceLock::new();
    SEEDS.get_or_init(|| Seeds::load(root()).expect("bundled files"))
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<usize>(), 0..EXTREMES.len())
            .prop_map(|(which, value)| Mutation::Number { which, value }),
        2 => (any::<usize>(), -330i32..330).prop_map(|(which, power)| Mutation::Scale { which, power }),
        3 => (0..KNOWN_KEYS.len(), 0usize..64).prop_map(|(key, value)| Mutation::SetKey { key, value }),
        1 => any::<usize>().prop_map(|which| Mutation::DeleteLine { which }),
        1 => any::<usize>().prop_map(|which| Mutation::DuplicateLine { which }),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines { a, b }),
        1 => (any::<usize>(), 0usize..3).prop_map(|(which, how)| Mutation::RenameKey { which, how }),
        1 => (any::<usize>(), 0usize..4).prop_map(|(which, kind)| Mutation::ChangeType { which, kind }),
        1 => any::<usize>().prop_map(|which| Mutation::DropSection { which }),
        1 => (0u32..1000).prop_map(|permille| Mutation::Truncate { permille }),
        1 => (0..RANGED.len(), 0usize..5, 0usize..7).prop_map(|(param, form, at)| Mutation::Ranged { param, form, at }),
        1 => (0..BELIEF_LISTS.len(), 0usize..16).prop_map(|(key, list)| Mutation::Belief { key, list }),
    ]
}

fn mutated(
    files: &[(std::path::PathBuf, String)],
    pick: usize,
    ms: &[Mutation],
) -> (std::path::PathBuf, String) {
    let (path, text) = &files[pick % files.len()];
    let mut t = text.clone();
    for m in ms {
        t = files::apply(&t, m);
    }
    (path.clone(), t)
}

/// Clean ends: located or named errors, or a finite successful run.
fn assert_clean(class: Class, detail: &str, text: &str) {
    assert!(
        matches!(class, Class::Located | Class::Named | Class::Success),
        "{class:?}: {detail}\n--- input ---\n{text}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: crate::support::cases(1500, 6000), rng_seed: proptest::test_runner::RngSeed::Fixed(20261134), .. ProptestConfig::default() })]

    #[test]
    fn mutated_scenarios_are_refused_cleanly_or_run_finitely(
        pick in any::<usize>(),
        ms in prop::collection::vec(mutation(), 1..5),
    ) {
        let (path, text) = mutated(&seeds().scenarios, pick, &ms);
        let r = files::check_scenario(&path, &text);
        assert_clean(r.class, &r.detail, &text);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: crate::support::cases(600, 3000), rng_seed: proptest::test_runner::RngSeed::Fixed(20261135), .. ProptestConfig::default() })]

    #[test]
    fn mutated_studies_are_refused_cleanly_or_run_finitely(
        pick in any::<usize>(),
        ms in prop::collection::vec(mutation(), 1..5),
    ) {
        let (path, text) = mutated(&seeds().studies, pick, &ms);
        let r = files::check_study(&path, &text);
        assert_clean(r.class, &r.detail, &text);
    }
}

/// The unmutated bundled scenarios and studies are accepted and run (so the properties above
/// are not passing only because everything is refused).
#[test]
fn bundled_files_run() {
    for (path, text) in seeds()
        .scenarios
        .iter()
        .filter(|(p, _)| p.starts_with(root().join("scenarios")))
    {
        let r = files::check_scenario(path, text);
        assert_eq!(r.class, Class::Success, "{}: {}", path.display(), r.detail);
    }
    for (path, text) in seeds()
        .studies
        .iter()
        .filter(|(p, _)| p.starts_with(root().join("studies")))
    {
        let r = files::check_study(path, text);
        assert_eq!(r.class, Class::Success, "{}: {}", path.display(), r.detail);
    }
}

/// Every issue 11 reproducer, spelled as a mutation of the quickstart scenario, is a located error.
#[test]
fn issue_reproducers_as_mutations_are_located() {
    let (path, text) = seeds()
        .scenarios
        .iter()
        .find(|(p, _)| p.ends_with("scenarios/quickstart.toml"))
        .expect("quickstart");
    for (from, to) in [
        ("scale = 0.02 ", "scale = 1e-200 "),
        ("scale = 0.02 ", "scale = 1e150 "),
        ("scale = 0.02 ", "scale = 1e-150 "),
        ("speed = 0.05 ", "speed = 5e-324 "),
        ("length = 0.6 ", "length = 1e308 "),
        ("headway = 4.0 ", "headway = 1e308 "),
        ("histogram_bin = 1 ", "histogram_bin = 1e-200 "),
        ("histogram_bin = 1 ", "histogram_bin = 1e-9 "),
    ] {
        assert!(text.contains(from), "{from}");
        let r = files::check_scenario(path, &text.replacen(from, to, 1));
        assert_eq!(r.class, Class::Located, "{to}: {}", r.detail);
    }
}

/// The seed file whose path ends with `name`.
fn seed_file<'a>(
    files: &'a [(std::path::PathBuf, String)],
    name: &str,
) -> &'a (std::path::PathBuf, String) {
    files
        .iter()
        .find(|(p, _)| p.ends_with(name))
        .unwrap_or_else(|| panic!("no seed {name}"))
}

/// The fuzzer's study-range tables (issue 57 item 6): a value just beyond either end of any
/// ranged parameter's documented range, and a normal truncated to one value, are refused where
/// they stand (file, line, column), in every form; a value at an end passes the range check (it
/// runs, or is refused for another reason: a parameter that reaches nothing on this line).
#[test]
fn study_range_tables_beyond_their_ends_are_located() {
    let (path, text) = seed_file(&seeds().studies, "studies/quickstart_mu_tripod.toml");
    for (param, name) in RANGED.iter().enumerate() {
        for (form, at) in [(0, 2), (0, 3), (1, 3), (2, 2), (4, 3), (3, 6)] {
            let t = files::apply(text, &Mutation::Ranged { param, form, at });
            let r = files::check_study(path, &t);
            assert_eq!(r.class, Class::Located, "{name}: {}\n{t}", r.detail);
        }
    }
    // At the ends of μc's range, on a line of pins: it runs.
    for at in [0, 1, 4, 5] {
        let t = files::apply(
            text,
            &Mutation::Ranged {
                param: 0,
                form: 0,
                at,
            },
        );
        let r = files::check_study(path, &t);
        assert_eq!(r.class, Class::Success, "{}\n{t}", r.detail);
    }
}

/// The fuzzer's belief lists (issue 57 item 7): a support or friction listed twice, an empty or
/// unknown list is refused at its line (an empty support list ran, meaning the part's own
/// support, while an empty friction list was refused); distinct values run the online
/// controller.
#[test]
fn belief_lists_with_duplicates_or_none_are_located_and_distinct_ones_run() {
    let (path, text) = seed_file(&seeds().scenarios, "scenarios/tripoly1_online.toml");
    let list = |key: &str, l: &str| {
        let k = BELIEF_LISTS.iter().position(|(n, _)| *n == key).unwrap();
        let j = BELIEF_LISTS[k].1.iter().position(|x| *x == l).unwrap();
        files::apply(text, &Mutation::Belief { key: k, list: j })
    };
    for (key, l) in [
        ("support", "[\"uniform\", \"uniform\"]"),
        ("support", "[\"tripod\", \"uniform\", \"tripod\"]"),
        ("support", "[]"),
        ("support", "[\"bogus\"]"),
        ("mu_c", "[0.5, 0.5]"),
        ("mu_c", "[]"),
        ("mu_c", "[5.01]"),
    ] {
        let t = list(key, l);
        let r = files::check_scenario(path, &t);
        assert_eq!(r.class, Class::Located, "{key} = {l}: {}\n{t}", r.detail);
    }
    for (key, l) in [
        ("support", "[\"uniform\", \"tripod\"]"),
        ("mu_c", "[0.3, 0.7]"),
    ] {
        let t = list(key, l);
        let r = files::check_scenario(path, &t);
        assert_eq!(r.class, Class::Success, "{key} = {l}: {}\n{t}", r.detail);
    }
}

/// The fuzzer's compare cases (issue 57 item 1): designs for one part give each row the same in
/// both orders and alone, with the feed the case imposes; designs for two parts are refused in
/// both orders.
#[test]
fn compare_cases_agree_in_both_orders_and_refuse_two_parts() {
    use pinfeed::scenario::FeedOverrides;
    use pinfeed::study::robustness::compares::{self, CompareCase};
    let corpus = Corpus::load(root()).unwrap();
    let s = &corpus.compare_seeds;
    let at = |name: &str| s.iter().position(|(p, _)| p.ends_with(name)).unwrap();
    let dir = std::env::temp_dir().join(format!("pinfeed-compare-fuzz-{}", std::process::id()));
    let overrides = FeedOverrides {
        parts: Some(4),
        seed: Some(3),
        headway: Some(3.0),
        uniform_orientation: true,
    };
    for (files, expected) in [
        (
            vec![
                "scenarios/quickstart.toml",
                "scenarios/tripoly2_fences.toml",
            ],
            Class::Success,
        ),
        (
            vec![
                "scenarios/tripoly1_sensing.toml",
                "scenarios/tripoly1_online.toml",
                "scenarios/tripoly1.toml",
            ],
            Class::Success,
        ),
        (
            vec!["scenarios/quickstart.toml", "scenarios/tripoly1.toml"],
            Class::Named,
        ),
    ] {
        let c = CompareCase {
            files: files.iter().map(|f| at(f)).collect(),
            overrides,
        };
        let r = compares::run(&c, s, &dir);
        assert_eq!(r.class, expected, "{}: {}", c.command(s), r.detail);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Driver settings for a test: seed, threads, a budget no case reaches.
fn options(seed: u64, threads: usize) -> Options {
    Options {
        seed,
        threads,
        budget: Duration::from_secs(600),
        root: root().to_path_buf(),
    }
}

/// The driver's counts do not depend on the thread count.
#[test]
fn fuzz_driver_is_deterministic_across_threads() {
    let corpus = Arc::new(Corpus::load(root()).unwrap());
    let opts = |threads| options(7, threads);
    let n = u64::from(crate::support::cases(50, 150));
    for target in [Target::Scenarios, Target::Studies, Target::Polygons] {
        let mut one = robustness::run_target(target, n, &corpus, &opts(1), &|_| {});
        let mut two = robustness::run_target(target, n, &corpus, &opts(3), &|_| {});
        one.seconds = 0.0;
        two.seconds = 0.0;
        assert_eq!(one, two, "{}", target.name());
        assert_eq!(one.generated, n);
        assert_eq!(
            one.count(Class::Panic) + one.count(Class::Hang),
            0,
            "{:?}",
            one.problems
        );
    }
}

/// Edited shards: an untouched set merges; every edit of a shard's content is refused.
#[test]
fn merge_tampering_is_refused_and_an_untouched_set_merges() {
    use pinfeed::study::robustness::merges::{self, Tamper};
    let corpus = Corpus::load(root()).unwrap();
    let shards = corpus.shards().unwrap();
    let dir = std::env::temp_dir().join(format!("pinfeed-merge-tamper-{}", std::process::id()));
    let untouched = merges::run(shards, &[], &dir.join("a"));
    assert_eq!(untouched.class, Class::Success, "{}", untouched.detail);
    for (i, edit) in [
        Tamper::Leaf {
            shard: 1,
            leaf: 7,
            how: 0,
        },
        Tamper::Leaf {
            shard: 0,
            leaf: 30,
            how: 3,
        },
        Tamper::Swap {
            sa: 0,
            a: 20,
            sb: 2,
            b: 21,
        },
        Tamper::Delete { shard: 2, leaf: 3 },
        Tamper::Missing { shard: 1 },
        Tamper::Twice { shard: 0 },
    ]
    .into_iter()
    .enumerate()
    {
        let r = merges::run(shards, &[edit], &dir.join(format!("e{i}")));
        assert!(
            matches!(r.class, Class::Named | Class::Located | Class::Success),
            "{edit:?}: {:?} {}",
            r.class,
            r.detail
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
