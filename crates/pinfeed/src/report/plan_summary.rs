//! The result of `pinfeed plan` ([`crate::plan::design`]) as printed and written: the text
//! summary, the JSON document, and the design's files (scenario, policy, uncertainty study and
//! drawing).

use crate::plan::design::reject::RejectDesign;
use crate::plan::design::{
    self, describe_obstacles, Candidate, Design, DesignOptions, Layout, Mode, Objective, Status,
};
use crate::plan::Problem;
use crate::report::{ReportError, ReportResult};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Where a design's files go: the scenario, the policy (a contingent design's) and the drawing.
#[derive(Debug, Clone)]
pub struct DesignPaths {
    /// The scenario file.
    pub scenario: PathBuf,
    /// The policy file, for a design with a sensor.
    pub policy: Option<PathBuf>,
    /// The drawing (SVG).
    pub draw: PathBuf,
}

impl DesignPaths {
    /// The files of design `o`: the scenario at `out` (default `pinfeed-out/plans/<name>.toml`),
    /// the policy beside it when `sensor`, the drawing at `draw` (default the scenario's `.svg`).
    pub fn new(
        out: Option<&Path>,
        draw: Option<&Path>,
        o: &DesignOptions,
        sensor: bool,
    ) -> DesignPaths {
        let scenario = out.map_or_else(
            || {
                PathBuf::from("pinfeed-out")
                    .join("plans")
                    .join(format!("{}.toml", o.name))
            },
            Path::to_path_buf,
        );
        let policy = sensor.then(|| scenario.with_file_name(format!("{}.policy.toml", o.name)));
        let draw = draw.map_or_else(|| scenario.with_extension("svg"), Path::to_path_buf);
        DesignPaths {
            scenario,
            policy,
            draw,
        }
    }
}

/// Write the chosen design's files (nothing when there is none) and return their names.
pub fn write_design(
    o: &DesignOptions,
    d: &Design,
    paths: &DesignPaths,
) -> ReportResult<Vec<String>> {
    let mut files = Vec::new();
    let DesignPaths {
        scenario,
        policy,
        draw,
    } = paths;
    if let (Some(c), Some(toml)) = (d.chosen(), &d.scenario_toml) {
        write(scenario, toml)?;
        files.push(scenario.display().to_string());
        if let (Some(p), Some((_, text))) = (policy, &d.policy_toml) {
            write(p, text)?;
            files.push(p.display().to_string());
        }
        draw_design(o, c, d, draw)?;
        files.push(draw.display().to_string());
        // A loop's scenario is not the open line the study was planned for.
        let looped = d.reject.as_ref().is_some_and(|r| r.gauge.is_some());
        if let Some(u) = c.uncertain_check.as_ref().filter(|_| !looped) {
            let file = scenario
                .file_name()
                .map_or("plan.toml".into(), |f| f.to_string_lossy().to_string());
            let study_path = scenario.with_file_name(format!("{}.uncertain.toml", o.name));
            let study_file = study_path
                .file_name()
                .map_or(String::new(), |f| f.to_string_lossy().to_string());
            let kinds: Vec<&str> = c.obstacles.iter().map(|o| o.kind.name()).collect();
            if let Some(study) =
                o.uncertainty()
                    .study_text(&kinds, &file, &study_file, o.problem.seed, u.parts)
            {
                write(&study_path, &study)?;
                files.push(study_path.display().to_string());
            }
        }
    }
    Ok(files)
}

/// The JSON document of `pinfeed plan --json`.
#[derive(Debug, Serialize)]
pub struct PlanJson<'a> {
    /// [`crate::SCHEMA_VERSION`].
    pub schema_version: u32,
    /// The version of pinfeed that planned.
    pub pinfeed_version: &'static str,
    /// The command that regenerates the design.
    pub command: &'a str,
    /// confirmed | not_confirmed | unchecked | no_design
    pub status: Status,
    /// One sentence: what was found and what the line says.
    pub message: &'a str,
    /// The design's name (its files are named after it).
    pub name: &'a str,
    /// The chosen design's mode (none without a design).
    pub mode: Option<Mode>,
    /// The particle abstraction's predicted success of the chosen design, in [0, 1].
    pub predicted_success: Option<f64>,
    /// The full line check of the chosen design.
    pub line_check: Option<&'a design::LineCheck>,
    /// The line check under the problem's uncertainty (a Monte Carlo study), when planned against
    /// one.
    pub uncertain_check: Option<&'a design::LineCheck>,
    /// The uncertainty the design was planned and checked against, in words.
    pub uncertainty: String,
    /// The chosen design's obstacles.
    pub obstacles: Option<&'a [design::ObstacleInfo]>,
    /// Belt length of the chosen design (m).
    pub belt_length_m: Option<f64>,
    /// Belt width the chosen design uses (m).
    pub belt_width_m: Option<f64>,
    /// Seconds between parts of the chosen design.
    pub headway_s: Option<f64>,
    /// Oriented parts per minute at that headway.
    pub oriented_per_min: Option<f64>,
    /// The files written.
    pub files: Vec<String>,
    /// A limit that cut the work short (the time limit), if any.
    pub limit: Option<&'a crate::plan::Limit>,
    /// Why lines touching only the hull cannot reach the target, if they cannot.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub certificate: Option<&'a crate::plan::certificate::Certificate>,
    /// Wall time of the planning (s).
    pub elapsed_s: f64,
    /// Every candidate considered.
    pub candidates: &'a [Candidate],
    /// The chosen candidate (also in `candidates`).
    pub chosen: Option<&'a Candidate>,
    /// A confirmed candidate of another mode that is simpler or faster than the chosen one (also
    /// in `candidates`): what the objective traded away.
    pub runner_up: Option<&'a Candidate>,
    /// Every mode asked for, with what became of it (searched, no plan and why, not needed,
    /// stopped by the time limit, not tried).
    pub modes: &'a [design::ModeReport],
    /// The planning problem.
    pub problem: &'a Problem,
    /// What the planner optimised.
    pub objective: Objective,
    /// The chosen design's scenario (TOML text; with `--reject` and a gauge, the loop's).
    pub scenario: Option<&'a str>,
    /// `--reject`: the states, the gauge, the loop and its verification.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reject: Option<&'a RejectDesign>,
}

/// The JSON document of a design, `files` being the ones written.
pub fn json(o: &DesignOptions, d: &Design, files: Vec<String>) -> ReportResult<String> {
    let c = d.chosen();
    let doc = PlanJson {
        schema_version: crate::SCHEMA_VERSION,
        pinfeed_version: env!("CARGO_PKG_VERSION"),
        command: &o.command,
        status: d.status,
        message: &d.message,
        name: &o.name,
        mode: c.map(|c| c.mode),
        predicted_success: c.map(|c| c.predicted_success),
        line_check: c.and_then(|c| c.line_check.as_ref()),
        uncertain_check: c.and_then(|c| c.uncertain_check.as_ref()),
        uncertainty: o.uncertainty().describe(),
        obstacles: c.map(|c| c.obstacles.as_slice()),
        belt_length_m: c.map(|c| c.belt_length_m),
        belt_width_m: c.map(|c| c.belt_width_m),
        headway_s: c.map(|c| c.headway_s),
        oriented_per_min: c.map(|c| c.oriented_per_min),
        files,
        limit: d.limit.as_ref(),
        certificate: d.certificate.as_ref(),
        elapsed_s: d.elapsed_s,
        candidates: &d.candidates,
        chosen: c,
        runner_up: d.runner_up(),
        modes: &d.modes,
        problem: &o.problem,
        objective: o.objective,
        scenario: d.scenario_toml.as_deref(),
        reject: d.reject.as_ref(),
    };
    Ok(crate::report::versioned::pretty(&doc)?)
}

/// Write `text` to `path` (creating its folder), whole or not at all.
fn write(path: &Path, text: &str) -> ReportResult<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::report::error::create_dir(dir)?;
    }
    crate::report::error::write_whole(path, text.as_bytes())
}

/// The drawing's title: the verdict with the line's number beside the prediction.
fn title(o: &DesignOptions, c: &Candidate, d: &Design) -> String {
    let verdict = match c.verdict_check() {
        Some(l) => format!(
            "{}: line {:.3} [{:.3}, {:.3}] of {} parts, target {}",
            d.status.word(),
            l.success_rate,
            l.ci95[0],
            l.ci95[1],
            l.parts,
            o.problem.target
        ),
        None => "unchecked".into(),
    };
    format!(
        "{} — {}; {verdict}; predicted {:.3}",
        o.name,
        describe_obstacles(c),
        c.predicted_success
    )
}

/// Draw the chosen candidate of a design into `path`.
pub fn draw_design(o: &DesignOptions, c: &Candidate, d: &Design, path: &Path) -> ReportResult<()> {
    let t = title(o, c, d);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::report::error::create_dir(dir)?;
    }
    // The plots write whole files or none (crate::output).
    match &c.layout {
        Layout::Sequence(plan) => crate::report::plot_plan::plot_plan(&c.problem, plan, &t, path),
        Layout::Contingent(plan) => {
            let mut planner = crate::plan::search::Planner::new(&c.problem)?;
            let stages = crate::plan::contingent::stage_states(&mut planner, plan)?;
            crate::report::plot_plan::plot_contingent(&c.problem, plan, &stages, &t, path)
        }
    }
    .map_err(ReportError::drawing(path))
}

/// The printed result: the command, the candidates, the verdict, the chosen layout and the files.
pub fn text(o: &DesignOptions, d: &Design, files: &[String]) -> String {
    let p = &o.problem;
    let mut t = format!("{}\n", o.command);
    t += &format!(
        "design      {}: modes {}; objective {:?}; goal ≥ {} of the parts in one ±{}° window{}, on the line\n",
        o.name,
        o.modes.iter().map(|m| m.name()).collect::<Vec<_>>().join(", "),
        o.objective,
        p.target,
        p.tolerance_deg,
        p.goal_deg.map_or(String::new(), |g| format!(" centred at {g}°"))
    );
    t += &format!("uncertainty {}\n", o.uncertainty().describe());
    t += "candidates  mode     round  particles  search                obstacles                        belt (m)  width (m)  predicted  line (parts, headway)\n";
    for (i, c) in d.candidates.iter().enumerate() {
        let line = match c.measured() {
            Some(l) => format!(
                "{:.4} [{:.4}, {:.4}] ({}, {} s){}",
                l.success_rate,
                l.ci95[0],
                l.ci95[1],
                l.parts,
                design::line::fmt_headway(l.headway_s),
                match (&c.line_check, c.screen_shared_with) {
                    (Some(_), _) => String::new(),
                    (None, Some(k)) => format!(" screen, as {}", k + 1),
                    (None, None) => " screen".into(),
                }
            ),
            None => "not run".into(),
        };
        t += &format!(
            "  {}{:<2}      {:<8} {:<6} {:>9}  {:<21} {:<32} {:>8.3}  {:>9.3}  {:>9.4}  {line}\n",
            if Some(i) == d.chosen { "*" } else { " " },
            i + 1,
            c.mode.name(),
            c.round,
            c.search.particles,
            format!("{} {:.1} s", c.search.result.name(), c.search.elapsed_s),
            describe_obstacles(c),
            c.belt_length_m,
            c.belt_width_m,
            c.predicted_success
        );
    }
    for (k, m) in d.modes.iter().enumerate() {
        let what = match (m.outcome, &m.reason) {
            (design::ModeOutcome::Searched, _) => format!("{} candidate(s)", m.candidates),
            (outcome, reason) => format!(
                "{}{}{}",
                outcome.word(),
                if m.candidates > 0 {
                    format!(" ({} candidate(s))", m.candidates)
                } else {
                    String::new()
                },
                reason.as_ref().map_or(String::new(), |r| format!(": {r}"))
            ),
        };
        let head = if k == 0 { "modes" } else { "" };
        t += &format!("{head:<11} {:<8} {what}\n", m.mode.name());
    }
    if let Some(c) = &d.certificate {
        t += &format!("certificate {}\n", c.describe());
    }
    t += &format!("result      {}\n", d.message);
    if let Some(c) = d.chosen() {
        if let Some(l) = &c.line_check {
            t += &format!(
                "line check  {} parts at headway {} s: success {:.4} (95% CI {:.4}–{:.4}) against predicted {:.4}{}; {} ({:.1} s)\n",
                l.parts,
                design::line::fmt_headway(l.headway_s),
                l.success_rate,
                l.ci95[0],
                l.ci95[1],
                c.predicted_success,
                c.predicted_with_confusion.map_or(String::new(), |w| format!(
                    " (perfect classifier), {w:.4} with the line's confusion (sensor accuracy {:.4})",
                    c.sensor_accuracy.unwrap_or(0.0)
                )),
                outcome_mix(&l.outcomes),
                l.elapsed_s
            );
            if let Some(u) = &c.uncertain_check {
                t += &format!(
                    "uncertain   {} samples under the uncertainty: success {:.4} (95% CI {:.4}–{:.4}; one-sided 95% lower bound {:.4}); {} — the verdict\n",
                    u.parts,
                    u.success_rate,
                    u.ci95[0],
                    u.ci95[1],
                    u.lower95,
                    outcome_mix(&u.outcomes)
                );
            }
            t += &headway_line(c.headway_s, c.headway_probes.len(), c.oriented_per_min);
        }
        if let Some(m) = &c.margins {
            t += &format!(
                "margins     {} — {} parts a step, each held to the target {}\n",
                m.describe(),
                m.parts_per_step(),
                m.target
            );
        }
        t += &format!(
            "belt        length {:.3} m, width {:.3} m\n",
            c.belt_length_m, c.belt_width_m
        );
        for ob in &c.obstacles {
            t += &format!(
                "  {:<10} {:<8} x {:.3} m  y {:+7.2} mm{}{}\n",
                ob.kind.name(),
                ob.name,
                ob.x_m,
                ob.y_m * 1e3,
                ob.angle_deg.map_or(String::new(), |a| format!(
                    "  angle {a:+}°  length {:.4} m",
                    ob.length_m.unwrap_or(0.0)
                )),
                if ob.targets_m.is_empty() {
                    String::new()
                } else {
                    format!(
                        "  targets (mm) [{}]",
                        ob.targets_m
                            .iter()
                            .map(|y| format!("{:+.2}", y * 1e3))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                }
            );
        }
    }
    if let Some(r) = d.runner_up() {
        t += &runner_up_line(d, r);
    }
    if let Some(l) = &d.limit {
        t += &match d.status {
            Status::Confirmed => format!(
                "cut short   {l}: the confirmed design is the best found within the limit; a longer limit may find a simpler or shorter one\n"
            ),
            _ => format!("limit       {l}\n"),
        };
    }
    if let Some(r) = &d.reject {
        t += &reject_lines(r);
    }
    t += &format!("time        {:.1} s\n", d.elapsed_s);
    if !files.is_empty() {
        t += &format!("wrote       {}\n", files.join(", "));
    }
    t
}

/// The `--reject` block: the states the line leaves, the gauge, the loop, each friction's run
/// and the verdict beside the open line.
fn reject_lines(r: &RejectDesign) -> String {
    let mut t = format!(
        "reject      measured {} parts at μ {}{}: {} state(s) leave the line\n",
        r.parts_per_friction * r.frictions.len() as u64,
        r.frictions
            .iter()
            .map(|m| m.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        if r.tripod { " on random tripods" } else { "" },
        r.states.len()
    );
    for s in &r.states {
        t += &format!(
            "  {:<5} {:>7.1}°  share {:.3}  width {:5.1} mm  edges (mm) low {:+.1}…{:+.1}  high {:+.1}…{:+.1}\n",
            if s.goal { "goal" } else { "other" },
            s.orientation_deg,
            s.share,
            s.width_mm,
            s.low_edge_m[0] * 1e3,
            s.low_edge_m[2] * 1e3,
            s.high_edge_m[0] * 1e3,
            s.high_edge_m[2] * 1e3,
        );
    }
    if let (Some(g), Some(l)) = (&r.gauge, &r.settings) {
        t += &format!(
            "  gauge      pin x {:.3} m  y {:+.2} mm  radius {:.1} mm ({:?} side: touched past {:+.2} mm)\n",
            g.x_m,
            g.y_m * 1e3,
            g.radius_m * 1e3,
            g.side,
            g.touch_m * 1e3
        );
        t += &format!(
            "  loop       gate at the belt's end (y {:+.1} mm ± {:.1} mm, reject_on contact); return uniform {}–{} s, buffer {}, max passes {}, merge gap {} s; feed headway {} s (planned yield per pass {:.3}); belt {:.3} × {:.3} m\n",
            l.gate_y_m * 1e3,
            l.gate_reach_m * 1e3,
            l.transit_s.0,
            l.transit_s.1,
            l.buffer,
            l.max_passes,
            design::line::fmt_headway(l.merge_gap_s),
            design::line::fmt_headway(l.feed_headway_s),
            l.planned_yield,
            l.belt_length_m,
            l.belt_width_m
        );
    }
    if let Some(v) = &r.verification {
        for f in &v.runs {
            t += &format!(
                "  μ {:<5}    {} new: delivered {}, in goal {}, purity 95% CI {:.4}–{:.4}, yield per pass {:.3}, {:.2} passes per delivered, {:.2} delivered/min\n",
                f.mu,
                f.new_parts,
                f.delivered,
                f.in_goal,
                f.purity_ci95[0],
                f.purity_ci95[1],
                f.yield_per_pass,
                f.passes_per_delivered,
                f.delivered_per_min.unwrap_or(0.0)
            );
        }
        t += &format!(
            "  loop       purity {:.4} (95% CI {:.4}–{:.4}) of {} delivered; yield per pass {:.3}; {:.2} passes per delivered part; {:.2} delivered / {:.2} oriented parts per minute ({:.1} s)\n",
            v.purity,
            v.purity_ci95[0],
            v.purity_ci95[1],
            v.delivered,
            v.yield_per_pass,
            v.passes_per_delivered,
            v.delivered_per_min,
            v.oriented_per_min,
            v.elapsed_s
        );
    }
    t += &format!(
        "  open line  {:.2} oriented parts per minute at purity {:.4}{}\n",
        r.open_oriented_per_min,
        r.open_purity,
        if r.open_purity < r.purity_target {
            format!(" (below {}: none at the required purity)", r.purity_target)
        } else {
            String::new()
        }
    );
    t += &format!(
        "  verdict    {} — {} ({:.1} s)\n",
        r.verdict.word(),
        r.reason,
        r.elapsed_s
    );
    t
}

/// The runner-up's line: what it is, its check, its throughput and its belt beside the chosen
/// design's.
fn runner_up_line(d: &Design, r: &Candidate) -> String {
    let Some(c) = d.chosen() else {
        return String::new();
    };
    let check = r.verdict_check().map_or(String::new(), |l| {
        format!(
            "confirmed {:.4} (95% CI {:.4}–{:.4}) of {} parts, ",
            l.success_rate, l.ci95[0], l.ci95[1], l.parts
        )
    });
    let mut why = Vec::new();
    if r.actuators < c.actuators {
        why.push(if r.actuators == 0 {
            "passive (no sensor or moving pin)".to_string()
        } else {
            format!("{} actuator(s) against {}", r.actuators, c.actuators)
        });
    }
    if r.oriented_per_min > c.oriented_per_min {
        why.push(format!(
            "{:.2} oriented parts/min against {:.2}",
            r.oriented_per_min, c.oriented_per_min
        ));
    }
    format!(
        "runner-up   {} ({} mode): {check}{:.2} oriented parts/min at headway {} s, belt {:.3} m ({:+.3} m); {}\n",
        describe_obstacles(r),
        r.mode.name(),
        r.oriented_per_min,
        design::line::fmt_headway(r.headway_s),
        r.belt_length_m,
        r.belt_length_m - c.belt_length_m,
        why.join(", ")
    )
}

/// "success 9987, wrong_orientation 13".
pub fn outcome_mix(o: &crate::engine::OutcomeCounts) -> String {
    let parts = [
        ("success", o.success),
        ("wrong_orientation", o.wrong_orientation),
        ("collision", o.collision),
        ("multi_contact", o.multi_contact),
        ("off_belt", o.off_belt),
        ("jam", o.jam),
        ("solver", o.solver),
    ];
    parts
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(k, n)| format!("{k} {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The `headway` line: the headway chosen by its search, or, when the time limit left the
/// search no probe, the one at which the parts ran far apart, said as such.
fn headway_line(headway_s: f64, probes: usize, per_min: f64) -> String {
    let h = design::line::fmt_headway(headway_s);
    if probes == 0 {
        format!(
            "headway     {h} s, the parts far apart (the time limit left the headway search no probe; a shorter one may hold): {per_min:.2} oriented parts per minute\n"
        )
    } else {
        format!(
            "headway     {h} s, the shortest with no collision and no loss of success over {probes} probe(s), with a 25% reserve: {per_min:.2} oriented parts per minute\n"
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A headway no probe tested is not called the shortest.
    #[test]
    fn an_unprobed_headway_is_not_called_the_shortest() {
        let none = headway_line(51.0, 0, 0.58);
        assert!(!none.contains("shortest"), "{none}");
        assert!(none.contains("no probe"), "{none}");
        let some = headway_line(2.0, 6, 29.7);
        assert!(
            some.contains("the shortest") && some.contains("over 6 probe(s)"),
            "{some}"
        );
    }
}
