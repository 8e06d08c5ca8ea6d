//! README.md and docs/*.md against the code: every relative link points at a file that exists
//! (and, with `#anchor`, at a heading of it), the command lines are read as a shell reads them,
//! and the range tables quote the library's. (That every documented `pinfeed …` command parses,
//! and that the units table matches `--help`, is tested in process, in `cli_in_process`.)

use crate::doc_commands::{commands, documents, root, shell_words};
use std::path::Path;

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == '-' || *c == ' ' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            out.push(anchor(line.trim_start_matches('#')));
        }
    }
    out
}

#[test]
fn relative_links_resolve() {
    let mut bad = Vec::new();
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        for (i, _) in text.match_indices("](") {
            let rest = &text[i + 2..];
            let Some(end) = rest.find(')') else { continue };
            let target = &rest[..end];
            if target.starts_with("http") || target.starts_with("mailto:") {
                continue;
            }
            let (file, frag) = target.split_once('#').unwrap_or((target, ""));
            let path = if file.is_empty() {
                doc.clone()
            } else {
                doc.parent().unwrap().join(file)
            };
            if !path.exists() {
                bad.push(format!("{}: {target}: no such file", doc.display()));
            } else if !frag.is_empty()
                && path.extension().is_some_and(|e| e == "md")
                && !anchors(&path).iter().any(|a| a == frag)
            {
                bad.push(format!("{}: {target}: no such heading", doc.display()));
            }
        }
    }
    assert!(bad.is_empty(), "broken links:\n{}", bad.join("\n"));
}

/// Split a shell command line into words: single and double quotes, backslash escapes; a `#`
/// starting a word begins a comment.
#[test]
fn shell_words_and_commands_are_read_as_a_shell_would() {
    assert_eq!(
        shell_words(r#"pinfeed part --vertices "0,0 1,0 0,1" --plot 'a b.svg' # comment"#),
        [
            "pinfeed",
            "part",
            "--vertices",
            "0,0 1,0 0,1",
            "--plot",
            "a b.svg"
        ]
    );
    let text = "```\ncargo run --release -- map --part tripoly1 \\\n    --d=0.1\nls\n```\n";
    assert_eq!(commands(text), ["pinfeed map --part tripoly1 --d=0.1"]);
}

/// Ways a document may write the number `v`: plain (`0.0001`, `1000`), exponent (`1e-4`, `1e3`)
/// or a power of ten with superscripts (`10⁴`).
fn forms(v: f64) -> Vec<String> {
    let mut f = vec![format!("{v}"), format!("{v:e}").replace("e0", "")];
    let exp = v.abs().log10();
    if v != 0.0 && exp.fract() == 0.0 {
        let sup: String = format!("{}", exp as i64)
            .chars()
            .map(|c| match c {
                '-' => '⁻',
                d => "⁰¹²³⁴⁵⁶⁷⁸⁹"
                    .chars()
                    .nth(d.to_digit(10).unwrap() as usize)
                    .unwrap(),
            })
            .collect();
        f.push(format!("10{sup}"));
    }
    f
}

/// The ranges docs/scenario-format.md quotes are those of the code's range table
/// (`pinfeed::scenario::limits`): each key's row names both ends of its range, in order.
#[test]
fn scenario_format_quotes_the_range_table() {
    use pinfeed::scenario::limits::*;
    let text = std::fs::read_to_string(root().join("docs/scenario-format.md")).unwrap();
    let row = |key: &str| -> &str {
        text.lines()
            .find(|l| l.starts_with('|') && l.contains(key))
            .unwrap_or_else(|| panic!("no row for {key}"))
    };
    let quotes = |line: &str, (lo, hi): (f64, f64)| {
        forms(lo).iter().any(|a| {
            forms(hi).iter().any(|b| {
                line.contains(&format!("[{a}, {b}]")) || line.contains(&format!("({a}, {b}]"))
            })
        })
    };
    let cases: [(&str, (f64, f64)); 13] = [
        ("`[belt]` `speed`", BELT_SPEED),
        ("`[belt]` `speed`", BELT_WIDTH),
        ("`[belt]` `speed`", BELT_LENGTH),
        ("`[part]` `scale`", PART_SCALE),
        ("`[part]` `scale`", PART_RADIUS),
        ("`[part]` `mu_c`", FRICTION),
        ("`[part]` `mass`", MASS_KG),
        ("`[feed]` `headway`", HEADWAY),
        ("`[feed]` `headway`", RATE),
        ("`[feed]` `jitter`", JITTER_DEG),
        ("`[feed]` `weights`", WEIGHT),
        ("`[model]` `tol`", TOL),
        ("`histogram_bin`", HISTOGRAM_BIN_DEG),
    ];
    for (key, range) in cases {
        assert!(
            quotes(row(key), range),
            "{key}: {range:?} not quoted in\n{}",
            row(key)
        );
    }
    let fence = row("`angle`, `length`");
    let (lo, hi) = FENCE_LENGTH_OF_A;
    assert!(
        fence.contains(&format!("{} a to {} a", forms(lo)[2], forms(hi)[2])),
        "{fence}"
    );
    let moving = row("`travel`, `speed`");
    assert!(
        quotes(moving, ACTUATOR_SPEED)
            && quotes(moving, ACTUATOR_ACCEL)
            && quotes(moving, ACTUATOR_TIME)
    );
}

/// docs/commands.md quotes the contact's ranges from the one table the scenarios, studies and the
/// planner share (`pinfeed::mechanics::limits`): μc, the integration tolerance and a fence's length.
#[test]
fn commands_quote_the_shared_range_table() {
    use pinfeed::mechanics::limits::{FENCE_LENGTH_A, MU_C, TOL};
    let text = std::fs::read_to_string(root().join("docs/commands.md")).unwrap();
    let row = |key: &str| -> &str {
        text.lines()
            .find(|l| l.starts_with("| `") && l.contains(key))
            .unwrap_or_else(|| panic!("no row for {key}"))
    };
    let quotes = |line: &str, (lo, hi): (f64, f64), unit: &str| {
        forms(lo).iter().any(|a| {
            forms(hi)
                .iter()
                .any(|b| line.contains(&format!("[{a}{unit}, {b}{unit}]")))
        })
    };
    let cases = [
        ("`--mu-c`, `--mu-s`", MU_C, ""),
        ("`--tol T`", TOL, ""),
        ("`--fence ANGLE[:LENGTH]`", FENCE_LENGTH_A, "·a"),
    ];
    for (key, range, unit) in cases {
        assert!(
            quotes(row(key), range, unit),
            "{key}: {range:?} not quoted in\n{}",
            row(key)
        );
    }
    // The scenario table reads the same ranges.
    use pinfeed::scenario::limits as scenario;
    assert_eq!(
        (
            scenario::FRICTION,
            scenario::TOL,
            scenario::FENCE_LENGTH_OF_A
        ),
        (MU_C, TOL, FENCE_LENGTH_A)
    );
}
