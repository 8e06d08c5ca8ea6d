//! Property tests over generated and mutated scenario and study files: the bundled
//! scenarios/*.toml and studies/*.toml and the fixtures, with numbers set to extremes (0,
//! negatives, 5e-324, 1e-200, 1e308, nan, ±inf, huge integers), keys set, deleted, duplicated or
//! renamed, types changed, sections dropped and files truncated
//! (`pinfeed::study::robustness::files`). Parsing, compiling and running a few parts or samples
//! must never panic (proptest reports a panic as a failure) and never hang (parts and samples are
//! bounded); an error is located (file:line:column with an excerpt) or names its cause; an
//! accepted file's run has no NaN or inf. The deeper run is `pinfeed fuzz` (README "Fuzzing and
//! robustness"). Failures proptest finds are kept in tests/fuzz_files.proptest-regressions.

use pinfeed::study::robustness::files::{self, Mutation, Seeds, EXTREMES, KNOWN_KEYS};
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
