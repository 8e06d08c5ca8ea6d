//! A survey of designs (`pinfeed bench designs` → `results/designs.md`): for each part, the
//! design workflow ([`super::design`]) once per single mode (pins, fences, sensor) and once with
//! every mode (the hybrid default), each verdict from the line; then the share of parts each
//! confirms.

use super::{describe_obstacles, design, Design, DesignOptions, Mode, Status};
use crate::plan::Problem;
use serde::Serialize;
use std::fmt::Write as _;

/// One part of a survey: its spec, metres per unit and a display name.
#[derive(Debug, Clone, Serialize)]
pub struct SurveyPart {
    /// The part specification, as `pinfeed plan --part` takes it.
    pub spec: String,
    /// Metres per unit of the part's coordinates (default 0.02).
    pub scale: f64,
    /// Display name in the report (the spec as given).
    pub label: String,
}

impl SurveyPart {
    /// A part given as `SPEC` or `SPEC@SCALE` (e.g. `vertices:0,0 40,0 20,30@0.001`).
    pub fn parse(s: &str) -> SurveyPart {
        let (spec, scale) = match s.rsplit_once('@') {
            Some((a, b)) if b.parse::<f64>().is_ok() => (a.to_string(), b.parse().unwrap()),
            _ => (s.to_string(), 0.02),
        };
        SurveyPart {
            label: spec.clone(),
            spec,
            scale,
        }
    }
}

/// A survey's settings.
#[derive(Debug, Clone)]
pub struct SurveySettings {
    /// The parts surveyed, in report order.
    pub parts: Vec<SurveyPart>,
    /// Each design's time limit (s).
    pub time_limit_s: f64,
    /// Parts of each design's line check.
    pub check_parts: u64,
    /// Robustness: plan and check against μc uniform in this range.
    pub mu_c_range: Option<(f64, f64)>,
    /// Robustness: plan and check against random tripod supports.
    pub tripod: bool,
    /// The uncertainty every design is planned and checked against (with `mu_c_range` and
    /// `tripod` applied to it as `pinfeed plan` applies them).
    pub uncertainty: super::UncertaintyChoice,
    /// Seed of every design's planning and line runs.
    pub seed: u64,
}

/// One design of a survey.
#[derive(Debug, Clone, Serialize)]
pub struct SurveyCell {
    /// The modes it was allowed ("pins", "fences", "sensor", or "all").
    pub modes: String,
    /// The design's verdict.
    pub status: Status,
    /// One sentence: what was found and what the line says.
    pub message: String,
    /// The mode of the chosen design (None without one).
    pub mode: Option<Mode>,
    /// The chosen design's obstacles, in one line (`–` without one).
    pub obstacles: String,
    /// Success rate of the verdict's check (under the uncertainty if any; None without one).
    pub success_rate: Option<f64>,
    /// Its 95% Wilson interval.
    pub ci95: Option<[f64; 2]>,
    /// Parts in the full line check.
    pub parts: Option<u64>,
    /// Length of the chosen design's belt (m).
    pub belt_length_m: Option<f64>,
    /// Width of the chosen design's belt (m).
    pub belt_width_m: Option<f64>,
    /// Headway chosen on the line (s).
    pub headway_s: Option<f64>,
    /// Oriented parts per minute at that headway.
    pub oriented_per_min: Option<f64>,
    /// Wall time of the design (s).
    pub elapsed_s: f64,
}

impl SurveyCell {
    fn of(modes: &str, d: &Design) -> SurveyCell {
        let c = d.chosen();
        let l = c.and_then(|c| c.verdict_check());
        SurveyCell {
            modes: modes.into(),
            status: d.status,
            message: d.message.clone(),
            mode: c.map(|c| c.mode),
            obstacles: c.map_or("–".into(), describe_obstacles),
            success_rate: l.map(|l| l.success_rate),
            ci95: l.map(|l| l.ci95),
            parts: l.map(|l| l.parts),
            belt_length_m: c.map(|c| c.belt_length_m),
            belt_width_m: c.map(|c| c.belt_width_m),
            headway_s: c.map(|c| c.headway_s),
            oriented_per_min: c.map(|c| c.oriented_per_min),
            elapsed_s: d.elapsed_s,
        }
    }

    fn refused(modes: &str, why: String) -> SurveyCell {
        SurveyCell {
            modes: modes.into(),
            status: Status::NoDesign,
            message: why,
            mode: None,
            obstacles: "–".into(),
            success_rate: None,
            ci95: None,
            parts: None,
            belt_length_m: None,
            belt_width_m: None,
            headway_s: None,
            oriented_per_min: None,
            elapsed_s: 0.0,
        }
    }
}

/// A part's row: one cell per mode set.
#[derive(Debug, Clone, Serialize)]
pub struct SurveyRow {
    /// The part.
    pub part: SurveyPart,
    /// One cell per mode set, in the order of `COLUMNS`.
    pub cells: Vec<SurveyCell>,
}

/// The mode sets of a survey's columns.
pub const COLUMNS: [(&str, &[Mode]); 4] = [
    ("pins", &[Mode::Pins]),
    ("fences", &[Mode::Fences]),
    ("sensor", &[Mode::Sensor]),
    (
        "all",
        &[Mode::Pins, Mode::Fences, Mode::Hybrid, Mode::Sensor],
    ),
];

/// Run one part's designs (`each` is told every finished cell).
pub fn survey_part(s: &SurveySettings, part: &SurveyPart) -> SurveyRow {
    let mut cells = Vec::new();
    for (name, modes) in COLUMNS {
        let mut p = Problem::new(&part.spec);
        p.scale = part.scale;
        p.mu_c_range = s.mu_c_range;
        p.tripod = s.tripod;
        p.seed = s.seed;
        let mut o = DesignOptions::new(p);
        o.modes = modes.to_vec();
        o.time_limit_s = s.time_limit_s;
        o.check_parts = s.check_parts;
        o.screen_parts = o.screen_parts.min(s.check_parts.max(1));
        o.uncertainty = s.uncertainty.clone();
        cells.push(match design(&o, &|_| {}) {
            Ok(d) => SurveyCell::of(name, &d),
            Err(e) => SurveyCell::refused(name, e.to_string()),
        });
    }
    SurveyRow {
        part: part.clone(),
        cells,
    }
}

fn cell_text(c: &SurveyCell) -> String {
    let line = match (c.success_rate, c.ci95, c.parts) {
        (Some(r), Some(ci), Some(n)) => format!("{r:.4} [{:.4}, {:.4}] of {n}", ci[0], ci[1]),
        _ => "–".into(),
    };
    match c.status {
        Status::NoDesign => format!("no design ({:.0} s)", c.elapsed_s),
        _ => format!(
            "**{}** {line}; {}{}; belt {:.2} × {:.2} m; headway {} s, {:.1}/min; {:.0} s",
            c.status.word(),
            c.obstacles,
            c.mode
                .filter(|_| c.modes == "all")
                .map_or(String::new(), |m| format!(" ({})", m.name())),
            c.belt_length_m.unwrap_or(0.0),
            c.belt_width_m.unwrap_or(0.0),
            super::line::fmt_headway(c.headway_s.unwrap_or(0.0)),
            c.oriented_per_min.unwrap_or(0.0),
            c.elapsed_s
        ),
    }
}

/// The survey as a Markdown section (a table and the shares).
pub fn markdown(title: &str, rows: &[SurveyRow]) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "## {title}\n");
    let _ = writeln!(
        m,
        "| part | pins | fences | sensor | all modes (the default) |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|");
    for r in rows {
        let _ = write!(m, "| `{}` |", r.part.label.replace('|', "/"));
        for c in &r.cells {
            let _ = write!(m, " {} |", cell_text(c));
        }
        m.push('\n');
    }
    let _ = writeln!(m, "\n| mode | confirmed | median time (s) | max time (s) |");
    let _ = writeln!(m, "|---|---|---|---|");
    for (k, (name, _)) in COLUMNS.iter().enumerate() {
        let n = rows
            .iter()
            .filter(|r| r.cells[k].status == Status::Confirmed)
            .count();
        let mut t: Vec<f64> = rows.iter().map(|r| r.cells[k].elapsed_s).collect();
        t.sort_by(f64::total_cmp);
        let med = if t.is_empty() { 0.0 } else { t[t.len() / 2] };
        let max = t.last().copied().unwrap_or(0.0);
        let _ = writeln!(
            m,
            "| {name} | {n} of {} ({:.0}%) | {med:.1} | {max:.1} |",
            rows.len(),
            100.0 * n as f64 / rows.len().max(1) as f64
        );
    }
    m
}

/// The whole report of a survey: its title, the command that regenerates it, what a cell means,
/// and the table of `rows` under a heading that names the physics (nominal or uncertain).
pub fn page(command: &str, s: &SurveySettings, rows: &[SurveyRow]) -> String {
    let mut m = format!(
        "# Designs the line confirms (`pinfeed bench designs`)\n\nRegenerate:\n\n    {command}\n\n"
    );
    m += "Each cell is one run of `pinfeed plan` (the design workflow) allowed one mode — fixed pins, fences, a sensor pin with moving pins — or all of them together with lines that mix pins and fences (the default). Every other setting is `pinfeed plan`'s default: a stable-state feed with equal weights, 2° jitter, ±2 mm lateral; μc 0.5 (fences μf = μc), 2 mm pins 15 cm apart, a 10 cm belt for pins (fences may widen it: the width is reported); goal ≥ 0.99 of the parts in one ±3° window modulo the part's symmetry. A design is **confirmed** when its line check (the parts below, at the headway the workflow chose on the line) holds the goal; otherwise the best design the line measured is reported **not confirmed** with its number. Cells: verdict, line success [95% CI] of N parts; obstacles (the mode chosen); belt length × width; headway and oriented parts per minute; wall time of the whole design on this 2-core machine.\n\n";
    let mut p = Problem::new("square");
    p.mu_c_range = s.mu_c_range;
    p.tripod = s.tripod;
    let mut o = DesignOptions::new(p);
    o.uncertainty = s.uncertainty.clone();
    let u = o.uncertainty();
    let title = if u.is_nominal() {
        "Nominal physics".to_string()
    } else {
        format!("Under {} (planned and checked against it)", u.describe())
    };
    m += &markdown(&title, rows);
    m
}
