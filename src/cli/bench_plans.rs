//! `pinfeed bench plans`: which polygons can pins orient? The three planners of `pinfeed plan`
//! (sensorless pins, one sensor with moving pins, fences) run on seeded random polygons
//! (`random:SEED`, [`crate::geometry::named::random_vertices`]) with the planner's defaults, each
//! plan checked on the line, and the table, the shares and a drawing of the polygons are written
//! to a Markdown report (rewritten after every polygon, so a long survey shows its progress).
//!
//! A part counts as **oriented** by a planner when the planner found a plan and the line check
//! confirms it: at least `--target` (default 0.99) of the checked parts in the goal window. The
//! sensing planner runs only on the parts the sensorless pins do not orient (a sensorless plan is
//! a sensing plan that ignores its sensor), so "with sensing" counts both.

use super::plan::{execute, PlanArgs, PlanSummary};
use crate::geometry::named::part_from_spec;
use crate::plan::problem::rotational_symmetry;
use anyhow::{Context, Result};
use clap::Parser;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Settings of a survey.
#[derive(Debug, Clone)]
pub struct Survey {
    /// The parts (`random:SEED` or any part spec).
    pub specs: Vec<String>,
    /// Run the sensing planner on every part, not only where sensorless pins fail.
    pub sense_all: bool,
    pub time_limit_s: f64,
    pub check_parts: u64,
    /// Belt width of the fence plans (m).
    pub fence_belt_m: f64,
    pub target: f64,
    pub threads: usize,
    pub out: PathBuf,
    /// The command line written at the top of the report.
    pub command: String,
}

/// One polygon's row.
#[derive(Debug, Clone)]
struct Row {
    spec: String,
    vertices: usize,
    convex: bool,
    stable: usize,
    symmetry: u32,
    pins: PlanSummary,
    sensing: Option<PlanSummary>,
    fences: PlanSummary,
}

#[derive(Parser)]
struct Wrap {
    #[command(flatten)]
    plan: PlanArgs,
}

/// Run `pinfeed plan` with these extra words and return its summary (a limit is a result here).
fn plan(spec: &str, extra: &[&str], s: &Survey) -> Result<PlanSummary> {
    let mut words: Vec<String> = ["plan", "--part", spec, "--time-limit"]
        .iter()
        .map(|w| w.to_string())
        .collect();
    words.push(s.time_limit_s.to_string());
    words.extend(["--check-parts".into(), s.check_parts.to_string()]);
    words.extend(["--target".into(), s.target.to_string()]);
    words.extend(["--threads".into(), s.threads.to_string()]);
    words.extend(extra.iter().map(|w| w.to_string()));
    let args = Wrap::try_parse_from(&words)
        .with_context(|| format!("survey arguments {words:?}"))?
        .plan;
    // A planner that refuses the problem (say, no sensor position touches every part) is a
    // result of the survey, not its end.
    Ok(match execute(&args) {
        Ok(done) => done.summary,
        Err(e) => PlanSummary {
            result: "refused",
            message: format!("{e:#}"),
            obstacles: None,
            predicted: None,
            check: None,
            uncertain_check: None,
            footprint_m: None,
            depth_completed: 0,
            search_s: 0.0,
            refined: Vec::new(),
        },
    })
}

fn oriented(p: &PlanSummary, target: f64) -> bool {
    p.result == "found" && p.check.as_ref().is_some_and(|c| c.success_rate >= target)
}

/// Run the survey, rewriting the report after every polygon.
pub fn run(s: &Survey) -> Result<()> {
    let mut rows: Vec<Row> = Vec::new();
    for spec in &s.specs {
        let spec = spec.clone();
        let poly = part_from_spec(&spec)?;
        eprintln!("bench plans: {spec} …");
        let pins = plan(&spec, &[], s)?;
        let sensing = if oriented(&pins, s.target) && !s.sense_all {
            None
        } else {
            Some(plan(&spec, &["--sensor"], s)?)
        };
        let width = s.fence_belt_m.to_string();
        let fences = plan(&spec, &["--fences", "--belt-width", &width], s)?;
        rows.push(Row {
            spec,
            vertices: poly.vertices().len(),
            convex: poly.is_convex(),
            stable: poly.stable_states().len(),
            symmetry: rotational_symmetry(&poly),
            pins,
            sensing,
            fences,
        });
        write_report(s, &rows)?;
    }
    Ok(())
}

fn cell(p: &PlanSummary, unit: &str) -> String {
    let n = p.obstacles.map_or("–".into(), |k| {
        let unit = if k == 1 {
            unit.trim_end_matches('s')
        } else {
            unit
        };
        format!("{k} {unit}")
    });
    let sim = p.check.as_ref().map_or("–".into(), |c| {
        format!(
            "{:.4} ({:.4}–{:.4})",
            c.success_rate, c.success_ci95[0], c.success_ci95[1]
        )
    });
    let pred = p.predicted.map_or("–".into(), |x| format!("{x:.3}"));
    let what = match p.result {
        "found" if p.refined.is_empty() => "shortest".to_string(),
        "found" => {
            let first = &p.refined[0];
            format!(
                "shortest after {} re-plan(s) with more particles (planned with {}: {} · {:.3} · {:.4} on the line)",
                p.refined.len(),
                first.particles,
                first.obstacles,
                first.predicted,
                first.simulated
            )
        }
        "none_up_to_depth" => format!("none ≤ {}; best", p.depth_completed),
        "exhausted" => format!("none at any depth (after {}); best", p.depth_completed),
        "refused" => return format!("refused: {}", p.message.replace('|', "/")),
        _ => format!("limit after depth {}; best", p.depth_completed),
    };
    format!(
        "{what}: {n} · {pred} · {sim} · {}",
        p.footprint_m.map_or("–".into(), |f| format!("{f:.2} m"))
    )
}

fn share(rows: &[Row], f: impl Fn(&Row) -> bool) -> String {
    let k = rows.iter().filter(|r| f(r)).count();
    format!(
        "{k} of {} ({:.0}%)",
        rows.len(),
        100.0 * k as f64 / rows.len() as f64
    )
}

fn write_report(s: &Survey, rows: &[Row]) -> Result<()> {
    let t = s.target;
    let mut m = String::new();
    let random = s.specs.iter().all(|p| p.starts_with("random:"));
    let svg = s.out.with_extension("svg");
    let svg_name = svg
        .file_name()
        .map_or(String::new(), |f| f.to_string_lossy().to_string());
    if random {
        writeln!(m, "# Which polygons can pins orient? A survey of random polygons (`pinfeed bench plans`)\n")?;
    } else {
        writeln!(
            m,
            "# Sensorless pins, one sensor, fences: {} (`pinfeed bench plans`)\n",
            s.specs.join(", ")
        )?;
    }
    writeln!(
        m,
        "Regenerate (this file, `{svg_name}` beside it):\n\n    {}\n",
        s.command
    )?;
    if random {
        write!(m, "Each polygon is `random:SEED` (a seeded star-shaped polygon, 3–8 vertices, radii 0.6–1.4 units, 2 cm per unit; `pinfeed part random:SEED` describes it). ")?;
    }
    let sensing_runs = if s.sense_all {
        "runs on every part"
    } else {
        "runs only where the sensorless pins do not orient the part"
    };
    writeln!(m, "Every planner runs with `pinfeed plan`'s defaults (stable-state feed with equal weights, 2° jitter, ±2 mm lateral; μc 0.5, 2 mm pins, 10 cm belt, pins 15 cm apart; goal ≥ {t} in one ±3° window modulo the part's symmetry; min margin 0.5 mm; depth ≤ 8), a search limit of {} s each, and a line check of {} parts. Fences get an {:.0} cm belt. A planner **orients** a part when it finds a plan and the line confirms it (≥ {t} of the checked parts in the window). Sensing (a force/torque sensor pin, then up to 3 moving pins, `--sensor`) {sensing_runs}. Cells: result: obstacles · predicted · simulated (95% CI) · belt footprint. A result other than \"shortest\" shows the best effort the search found (the shortest plan with the most particles in one window), checked on the line the same way.\n",
        s.time_limit_s, s.check_parts, s.fence_belt_m * 100.0)?;
    writeln!(m, "| part | vertices | convex | stable states | symmetry | sensorless pins | with one sensor | fences | search s (pins / sensor / fences) |")?;
    writeln!(m, "|---|---|---|---|---|---|---|---|---|")?;
    for r in rows {
        let sens = r
            .sensing
            .as_ref()
            .map_or("(sensorless suffices)".into(), |p| cell(p, "obstacles"));
        writeln!(
            m,
            "| `{}` | {} | {} | {} | {} | {} | {} | {} | {:.1} / {} / {:.1} |",
            r.spec,
            r.vertices,
            if r.convex { "yes" } else { "no" },
            r.stable,
            r.symmetry,
            cell(&r.pins, "pins"),
            sens,
            cell(&r.fences, "fences"),
            r.pins.search_s,
            r.sensing
                .as_ref()
                .map_or("–".into(), |p| format!("{:.1}", p.search_s)),
            r.fences.search_s
        )?;
    }
    let pins = |r: &Row| oriented(&r.pins, t);
    let sensing = |r: &Row| pins(r) || r.sensing.as_ref().is_some_and(|p| oriented(p, t));
    let fences = |r: &Row| oriented(&r.fences, t);
    writeln!(m, "\n## Shares ({} polygons)\n", rows.len())?;
    writeln!(
        m,
        "| oriented by | share | planned (before the line check) |"
    )?;
    writeln!(m, "|---|---|---|")?;
    writeln!(
        m,
        "| sensorless pins | {} | {} |",
        share(rows, pins),
        share(rows, |r| r.pins.result == "found")
    )?;
    writeln!(
        m,
        "| pins with one sensor (or sensorless) | {} | {} |",
        share(rows, sensing),
        share(rows, |r| r.pins.result == "found"
            || r.sensing.as_ref().is_some_and(|p| p.result == "found"))
    )?;
    writeln!(
        m,
        "| fences | {} | {} |",
        share(rows, fences),
        share(rows, |r| r.fences.result == "found")
    )?;
    writeln!(
        m,
        "| pins or fences | {} | |",
        share(rows, |r| sensing(r) || fences(r))
    )?;
    let dir = s.out.parent().unwrap_or(Path::new("."));
    crate::report::plot_survey::plot_survey(
        &rows
            .iter()
            .map(|r| (r.spec.clone(), [pins(r), sensing(r) && !pins(r), fences(r)]))
            .collect::<Vec<_>>(),
        &svg,
    )?;
    writeln!(
        m,
        "\n![The polygons and who orients them](./{})\n",
        svg.strip_prefix(dir).unwrap_or(&svg).display()
    )?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(&s.out, m).with_context(|| format!("writing {}", s.out.display()))
}
