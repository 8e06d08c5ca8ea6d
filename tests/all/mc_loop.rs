//! Monte Carlo studies of a closed loop (studies/tripoly1_loop_uncertain.toml): one part per
//! sample sent round until delivered or taken off for good. Its purity under friction in
//! [0.3, 0.7] at pins and fences and random tripods; the same report for one or two threads and
//! for merged shards; an open line's report keeps no trace of the loop.

use crate::support::{fresh_dir, pinfeed_json, pinfeed_ok};
use std::path::Path;

const STUDY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/studies/tripoly1_loop_uncertain.toml"
);

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The bundled loop under the harsh set: the 95% Wilson lower bound of its purity is at least
/// 0.995; parts make 2 to 4 passes on average (a third of the passes deliver); the parts taken
/// off for good are counted as `rejected` and success + wrong + rejected + the rest add up.
#[test]
fn the_loop_is_pure_under_uncertain_friction_and_random_tripods() {
    let d = fresh_dir("mc-loop-purity");
    let r = pinfeed_json(&[
        "mc",
        STUDY,
        "--samples",
        "1500",
        "--json",
        "--quiet",
        "--out",
        s(&d),
    ]);
    let p = &r["results"][0];
    let l = &p["closed_loop"];
    assert!(l["purity_ci95"][0].as_f64().unwrap() >= 0.995, "{l}");
    let passes = l["passes_per_part"].as_f64().unwrap();
    assert!((2.0..=4.0).contains(&passes), "{passes}");
    let o = &p["outcomes"];
    let total: u64 = o
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 1500);
    assert!(p["shares"]["rejected"]["count"].as_u64().is_some(), "{p}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// The report is the same for one and two threads, and for two merged shards.
#[test]
fn a_loop_study_is_the_same_for_any_thread_count_and_sharding() {
    let d = fresh_dir("mc-loop-shards");
    let run = |threads: &str| {
        let out = d.join(format!("t{threads}"));
        let o = pinfeed_ok(&[
            "mc",
            STUDY,
            "--samples",
            "60",
            "--threads",
            threads,
            "--json",
            "--quiet",
            "--out",
            s(&out),
        ]);
        o.stdout
    };
    let strip = |b: &[u8]| {
        // The report names its own folder in its command; compare everything else.
        let mut v: serde_json::Value = serde_json::from_slice(b).unwrap();
        v.as_object_mut().unwrap().remove("command");
        v
    };
    let one = run("1");
    assert!(strip(&one) == strip(&run("2")), "1 and 2 threads differ");
    let shards = d.join("shards");
    for k in 0..2 {
        pinfeed_ok(&[
            "mc",
            STUDY,
            "--samples",
            "60",
            "--shard",
            &format!("{k}/2"),
            "--out",
            s(&shards),
            "--quiet",
        ]);
    }
    let files: Vec<String> = (0..2)
        .map(|k| s(&shards.join(format!("shard-000{k}-of-0002.json"))).to_string())
        .collect();
    let merged = d.join("merged");
    let mut args = vec!["merge", "--json", "--quiet", "--out", s(&merged)];
    args.extend(files.iter().map(String::as_str));
    let m = pinfeed_ok(&args);
    assert!(
        strip(&one)["results"] == strip(&m.stdout)["results"],
        "merged shards differ from one run"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// A study of an open line writes no closed-loop field, no `rejected` class and no passes.
#[test]
fn an_open_lines_study_keeps_no_trace_of_the_loop() {
    let d = fresh_dir("mc-loop-open");
    let study = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/studies/quickstart_mu_tripod.toml"
    );
    let out = pinfeed_ok(&[
        "mc",
        study,
        "--samples",
        "20",
        "--json",
        "--quiet",
        "--out",
        s(&d),
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    for word in ["closed_loop", "rejected", "passes"] {
        assert!(!text.contains(word), "{word} in an open line's report");
    }
    std::fs::remove_dir_all(&d).unwrap();
}
