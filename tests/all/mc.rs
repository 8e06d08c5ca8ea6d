//! Monte Carlo studies (issue 6 acceptance): one run and merged shards give the same bytes, the
//! thread count changes nothing, `merge` refuses shards that do not fit, an interrupted shard job
//! leaves no shard file, bad study files give located errors, and perturbations are reproducible
//! per sample index.

use crate::support::{pinfeed, pinfeed_ok};
use pinfeed::study::mc::{self, sample};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scenario() -> String {
    format!("{}/scenarios/quickstart.toml", env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty folder for one test.
fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinfeed-mc-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every uncertain parameter, a 3 × 2 grid and a handful of samples per point.
const GRID_STUDY: &str = r#"
name = "grid"
seed = 3
samples = 5

[uncertain.mu_c]
distribution = "uniform"
min = 0.3
max = 0.7

[uncertain.belt_speed]
distribution = "normal"
mean = 0.05
sd = 0.005
min = 0.03

[uncertain.shape]
distribution = "normal"
sd = 0.0002

[uncertain.pin_x]
distribution = "triangular"
min = -0.001
mode = 0.0
max = 0.001

[uncertain.pin_y]
distribution = "normal"
sd = 0.001

[uncertain.pin_radius]
distribution = "uniform"
min = -0.0005
max = 0.0005

[uncertain.pose_theta]
distribution = "normal"
sd = 2.0

[uncertain.pose_y]
distribution = "uniform"
min = -0.001
max = 0.001

[uncertain.support]
model = "tripod"

[[sweep]]
parameter = "shape.sd"
values = [0.0, 0.0005, 0.001]

[[sweep]]
parameter = "mu_c.max"
from = 0.6
to = 0.8
steps = 2
"#;

fn write_study(dir: &Path, body: &str) -> PathBuf {
    let p = dir.join("study.toml");
    std::fs::write(&p, format!("scenario = \"{}\"\n{body}", scenario())).unwrap();
    p
}

/// The command must fail with exit code 1, print nothing on stdout, and not panic; returns stderr.
pub(crate) fn refused(args: &[&str]) -> String {
    let out = pinfeed(args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?} printed a result");
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    stderr
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const REPORT_FILES: [&str; 3] = ["report.md", "report.json", "sensitivity.svg"];

#[test]
fn four_merged_shards_give_the_same_bytes_as_one_run() {
    let d = tmp("shards");
    let study = write_study(&d, GRID_STUDY);
    let full = d.join("full");
    let one = pinfeed_ok(&["mc", s(&study), "--json", "--quiet", "--out", s(&full)]);
    let shards = d.join("shards");
    for k in 0..4 {
        pinfeed_ok(&[
            "mc",
            s(&study),
            "--shard",
            &format!("{k}/4"),
            "--out",
            s(&shards),
            "--quiet",
        ]);
    }
    // Given in any order.
    let files: Vec<String> = [3, 1, 0, 2]
        .iter()
        .map(|k| s(&shards.join(format!("shard-000{k}-of-0004.json"))).to_string())
        .collect();
    // The merge writes into the same folder (a report's command names its folder), after the
    // full run's files are read and removed.
    let before: Vec<Vec<u8>> = REPORT_FILES
        .iter()
        .map(|f| std::fs::read(full.join(f)).unwrap())
        .collect();
    std::fs::remove_dir_all(&full).unwrap();
    let merged = full.clone();
    let mut args = vec!["merge", "--json", "--quiet", "--out", s(&merged)];
    args.extend(files.iter().map(String::as_str));
    let m = pinfeed_ok(&args);
    assert_eq!(one.stdout, m.stdout, "JSON on stdout differs");
    for (f, a) in REPORT_FILES.iter().zip(before) {
        let b = std::fs::read(merged.join(f)).unwrap();
        assert!(
            a == b,
            "{f} differs between the full run and the merged shards"
        );
    }
    // The report covers every sample of the 3 × 2 grid.
    let r: serde_json::Value = serde_json::from_slice(&one.stdout).unwrap();
    assert_eq!(r["total_samples"], 30);
    assert_eq!(r["results"].as_array().unwrap().len(), 6);
    // The table (not JSON) is the same too.
    let t1 = pinfeed_ok(&["mc", s(&study), "--out", s(&full)]);
    let mut args = vec!["merge", "--out", s(&merged)];
    args.extend(files.iter().map(String::as_str));
    let t2 = pinfeed_ok(&args);
    let table = |o: &Output| {
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter(|l| l.starts_with('|'))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(table(&t1), table(&t2));
    assert!(table(&t1).contains("| shape.sd | mu_c.max | samples | success % [95% CI]"));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn one_and_two_threads_give_identical_results() {
    let d = tmp("threads");
    let body = r#"
samples = 24
[uncertain.mu_c]
distribution = "uniform"
min = 0.3
max = 0.7
[uncertain.support]
model = "smooth"
bumps = 2
points = 24
"#;
    let study = write_study(&d, body);
    let (a, b) = (d.join("a"), d.join("b"));
    pinfeed_ok(&["mc", s(&study), "--threads", "1", "--quiet", "--out", s(&a)]);
    pinfeed_ok(&["mc", s(&study), "--threads", "2", "--quiet", "--out", s(&b)]);
    for f in REPORT_FILES {
        assert_eq!(
            crate::support::report_text(&a, f),
            crate::support::report_text(&b, f),
            "{f}"
        );
    }
    // And sample by sample, through the library.
    let st = mc::load(&study, None).unwrap();
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            use rayon::prelude::*;
            (0..st.total_samples())
                .into_par_iter()
                .map(|g| mc::run::run_global(&st, g).unwrap())
                .collect::<Vec<_>>()
        })
    };
    assert_eq!(run(1), run(2));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn merge_refuses_shards_that_do_not_fit() {
    let d = tmp("refuse");
    let study = write_study(
        &d,
        "samples = 20\n[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = 0.4\nmax = 0.6\n",
    );
    let shards = d.join("shards");
    // One folder per run (`label`): the same spec of another study must not overwrite a file.
    let run_shard = |label: &str, spec: &str, extra: &[&str]| {
        let dir = shards.join(label);
        let mut args = vec![
            "mc",
            s(&study),
            "--shard",
            spec,
            "--quiet",
            "--out",
            s(&dir),
        ];
        args.extend_from_slice(extra);
        pinfeed_ok(&args);
        let k: Vec<&str> = spec.split('/').collect();
        dir.join(format!(
            "shard-{:04}-of-{:04}.json",
            k[0].parse::<u32>().unwrap(),
            k[1].parse::<u32>().unwrap()
        ))
    };
    let a0 = run_shard("a0", "0/2", &[]);
    let a1 = run_shard("a1", "1/2", &[]);
    let b1 = run_shard("b1", "1/3", &[]);
    let merged = d.join("merged");
    let merge = |files: &[&Path]| {
        let mut args = vec!["merge", "--out", s(&merged)];
        args.extend(files.iter().map(|p| s(p)));
        refused(&args)
    };
    // Missing: half the samples.
    let e = merge(&[&a0]);
    assert!(e.contains("samples [10, 20) are missing"), "{e}");
    // Overlapping: the same shard twice, and shards of different splits.
    let e = merge(&[&a0, &a1, &a1]);
    assert!(e.contains("shards overlap"), "{e}");
    let e = merge(&[&a0, &a1, &b1]);
    assert!(e.contains("shards overlap") && e.contains("[6, 13)"), "{e}");
    // Mismatched: another sample count is another study.
    // A gap of one sample between shards of different splits ([0, 5) of 4, [6, 20) of 3) is
    // named as missing, with the rerun help, not found later as a point short of samples.
    let q0 = run_shard("q0", "0/4", &[]);
    let t1 = run_shard("t1", "1/3", &[]);
    let t2 = run_shard("t2", "2/3", &[]);
    let e = merge(&[&q0, &t1, &t2]);
    assert!(e.contains("samples [5, 6) are missing"), "{e}");
    // The rerun help counts only the shards of the first file's split (4): 1/3 is not 1/4.
    assert!(
        e.contains("rerun only the missing shards of 4:") && e.contains("--shard 1/4 "),
        "{e}"
    );
    // Overlapping by one sample ([0, 6) of 3, [5, 10) of 4).
    let t0 = run_shard("t0", "0/3", &[]);
    let q1 = run_shard("q1", "1/4", &[]);
    let q2 = run_shard("q2", "2/4", &[]);
    let q3 = run_shard("q3", "3/4", &[]);
    let e = merge(&[&t0, &q1, &q2, &q3]);
    assert!(e.contains("shards overlap") && e.contains("[5, 10)"), "{e}");
    let c1 = run_shard("c1", "1/2", &["--samples", "30"]);
    let e = merge(&[&a0, &c1]);
    assert!(e.contains("belongs to a different study"), "{e}");
    // Another seed changes the study file, hence the hash.
    let text = std::fs::read_to_string(&study).unwrap();
    std::fs::write(
        &study,
        text.replace("samples = 20", "seed = 99\nsamples = 20"),
    )
    .unwrap();
    let s1 = run_shard("seed", "1/2", &[]);
    let e = merge(&[&a0, &s1]);
    assert!(e.contains("different study"), "{e}");
    // Another pinfeed version.
    let v1 = d.join("v1.json");
    let t = std::fs::read_to_string(&a1).unwrap();
    std::fs::write(
        &v1,
        t.replace("\"pinfeed_version\": \"", "\"pinfeed_version\": \"9"),
    )
    .unwrap();
    // (A hand-edited shard no longer matches its checksum, issue 28.)
    let e = merge(&[&a0, &v1]);
    assert!(e.contains("field `checksum`"), "{e}");
    // Counts that do not add up to the shard's range.
    let bad = d.join("bad.json");
    std::fs::write(&bad, t.replace("\"samples\": 10", "\"samples\": 9")).unwrap();
    let e = merge(&[&a0, &bad]);
    assert!(e.contains("field `checksum`"), "{e}");
    // Not a shard at all.
    let junk = d.join("junk.json");
    std::fs::write(&junk, "{\"hello\": 1}").unwrap();
    let e = merge(&[&junk]);
    assert!(e.contains("not a pinfeed shard file"), "{e}");
    assert!(!merged.exists(), "a refused merge wrote a report");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Run `study` as shards 0/2 and 1/2 into `shards`; their paths.
fn two_shards(study: &Path, shards: &Path) -> [PathBuf; 2] {
    [0, 1].map(|k| {
        let spec = format!("{k}/2");
        pinfeed_ok(&[
            "mc",
            s(study),
            "--shard",
            &spec,
            "--quiet",
            "--out",
            s(shards),
        ]);
        shards.join(format!("shard-{k:04}-of-0002.json"))
    })
}

/// Issue 57 item 19: a shard whose counts were edited (successes and wrong orientations swapped:
/// every total still adds up) and whose `checksum` was left as it was, blanked or removed is
/// refused, with the file, the field's line and what is wrong; only a checksum recomputed over the
/// edit gets through (it is not cryptographic), and then the counts change the report.
#[test]
fn merge_refuses_a_shard_whose_checksum_is_blank_or_missing() {
    let d = tmp("checksum");
    let study = write_study(&d, "samples = 8\n");
    let [a0, a1] = two_shards(&study, &d.join("shards"));
    let merged = d.join("merged");
    let success = |dir: &Path| -> serde_json::Value {
        let r: serde_json::Value =
            serde_json::from_str(&crate::support::report_text(dir, "report.json")).unwrap();
        r["results"][0]["outcomes"]["success"].clone()
    };
    pinfeed_ok(&["merge", "--quiet", "--out", s(&merged), s(&a0), s(&a1)]);
    let honest = success(&merged);
    std::fs::remove_dir_all(&merged).unwrap();

    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&a1).unwrap()).unwrap();
    let o = &mut v["points"][0]["outcomes"];
    let (ok, wrong) = (o["success"].clone(), o["wrong_orientation"].clone());
    assert_ne!(ok, wrong, "the swap must change the counts");
    (o["success"], o["wrong_orientation"]) = (wrong, ok);
    let edited = d.join("edited.json");
    let write = |v: &serde_json::Value| {
        let text = serde_json::to_string_pretty(v).unwrap() + "\n";
        std::fs::write(&edited, &text).unwrap();
        // The line of the `checksum` key, 1-based.
        text.lines()
            .position(|l| l.contains("\"checksum\""))
            .map(|i| i + 1)
    };
    let kept = v["checksum"].as_str().unwrap().to_string();
    for (what, checksum) in [
        ("kept", Some(kept.as_str())),
        ("blank", Some("")),
        ("blank", Some("  ")),
        ("missing", None),
    ] {
        let mut e = v.clone();
        match checksum {
            Some(c) => e["checksum"] = c.into(),
            None => {
                e.as_object_mut().unwrap().remove("checksum");
            }
        }
        let line = write(&e);
        let err = refused(&["merge", "--quiet", "--out", s(&merged), s(&a0), s(&edited)]);
        let at = match line {
            Some(l) => format!("{}:{l}: field `checksum` ", edited.display()),
            None => format!("{}: field `checksum` is missing", edited.display()),
        };
        assert!(err.contains(&at), "{what}: {err}");
        let why = match what {
            "kept" => format!("is \"{kept}\" but the content gives "),
            "blank" => "is blank".to_string(),
            _ => "is missing".to_string(),
        };
        assert!(err.contains(&why), "{what}: {err}");
        assert!(err.contains("was edited or damaged"), "{what}: {err}");
        assert!(!merged.exists(), "{what}: a refused merge wrote a report");
        // The library refuses it too.
        assert!(mc::shard::read(&edited).is_err(), "{what}");
    }
    // Resealed, the edited counts merge and change the report: the checksum is what stops them.
    let mut sealed: mc::shard::ShardFile = serde_json::from_value(v.clone()).unwrap();
    sealed.checksum = sealed.content_checksum();
    std::fs::write(&edited, serde_json::to_string_pretty(&sealed).unwrap()).unwrap();
    pinfeed_ok(&["merge", "--quiet", "--out", s(&merged), s(&a0), s(&edited)]);
    assert_ne!(
        success(&merged),
        honest,
        "the edit changed no report number"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// Issue 57 item 13: merge's "rerun only the missing shards" commands name the study from the
/// folder merge runs in, not as the shard job named it from its own folder: run as printed, from
/// there, they write the missing shard and the merge goes through.
#[test]
fn merge_s_rerun_commands_work_from_where_they_are_printed() {
    let d = tmp("rerun-here");
    let job = d.join("job");
    std::fs::create_dir_all(&job).unwrap();
    write_study(&job, "samples = 8\n");
    // The shard job runs in its own folder and names the study relative to it.
    let o = crate::support::pinfeed_in(
        &job,
        &[
            "mc",
            "study.toml",
            "--shard",
            "0/2",
            "--quiet",
            "--out",
            "shards",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let merge = [
        "merge",
        "job/shards/shard-0000-of-0002.json",
        "job/shards/shard-0001-of-0002.json",
    ];
    let o =
        crate::support::pinfeed_in(&d, &[&merge[..2], &["--quiet", "--out", "merged"]].concat());
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    let rerun = err
        .lines()
        .find(|l| l.trim_start().starts_with("pinfeed mc "))
        .unwrap_or_else(|| panic!("no rerun command: {err}"));
    assert!(rerun.contains("pinfeed mc job/study.toml "), "{err}");
    let words: Vec<&str> = rerun.split_whitespace().skip(1).collect();
    let o = crate::support::pinfeed_in(&d, &words);
    assert!(
        o.status.success(),
        "`{rerun}` fails where it is printed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = crate::support::pinfeed_in(&d, &[&merge[..], &["--quiet", "--out", "merged"]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(&d).unwrap();
}

/// Issue 57 item 4: a report written into the user's folder heads with the command as the user
/// runs it (`pinfeed mc study.toml …`, not `cargo run --release -- …`, which runs only in the
/// source tree), and that command rewrites the report from there.
#[test]
fn a_report_in_the_user_s_folder_names_the_command_as_run() {
    let d = tmp("as-run");
    write_study(&d, "samples = 4\n");
    crate::support::pinfeed_in(&d, &["mc", "study.toml", "--quiet", "--out", "rep"]);
    let md = std::fs::read_to_string(d.join("rep/report.md")).unwrap();
    assert!(!md.contains("cargo run"), "{md}");
    let line = md
        .lines()
        .find(|l| l.starts_with("pinfeed mc "))
        .unwrap_or_else(|| panic!("no command: {md}"));
    assert_eq!(line, "pinfeed mc study.toml --samples 4 --out rep");
    std::fs::remove_dir_all(d.join("rep")).unwrap();
    let words: Vec<&str> = line.split_whitespace().skip(1).collect();
    let o = crate::support::pinfeed_in(&d, &[&words[..], &["--quiet"]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(d.join("rep/report.md").is_file());
    // `sense` writes its report the same way.
    let o = crate::support::pinfeed_in(
        &d,
        &[
            "sense", "--part", "tripoly1", "--d=-0.2", "--trials", "3", "--out", "sense",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(d.join("sense/report.md")).unwrap();
    assert!(!md.contains("cargo run"), "{md}");
    assert!(md.contains("\n    pinfeed sense --part tripoly1 "), "{md}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Issue 57 item 16: a sweep given as `from`, `to`, `steps` printed the values it computes with
/// every digit (`0.9000000000000001`, `0.3666666666666667`) in the report, its table and the
/// figure's legend; they print rounded to 6 significant digits, while report.json keeps every
/// digit (it is read back by programs).
#[test]
fn a_swept_range_prints_its_computed_values_rounded() {
    let d = tmp("sweep-digits");
    let study = write_study(
        &d,
        "samples = 2\n[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = 0.05\nmax = 0.7\n\
         [uncertain.pose_theta]\ndistribution = \"normal\"\nsd = 1\n\
         [[sweep]]\nparameter = \"mu_c.max\"\nfrom = 0.1\nto = 0.9\nsteps = 4\n\
         [[sweep]]\nparameter = \"pose_theta.sd\"\nfrom = 0.1\nto = 0.5\nsteps = 3\n",
    );
    let out = d.join("rep");
    pinfeed_ok(&["mc", s(&study), "--quiet", "--out", s(&out)]);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("- swept: `mu_c.max` over 0.1, 0.366667, 0.633333, 0.9\n"),
        "{md}"
    );
    assert!(
        md.contains("- swept: `pose_theta.sd` over 0.1, 0.3, 0.5\n"),
        "{md}"
    );
    assert!(md.contains("\n| 0.9 | 0.3 | 2 |"), "{md}");
    // The figure's words (not its attributes, whose font sizes carry digits of their own).
    let svg = std::fs::read_to_string(out.join("sensitivity.svg")).unwrap();
    let words: Vec<&str> = svg
        .split('>')
        .filter_map(|p| p.split('<').next())
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .collect();
    assert!(words.contains(&"pose_theta.sd = 0.3"), "{words:?}");
    let words = words.join("\n");
    for text in [&md, &words] {
        assert!(
            !text.contains("0000000") && !text.contains("6666666") && !text.contains("3333333"),
            "a value with every digit: {text}"
        );
    }
    let json = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(json.contains("0.9000000000000001"), "{json}");
    std::fs::remove_dir_all(&d).ok();
}

/// A shard rewritten with `edit` and its checksum recomputed: it reads, but its counts are what
/// `edit` made them.
fn resealed(from: &Path, to: &Path, edit: impl FnOnce(&mut mc::shard::ShardFile)) -> PathBuf {
    let mut f = mc::shard::read(from).unwrap();
    edit(&mut f);
    f.checksum = f.content_checksum();
    std::fs::write(to, serde_json::to_string_pretty(&f).unwrap() + "\n").unwrap();
    to.to_path_buf()
}

#[test]
fn merge_refuses_resealed_shards_whose_counts_do_not_hang_together() {
    use mc::shard::ShardPointError;
    use mc::StudyError;
    let d = tmp("resealed");
    let study = write_study(&d, "samples = 4\n");
    let [a0, a1] = two_shards(&study, &d.join("shards"));
    let merge = |second: &Path| {
        let files: Vec<_> = [&a0, second]
            .iter()
            .map(|p| (p.to_path_buf(), mc::shard::read(p).unwrap()))
            .collect();
        let e = mc::shard::merge(&files).unwrap_err();
        let cli = refused(&["merge", "--out", s(&d.join("merged")), s(&a0), s(second)]);
        assert_eq!(cli, format!("error: {e}\n"));
        e
    };
    // An outcome count one short of the point's samples.
    let short = resealed(&a1, &d.join("short.json"), |f| {
        *f.points[0].outcomes.values_mut().find(|n| **n > 0).unwrap() -= 1;
    });
    let e = merge(&short);
    assert!(
        matches!(
            &e,
            StudyError::ShardPoint {
                path,
                error: ShardPointError::OutcomeTotal { point: 0, total: 1, samples: 2 },
            } if *path == short
        ),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        format!(
            "{}: point 0: the outcome counts add up to 1, not to its 2 samples",
            short.display()
        )
    );
    // A point index beyond the study's grid (one point: index 1) is refused, not a panic.
    let beyond = resealed(&a1, &d.join("beyond.json"), |f| f.points[0].point = 1);
    let e = merge(&beyond);
    assert!(
        e.to_string()
            .contains("point 1 holds 2 samples but the shard's range [2, 4) gives it 0"),
        "{e}"
    );
    // Online counts without their calibration bins.
    let online = resealed(&a1, &d.join("online.json"), |f| {
        f.points[0].online.decisions = 1;
    });
    let e = merge(&online);
    assert!(
        matches!(
            &e,
            StudyError::ShardPoint {
                error: ShardPointError::Online { point: 0, .. },
                ..
            }
        ),
        "{e:?}"
    );
    assert_eq!(
        e.to_string(),
        format!(
            "{}: point 0: online: 0 calibration bins, not 10",
            online.display()
        )
    );
    // A shard that lacks the counts of a point its range touches: the point ends up short
    // (a mutant checking only for too many samples after merging passed every test).
    let lacking = resealed(&a1, &d.join("lacking.json"), |f| f.points.clear());
    let e = merge(&lacking);
    assert!(
        e.to_string()
            .contains("point 0 has 2 samples after merging, expected 4"),
        "{e}"
    );
    // An extra point just past the grid (index 1 of one point) with no samples: refused, not
    // an index out of bounds (a mutant testing `point > len` passed every test).
    let extra = resealed(&a1, &d.join("extra.json"), |f| {
        let mut p = f.points[0].clone();
        p.point = 1;
        p.samples = 0;
        p.outcomes.values_mut().for_each(|n| *n = 0);
        f.points.push(p);
    });
    let e = merge(&extra);
    assert!(
        e.to_string()
            .contains("point 1 holds 0 samples but the shard's range [2, 4) gives it 0"),
        "{e}"
    );
    assert!(!d.join("merged").exists(), "a refused merge wrote a report");
    std::fs::remove_dir_all(&d).unwrap();
}

/// File names in `dir` (none if it does not exist).
fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().to_string())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// A shard job killed between writing its shard and renaming it into place leaves no shard file
/// (or the previous one, untouched), and a rerun writes the shard whole. The kill is injected, not
/// timed: `PINFEED_FAULT=after-temp-write` aborts the process right after the hidden temporary file
/// is complete and before the rename (crates/pinfeed/src/study/mc/atomic.rs). The test fails if the shard were
/// written in place (a `shard-*` file after the abort, or the previous one changed), if the fault
/// struck before the bytes were complete (the temporary file differs from what the rerun writes),
/// if the rename came before the fault point, or if the rerun did not write a whole, readable shard.
#[test]
fn an_interrupted_shard_job_leaves_no_shard_file() {
    let d = tmp("interrupt");
    let study = write_study(&d, "samples = 20\n");
    let out = d.join("shards");
    let args = [
        "mc",
        s(&study),
        "--shard",
        "0/1",
        "--quiet",
        "--out",
        s(&out),
    ];
    let final_name = "shard-0000-of-0001.json";
    // Runs the job with the fault; returns the bytes of the temporary file it left (one not in
    // `earlier`: its name carries the job's pid).
    let killed_run = |earlier: &[String]| {
        let o = Command::new(env!("CARGO_BIN_EXE_pinfeed"))
            .args(args)
            .env("PINFEED_FAULT", "after-temp-write")
            .output()
            .expect("run pinfeed");
        assert!(
            !o.status.success(),
            "the injected fault did not stop the job"
        );
        #[cfg(unix)]
        {
            use std::os::unix::process::ExitStatusExt;
            assert_eq!(
                o.status.signal(),
                Some(6),
                "not killed by SIGABRT: {:?}",
                o.status
            );
        }
        let temps: Vec<String> = names_in(&out)
            .into_iter()
            .filter(|n| n.starts_with(&format!(".{final_name}.tmp-")) && !earlier.contains(n))
            .collect();
        assert_eq!(temps.len(), 1, "{:?}", names_in(&out));
        std::fs::read(out.join(&temps[0])).unwrap()
    };
    // 1. No shard yet: the killed job leaves none under the final name.
    let interrupted = killed_run(&[]);
    assert!(
        names_in(&out).iter().all(|n| !n.starts_with("shard-")),
        "shard file left behind by a killed job: {:?}",
        names_in(&out)
    );
    // 2. A rerun writes it whole: the same bytes the killed job had complete in its temporary file.
    pinfeed_ok(&args);
    let shard_path = out.join(final_name);
    let whole = std::fs::read(&shard_path).expect("the rerun wrote the shard");
    assert_eq!(
        whole, interrupted,
        "the rerun's shard differs from the killed job's bytes"
    );
    let shard = pinfeed::study::mc::shard::read(&shard_path).unwrap();
    assert_eq!(shard.samples, [0, 20]);
    assert_eq!(shard.points.iter().map(|p| p.samples).sum::<u64>(), 20);
    // 3. A job killed while an earlier shard file is in place leaves that file as it was.
    let earlier = names_in(&out);
    std::fs::write(&shard_path, b"earlier shard").unwrap();
    killed_run(&earlier);
    assert_eq!(std::fs::read(&shard_path).unwrap(), b"earlier shard");
    // ... and a rerun replaces it whole.
    pinfeed_ok(&args);
    assert_eq!(std::fs::read(&shard_path).unwrap(), whole);
    std::fs::remove_dir_all(&d).unwrap();
}

fn fixture(name: &str) -> String {
    format!(
        "{}/tests/fixtures/studies/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// `pinfeed mc FIXTURE` fails with `FILE:LINE:COLUMN: key `KEY`: ...` containing every word.
fn assert_located(name: &str, line: usize, column: usize, key: &str, words: &[&str]) {
    let out_dir = tmp(&format!("bad-{name}"));
    let e = refused(&["mc", &fixture(name), "--out", s(&out_dir)]);
    let head = format!("{name}:{line}:{column}: key `{key}`: ");
    assert!(e.contains(&head), "{name}: expected '{head}' in:\n{e}");
    for w in words {
        assert!(e.contains(w), "{name}: expected '{w}' in:\n{e}");
    }
    assert!(
        e.contains(&format!("{line} | ")),
        "{name}: no excerpt:\n{e}"
    );
    std::fs::remove_dir_all(&out_dir).unwrap();
}

#[test]
fn bad_study_files_give_located_errors() {
    assert_located(
        "unknown_key.toml",
        5,
        12,
        "uncertain.mu_cc",
        &["unknown field `mu_cc`", "`mu_c`"],
    );
    assert_located(
        "negative_friction.toml",
        7,
        7,
        "uncertain.mu_c.min",
        &["mu_c must be at least 0", "-0.1"],
    );
    assert_located(
        "wrong_field.toml",
        9,
        6,
        "uncertain.pin_y.sd",
        &["does not apply to this distribution, which takes min, max"],
    );
    assert_located(
        "undeclared_sweep.toml",
        6,
        13,
        "sweep[0].parameter",
        &["[uncertain.shape] is not declared"],
    );
    assert_located(
        "bad_sweep_value.toml",
        9,
        1,
        "sweep[0]",
        &["at mu_c = -0.2", "must be at least 0"],
    );
    assert_located(
        "missing_scenario.toml",
        2,
        12,
        "scenario",
        &["cannot read the scenario", "relative to the study file"],
    );
    assert_located(
        "wrong_type.toml",
        3,
        11,
        "samples",
        &["invalid type: string \"many\""],
    );
    assert_located(
        "bad_support.toml",
        6,
        9,
        "uncertain.support.model",
        &["unknown variant `warped`", "`smooth`"],
    );
}

/// The study with every parameter, loaded through the library.
fn grid_study(name: &str) -> (PathBuf, mc::Study) {
    let d = tmp(name);
    let p = write_study(&d, GRID_STUDY);
    let st = mc::load(&p, None).unwrap();
    (d, st)
}

#[test]
fn perturbations_are_reproducible_per_sample_index() {
    let (d, st) = grid_study("repro");
    let key = |point: usize, i: u64| {
        let ds = sample::draw_scene(&st.scene, &st.points[point], st.seed, i).unwrap();
        let sc = ds.scene;
        (
            format!("{:?}", sc.part.polygon.vertices()),
            format!("{:?}", sc.obstacles),
            format!("{:?} {:?}", sc.feed.orientation, sc.feed.lateral),
            sc.contact.mu_c,
            sc.belt.speed,
        )
    };
    let first = key(3, 4);
    // Other samples drawn in between change nothing.
    for i in 0..4 {
        key(3, i);
    }
    assert_eq!(first, key(3, 4));
    assert_ne!(first.0, key(3, 5).0);
    assert_ne!(first.1, key(3, 5).1);
    assert_ne!(first.2, key(3, 5).2);
    // Common random numbers: at shape.sd 0.001 each vertex moves exactly twice as far as at
    // 0.0005 (points 4 and 2 share mu_c.max), before re-centring on the new centroid.
    let base = st.scene.part.polygon.vertices().to_vec();
    let offsets = |point: usize| {
        let ds = sample::draw_scene(&st.scene, &st.points[point], st.seed, 7).unwrap();
        let v = ds.scene.part.polygon.vertices().to_vec();
        // Undo the re-centring: the polygon's offset is where its centroid moved.
        let off = ds.scene.part.polygon.offset();
        v.iter()
            .zip(&base)
            .map(|(a, b)| (a.x + off.x - b.x, a.y + off.y - b.y))
            .collect::<Vec<_>>()
    };
    let (half, full) = (offsets(2), offsets(4));
    for (h, f) in half.iter().zip(&full) {
        assert!((2.0 * h.0 - f.0).abs() < 1e-12 && (2.0 * h.1 - f.1).abs() < 1e-12);
    }
    assert!(half.iter().any(|h| h.0.abs() > 1e-6));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn invalid_perturbed_polygons_are_redrawn_or_reported() {
    let d = tmp("shape");
    let big = |sd: f64, support: &str| {
        let p = write_study(
            &d,
            &format!("samples = 10\n[uncertain.shape]\ndistribution = \"normal\"\nsd = {sd}\n[uncertain.support]\nmodel = \"{support}\"\n"),
        );
        mc::load(&p, None).unwrap()
    };
    // 3 cm vertex errors on a 4 cm part: many triangles no longer fit the 10 cm belt.
    let st = big(0.03, "uniform");
    let mut redraws = 0;
    for i in 0..10 {
        let ds = sample::draw_scene(&st.scene, &st.points[0], st.seed, i).unwrap();
        assert!(2.0 * ds.scene.part.radius <= st.scene.belt.width);
        redraws += ds.shape_redraws;
    }
    assert!(redraws > 0);
    // 10 m errors: no valid part comes out; a clear error, no panic, no endless loop.
    // Slivers that cannot carry a tripod around their centroid are redrawn too, never an error.
    // The shape streams are the same for both supports (one stream per parameter), so any extra
    // redraw under the tripod is a sliver the tripod could not stand on.
    let redraws = |support: &str| {
        let st = big(0.008, support);
        (0..40)
            .map(|i| {
                sample::draw_scene(&st.scene, &st.points[0], st.seed, i)
                    .unwrap()
                    .shape_redraws
            })
            .sum::<u32>()
    };
    let (uniform, tripod) = (redraws("uniform"), redraws("tripod"));
    assert!(tripod > uniform, "tripod {tripod}, uniform {uniform}");
    let st = big(0.03, "uniform");
    let mut p = st.points[0].clone();
    p.shape = Some(mc::distribution::Distribution::Normal {
        mean: 0.0,
        sd: 10.0,
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    });
    let e = sample::draw_scene(&st.scene, &p, st.seed, 0)
        .err()
        .expect("refused");
    assert!(
        matches!(e, sample::SampleError::Shape { last: Some(_) }),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("shape tolerance is too large"),
        "{e}"
    );
    // The study file says so when it is read, at the table (the first sample cannot be drawn).
    write_study(
        &d,
        "samples = 10\n[uncertain.shape]\ndistribution = \"normal\"\nsd = 10.0\n",
    );
    let e = refused(&["mc", s(&d.join("study.toml")), "--out", s(&d.join("o"))]);
    assert!(
        e.contains("key `uncertain.shape`: no valid sample can be drawn on this scenario: shape:"),
        "{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_study_without_uncertainty_reproduces_the_nominal_line() {
    let d = tmp("nominal");
    let p = write_study(&d, "samples = 40\n");
    let out = pinfeed_ok(&["mc", s(&p), "--json", "--quiet", "--out", s(&d.join("o"))]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The quickstart layout brings every part to 16° ± 3° (scenarios/quickstart.toml).
    assert_eq!(r["results"][0]["outcomes"]["success"], 40, "{r}");
    assert_eq!(r["results"][0]["shares"]["success"]["ci95"][1], 1.0);
    std::fs::remove_dir_all(&d).unwrap();
}

/// A study over a map-tier scene: samples that share a map's inputs share one map (built once,
/// cached); where μc varies from sample to sample each sample would need its own map, so those
/// samples run the exact model, build no map, and the report says so.
#[test]
fn a_map_scene_builds_one_map_per_input_not_per_sample() {
    let d = tmp("map-scene");
    let text = std::fs::read_to_string(scenario()).unwrap().replace(
        "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"",
        "fidelity = \"map\"\nmap_grid = [8, 2, 0]",
    );
    assert!(text.contains("map_grid"));
    let scene = d.join("map.toml");
    std::fs::write(&scene, text).unwrap();
    let study = |name: &str, mu: &str| {
        let p = d.join(format!("{name}.toml"));
        let body = format!(
            "scenario = \"{}\"\nname = \"{name}\"\nsamples = 6\n\n[uncertain.mu_c]\n{mu}\n\n[uncertain.pose_theta]\ndistribution = \"normal\"\nsd = 2.0\n",
            s(&scene)
        );
        std::fs::write(&p, body).unwrap();
        p
    };
    let run = |p: &Path, cache: &Path| {
        let out = Command::new(env!("CARGO_BIN_EXE_pinfeed"))
            .args(["mc", s(p), "--json", "--quiet", "--out", s(&d.join("o"))])
            .env("PINFEED_CACHE", cache)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let maps = std::fs::read_dir(cache).map_or(0, |r| r.count());
        (r, maps)
    };
    // μc fixed: one map per pin (the quickstart's pins share radius and μc: one file).
    let (fixed, maps) = run(
        &study("fixed", "distribution = \"fixed\"\nvalue = 0.45"),
        &d.join("cache-fixed"),
    );
    assert_eq!(fixed["fidelity"], "map", "{fixed}");
    assert_eq!(maps, 1);
    // μc drawn per sample: no map at all, the samples run the exact model.
    let (varied, maps) = run(
        &study("varied", "distribution = \"uniform\"\nmin = 0.4\nmax = 0.6"),
        &d.join("cache-varied"),
    );
    let fidelity = varied["fidelity"].as_str().unwrap();
    assert!(
        fidelity.starts_with("exact (map tier off: `mu_c` varies"),
        "{fidelity}"
    );
    assert_eq!(maps, 0);
    assert_eq!(varied["results"][0]["samples"], 6, "{varied}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// A study over a map scene whose samples run in parallel builds the map's cells as its lines
/// reach them (a worker building a cell never waits on itself): one and two threads, each from
/// an empty cache, give the same report, and each leaves one map file behind.
#[test]
fn a_map_scene_study_gives_the_same_report_on_one_and_two_threads() {
    let d = tmp("map-threads");
    let text = std::fs::read_to_string(scenario()).unwrap().replace(
        "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"",
        "fidelity = \"map\"\nmap_grid = [16, 4, 1]",
    );
    assert!(text.contains("map_grid"));
    let scene = d.join("map.toml");
    std::fs::write(&scene, text).unwrap();
    let study = d.join("study.toml");
    std::fs::write(
        &study,
        format!(
            "scenario = \"{}\"\nname = \"map-threads\"\nsamples = 12\n\n[uncertain.pose_theta]\ndistribution = \"normal\"\nsd = 3.0\n",
            s(&scene)
        ),
    )
    .unwrap();
    let run = |threads: &str, out: &Path, cache: &Path| {
        let o = Command::new(env!("CARGO_BIN_EXE_pinfeed"))
            .args([
                "mc",
                s(&study),
                "--threads",
                threads,
                "--quiet",
                "--out",
                s(out),
            ])
            .env("PINFEED_CACHE", cache)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(std::fs::read_dir(cache).unwrap().count(), 1, "one map file");
    };
    let (a, b) = (d.join("a"), d.join("b"));
    run("1", &a, &d.join("cache-1"));
    run("2", &b, &d.join("cache-2"));
    for f in ["report.md", "report.json"] {
        assert_eq!(
            crate::support::report_text(&a, f),
            crate::support::report_text(&b, f),
            "{f}"
        );
    }
    std::fs::remove_dir_all(&d).unwrap();
}
