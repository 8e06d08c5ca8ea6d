//! The checks every scenario section makes: a number finite and within its allowed range
//! ([`super::limits`]), and an error located at the key at fault (through [`Locator`]).

use super::error::{KeyLocation, Locator, ScenarioError};
use super::limits;
use super::location::KeyPath;

type R<T> = Result<T, ScenarioError>;

/// Builds located errors and checks numbers against their allowed ranges.
pub(super) struct Checker<'a, 'b> {
    loc: &'b Locator<'a>,
}

impl<'a, 'b> Checker<'a, 'b> {
    /// A checker whose errors are located through `loc`.
    pub(super) fn new(loc: &'b Locator<'a>) -> Self {
        Checker { loc }
    }

    /// The folder of the file being checked (where its relative paths start).
    pub(super) fn folder(&self) -> &std::path::Path {
        self.loc.file.parent().unwrap_or(std::path::Path::new(""))
    }
    /// An error at key path `path` (e.g. `belt.speed`, `obstacles[1].x`).
    pub(super) fn err(&self, path: &str, msg: impl Into<String>) -> ScenarioError {
        self.loc.at_key(&KeyPath::parse(path), msg)
    }
    /// Where key path `path` is written, to locate an error found after reading the file.
    pub(super) fn locate(&self, path: &str) -> KeyLocation {
        KeyLocation::of(self.err(path, "")).expect("a checker's errors are located")
    }
    /// `v`, if it is a finite number.
    pub(super) fn finite(&self, path: &str, v: f64) -> R<f64> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(path, format!("must be a finite number, got {v}")))
        }
    }
    /// `v`, if it lies in [lo, hi] (`unit` names the unit in the message).
    pub(super) fn within(&self, path: &str, v: f64, lo: f64, hi: f64, unit: &str) -> R<f64> {
        self.finite(path, v)?;
        if v >= lo && v <= hi {
            Ok(v)
        } else {
            Err(self.err(
                path,
                format!(
                    "must lie in [{}, {}] ({unit}), got {}",
                    limits::num(lo),
                    limits::num(hi),
                    limits::num(v)
                ),
            ))
        }
    }
    /// `v` within one of the [`super::limits`] ranges.
    pub(super) fn range(&self, path: &str, v: f64, r: (f64, f64), unit: &str) -> R<f64> {
        self.within(path, v, r.0, r.1, unit)
    }
    /// A missing section: the error is placed at `section`.
    pub(super) fn missing(&self, section: &str, msg: &str) -> ScenarioError {
        self.err(section, msg.to_string())
    }
}
