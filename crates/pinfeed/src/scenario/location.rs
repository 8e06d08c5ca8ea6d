//! Where in a scenario file a key lives: byte spans from the TOML parser turned into line and
//! column, and key paths (`obstacles[2].radius`) resolved to the span of their value.
//!
//! The scenario is parsed twice: once into typed structs (serde, [`super::raw`]) and once into
//! toml's spanned document tree, which this module walks. Errors found by serde carry a byte span;
//! errors found by validation carry a key path; both end up as file:line:column plus the key.

use std::ops::Range;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// One step of a key path: a table key or an array index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PathStep {
    /// A table key.
    Key(String),
    /// An array index (0-based).
    Index(usize),
}

/// A key path from the document root, e.g. `obstacles[2].radius`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct KeyPath(pub Vec<PathStep>);

impl KeyPath {
    /// The empty path (the document root).
    pub fn root() -> KeyPath {
        KeyPath(Vec::new())
    }
    /// Parse a dotted path with optional indices: `feed.lateral.min`, `obstacles[1].x`.
    pub fn parse(text: &str) -> KeyPath {
        let mut steps = Vec::new();
        for part in text.split('.').filter(|p| !p.is_empty()) {
            let (key, mut rest) = match part.find('[') {
                Some(i) => (&part[..i], &part[i..]),
                None => (part, ""),
            };
            if !key.is_empty() {
                steps.push(PathStep::Key(key.to_string()));
            }
            while let Some(close) = rest.find(']') {
                if let Ok(i) = rest[1..close].parse() {
                    steps.push(PathStep::Index(i));
                }
                rest = &rest[close + 1..];
            }
        }
        KeyPath(steps)
    }
    /// This path extended by table key `k`.
    pub fn key(&self, k: &str) -> KeyPath {
        let mut p = self.clone();
        p.0.push(PathStep::Key(k.to_string()));
        p
    }
    /// This path extended by array index `i`.
    pub fn index(&self, i: usize) -> KeyPath {
        let mut p = self.clone();
        p.0.push(PathStep::Index(i));
        p
    }
    /// Is this the empty path?
    pub fn is_root(&self) -> bool {
        self.0.is_empty()
    }
}

impl std::fmt::Display for KeyPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_empty() {
            return f.write_str("(top level)");
        }
        for (i, s) in self.0.iter().enumerate() {
            match s {
                PathStep::Key(k) if i == 0 => write!(f, "{k}")?,
                PathStep::Key(k) => write!(f, ".{k}")?,
                PathStep::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// 1-based line and column (in characters) of a byte offset.
pub fn line_column(source: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(source.len());
    let before = &source[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
    let column = source[line_start..offset].chars().count() + 1;
    (line, column)
}

/// The spanned document tree of a scenario file (None if the file is not valid TOML).
pub struct SpannedDoc<'a> {
    root: Option<Spanned<DeTable<'a>>>,
}

impl<'a> SpannedDoc<'a> {
    /// Parse `source` (a file that is not valid TOML gives a tree that locates nothing).
    pub fn parse(source: &'a str) -> SpannedDoc<'a> {
        SpannedDoc {
            root: DeTable::parse(source).ok(),
        }
    }

    /// Did the file parse as TOML?
    pub fn is_toml(&self) -> bool {
        self.root.is_some()
    }

    /// Span of the value at `path`, or of its nearest existing ancestor (for a missing key: the
    /// table that should hold it). The root maps to the start of the file.
    pub fn span_of(&self, path: &KeyPath) -> Range<usize> {
        let Some(root) = &self.root else {
            return 0..0;
        };
        let mut best: Range<usize> = 0..0;
        let mut table: Option<&DeTable> = Some(root.get_ref());
        let mut value: Option<&Spanned<DeValue>> = None;
        for step in &path.0 {
            let next = match (step, table, value) {
                (PathStep::Key(k), Some(t), _) => t
                    .iter()
                    .find(|(key, _)| key.get_ref().as_ref() == k.as_str())
                    .map(|(_, v)| v),
                (PathStep::Index(i), _, Some(v)) => v.get_ref().as_array().and_then(|a| a.get(*i)),
                _ => None,
            };
            let Some(v) = next else { break };
            best = v.span();
            value = Some(v);
            table = v.get_ref().as_table();
        }
        best
    }

    /// The key path of the tightest key or value span that contains `span` (for errors reported
    /// by serde with a span but no key). Table headers' spans do not cover their bodies, so the
    /// whole tree is searched.
    pub fn path_at(&self, span: &Range<usize>) -> KeyPath {
        let Some(root) = &self.root else {
            return KeyPath::root();
        };
        let mut best: Option<(usize, KeyPath)> = None;
        walk_table(root.get_ref(), &KeyPath::root(), span, &mut best);
        best.map(|(_, p)| p).unwrap_or_default()
    }
}

fn consider(
    r: &Range<usize>,
    span: &Range<usize>,
    path: &KeyPath,
    best: &mut Option<(usize, KeyPath)>,
) {
    let contains = r.start <= span.start && span.end <= r.end.max(r.start + 1);
    if !contains {
        return;
    }
    let size = r.end - r.start;
    let better = match best {
        None => true,
        Some((s, p)) => size < *s || (size == *s && path.0.len() > p.0.len()),
    };
    if better {
        *best = Some((size, path.clone()));
    }
}

fn walk_value(
    v: &Spanned<DeValue>,
    path: &KeyPath,
    span: &Range<usize>,
    best: &mut Option<(usize, KeyPath)>,
) {
    consider(&v.span(), span, path, best);
    if let Some(t) = v.get_ref().as_table() {
        walk_table(t, path, span, best);
    } else if let Some(a) = v.get_ref().as_array() {
        for (i, item) in a.iter().enumerate() {
            walk_value(item, &path.index(i), span, best);
        }
    }
}

fn walk_table(
    t: &DeTable,
    path: &KeyPath,
    span: &Range<usize>,
    best: &mut Option<(usize, KeyPath)>,
) {
    for (k, v) in t.iter() {
        let p = path.key(k.get_ref());
        consider(&k.span(), span, &p, best);
        walk_value(v, &p, span, best);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column() {
        let s = "a = 1\nbb = 2\n";
        assert_eq!(line_column(s, 0), (1, 1));
        assert_eq!(line_column(s, 6), (2, 1));
        assert_eq!(line_column(s, 11), (2, 6));
    }

    #[test]
    fn paths_resolve_to_spans_and_back() {
        let s =
            "[belt]\nspeed = 0.05\n\n[[obstacles]]\nx = 1\n\n[[obstacles]]\nx = 2\nradius = 3\n";
        let doc = SpannedDoc::parse(s);
        let p = KeyPath::parse("obstacles[1].radius");
        assert_eq!(p.to_string(), "obstacles[1].radius");
        let span = doc.span_of(&p);
        assert_eq!(&s[span.clone()], "3");
        assert_eq!(line_column(s, span.start), (9, 10));
        assert_eq!(doc.path_at(&span), p);
        let speed = doc.span_of(&KeyPath::parse("belt.speed"));
        assert_eq!(&s[speed.clone()], "0.05");
        assert_eq!(doc.path_at(&speed).to_string(), "belt.speed");
        // A missing key falls back to its table.
        let missing = doc.span_of(&KeyPath::parse("belt.width"));
        assert!(missing.start <= 7);
    }
}
