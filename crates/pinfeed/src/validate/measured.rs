//! The measured-bands file (docs/commands.md#validating-against-measurements-pinfeed-validate-pinfeed-calibrate): CSV with a header,
//! `#` comment lines and blank lines allowed, one measured band per row:
//!
//! ```text
//! part,d,input,min_deg,max_deg,trials
//! tripoly1,0.5,state:0,350,12,20
//! tripoly1,-0.3,theta:30:90,100,140,
//! tripoly1,0.1,all,200,230,
//! ```
//!
//! * `part`: the part (`tripoly1`, `rect:2:1`, …, or a vertex list quoted as CSV quotes a field
//!   with commas: `"vertices:0,0 36,0 8,22"`); with `--part P` the column may be left out, and
//!   when present P replaces it in every row;
//! * `d`: contact parameter, |d| ≤ 1 + (largest pin radius)/a;
//! * `input`: `state:K` (resting in stable state K, numbered as `pinfeed part` lists them),
//!   `theta:MIN:MAX` (θ0 spread over the arc from MIN to MAX degrees, counter-clockwise) or `all`;
//! * `min_deg`, `max_deg`: the measured band of final orientations, in [0, 360]; `max < min`
//!   straddles 0°/360°;
//! * `trials` (optional column, may be empty): how many trials the band summarises.
//!
//! Every error names the file, the line and the field.

use crate::geometry::{part_from_spec, Polygon};
use crate::maps::arcs::Arc;
use crate::maps::ensemble::{stable_states_deg, InputState};
use crate::maps::sample::max_contact_parameter;
use std::path::{Path, PathBuf};

/// The columns, in order (`trials` may be left out).
pub const COLUMNS: [&str; 6] = ["part", "d", "input", "min_deg", "max_deg", "trials"];
/// Most trials a row may claim.
pub const MAX_TRIALS: u32 = 1_000_000;

/// A bad measured-bands file: where, which field, what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {}{message}", self.place(), field.as_ref().map(|f| format!("field `{f}`: ")).unwrap_or_default())]
pub struct MeasuredError {
    /// The measured-bands file.
    pub file: PathBuf,
    /// 1-based line number (0: the file as a whole).
    pub line: usize,
    /// The column at fault, if one.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
    /// The caller's setting that would supply what is missing (`part`: the part of a file without
    /// a `part` column), if that is what is wrong.
    pub missing_setting: Option<&'static str>,
}

impl MeasuredError {
    /// `FILE:LINE`, or `FILE` for the file as a whole.
    fn place(&self) -> String {
        match self.line {
            0 => self.file.display().to_string(),
            n => format!("{}:{n}", self.file.display()),
        }
    }
}

/// One measured band.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredRow {
    /// 1-based line in the file.
    pub line: usize,
    /// The part spec (the `--part` given replaces the column).
    pub part: String,
    /// Contact parameter d (units of a).
    pub d: f64,
    /// How the part lies before the pass: a stable state, a θ0 arc or `all`.
    pub input: InputState,
    /// The measured band [min_deg, max_deg].
    pub band: Arc,
    /// Start of the band, counter-clockwise (degrees, in [0, 360]).
    pub min_deg: f64,
    /// End of the band (degrees, in [0, 360]; below `min_deg` the band straddles 0°).
    pub max_deg: f64,
    /// How many trials the band summarises, if given (at most [`MAX_TRIALS`]).
    pub trials: Option<u32>,
}

/// A parsed file: its rows and the parts they name (compiled once each).
#[derive(Debug, Clone)]
pub struct Measured {
    /// The file read.
    pub file: PathBuf,
    /// Its measured bands, in file order.
    pub rows: Vec<MeasuredRow>,
    /// (part spec, polygon), in order of first appearance.
    pub parts: Vec<(String, Polygon)>,
}

impl Measured {
    /// The polygon of a row's part.
    pub fn polygon(&self, part: &str) -> &Polygon {
        &self
            .parts
            .iter()
            .find(|(p, _)| p == part)
            .expect("parsed")
            .1
    }
}

/// Read and check a measured-bands file; `max_pin_radius` (part units) sets the reach of d.
pub fn load(path: &Path, max_pin_radius: f64) -> Result<Measured, MeasuredError> {
    load_for(path, max_pin_radius, None)
}

/// [`load`], with `part` (`--part`) in place of the file's part column, which may then be absent.
pub fn load_for(
    path: &Path,
    max_pin_radius: f64,
    part: Option<&str>,
) -> Result<Measured, MeasuredError> {
    let text = crate::input::read_text(path).map_err(|e| MeasuredError {
        file: path.to_path_buf(),
        line: 0,
        field: None,
        message: format!("cannot read the file: {e}"),
        missing_setting: None,
    })?;
    parse_for(path, &text, max_pin_radius, part)
}

/// Check the text of a measured-bands file (`file` names it in errors).
pub fn parse(file: &Path, text: &str, max_pin_radius: f64) -> Result<Measured, MeasuredError> {
    parse_for(file, text, max_pin_radius, None)
}

/// Why a CSV line could not be split into fields ([`split_fields`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FieldsError {
    /// A quoted field runs to the end of the line.
    #[error("a quoted field is not closed (a `\"` is missing)")]
    Unclosed,
    /// Something other than a comma follows a closing quote.
    #[error("'{0}' after a closing quote (expected ',')")]
    AfterQuote(char),
}

/// The fields of one CSV line, trimmed: a field in double quotes may hold commas, and `""` in it
/// is one quote (RFC 4180).
pub fn split_fields(line: &str) -> Result<Vec<String>, FieldsError> {
    let mut fields = Vec::new();
    let mut chars = line.chars().peekable();
    loop {
        let mut field = String::new();
        // Spaces before an opening quote are not part of the field.
        while chars.peek() == Some(&' ') || chars.peek() == Some(&'\t') {
            chars.next();
        }
        if chars.peek() == Some(&'"') {
            chars.next();
            loop {
                match chars.next() {
                    Some('"') if chars.peek() == Some(&'"') => {
                        chars.next();
                        field.push('"');
                    }
                    Some('"') => break,
                    Some(c) => field.push(c),
                    None => return Err(FieldsError::Unclosed),
                }
            }
            while chars.peek().is_some_and(|c| *c == ' ' || *c == '\t') {
                chars.next();
            }
            match chars.next() {
                None => {
                    fields.push(field);
                    return Ok(fields);
                }
                Some(',') => fields.push(field),
                Some(c) => return Err(FieldsError::AfterQuote(c)),
            }
        } else {
            loop {
                match chars.next() {
                    None => {
                        fields.push(field.trim().to_string());
                        return Ok(fields);
                    }
                    Some(',') => break,
                    Some(c) => field.push(c),
                }
            }
            fields.push(field.trim().to_string());
        }
    }
}

/// [`parse`], with `part` (`--part`) in place of the file's part column, which may then be absent.
pub fn parse_for(
    file: &Path,
    text: &str,
    max_pin_radius: f64,
    part: Option<&str>,
) -> Result<Measured, MeasuredError> {
    let err = |line: usize, field: Option<&str>, message: String| MeasuredError {
        file: file.to_path_buf(),
        line,
        field: field.map(str::to_string),
        message,
        missing_setting: None,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (hline, header) = lines
        .next()
        .ok_or_else(|| err(1, None, "empty file: expected the header `part,d,input,min_deg,max_deg,trials` and at least one row".into()))?;
    let names: Vec<String> = split_fields(header).map_err(|m| err(hline, None, m.to_string()))?;
    let has_part = names.first().is_some_and(|n| n == "part");
    let without_part: Vec<&str> = names[usize::from(has_part)..]
        .iter()
        .map(String::as_str)
        .collect();
    if without_part != COLUMNS[1..5] && without_part != COLUMNS[1..] {
        return Err(err(
            hline,
            None,
            format!(
                "the header must be `{}` (trials optional; part optional when one part is given for the whole file), got `{header}`",
                COLUMNS.join(",")
            ),
        ));
    }
    if !has_part && part.is_none() {
        return Err(MeasuredError {
            missing_setting: Some("part"),
            ..err(
                hline,
                None,
                "the header has no `part` column and no part was given for the whole file".into(),
            )
        });
    }
    let mut out = Measured {
        file: file.to_path_buf(),
        rows: Vec::new(),
        parts: Vec::new(),
    };
    for (line, text) in lines {
        let mut fields: Vec<String> =
            split_fields(text).map_err(|m| err(line, None, m.to_string()))?;
        let full = names.len() + usize::from(!has_part);
        if fields.len() != names.len() && !(full == 6 && fields.len() + 1 == names.len()) {
            return Err(err(
                line,
                None,
                format!(
                    "expected {} comma-separated fields ({}), got {}",
                    names.len(),
                    names.join(","),
                    fields.len()
                ),
            ));
        }
        match (part, has_part) {
            (Some(p), true) => fields[0] = p.to_string(),
            (Some(p), false) => fields.insert(0, p.to_string()),
            (None, _) => {}
        }
        let fields: Vec<&str> = fields.iter().map(String::as_str).collect();
        let row = parse_row(line, &fields, &mut out.parts, max_pin_radius)
            .map_err(|(field, m)| err(line, Some(field), m))?;
        out.rows.push(row);
    }
    if out.rows.is_empty() {
        return Err(err(
            hline,
            None,
            "no measurement rows after the header".into(),
        ));
    }
    Ok(out)
}

type FieldResult<T> = Result<T, (&'static str, String)>;

fn number(field: &'static str, s: &str) -> FieldResult<f64> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err((field, format!("'{s}' is not a finite number"))),
    }
}

fn angle(field: &'static str, s: &str) -> FieldResult<f64> {
    let v = number(field, s)?;
    if !(0.0..=360.0).contains(&v) {
        return Err((
            field,
            format!("{v} is out of range: angles lie in [0, 360] degrees"),
        ));
    }
    Ok(v)
}

fn parse_row(
    line: usize,
    f: &[&str],
    parts: &mut Vec<(String, Polygon)>,
    max_pin_radius: f64,
) -> FieldResult<MeasuredRow> {
    let part = f[0].to_string();
    if !parts.iter().any(|(p, _)| *p == part) {
        let poly =
            part_from_spec(&part).map_err(|e| ("part", format!("unknown part '{part}': {e}")))?;
        parts.push((part.clone(), poly));
    }
    let poly = &parts
        .iter()
        .find(|(p, _)| *p == part)
        .expect("just added")
        .1;
    let d = number("d", f[1])?;
    let limit = max_contact_parameter(poly, max_pin_radius);
    if d.abs() > limit {
        return Err((
            "d",
            format!("d = {d} is out of range: |d| must be at most {limit:.4} for {part} (beyond it the pin cannot touch the part)"),
        ));
    }
    let input = parse_input(f[2], stable_states_deg(poly).len())?;
    let (min_deg, max_deg) = (angle("min_deg", f[3])?, angle("max_deg", f[4])?);
    let trials = match f.get(5).copied().unwrap_or("") {
        "" => None,
        s => match s.parse::<u32>() {
            Ok(n) if (1..=MAX_TRIALS).contains(&n) => Some(n),
            _ => {
                return Err((
                    "trials",
                    format!("'{s}' must be a whole number in [1, {MAX_TRIALS}] or empty"),
                ))
            }
        },
    };
    Ok(MeasuredRow {
        line,
        part,
        d,
        input,
        band: Arc::from_measured_ends(min_deg, max_deg),
        min_deg,
        max_deg,
        trials,
    })
}

fn parse_input(s: &str, states: usize) -> FieldResult<InputState> {
    if s == "all" {
        return Ok(InputState::All);
    }
    if let Some(k) = s.strip_prefix("state:") {
        return match k.parse::<usize>() {
            Ok(index) if index < states => Ok(InputState::State { index }),
            _ => Err((
                "input",
                format!(
                    "'{s}': the part has {states} stable states, numbered 0 to {}",
                    states.saturating_sub(1)
                ),
            )),
        };
    }
    if let Some(rest) = s.strip_prefix("theta:") {
        if let Some((a, b)) = rest.split_once(':') {
            let (a, b) = (angle("input", a)?, angle("input", b)?);
            return Ok(InputState::Theta {
                arc: Arc::from_measured_ends(a, b),
            });
        }
    }
    Err((
        "input",
        format!("'{s}' must be state:K, theta:MIN:MAX (degrees) or all"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_parse_with_comments_and_an_empty_trials_field() {
        let t = "# bench, day 1\npart,d,input,min_deg,max_deg,trials\n\ntripoly1,0.5,state:1,350,12,20\ntripoly1,-0.3,theta:30:90,100,140,\ntripoly1,0.1,all,200,230\n";
        let m = parse(Path::new("m.csv"), t, 0.0).unwrap();
        assert_eq!(m.rows.len(), 3);
        assert_eq!(m.rows[0].line, 4);
        assert_eq!(m.rows[0].input, InputState::State { index: 1 });
        assert_eq!(m.rows[0].band.width, 22.0);
        assert_eq!(m.rows[1].trials, None);
        assert_eq!(m.rows[2].input, InputState::All);
    }
}
