//! `pinfeed plan --sensor`: the contingent planner ([`crate::plan::contingent`]): a sensor pin and
//! per-decision moving pins, written as a scenario plus its policy file, and checked on the line
//! (the real sensor and classifier), whose success is printed beside the prediction with a perfect
//! classifier and with the confusion the line measured.

use super::plan::{check_text, write_file, CheckReport, Executed, PlanArgs, PlanSummary};
use super::shell_word;
use crate::plan::contingent::{self, ContingentOutcome, ContingentPlan, ContingentStats};
use crate::plan::search::Planner;
use crate::plan::{emit, Problem};
use anyhow::{Context, Result};
use serde::Serialize;
use std::path::PathBuf;

/// The JSON document of `pinfeed plan --sensor --json`.
#[derive(Debug, Serialize)]
pub struct SensorReport<'a> {
    pub command: String,
    pub problem: &'a Problem,
    /// found | none_up_to_depth | limit
    pub result: &'static str,
    pub message: String,
    pub plan: Option<&'a ContingentPlan>,
    pub stats: &'a ContingentStats,
    pub check: Option<CheckReport>,
    /// The classifier's accuracy on the line, and the prediction with its confusion.
    pub sensor_accuracy: Option<f64>,
    pub predicted_with_confusion: Option<f64>,
    pub scenario: Option<String>,
    pub policy: Option<String>,
}

fn plan_text(problem: &Problem, plan: &ContingentPlan) -> String {
    let mut t = format!(
        "sensor      probe  x {:.3}  y {:+.2} mm  interval [{:+.2}, {:+.2}] mm  margin {:.2} mm\n",
        problem.spacing_m,
        plan.sensor.y_m * 1e3,
        plan.sensor.lo_m * 1e3,
        plan.sensor.hi_m * 1e3,
        plan.sensor.margin_m * 1e3
    );
    t += &format!(
        "moving pins {} (x = {:.3} m on, every {:.3} m)\n",
        plan.k,
        2.0 * problem.spacing_m,
        problem.spacing_m
    );
    for b in &plan.branches {
        let ys: Vec<String> = b
            .targets_m
            .iter()
            .enumerate()
            .map(|(j, y)| {
                if j < b.pins.len() {
                    format!("{:+.2}", y * 1e3)
                } else {
                    format!("park {:+.1}", y * 1e3)
                }
            })
            .collect();
        t += &format!(
            "  decides {:>6}  pins at y (mm) [{}]  {} of {} inside\n",
            b.label,
            ys.join(", "),
            b.inside,
            b.total
        );
    }
    t += &format!(
        "goal        {:.2}° ± {}°: predicted success {:.4} (perfect classifier)\n",
        plan.centre_deg, problem.tolerance_deg, plan.predicted_success
    );
    t
}

/// Plan with sensing, write, check; print nothing (see [`super::plan::execute`]).
pub fn execute(
    args: &PlanArgs,
    problem: &Problem,
    command: &str,
    pool: &rayon::ThreadPool,
) -> Result<Executed> {
    let mut planner = Planner::new(problem)?;
    let (outcome, stats) =
        pool.install(|| contingent::search(&mut planner, args.max_moving, args.sensor_candidates))?;
    let (result, message, plan, failure) = match &outcome {
        ContingentOutcome::Found(p) => (
            "found",
            format!(
                "found a contingent plan: one sensor pin and {} moving pin(s), the fewest for this action set",
                p.k
            ),
            Some(p),
            None,
        ),
        ContingentOutcome::NoneUpTo { depth } => (
            "none_up_to_depth",
            format!(
                "no contingent plan up to {depth} moving pin(s) for {} sensor position(s): none brings {} of the parts into one ±{}° window",
                stats.sensor_candidates, problem.target, problem.tolerance_deg
            ),
            None,
            None,
        ),
        ContingentOutcome::LimitHit {
            limit,
            depth_completed,
        } => {
            let m = format!(
                "contingent search stopped by its {limit} after completing {depth_completed} moving pin(s): no plan with at most {depth_completed} reaches the goal"
            );
            ("limit", m.clone(), None, Some(m))
        }
    };
    let mut scenario = None;
    let mut policy = None;
    let mut check = None;
    let mut accuracy = None;
    let mut with_confusion = None;
    let mut footprint_m = None;
    if let Some(plan) = plan {
        let out = args.out.clone().unwrap_or_else(|| {
            std::env::temp_dir()
                .join(format!("pinfeed_plan_{}", std::process::id()))
                .join("plan.toml")
        });
        let file = shell_word(&out.display().to_string());
        let stem = out
            .file_stem()
            .map_or("plan".to_string(), |s| s.to_string_lossy().to_string());
        let policy_name = format!("{stem}.policy.toml");
        let (toml, pol) = emit::contingent_toml(
            problem,
            plan,
            planner.compiled.stable_deg.len(),
            planner.compiled.symmetry,
            args.check_parts.max(1),
            command,
            &file,
            &policy_name,
        );
        let policy_path: PathBuf = out.with_file_name(&policy_name);
        write_file(&out, &toml)?;
        write_file(&policy_path, &pol)?;
        if args.check_parts > 0 {
            let started = std::time::Instant::now();
            let summary = pool.install(|| {
                crate::plan::check::check(&toml, &out, args.check_parts, problem.seed)
            })?;
            if let Some(s) = summary.sensors.first() {
                accuracy = Some(s.confusion.accuracy());
                // Rows and columns in branch order (labels matched by name).
                let idx: Vec<Option<usize>> = plan
                    .branches
                    .iter()
                    .map(|b| s.confusion.labels.iter().position(|l| *l == b.label))
                    .collect();
                if idx.iter().all(|i| i.is_some()) {
                    let n = plan.branches.len();
                    let counts: Vec<Vec<u64>> = idx
                        .iter()
                        .map(|i| {
                            let row = &s.confusion.counts[i.unwrap()];
                            let mut r: Vec<u64> = idx.iter().map(|j| row[j.unwrap()]).collect();
                            r.push(row[row.len() - 1]);
                            debug_assert_eq!(r.len(), n + 1);
                            r
                        })
                        .collect();
                    with_confusion = Some(plan.with_confusion(&counts));
                }
            }
            check = Some(CheckReport::of(&summary, started));
        }
        footprint_m = crate::plan::check::footprint_m(&toml, &out);
        if let Some(draw) = args
            .draw
            .clone()
            .or(args.out.as_ref().map(|o| o.with_extension("svg")))
        {
            let stages = contingent::stage_states(&mut planner, plan)?;
            crate::report::plot_plan::plot_contingent(problem, plan, &stages, &draw)
                .with_context(|| format!("drawing {}", draw.display()))?;
        }
        if args.out.is_none() {
            let _ = std::fs::remove_file(&out);
            let _ = std::fs::remove_file(&policy_path);
        }
        scenario = Some(toml);
        policy = Some(pol);
    }
    let summary = PlanSummary {
        result,
        message: message.clone(),
        obstacles: plan.map(|p| p.k + 1),
        predicted: plan.map(|p| p.predicted_success),
        check: check.clone(),
        uncertain_check: None,
        footprint_m,
        depth_completed: stats.states_per_depth.len().saturating_sub(1),
        search_s: stats.elapsed_s,
        refined: Vec::new(),
    };
    let output = if args.json {
        let report = SensorReport {
            command: command.to_string(),
            problem,
            result,
            message: message.clone(),
            plan,
            stats: &stats,
            check,
            sensor_accuracy: accuracy,
            predicted_with_confusion: with_confusion,
            scenario,
            policy,
        };
        serde_json::to_string_pretty(&report)? + "\n"
    } else {
        let mut t = format!("{command}\n");
        let levels: Vec<String> = stats
            .states_per_depth
            .iter()
            .enumerate()
            .map(|(k, n)| format!("{k}:{n}"))
            .collect();
        t += &format!(
            "search      {} sensor position(s); new states per moving pin {}; {:.3} s; peak RSS {}\n",
            stats.sensor_candidates,
            levels.join("  "),
            stats.elapsed_s,
            stats
                .peak_rss_bytes
                .map_or("n/a".into(), |b| format!("{:.1} MB", b as f64 / 1e6))
        );
        t += &format!("result      {message}\n");
        if let Some(plan) = plan {
            t += &plan_text(problem, plan);
        }
        if let Some(c) = &check {
            let extra = match (accuracy, with_confusion) {
                (Some(a), Some(w)) => format!(
                    " (perfect classifier), {w:.4} with the line's confusion (accuracy {a:.4})"
                ),
                _ => String::new(),
            };
            t += &check_text(c, plan.map_or(0.0, |p| p.predicted_success), &extra);
        }
        if let (Some(out), Some(_)) = (&args.out, plan) {
            let stem = out
                .file_stem()
                .map_or("plan".into(), |s| s.to_string_lossy().to_string());
            let draw = args
                .draw
                .clone()
                .unwrap_or_else(|| out.with_extension("svg"));
            t += &format!(
                "wrote       {}, {} and {}\n",
                out.display(),
                out.with_file_name(format!("{stem}.policy.toml")).display(),
                draw.display()
            );
        }
        t
    };
    Ok(Executed {
        output,
        summary,
        failure,
    })
}
