//! README followed as a new user would, in a copy of the repository: its tracked files, committed
//! in a fresh git repository. Every command block of README runs in order, from the folder README
//! has the user in (`mkdir … && cd …`), with the files README asks the user to write (a `toml`
//! block after "write `NAME`"); output blocks are skipped. Afterwards `git status --porcelain` must
//! be empty: no command in README writes into a tracked file or leaves an untracked one outside
//! the ignored paths. The tutorial's plan must reach a confirmed line (exit status 0).

use std::path::{Path, PathBuf};
use std::process::Command;

/// One thing README has the user do.
#[derive(Debug, PartialEq)]
enum Step {
    Mkdir(String),
    Cd(String),
    /// Write a file (name, text).
    Write(String, String),
    /// `pinfeed ARGS` (or `cargo run --release -- ARGS`).
    Pinfeed(Vec<String>),
}

/// Whether a line of a code block is a command the user types.
fn is_command(line: &str) -> bool {
    ["pinfeed ", "cargo ", "mkdir ", "cd "]
        .iter()
        .any(|p| line.starts_with(p))
}

/// The steps of a README, in order.
fn steps(readme: &str) -> Vec<Step> {
    let mut out = Vec::new();
    let mut prose = String::new();
    let mut lines = readme.lines();
    while let Some(line) = lines.next() {
        let Some(lang) = line.strip_prefix("```") else {
            prose.push_str(line);
            prose.push('\n');
            continue;
        };
        let block: Vec<&str> = lines
            .by_ref()
            .take_while(|l| !l.starts_with("```"))
            .collect();
        if lang == "toml" {
            let name = prose
                .rsplit("write `")
                .next()
                .filter(|_| prose.contains("write `"))
                .and_then(|r| r.split('`').next())
                .unwrap_or_else(|| panic!("a toml block without \"write `NAME`\" before it"));
            out.push(Step::Write(name.to_string(), block.join("\n") + "\n"));
        } else {
            // A command block: each line a command or a continuation of one; else output.
            let joined = block.join("\n").replace("\\\n", " ");
            let cmds: Vec<&str> = joined
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .collect();
            if !cmds.is_empty() && cmds.iter().all(|l| is_command(l)) {
                for cmd in cmds {
                    for part in cmd.split("&&") {
                        out.extend(step(part));
                    }
                }
            }
        }
        prose.clear();
    }
    out
}

/// The step of one shell command; None for the ones the test does itself (building, installing
/// and testing: the binary under test is already built).
fn step(cmd: &str) -> Option<Step> {
    assert!(
        !cmd.contains(['>', '|', '$']),
        "README command the test cannot follow: {cmd}"
    );
    let words = crate::doc_commands::shell_words(cmd);
    let w: Vec<&str> = words.iter().map(String::as_str).collect();
    match w.as_slice() {
        ["mkdir", dir] => Some(Step::Mkdir(dir.to_string())),
        ["cd", dir] => Some(Step::Cd(dir.to_string())),
        ["cargo", "build" | "install" | "test", ..] => None,
        ["cargo", "run", "--release", "--", rest @ ..] | ["pinfeed", rest @ ..] => {
            Some(Step::Pinfeed(rest.iter().map(|s| s.to_string()).collect()))
        }
        _ => panic!("README command the test does not know: {cmd}"),
    }
}

fn git(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new("git")
        .args([
            "-c",
            "user.name=pinfeed test",
            "-c",
            "user.email=test@example.invalid",
            "-c",
            "commit.gpgsign=false",
        ])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run git")
}

/// A copy of the repository's tracked files (as they are in the working tree), committed in a
/// fresh git repository; None when this is not a git checkout or git is missing.
fn repository_copy() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let listed = Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())?;
    let copy = crate::support::fresh_dir("readme-tutorial");
    for name in listed.stdout.split(|&b| b == 0).filter(|n| !n.is_empty()) {
        let name = std::str::from_utf8(name).expect("UTF-8 file names");
        let (from, to) = (root.join(name), copy.join(name));
        if !from.is_file() {
            continue; // deleted in the working tree
        }
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(&from, &to).unwrap();
    }
    for args in [
        &["init", "-q"][..],
        &["add", "-A"],
        &["commit", "-q", "-m", "copy"],
    ] {
        let o = git(&copy, args);
        assert!(o.status.success(), "git {args:?}: {o:?}");
    }
    Some(copy)
}

#[test]
fn readme_s_steps_are_read_as_a_user_follows_them() {
    let readme = "Work here:\n\n```\nmkdir t && cd t\ncargo build --release   # builds\n```\n\n\
                  Output:\n\n```\npinfeed plan --part square\ndesign plan\n```\n\n\
                  Then write `s.toml`:\n\n```toml\nsamples = 2\n```\n\n```\npinfeed mc s.toml \\\n    --json\n```\n";
    assert_eq!(
        steps(readme),
        [
            Step::Mkdir("t".into()),
            Step::Cd("t".into()),
            Step::Write("s.toml".into(), "samples = 2\n".into()),
            Step::Pinfeed(vec!["mc".into(), "s.toml".into(), "--json".into()]),
        ]
    );
}

#[test]
fn readme_tutorial_leaves_the_repository_clean() {
    let Some(copy) = repository_copy() else {
        eprintln!("not a git checkout (or no git): README's tutorial was not followed");
        return;
    };
    let readme = std::fs::read_to_string(copy.join("README.md")).unwrap();
    let mut cwd = copy.clone();
    let mut ran = std::collections::BTreeSet::new();
    for s in steps(&readme) {
        match s {
            Step::Mkdir(d) => std::fs::create_dir_all(cwd.join(d)).unwrap(),
            Step::Cd(d) => cwd = cwd.join(d),
            Step::Write(name, text) => std::fs::write(cwd.join(name), text).unwrap(),
            Step::Pinfeed(args) => {
                let o = crate::support::pinfeed_in(
                    &cwd,
                    &args.iter().map(String::as_str).collect::<Vec<_>>(),
                );
                assert!(
                    o.status.success(),
                    "pinfeed {args:?} in {}: {}\n{}",
                    cwd.display(),
                    o.status,
                    String::from_utf8_lossy(&o.stderr)
                );
                ran.insert(args[0].clone());
            }
        }
    }
    for cmd in [
        "part",
        "plan",
        "run",
        "mc",
        "compare",
        "calibrate",
        "validate",
    ] {
        assert!(
            ran.contains(cmd),
            "README's tutorial runs `{cmd}`: ran {ran:?}"
        );
    }
    let status = git(&copy, &["status", "--porcelain", "--untracked-files=all"]);
    assert!(status.status.success());
    assert!(
        status.stdout.is_empty(),
        "README's commands changed the repository:\n{}",
        String::from_utf8_lossy(&status.stdout)
    );
    let _ = std::fs::remove_dir_all(&copy);
}
