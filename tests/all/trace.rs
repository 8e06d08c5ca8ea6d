//! `pinfeed run --trace FILE.jsonl` (issue 53): the trace parses line by line as JSON, its events
//! are in time order, every entry has one beginning (arrival or reentry) and one end (exit, reject
//! or loss); the run's summary is the same with or without it; an unwritable path is refused,
//! naming it, and leaves nothing.

use crate::support::{fresh_dir, pinfeed, pinfeed_ok};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `pinfeed run SCENARIO --parts N --json` with `--trace` (into `dir`) or without: the summary,
/// and the trace's lines parsed.
fn traced(scenario: &str, parts: &str, dir: &Path) -> (Value, Vec<Value>) {
    let trace = dir.join("trace.jsonl");
    let args = ["run", scenario, "--parts", parts, "--quiet", "--json"];
    let with = pinfeed_ok(
        &[
            &args[..],
            &["--out", s(&dir.join("a")), "--trace", s(&trace)],
        ]
        .concat(),
    );
    let without = pinfeed_ok(&[&args[..], &["--out", s(&dir.join("b"))]].concat());
    let summary: Value = serde_json::from_slice(&with.stdout).unwrap();
    assert_eq!(
        summary,
        serde_json::from_slice::<Value>(&without.stdout).unwrap(),
        "the trace changes nothing in the run"
    );
    let text = std::fs::read_to_string(&trace).unwrap();
    let lines = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (summary, lines)
}

/// Kinds per entry, after checking the time order.
fn per_entry(events: &[Value]) -> BTreeMap<u64, Vec<String>> {
    let times: Vec<f64> = events.iter().map(|e| e["t"].as_f64().unwrap()).collect();
    assert!(
        times.windows(2).all(|w| w[0] <= w[1]),
        "events in time order"
    );
    let mut by = BTreeMap::<u64, Vec<String>>::new();
    for e in events {
        if let Some(entry) = e["entry"].as_u64() {
            by.entry(entry)
                .or_default()
                .push(e["kind"].as_str().unwrap().into());
        }
    }
    for (entry, kinds) in &by {
        let count = |ks: &[&str]| kinds.iter().filter(|k| ks.contains(&k.as_str())).count();
        assert_eq!(
            count(&["arrival", "reentry"]),
            1,
            "entry {entry}: {kinds:?}"
        );
        assert!(
            ["arrival", "reentry"].contains(&kinds[0].as_str()),
            "{kinds:?}"
        );
        assert_eq!(
            count(&["exit", "reject", "loss"]),
            1,
            "entry {entry}: {kinds:?}"
        );
    }
    by
}

fn count(events: &[Value], kind: &str) -> u64 {
    events.iter().filter(|e| e["kind"] == kind).count() as u64
}

#[test]
fn a_closed_loop_traces_every_entry_from_its_arrival_to_its_end() {
    let d = fresh_dir("trace-loop");
    let (summary, events) = traced("tripoly1_loop", "30", &d);
    let by = per_entry(&events);
    let l = &summary["closed_loop"];
    assert_eq!(
        by.len() as u64,
        l["passes"].as_u64().unwrap(),
        "one entry a pass"
    );
    assert_eq!(count(&events, "arrival"), 30);
    assert_eq!(
        count(&events, "reentry"),
        l["recirculated"].as_u64().unwrap()
    );
    assert_eq!(
        count(&events, "return"),
        l["recirculated"].as_u64().unwrap()
    );
    assert_eq!(
        count(&events, "reject"),
        l["gate_counts"]["acted"].as_u64().unwrap()
    );
    let delivered = l["fates"]["delivered_ok"].as_u64().unwrap()
        + l["fates"]["delivered_wrong"].as_u64().unwrap();
    assert_eq!(count(&events, "exit"), delivered);
    assert!(count(&events, "reentry") > 0 && count(&events, "contact_begin") > 0);
    let exit = events.iter().find(|e| e["kind"] == "exit").unwrap();
    assert_eq!(exit["pose"].as_array().unwrap().len(), 3);
    assert!(exit["outcome"] == "success" || exit["outcome"] == "wrong_orientation");
    let touch = events
        .iter()
        .find(|e| e["kind"] == "contact_begin")
        .unwrap();
    assert!(["align", "gauge"].contains(&touch["obstacle"].as_str().unwrap()));
}

/// The online controller's line: readings with their labels, decisions, exits and losses.
#[test]
fn a_sensing_line_traces_its_readings_and_decisions() {
    let d = fresh_dir("trace-online");
    let (summary, events) = traced("tripoly1_online", "20", &d);
    let by = per_entry(&events);
    assert_eq!(by.len(), 20);
    assert_eq!(count(&events, "arrival"), 20);
    assert!(count(&events, "reading") > 0 && count(&events, "decision") > 0);
    let reading = events.iter().find(|e| e["kind"] == "reading").unwrap();
    assert!(reading["label"].is_string() && reading["obstacle"].is_string());
    let ended = count(&events, "exit") + count(&events, "loss");
    assert_eq!(ended, summary["parts_in"].as_u64().unwrap());
}

#[test]
fn an_unwritable_trace_is_refused_naming_it() {
    let d = fresh_dir("trace-unwritable");
    std::fs::write(d.join("blocker"), "a file, not a folder").unwrap();
    let path = d.join("blocker/trace.jsonl");
    let out = pinfeed(&[
        "run",
        "quickstart",
        "--parts",
        "5",
        "--out",
        s(&d),
        "--trace",
        s(&path),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("--trace") && err.contains(s(&d.join("blocker"))),
        "{err}"
    );
    assert!(!d.join("quickstart").exists(), "nothing is run");
}

/// The trace and the `sequential` line the documents show are what the commands write.
#[test]
fn the_documented_examples_are_what_the_commands_write() {
    let d = fresh_dir("trace-docs");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let outputs = std::fs::read_to_string(root.join("docs/outputs.md")).unwrap();
    let block = outputs
        .split("--parts 3 --trace loop.jsonl`:\n\n```\n")
        .nth(1)
        .unwrap();
    let shown: Vec<&str> = block.split("\n```").next().unwrap().lines().collect();
    let trace = d.join("loop.jsonl");
    let loop_args = ["run", "tripoly1_loop", "--parts", "3", "--quiet"];
    pinfeed_ok(&[&loop_args[..], &["--out", s(&d), "--trace", s(&trace)]].concat());
    let written = std::fs::read_to_string(&trace).unwrap();
    assert_eq!(shown, written.lines().take(shown.len()).collect::<Vec<_>>());
    let commands = std::fs::read_to_string(root.join("docs/commands.md")).unwrap();
    let out = pinfeed_ok(&["run", "quickstart", "--precision", "0.05", "--out", s(&d)]);
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text.lines().find(|l| l.starts_with("sequential")).unwrap();
    assert!(commands.contains(&format!("```\n{line}\n```")), "{line}");
    let json = std::fs::read_to_string(d.join("quickstart/summary.json")).unwrap();
    let v: Value = serde_json::from_str(&json).unwrap();
    let shown = outputs.split("\"sequential\": ").nth(1).unwrap();
    let shown: Value = serde_json::from_str(shown.split("\n```").next().unwrap()).unwrap();
    assert_eq!(shown, v["sequential"]);
}
