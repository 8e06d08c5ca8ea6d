//! Every JSON document pinfeed prints or writes starts with `schema_version` and
//! `pinfeed_version` (docs/outputs.md#versions-in-json): each JSON-printing command is run on a
//! small input, and the files the commands write are read back.

use crate::support::{fresh_dir, pinfeed_json, pinfeed_ok};
use serde_json::Value;
use std::path::Path;

/// The arguments of `line` split at white space, with `{DIR}` a word for `dir` (which may hold
/// spaces) and `{ROOT}` for the package root.
fn words(line: &str, dir: &Path) -> Vec<String> {
    let root = env!("CARGO_MANIFEST_DIR");
    line.split_whitespace()
        .map(|w| {
            w.replace("{DIR}", dir.to_str().unwrap())
                .replace("{ROOT}", root)
        })
        .collect()
}

fn json_of(line: &str, dir: &Path) -> Value {
    let args = words(line, dir);
    pinfeed_json(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

fn ok(line: &str, dir: &Path) {
    let args = words(line, dir);
    pinfeed_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
}

fn has_versions(what: &str, v: &Value) {
    assert_eq!(v["schema_version"], pinfeed::SCHEMA_VERSION, "{what}: {v}");
    assert_eq!(
        v["pinfeed_version"],
        pinfeed::PINFEED_VERSION,
        "{what}: {v}"
    );
}

fn file(path: &Path) -> Value {
    let text =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{} is not JSON: {e}", path.display()))
}

fn file_has_versions(path: &Path) {
    has_versions(&path.display().to_string(), &file(path));
}

#[test]
fn every_json_a_command_prints_carries_both_versions() {
    let dir = fresh_dir("json-versions-printed");
    ok(
        "calibrate {DIR}/m.csv --synthesize --members 50 --score-members 10 --no-write --quiet",
        &dir,
    );
    let commands = [
        "part tripoly1 --json",
        "contact --part tripoly1 --theta0 10 --d 0.2 --json",
        "map --part tripoly1 --d=0.3 --json --no-write",
        "run quickstart --parts 20 --json --quiet --out {DIR}/runs",
        "compare {ROOT}/scenarios/quickstart.toml {ROOT}/scenarios/tripoly2_fences.toml --parts 20 --json",
        "mc quickstart_mu_tripod --samples 3 --json --quiet --out {DIR}/mc",
        "sense --part tripoly1 --d=0.1 --trials 20 --templates 4 --json --no-write",
        "plan --part square --pins --nominal --check-parts 200 --screen-parts 200 --no-write --json",
        "validate {DIR}/m.csv --members 20 --json --no-write",
        "calibrate {DIR}/m.csv --members 100 --score-members 20 --json --no-write",
    ];
    for line in commands {
        has_versions(line, &json_of(line, &dir));
    }
    // Shards and their merge.
    for k in ["0/2", "1/2"] {
        ok(
            &format!(
                "mc quickstart_mu_tripod --samples 3 --shard {k} --quiet --out {{DIR}}/shards"
            ),
            &dir,
        );
    }
    for f in ["shard-0000-of-0002.json", "shard-0001-of-0002.json"] {
        file_has_versions(&dir.join("shards").join(f));
    }
    let merge = "merge --json --quiet --out {DIR}/merged {DIR}/shards/shard-0000-of-0002.json {DIR}/shards/shard-0001-of-0002.json";
    has_versions("merge", &json_of(merge, &dir));
}

#[test]
fn every_json_file_a_command_writes_carries_both_versions() {
    let dir = fresh_dir("json-versions-written");
    // A line with moving pins and the event log: summary.json, events.json, control.json.
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/scenarios/tripoly1_online.toml")).unwrap();
    let logged = text.replace("[model]", "[effects]\nevent_log = true\n\n[model]");
    std::fs::write(dir.join("logged.toml"), logged).unwrap();
    ok(
        "run {DIR}/logged.toml --parts 12 --quiet --out {DIR}/runs",
        &dir,
    );
    let run_dir = std::fs::read_dir(dir.join("runs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    for (name, key) in [
        ("summary.json", None),
        ("events.json", Some("events")),
        ("control.json", Some("control")),
    ] {
        let v = file(&run_dir.join(name));
        has_versions(name, &v);
        if let Some(key) = key {
            assert!(!v[key].as_array().unwrap().is_empty(), "{name}: {v}");
        }
    }
    let written = [
        ("mc quickstart_mu_tripod --samples 3 --quiet --out {DIR}/mc", "mc/report.json"),
        ("map --part tripoly1 --d=0.3 --out-dir {DIR}/map", "map/map.json"),
        ("map --part tripoly1 --d 0.3 --uncertain mu_c=normal:0.5:0.1 --members 4 --out-dir {DIR}/ens", "ens/ensemble.json"),
        ("sense --part tripoly1 --d=0.1 --trials 20 --templates 4 --quiet --out {DIR}/sense", "sense/sense.json"),
        ("calibrate {DIR}/m.csv --synthesize --members 100 --score-members 20 --quiet --out-dir {DIR}/cal", "cal/calibration.json"),
        ("validate {DIR}/m.csv --members 20 --quiet --out-dir {DIR}/val", "val/validate.json"),
    ];
    for (line, name) in written {
        ok(line, &dir);
        file_has_versions(&dir.join(name));
    }
}
