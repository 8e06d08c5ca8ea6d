//! The bundled examples (`pinfeed examples`, `run NAME`, `mc NAME`) and shell completion
//! (`pinfeed completions`), as an installed binary sees them: run from empty folders outside the
//! project, where `scenarios/` and `studies/` do not exist.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// An empty scratch folder of this test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pinfeed-examples-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn pinfeed(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn ok(out: Output) -> String {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The `.toml` files of a project folder, sorted.
fn project_files(dir: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    names
}

/// Every scenario and study of the project is bundled and listed with a description.
#[test]
fn examples_lists_every_bundled_file() {
    let dir = scratch("list");
    let listing = ok(pinfeed(&dir, &["examples"]));
    for (folder, n) in [("scenarios", 11), ("studies", 2)] {
        let files = project_files(folder);
        assert!(files.len() >= n, "{folder}: {files:?}");
        for f in files {
            let name = f.trim_end_matches(".toml");
            let line = listing
                .lines()
                .find(|l| l.split_whitespace().next() == Some(name))
                .unwrap_or_else(|| panic!("{name} is not listed:\n{listing}"));
            assert!(line.len() > name.len() + 10, "{name} has no description");
        }
    }
    assert!(
        std::fs::read_dir(&dir).unwrap().next().is_none(),
        "listing wrote files"
    );
}

/// A study is written with the scenario it names, byte for byte as in the project; writing again
/// is refused without --force and changes nothing; --force rewrites; no temporary file remains.
#[test]
fn examples_writes_files_and_never_overwrites_unasked() {
    let dir = scratch("write");
    let out = ok(pinfeed(
        &dir,
        &["examples", "quickstart_mu_tripod", "--to", "ex"],
    ));
    assert!(
        out.contains("ex/studies/quickstart_mu_tripod.toml"),
        "{out}"
    );
    for rel in [
        "studies/quickstart_mu_tripod.toml",
        "scenarios/quickstart.toml",
    ] {
        let written = std::fs::read(dir.join("ex").join(rel)).unwrap();
        assert_eq!(written, std::fs::read(root().join(rel)).unwrap(), "{rel}");
    }
    // The written study runs where it was written.
    ok(pinfeed(
        &dir,
        &[
            "mc",
            "ex/studies/quickstart_mu_tripod.toml",
            "--samples",
            "20",
            "--out",
            "mc1",
            "--quiet",
        ],
    ));

    let edited = dir.join("ex/scenarios/quickstart.toml");
    std::fs::write(&edited, "# my edits\n").unwrap();
    let again = pinfeed(&dir, &["examples", "quickstart", "tripoly1", "--to", "ex"]);
    assert!(!again.status.success());
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(
        err.contains("already exists") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&edited).unwrap(), "# my edits\n");
    assert!(
        !dir.join("ex/scenarios/tripoly1.toml").exists(),
        "a refused write wrote nothing"
    );

    ok(pinfeed(
        &dir,
        &["examples", "quickstart", "--to", "ex", "--force"],
    ));
    assert_eq!(
        std::fs::read(&edited).unwrap(),
        std::fs::read(root().join("scenarios/quickstart.toml")).unwrap()
    );
    ok(pinfeed(&dir, &["examples", "--all", "--to", "all"]));
    let written: Vec<String> = ["scenarios", "studies"]
        .iter()
        .flat_map(|f| {
            std::fs::read_dir(dir.join("all").join(f))
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        })
        .collect();
    assert_eq!(
        written.len(),
        project_files("scenarios").len() + project_files("studies").len()
    );
    assert!(written.iter().all(|n| !n.starts_with('.')), "{written:?}");

    let unknown = pinfeed(&dir, &["examples", "no_such_example", "--to", "ex"]);
    assert!(!unknown.status.success());
    assert!(String::from_utf8_lossy(&unknown.stderr).contains("pinfeed examples"));
}

/// `run NAME` and `mc NAME` run the bundled files from a folder without them, with the results
/// the project's files give.
#[test]
fn run_and_mc_accept_bundled_names() {
    let dir = scratch("run");
    ok(pinfeed(
        &dir,
        &[
            "run",
            "quickstart",
            "--parts",
            "30",
            "--out",
            "named",
            "--quiet",
        ],
    ));
    let project = root().join("scenarios/quickstart.toml");
    ok(pinfeed(
        &dir,
        &[
            "run",
            project.to_str().unwrap(),
            "--parts",
            "30",
            "--out",
            "file",
            "--quiet",
        ],
    ));
    assert_eq!(
        std::fs::read(dir.join("named/quickstart/summary.json")).unwrap(),
        std::fs::read(dir.join("file/quickstart/summary.json")).unwrap()
    );

    ok(pinfeed(
        &dir,
        &[
            "mc",
            "quickstart_shape_tolerance",
            "--samples",
            "15",
            "--out",
            "named",
            "--quiet",
        ],
    ));
    let study = root().join("studies/quickstart_shape_tolerance.toml");
    ok(pinfeed(
        &dir,
        &[
            "mc",
            study.to_str().unwrap(),
            "--samples",
            "15",
            "--out",
            "file",
            "--quiet",
        ],
    ));
    let report = |sub: &str| {
        let mut v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join(sub).join("report.json")).unwrap())
                .unwrap();
        let obj = v.as_object_mut().unwrap();
        // The command line and the file paths name what was typed; the rest must agree.
        for k in ["command", "study_file", "scenario_file"] {
            obj.remove(k);
        }
        v
    };
    assert_eq!(report("named"), report("file"));

    // A name that is neither a file nor a bundled example is still an error; a scenario name is
    // not a study.
    assert!(!pinfeed(&dir, &["run", "no_such_scenario"]).status.success());
    assert!(!pinfeed(&dir, &["mc", "quickstart", "--samples", "5"])
        .status
        .success());
}

/// `pinfeed completions bash` completes every subcommand.
#[test]
fn completions_cover_the_subcommands() {
    let dir = scratch("completions");
    let bash = ok(pinfeed(&dir, &["completions", "bash"]));
    for sub in [
        "run",
        "mc",
        "plan",
        "map",
        "contact",
        "examples",
        "completions",
        "merge",
    ] {
        assert!(bash.contains(sub), "bash completion lacks {sub}");
    }
    assert!(bash.contains("complete") && bash.contains("pinfeed"));
    assert!(!ok(pinfeed(&dir, &["completions", "zsh"])).is_empty());
    assert!(!pinfeed(&dir, &["completions", "no-such-shell"])
        .status
        .success());
}

/// Issue 57 item 9: a name one or two edits from a bundled one gets a "did you mean".
#[test]
fn a_mistyped_bundled_name_gets_a_did_you_mean() {
    let dir = scratch("did-you-mean");
    for (args, meant) in [
        (
            &["run", "quickstrat"][..],
            "did you mean `quickstart` (bundled: `pinfeed run quickstart`)?",
        ),
        (
            &["mc", "quickstart_mu_tripd"][..],
            "did you mean `quickstart_mu_tripod` (bundled: `pinfeed mc quickstart_mu_tripod`)?",
        ),
    ] {
        let out = pinfeed(&dir, args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(meant), "{args:?}: {err}");
    }
    let out = pinfeed(&dir, &["run", "nothing_like_it"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("did you mean"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 57 item 10: the online scenarios and their studies run by name outside the source tree
/// (tripoly2_online named a policy under ../results/, which is not bundled).
#[test]
fn bundled_online_scenarios_and_studies_run_anywhere() {
    let dir = scratch("online-anywhere");
    for args in [
        &["run", "tripoly2_online", "--parts", "2", "--out", "runs"][..],
        &["run", "tripoly1_online", "--parts", "2", "--out", "runs"][..],
        &[
            "mc",
            "tripoly2_online_uncertain",
            "--samples",
            "1",
            "--quiet",
            "--out",
            "mc2",
        ][..],
        &[
            "mc",
            "tripoly1_online_uncertain",
            "--samples",
            "1",
            "--quiet",
            "--out",
            "mc1",
        ][..],
    ] {
        ok(pinfeed(&dir, args));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 57 item 12: `examples --all --to DIR` writes every file or none (a failure half way left
/// 7 of 17 files, and the retry was refused "already exists"); the OS error prints once; a
/// dangling symbolic link is named as one, not "File exists".
#[test]
fn examples_write_all_files_or_none() {
    let dir = scratch("all-or-none");
    let to = dir.join("ex");
    std::fs::create_dir_all(&to).unwrap();
    // The studies' folder cannot be made: the scenarios (written first) must not stay behind.
    std::fs::write(to.join("studies"), "in the way").unwrap();
    let out = pinfeed(&dir, &["examples", "--all", "--to", "ex"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("nothing was written"), "{err}");
    assert_eq!(
        err.matches("(os error").count(),
        1,
        "the OS error once: {err}"
    );
    let mut left: Vec<_> = std::fs::read_dir(&to)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["studies"], "a failed write left files behind");
    // The retry, with the obstacle gone, writes everything.
    std::fs::remove_file(to.join("studies")).unwrap();
    let wrote = ok(pinfeed(&dir, &["examples", "--all", "--to", "ex"]));
    assert_eq!(
        wrote.lines().count(),
        project_files("scenarios").len() + project_files("studies").len()
    );

    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("nowhere"), dir.join("link")).unwrap();
        let out = pinfeed(&dir, &["examples", "quickstart", "--to", "link"]);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("link is a symbolic link to")
                && err.contains("nowhere, which does not exist"),
            "{err}"
        );
        assert!(!err.contains("File exists"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
