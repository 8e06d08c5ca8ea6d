//! Reading the documents the way a user does: README.md and docs/*.md, the `pinfeed` command
//! lines in their code blocks, and a command line split into words as a POSIX shell would. Shared
//! by the integration tests and the command line's own tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// The repository's root folder.
pub(crate) fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every Markdown file in docs/.
pub(crate) fn documents() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    docs.insert(0, root().join("README.md"));
    docs
}

/// A command line split into words: quotes, backslashes and `#` comments as a POSIX shell reads them.
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
pub(crate) fn commands(text: &str) -> Vec<String> {
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
