//! README.md and docs/*.md against the code: every relative link points at a file that exists
//! (and, with `#anchor`, at a heading of it), and every `pinfeed …` command shown in a code block
//! parses with the command line the binary uses (flags, values, subcommands), so a renamed or
//! removed option cannot leave the guide behind.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every Markdown file in docs/.
fn documents() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    docs.insert(0, root().join("README.md"));
    docs
}

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
pub(crate) fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\'' => {
                in_word = true;
                for d in chars.by_ref() {
                    if d == '\'' {
                        break;
                    }
                    word.push(d);
                }
            }
            '"' => {
                in_word = true;
                while let Some(d) = chars.next() {
                    match d {
                        '"' => break,
                        '\\' => word.extend(chars.next()),
                        _ => word.push(d),
                    }
                }
            }
            '\\' => {
                in_word = true;
                word.extend(chars.next());
            }
            '#' if !in_word => break,
            c if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            c => {
                in_word = true;
                word.push(c);
            }
        }
    }
    if in_word {
        words.push(word);
    }
    words
}

/// The `pinfeed` command lines in the code blocks of a document (fenced or indented), with
/// `cargo run --release --` read as `pinfeed`, continuation lines joined. Lines using shell
/// variables are skipped (they need a scheduler's environment).
fn commands(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    let mut pending: Option<String> = None;
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
            continue;
        }
        let code = fenced || line.starts_with("    ");
        if !code {
            continue;
        }
        let l = line.trim();
        let joined = match pending.take() {
            Some(p) => format!("{p} {l}"),
            None => match l
                .strip_prefix("cargo run --release -- ")
                .map(|r| format!("pinfeed {r}"))
                .or_else(|| l.starts_with("pinfeed ").then(|| l.to_string()))
            {
                Some(c) => c,
                None => continue,
            },
        };
        if let Some(head) = joined.strip_suffix('\\') {
            pending = Some(head.trim_end().to_string());
        } else if !joined.contains('$') {
            out.push(joined);
        }
    }
    out
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
            if let Err(e) = pinfeed::cli::Cli::try_parse_from(&words) {
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

/// The flags that take a length (or a ratio of lengths): each is in docs/commands.md's table of
/// units with the unit its `--help` names, and no command has one the table leaves out.
#[test]
fn every_length_flag_names_its_unit_as_the_units_table_does() {
    use clap::CommandFactory;
    const LENGTH_FLAGS: [&str; 13] = [
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
    let cli = pinfeed::cli::Cli::command();
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
