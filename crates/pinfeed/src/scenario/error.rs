//! The error a bad scenario file produces: file, line, column, the key at fault and what is
//! allowed there, followed by the offending source line with a caret (like a compiler).

use super::location::{line_column, KeyPath, SpannedDoc};
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a scenario could not be loaded.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The file could not be read.
    /// (The cause is in the message, not a `source`, so that it is printed once.)
    #[error("{}: cannot read the scenario: {error}{hint}", path.display())]
    Io {
        /// The file that could not be read.
        path: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
        /// What the user may have meant (`; did you mean …`), or empty.
        hint: String,
    },
    /// The file is not valid TOML, or a key or value is wrong.
    #[error("{0}")]
    Invalid(Box<InvalidScenario>),
    /// A scene built in code (with no file to point at) is refused after parsing: its online
    /// controller's model cannot be built.
    #[error("{0}")]
    Unlocated(String),
}

/// A located problem in a scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct InvalidScenario {
    /// The scenario (or policy) file at fault, as given.
    pub file: PathBuf,
    /// 1-based line of the key or value at fault.
    pub line: usize,
    /// 1-based column (in characters) of the key or value at fault.
    pub column: usize,
    /// The key path at fault, e.g. `belt.speed` or `obstacles[1].kind`.
    pub key: String,
    /// What is wrong and what is allowed.
    pub message: String,
    /// The source line and a caret under the fault.
    pub excerpt: String,
}

impl fmt::Display for InvalidScenario {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: key `{}`: {}",
            self.file.display(),
            self.line,
            self.column,
            self.key,
            self.message
        )?;
        if !self.excerpt.is_empty() {
            write!(f, "\n{}", self.excerpt)?;
        }
        Ok(())
    }
}

impl ScenarioError {
    /// The located details (None for I/O errors).
    pub fn invalid(&self) -> Option<&InvalidScenario> {
        match self {
            ScenarioError::Invalid(i) => Some(i),
            ScenarioError::Io { .. } | ScenarioError::Unlocated(_) => None,
        }
    }
}

/// Where a key is written in a file: locates an error found after parsing (the online
/// controller's model is built from the parsed scene, then refused at the key that declared it).
#[derive(Debug, Clone, PartialEq)]
pub struct KeyLocation(Box<InvalidScenario>);

impl KeyLocation {
    /// The location of `error` (its message is replaced by each [`KeyLocation::error`]); None
    /// for an I/O error, which has no location.
    pub fn of(error: ScenarioError) -> Option<KeyLocation> {
        match error {
            ScenarioError::Invalid(i) => Some(KeyLocation(i)),
            ScenarioError::Io { .. } | ScenarioError::Unlocated(_) => None,
        }
    }

    /// The error `message`, located here.
    pub fn error(&self, message: impl Into<String>) -> ScenarioError {
        let mut i = self.0.clone();
        i.message = message.into();
        ScenarioError::Invalid(i)
    }
}

/// Builds located errors for one source file.
pub struct Locator<'a> {
    /// The file, as named in messages.
    pub file: &'a Path,
    /// The file's whole text.
    pub source: &'a str,
    /// The file's spanned TOML tree, to locate key paths.
    pub doc: SpannedDoc<'a>,
    /// What the file is, as a missing key's message names it ("the scenario", "a policy file").
    pub what: &'static str,
}

impl<'a> Locator<'a> {
    /// A locator for a scenario file.
    pub fn new(file: &'a Path, source: &'a str) -> Locator<'a> {
        Locator {
            file,
            source,
            doc: SpannedDoc::parse(source),
            what: "the scenario",
        }
    }

    /// The same, for a file that is not a scenario (`what` names it in messages).
    pub fn of(file: &'a Path, source: &'a str, what: &'static str) -> Locator<'a> {
        Locator {
            what,
            ..Locator::new(file, source)
        }
    }

    /// An error at a byte span, with an explicit key path.
    pub fn at_span(&self, span: Range<usize>, key: &KeyPath, message: String) -> ScenarioError {
        let (line, column) = line_column(self.source, span.start);
        let text_line = self.source.lines().nth(line - 1).unwrap_or("");
        let width = self.source[span.start.min(self.source.len())..span.end.min(self.source.len())]
            .lines()
            .next()
            .map(|s| s.chars().count())
            .unwrap_or(0)
            .max(1);
        let gutter = line.to_string().len();
        let excerpt = if span == (0..0) {
            String::new()
        } else {
            format!(
                "{:gutter$} |\n{line} | {text_line}\n{:gutter$} | {}{}",
                "",
                "",
                " ".repeat(column - 1),
                "^".repeat(width)
            )
        };
        ScenarioError::Invalid(Box::new(InvalidScenario {
            file: self.file.to_path_buf(),
            line,
            column,
            key: key.to_string(),
            message,
            excerpt,
        }))
    }

    /// An error about the value at `path` (or, if it is missing, about the table that should hold it).
    pub fn at_key(&self, path: &KeyPath, message: impl Into<String>) -> ScenarioError {
        let span = self.doc.span_of(path);
        self.at_span(span, path, message.into())
    }

    /// Turn a toml/serde error into a located error: the key comes from the span, plus the field
    /// a "missing field" or "unknown field" message names.
    pub fn from_toml(&self, e: &toml::de::Error) -> ScenarioError {
        let span = e.span().unwrap_or(0..0);
        let message = e.message().trim().to_string();
        if !self.doc.is_toml() {
            return self.at_span(
                span,
                &KeyPath::parse("(TOML syntax)"),
                format!("{message} (the file is not valid TOML)"),
            );
        }
        let mut key = self.doc.path_at(&span);
        if let Some(field) = backticked_after(&message, "missing field ") {
            key = key.key(&field);
            let message = if key.0.len() == 1 && self.what == "the scenario" {
                format!("{message}: the scenario needs a [{field}] section or `{field} = ...` key")
            } else if key.0.len() == 1 {
                format!("{message}: {} needs `{field} = ...`", self.what)
            } else {
                message
            };
            return self.at_span(span, &key, message);
        }
        if let Some(field) = backticked_after(&message, "unknown field ") {
            if key.0.last() != Some(&super::location::PathStep::Key(field.clone())) {
                key = key.key(&field);
            }
        }
        self.at_span(span, &key, message)
    }
}

/// The text between backticks right after `prefix` in `message`.
fn backticked_after(message: &str, prefix: &str) -> Option<String> {
    let rest = message.strip_prefix(prefix)?;
    let rest = rest.strip_prefix('`')?;
    let end = rest.find('`')?;
    Some(rest[..end].to_string())
}
