//! `pinfeed plan`: the sensorless pin planner ([`crate::plan`]): a shortest robust sequence of
//! fixed pins that orients a part, written as a runnable scenario, drawn, and checked on the line.
//!
//! Standard output gets the search statistics, the plan table and the line check (or, with
//! `--json`, one JSON document). `--out FILE.toml` writes the scenario (headed by the command that
//! wrote it) and, unless `--draw` names another file, its drawing beside it (`FILE.svg`). A search
//! that finds no plan up to its depth reports so and succeeds (that is an answer); one stopped by a
//! limit (`--max-states`, `--time-limit`) or a bad input exits non-zero with a message.

use super::shell_word;
use super::stdout::print_result;
use crate::plan::fences::FenceTransition;
use crate::plan::search::{Planner, SearchStats};
use crate::plan::{emit, Action, FeedKind, Outcome, Plan, Problem};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Arguments of `pinfeed plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Part: tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, random:SEED[:N], or vertices:"x,y x,y ...".
    #[arg(long)]
    pub part: String,
    /// Metres per unit of the part's coordinates.
    #[arg(long, default_value_t = 0.02, allow_hyphen_values = true)]
    pub scale: f64,
    /// Feed orientation: stable (the stable states, equal weights, with --jitter) or uniform.
    #[arg(long, default_value = "stable")]
    pub feed: String,
    /// Orientation jitter of a stable feed: standard deviation (degrees).
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    pub jitter: f64,
    /// Lateral offset at entry: uniform in ±LATERAL (m).
    #[arg(long, default_value_t = 0.002, allow_hyphen_values = true)]
    pub lateral: f64,
    /// Particles per stable state: this many jitter quantiles …
    #[arg(long, default_value_t = 5)]
    pub jitter_samples: usize,
    /// … times this many lateral offsets.
    #[arg(long, default_value_t = 5)]
    pub offset_samples: usize,
    /// Orientations of a uniform feed (each times --offset-samples).
    #[arg(long, default_value_t = 72)]
    pub orientation_samples: usize,
    /// Pin–part friction μc.
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Be robust against μc: each particle draws its own μc uniformly in LO:HI.
    #[arg(long, value_name = "LO:HI")]
    pub mu_c_range: Option<String>,
    /// Be robust against the support: each particle gets its own random tripod.
    #[arg(long)]
    pub tripod: bool,
    /// Pin radius (m; 0 = point pin).
    #[arg(long, default_value_t = 0.002, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Belt width (m).
    #[arg(long, default_value_t = 0.1, allow_hyphen_values = true)]
    pub belt_width: f64,
    /// Distance between pins along the belt (m).
    #[arg(long, default_value_t = 0.15, allow_hyphen_values = true)]
    pub spacing: f64,
    /// Most pins (the search depth).
    #[arg(long, alias = "depth", default_value_t = 8)]
    pub max_pins: usize,
    /// Goal: half-width of the orientation window (degrees).
    #[arg(long, default_value_t = 3.0, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// Goal: share of the parts inside one window.
    #[arg(long, default_value_t = 0.99, allow_hyphen_values = true)]
    pub target: f64,
    /// Minimise the number of orientation sets instead (searches every depth unless one set is reached).
    #[arg(long)]
    pub fewest_sets: bool,
    /// Smallest robustness margin of a pin position (mm).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub min_margin: f64,
    /// Lateral quantum of particles and pin grid (mm).
    #[arg(long, default_value_t = 0.25, allow_hyphen_values = true)]
    pub y_quantum: f64,
    /// Orientation quantum of particles (degrees; divides 360).
    #[arg(long, default_value_t = 0.25, allow_hyphen_values = true)]
    pub theta_quantum: f64,
    /// Sample each orientation's outcome every COARSE pin positions and bisect changes (1 = all).
    #[arg(long, default_value_t = 4)]
    pub coarse: usize,
    /// Stop after this many distinct states kept (each ≈ 16 bytes per particle).
    #[arg(long, default_value_t = 1_000_000)]
    pub max_states: usize,
    /// Expand every state, even those that cannot beat the best effort within the pins left
    /// (branch and bound off: same result, more work; for comparison).
    #[arg(long)]
    pub no_bound: bool,
    /// Stop after this many seconds of search.
    #[arg(long, default_value_t = 600.0, allow_hyphen_values = true)]
    pub time_limit: f64,
    /// Integration tolerance of the contact model while planning.
    #[arg(long, default_value_t = 1e-5, allow_hyphen_values = true)]
    pub contact_tol: f64,
    /// Seed of the particles (and of the line check).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write the plan as a scenario file.
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<PathBuf>,
    /// Draw the plan (SVG) [default: beside --out, FILE.svg].
    #[arg(long, value_name = "FILE.svg")]
    pub draw: Option<PathBuf>,
    /// Parts run through the line to check the plan (0: no check).
    #[arg(long, default_value_t = 10_000)]
    pub check_parts: u64,
    /// Print one JSON document.
    #[arg(long)]
    pub json: bool,
    /// Contingent plan with sensing: a sensor pin, then per-decision moving pins (a policy file).
    #[arg(long)]
    pub sensor: bool,
    /// With --sensor: most moving pins after the sensor.
    #[arg(long, default_value_t = 3)]
    pub max_moving: usize,
    /// With --sensor: sensor positions tried (the most robust pin intervals that touch every part).
    #[arg(long, default_value_t = 6)]
    pub sensor_candidates: usize,
    /// Fence plan: each action is a fence (angles ±15°…±60° in 5° steps below the jam limit).
    #[arg(long)]
    pub fences: bool,
    /// With --fences: fence friction μf [default: --mu-c].
    #[arg(long)]
    pub mu_f: Option<f64>,
    /// With --fences: downstream overhang of each fence past the parts' reach (units of a).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub fence_overhang: f64,
    /// With --fences: largest |angle| tried (degrees; candidates ±15° … ±60°, always below the jam
    /// limit). At 60° (3.4° from the jam limit at μf 0.5) the line parted from the plan (tripoly2:
    /// 83% against 100%), hence 55.
    #[arg(long, default_value_t = 55.0, allow_hyphen_values = true)]
    pub max_fence_angle: f64,
    /// With --fences: step between candidate angles (degrees; from ±15°). A finer step is a larger
    /// action set: shorter designs, longer searches.
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    pub fence_angle_step: f64,
    /// When the line check holds less than --target of a found plan's parts, re-plan with more
    /// particles (2 more jitter and offset samples; a uniform feed 1.5× the orientations), at most
    /// this many times (0: never). Not with --sensor.
    #[arg(long, default_value_t = 2)]
    pub refine: usize,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

fn parse_range(s: &str) -> Result<(f64, f64)> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| anyhow!("--mu-c-range '{s}': expected LO:HI, e.g. 0.3:0.7"))?;
    let p = |t: &str| -> Result<f64> {
        t.trim()
            .parse::<f64>()
            .map_err(|_| anyhow!("--mu-c-range '{s}': '{t}' is not a number"))
    };
    Ok((p(a)?, p(b)?))
}

/// The problem described by the arguments.
pub fn problem_of(args: &PlanArgs) -> Result<Problem> {
    let mut p = Problem::new(&args.part);
    p.scale = args.scale;
    p.feed = match args.feed.trim() {
        "stable" => FeedKind::Stable,
        "uniform" => FeedKind::Uniform,
        other => bail!("--feed '{other}': expected 'stable' or 'uniform'"),
    };
    p.jitter_deg = args.jitter;
    p.lateral_m = args.lateral;
    p.jitter_samples = args.jitter_samples;
    p.offset_samples = args.offset_samples;
    p.orientation_samples = args.orientation_samples;
    p.mu_c = args.mu_c;
    p.mu_c_range = args.mu_c_range.as_deref().map(parse_range).transpose()?;
    p.tripod = args.tripod;
    p.pin_radius_m = args.pin_radius;
    p.belt_width_m = args.belt_width;
    p.spacing_m = args.spacing;
    p.max_pins = args.max_pins;
    p.tolerance_deg = args.tolerance;
    p.target = args.target;
    p.fewest_sets = args.fewest_sets;
    p.bound = !args.no_bound;
    p.min_margin_m = args.min_margin * 1e-3;
    p.y_quantum_m = args.y_quantum * 1e-3;
    p.theta_quantum_deg = args.theta_quantum;
    p.coarse = args.coarse;
    p.max_states = args.max_states;
    p.time_limit_s = args.time_limit;
    p.contact_tol = args.contact_tol;
    p.seed = args.seed;
    p.compile()?;
    Ok(p)
}

/// The command line that reproduces a plan: the part and every setting that differs from its
/// default, in a fixed order (the output file names are not part of it).
pub fn command_line(args: &PlanArgs) -> String {
    let mut w = vec!["pinfeed plan --part".to_string(), shell_word(&args.part)];
    let d = Problem::new(&args.part);
    fn opt_into(w: &mut Vec<String>, flag: &str, v: String, default: String) {
        if v != default {
            w.push(format!("{flag} {v}"));
        }
    }
    macro_rules! opt {
        ($f:expr, $v:expr, $d:expr) => {
            opt_into(&mut w, $f, $v, $d)
        };
    }
    opt!("--scale", args.scale.to_string(), d.scale.to_string());
    opt!("--feed", shell_word(&args.feed), "stable".into());
    opt!(
        "--jitter",
        args.jitter.to_string(),
        d.jitter_deg.to_string()
    );
    opt!(
        "--lateral",
        args.lateral.to_string(),
        d.lateral_m.to_string()
    );
    opt!(
        "--jitter-samples",
        args.jitter_samples.to_string(),
        "5".into()
    );
    opt!(
        "--offset-samples",
        args.offset_samples.to_string(),
        "5".into()
    );
    opt!(
        "--orientation-samples",
        args.orientation_samples.to_string(),
        "72".into()
    );
    opt!("--mu-c", args.mu_c.to_string(), d.mu_c.to_string());
    if let Some(r) = &args.mu_c_range {
        w.push(format!("--mu-c-range {}", shell_word(r)));
    }
    if args.tripod {
        w.push("--tripod".into());
    }
    opt!(
        "--pin-radius",
        args.pin_radius.to_string(),
        d.pin_radius_m.to_string()
    );
    opt!(
        "--belt-width",
        args.belt_width.to_string(),
        d.belt_width_m.to_string()
    );
    opt!(
        "--spacing",
        args.spacing.to_string(),
        d.spacing_m.to_string()
    );
    opt!(
        "--max-pins",
        args.max_pins.to_string(),
        d.max_pins.to_string()
    );
    opt!(
        "--tolerance",
        args.tolerance.to_string(),
        d.tolerance_deg.to_string()
    );
    opt!("--target", args.target.to_string(), d.target.to_string());
    if args.no_bound {
        w.push("--no-bound".into());
    }
    if args.fewest_sets {
        w.push("--fewest-sets".into());
    }
    opt!("--min-margin", args.min_margin.to_string(), "0.5".into());
    opt!("--y-quantum", args.y_quantum.to_string(), "0.25".into());
    opt!(
        "--theta-quantum",
        args.theta_quantum.to_string(),
        "0.25".into()
    );
    opt!("--coarse", args.coarse.to_string(), "4".into());
    opt!("--refine", args.refine.to_string(), "2".into());
    opt!(
        "--max-states",
        args.max_states.to_string(),
        d.max_states.to_string()
    );
    opt!(
        "--time-limit",
        args.time_limit.to_string(),
        d.time_limit_s.to_string()
    );
    opt!(
        "--contact-tol",
        args.contact_tol.to_string(),
        d.contact_tol.to_string()
    );
    opt!("--seed", args.seed.to_string(), "1".into());
    if args.fences {
        w.push("--fences".into());
        if let Some(m) = args.mu_f {
            w.push(format!("--mu-f {m}"));
        }
        opt!(
            "--fence-overhang",
            args.fence_overhang.to_string(),
            "0".into()
        );
        opt!(
            "--max-fence-angle",
            args.max_fence_angle.to_string(),
            "55".into()
        );
        opt!(
            "--fence-angle-step",
            args.fence_angle_step.to_string(),
            "5".into()
        );
    }
    if args.sensor {
        w.push("--sensor".into());
        opt!("--max-moving", args.max_moving.to_string(), "3".into());
        opt!(
            "--sensor-candidates",
            args.sensor_candidates.to_string(),
            "6".into()
        );
    }
    w.join(" ")
}

/// The line check of a plan, as reported.
#[derive(Debug, Clone, Serialize)]
pub struct CheckReport {
    pub parts: u64,
    pub success_rate: f64,
    pub success_ci95: [f64; 2],
    pub outcomes: crate::engine::OutcomeCounts,
    pub elapsed_s: f64,
}

/// A found plan the line did not confirm (below `--target`), with the particles it was planned
/// with; the planner then re-planned with more (`--refine`).
#[derive(Debug, Clone, Serialize)]
pub struct RefineRound {
    /// Particles per stable state (jitter × offset samples), or orientations × offsets.
    pub particles: String,
    pub obstacles: usize,
    pub predicted: f64,
    /// The line check's success.
    pub simulated: f64,
}

/// The particles of a problem, as printed.
fn particles_text(p: &Problem) -> String {
    match p.feed {
        FeedKind::Stable => format!(
            "{}×{} particles per stable state",
            p.jitter_samples, p.offset_samples
        ),
        FeedKind::Uniform => format!(
            "{} orientations × {} offsets (particles)",
            p.orientation_samples, p.offset_samples
        ),
    }
}

/// The same problem with more particles: 2 more jitter and offset samples (a uniform feed: 1.5×
/// the orientations and 2 more offsets).
fn denser(p: &Problem) -> Problem {
    let mut q = p.clone();
    match q.feed {
        FeedKind::Stable => q.jitter_samples += 2,
        FeedKind::Uniform => q.orientation_samples += q.orientation_samples.div_ceil(2),
    }
    q.offset_samples += 2;
    q
}

/// A plan written as a scenario and checked on the line.
struct Checked {
    toml: String,
    footprint_m: Option<f64>,
    check: Option<CheckReport>,
    uncertain: Option<CheckReport>,
}

/// Emit `plan` as a scenario and run it through the line (with `--check-parts` > 0), and under
/// the planned uncertainty if any.
fn emit_and_check(
    args: &PlanArgs,
    problem: &Problem,
    planner: &Planner,
    plan: &Plan,
    command: &str,
    pool: &rayon::ThreadPool,
) -> Result<Checked> {
    let path = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("plan.toml"));
    let file = shell_word(&path.display().to_string());
    let toml = emit::scenario_toml(
        problem,
        plan,
        planner.compiled.stable_deg.len(),
        planner.compiled.symmetry,
        args.check_parts.max(1),
        command,
        &file,
    );
    let footprint_m = crate::plan::check::footprint_m(&toml, &path);
    let (mut check, mut uncertain) = (None, None);
    if args.check_parts > 0 {
        let started = std::time::Instant::now();
        let summary = pool
            .install(|| crate::plan::check::check(&toml, &path, args.check_parts, problem.seed))?;
        check = Some(CheckReport::of(&summary, started));
        uncertain = check_uncertain(args, problem, &toml, pool)?;
    }
    Ok(Checked {
        toml,
        footprint_m,
        check,
        uncertain,
    })
}

/// The JSON document of `pinfeed plan --json`.
#[derive(Debug, Serialize)]
pub struct PlanReport<'a> {
    pub command: String,
    pub problem: &'a Problem,
    /// found | none_up_to_depth | exhausted | limit
    pub result: &'static str,
    pub message: String,
    /// Found plans the line did not confirm, before this one (`--refine`).
    pub refined: Vec<RefineRound>,
    /// The plan found, or (result ≠ found) the best effort: the shortest plan bringing the most
    /// particles into one window.
    pub plan: Option<&'a Plan>,
    pub stats: &'a SearchStats,
    pub check: Option<CheckReport>,
    /// The plan under the uncertainty it was planned against (a Monte Carlo study).
    pub uncertain_check: Option<CheckReport>,
    pub scenario: Option<String>,
}

/// What one planning run produced, whatever the planner (sensorless pins, fences, sensing): what
/// `pinfeed bench plans` tabulates.
#[derive(Debug, Clone, Serialize)]
pub struct PlanSummary {
    /// found | none_up_to_depth | exhausted | limit
    pub result: &'static str,
    pub message: String,
    /// Obstacles of the plan (pins, fences, or the sensor pin plus the moving pins); with a
    /// result other than found, of the best effort.
    pub obstacles: Option<usize>,
    pub predicted: Option<f64>,
    pub check: Option<CheckReport>,
    pub uncertain_check: Option<CheckReport>,
    /// Belt length the layout occupies (m; [`crate::study::compare`]'s footprint).
    pub footprint_m: Option<f64>,
    /// Search depth completed (pins, fences or moving pins).
    pub depth_completed: usize,
    pub search_s: f64,
    /// Found plans the line did not confirm, re-planned with more particles (`--refine`).
    pub refined: Vec<RefineRound>,
}

/// A planning run, ready to print.
pub struct Executed {
    /// The table (or, with `--json`, the JSON document).
    pub output: String,
    pub summary: PlanSummary,
    /// A limit stopped the search: the command fails with this message after printing.
    pub failure: Option<String>,
}

fn mb(bytes: f64) -> String {
    format!("{:.1} MB", bytes / 1e6)
}

fn stats_text(s: &SearchStats) -> String {
    let mut t = String::new();
    t += &format!(
        "search      {} particles, {} physics sample(s); {:.3} s\n",
        s.particles, s.physics_samples, s.elapsed_s
    );
    let levels: Vec<String> = s
        .states_per_depth
        .iter()
        .enumerate()
        .map(|(k, n)| format!("{k}:{n}"))
        .collect();
    t += &format!("  new open states per depth  {}\n", levels.join("  "));
    t += &format!(
        "  expanded {}, generated {} ({} duplicates), {:.1} actions per state\n",
        s.expanded, s.generated, s.duplicates, s.actions_per_expansion
    );
    t += &format!(
        "  bound: {} actions or states cut (cannot beat the best effort with the pins left)\n",
        s.pruned
    );
    t += &format!(
        "  pushes computed {}, memo hits {}, orientation columns {}, memo entries {}\n",
        s.pushes.computed, s.pushes.memo_hits, s.pushes.columns, s.memo_entries
    );
    t += &format!(
        "  memory: states + memo ≈ {}, peak RSS {}\n",
        mb(s.memory_estimate_bytes as f64),
        s.peak_rss_bytes.map_or("n/a".into(), |b| mb(b as f64))
    );
    t
}

fn plan_text(problem: &Problem, plan: &Plan) -> String {
    let mut t = String::new();
    t += "plan        pin    x (m)   y (mm)   interval (mm)      margin (mm)  sets  best window\n";
    t += &format!(
        "            feed                                                  {:>4}  {:.3} at {:.2}°\n",
        plan.initial_sets, plan.initial_window.share, plan.initial_window.centre_deg
    );
    for (k, s) in plan.steps.iter().enumerate() {
        let p = match s.action {
            Action::Pin(p) => p,
            Action::Fence(f) => {
                t += &format!(
                    "            fence{:<1} {:>+5.0}°  y {:>+7.2} → {:>+7.2} mm, length {:.4} m, margin {:.2} mm  {:>4}  {:.3} at {:.2}°\n",
                    k + 1,
                    f.angle_deg,
                    f.y0_m * 1e3,
                    f.y1_m * 1e3,
                    f.length_m,
                    f.margin_m * 1e3,
                    s.sets,
                    s.window.share,
                    s.window.centre_deg
                );
                continue;
            }
        };
        t += &format!(
            "            pin{:<3} {:>5.3}  {:>+7.2}   [{:>+6.2}, {:>+6.2}]   {:>10.2}  {:>4}  {:.3} at {:.2}°\n",
            k + 1,
            problem.spacing_m * (k as f64 + 1.0),
            p.y_m * 1e3,
            p.lo_m * 1e3,
            p.hi_m * 1e3,
            p.margin_m * 1e3,
            s.sets,
            s.window.share,
            s.window.centre_deg
        );
    }
    t += &format!(
        "goal        {:.2}° ± {}°: predicted success {:.4} ({} of {} particles)\n",
        plan.window.centre_deg,
        problem.tolerance_deg,
        plan.predicted_success,
        plan.window.inside,
        plan.initial.total()
    );
    t
}

/// Run `pinfeed plan`.
pub fn run(args: &PlanArgs) -> Result<()> {
    let done = execute(args)?;
    print_result(&done.output)?;
    if let Some(msg) = done.failure {
        bail!(msg);
    }
    Ok(())
}

/// Plan, write, draw and check as the arguments say; print nothing.
pub fn execute(args: &PlanArgs) -> Result<Executed> {
    let problem = problem_of(args)?;
    let command = command_line(args);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("starting the worker threads")?;
    if args.sensor && args.fences {
        bail!("--sensor and --fences: the contingent planner uses pins; choose one");
    }
    if args.sensor {
        return super::plan_sensor::execute(args, &problem, &command, &pool);
    }
    // Plan, check on the line, and re-plan with more particles while the line does not confirm a
    // found plan (`--refine`).
    let mut problem = problem;
    let mut refined: Vec<RefineRound> = Vec::new();
    let (outcome, stats, checked) = loop {
        let mut planner = Planner::new(&problem)?;
        if args.fences {
            planner.fences = Some(fence_transition(args, &problem)?);
        }
        let (outcome, stats) = pool.install(|| planner.search());
        let plan = match &outcome {
            Outcome::Found(p) => Some(p),
            Outcome::NoneUpTo { best, .. }
            | Outcome::Exhausted { best, .. }
            | Outcome::LimitHit { best, .. } => best.as_ref(),
        };
        let checked = match plan {
            Some(plan) => Some(emit_and_check(
                args, &problem, &planner, plan, &command, &pool,
            )?),
            None => None,
        };
        let short = match (&outcome, &checked) {
            (Outcome::Found(plan), Some(Checked { check: Some(c), .. })) => {
                (c.success_rate < problem.target).then(|| RefineRound {
                    particles: particles_text(&problem),
                    obstacles: plan.steps.len(),
                    predicted: plan.predicted_success,
                    simulated: c.success_rate,
                })
            }
            _ => None,
        };
        match short {
            Some(round) if refined.len() < args.refine => {
                refined.push(round);
                problem = denser(&problem);
            }
            _ => break (outcome, stats, checked),
        }
    };
    let what = if args.fences { "fence" } else { "pin" };
    let (result, message, plan, failure) = describe(&problem, &outcome, &stats, what);
    let (scenario, check, footprint_m, uncertain_check) = match checked {
        Some(c) => (Some(c.toml), c.check, c.footprint_m, c.uncertain),
        None => (None, None, None, None),
    };
    if let (Some(plan), Some(toml)) = (plan, &scenario) {
        if let Some(draw) = args
            .draw
            .clone()
            .or(args.out.as_ref().map(|o| o.with_extension("svg")))
        {
            if let Some(out) = &args.out {
                write_file(out, toml)?;
            }
            crate::report::plot_plan::plot_plan(&problem, plan, &draw)
                .with_context(|| format!("drawing {}", draw.display()))?;
        }
    }
    let summary = PlanSummary {
        result,
        message: message.clone(),
        obstacles: plan.map(|p| p.steps.len()),
        predicted: plan.map(|p| p.predicted_success),
        check: check.clone(),
        uncertain_check: uncertain_check.clone(),
        footprint_m,
        depth_completed: stats.depth_completed,
        search_s: stats.elapsed_s,
        refined: refined.clone(),
    };
    let output = if args.json {
        let report = PlanReport {
            command,
            problem: &problem,
            result,
            message,
            refined,
            plan,
            stats: &stats,
            check,
            uncertain_check,
            scenario,
        };
        serde_json::to_string_pretty(&report)? + "\n"
    } else {
        let mut t = format!("{command}\n");
        for r in &refined {
            t += &format!(
                "refined     planned with {}, a plan of {} obstacle(s) (predicted {:.4}) held {:.4} on the line, below --target {}: re-planned with more particles\n",
                r.particles, r.obstacles, r.predicted, r.simulated, problem.target
            );
        }
        if !refined.is_empty() {
            t += &format!("particles   {}\n", particles_text(&problem));
        }
        t += &stats_text(&stats);
        t += &format!("result      {message}\n");
        if let Some(plan) = plan {
            if result != "found" {
                t += "best effort (does not reach the goal):\n";
            }
            t += &plan_text(&problem, plan);
        }
        if let Some(c) = &check {
            t += &check_text(c, plan.map_or(0.0, |p| p.predicted_success), "");
        }
        if let Some(c) = &uncertain_check {
            t += &check_text(c, plan.map_or(0.0, |p| p.predicted_success), "")
                .replacen("line check  ", "uncertain   ", 1)
                .replacen(" parts:", " parts under the planned μc range / tripods:", 1);
        }
        if let (Some(out), Some(_)) = (&args.out, plan) {
            let draw = args
                .draw
                .clone()
                .unwrap_or_else(|| out.with_extension("svg"));
            t += &format!("wrote       {} and {}\n", out.display(), draw.display());
        }
        t
    };
    Ok(Executed {
        output,
        summary,
        failure,
    })
}

impl CheckReport {
    pub(crate) fn of(summary: &crate::engine::Summary, started: std::time::Instant) -> Self {
        CheckReport {
            parts: summary.parts_in,
            success_rate: summary.success_rate,
            success_ci95: summary.success_ci95,
            outcomes: summary.outcomes,
            elapsed_s: started.elapsed().as_secs_f64(),
        }
    }
}

/// The plan run under the uncertainty it was planned against (`--mu-c-range`, `--tripod`): a
/// Monte Carlo study of `--check-parts` samples, written beside `--out` as `STEM.uncertain.toml`
/// (so `pinfeed mc` reruns it) or to a temporary folder.
fn check_uncertain(
    args: &PlanArgs,
    problem: &Problem,
    toml: &str,
    pool: &rayon::ThreadPool,
) -> Result<Option<CheckReport>> {
    let (dir, file) = match &args.out {
        Some(out) => (
            out.parent().map_or(PathBuf::from("."), Path::to_path_buf),
            out.file_name()
                .map_or("plan.toml".into(), |f| f.to_string_lossy().to_string()),
        ),
        None => (
            std::env::temp_dir().join(format!("pinfeed_plan_uncertain_{}", std::process::id())),
            "plan.toml".to_string(),
        ),
    };
    let stem = file.trim_end_matches(".toml");
    let study_file = format!("{stem}.uncertain.toml");
    let Some(study) =
        crate::plan::check::uncertainty_study(problem, &file, &study_file, args.check_parts)
    else {
        return Ok(None);
    };
    let started = std::time::Instant::now();
    let (outcomes, n) = pool
        .install(|| crate::plan::check::check_uncertain(toml, &study, &dir, &file, &study_file))?;
    if args.out.is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(Some(CheckReport {
        parts: n,
        success_rate: outcomes.success as f64 / n.max(1) as f64,
        success_ci95: crate::statistics::wilson_interval(outcomes.success, n),
        outcomes,
        elapsed_s: started.elapsed().as_secs_f64(),
    }))
}

/// The line check's line of the table (`extra` follows the prediction).
pub(crate) fn check_text(c: &CheckReport, predicted: f64, extra: &str) -> String {
    format!(
        "line check  {} parts: success {:.4} (95% CI {:.4}–{:.4}) against predicted {:.4}{extra}; {} ({:.1} s)\n",
        c.parts,
        c.success_rate,
        c.success_ci95[0],
        c.success_ci95[1],
        predicted,
        outcome_mix(&c.outcomes),
        c.elapsed_s
    )
}

/// The fence planner's transition from the arguments (`--fences`).
fn fence_transition(args: &PlanArgs, problem: &Problem) -> Result<FenceTransition> {
    let mu_f = args.mu_f.unwrap_or(problem.mu_c);
    if !(mu_f.is_finite() && mu_f >= 0.0) {
        bail!("--mu-f {mu_f}: must be a finite number ≥ 0");
    }
    if !(args.fence_overhang.is_finite() && args.fence_overhang >= 0.0) {
        bail!(
            "--fence-overhang {}: must be a finite number ≥ 0",
            args.fence_overhang
        );
    }
    if !args.max_fence_angle.is_finite() {
        bail!(
            "--max-fence-angle {}: must be a finite angle in degrees",
            args.max_fence_angle
        );
    }
    if !(args.fence_angle_step.is_finite() && (0.5..=45.0).contains(&args.fence_angle_step)) {
        bail!(
            "--fence-angle-step {}: must lie in [0.5, 45] degrees",
            args.fence_angle_step
        );
    }
    let mut opts =
        crate::plan::FenceOptions::grid(mu_f, args.fence_angle_step, args.max_fence_angle);
    opts.overhang_a = args.fence_overhang;
    if opts.angles_deg.is_empty() {
        bail!(
            "--max-fence-angle {}: no candidate angle (from ±15°, below the jam limit {:.1}° for μf {mu_f}) is left",
            args.max_fence_angle,
            90.0 - mu_f.atan().to_degrees()
        );
    }
    Ok(FenceTransition::new(opts))
}

/// The result word, the message, the plan to emit (found or best effort) and the failure message
/// (a limit) of a search.
fn describe<'a>(
    problem: &Problem,
    outcome: &'a Outcome,
    stats: &SearchStats,
    what: &str,
) -> (&'static str, String, Option<&'a Plan>, Option<String>) {
    let best_text = |best: &Option<Plan>| {
        best.as_ref().map_or(
            format!("; no {what} sequence brings more of them into one window than the feed"),
            |b| {
                format!(
                    "; the best effort, {} {what}(s), brings {:.4} of them into one window",
                    b.steps.len(),
                    b.predicted_success
                )
            },
        )
    };
    match outcome {
        Outcome::Found(p) => {
            let m = if problem.fewest_sets {
                format!(
                    "found a plan of {} {what}(s) to {} orientation set(s), the fewest up to depth {}",
                    p.steps.len(),
                    p.sets,
                    stats.depth_completed.max(p.steps.len())
                )
            } else {
                format!("found a shortest plan: {} {what}(s)", p.steps.len())
            };
            ("found", m, Some(p), None)
        }
        Outcome::NoneUpTo { depth, best } => (
            "none_up_to_depth",
            format!(
                "no sensorless plan up to depth {depth}: every plan of at most {depth} {what}s in this action set leaves less than {} of the parts in one ±{}° window{}",
                problem.target,
                problem.tolerance_deg,
                best_text(best)
            ),
            best.as_ref(),
            None,
        ),
        Outcome::Exhausted { depth, best } => (
            "exhausted",
            format!(
                "no sensorless plan at any depth: after {depth} {what}(s) no new state that could still reach the goal is reachable in this action set{}{}",
                if *depth == 0 {
                    " (no position keeps every particle at least --min-margin from a band edge; try a smaller --min-margin)"
                } else {
                    ""
                },
                best_text(best)
            ),
            best.as_ref(),
            None,
        ),
        Outcome::LimitHit {
            limit,
            depth_completed,
            best,
        } => {
            let msg = format!(
                "search stopped by its {limit} after completing depth {depth_completed} ({} states kept): no plan of at most {depth_completed} {what}(s) reaches the goal; deeper levels were not finished{}",
                stats.states_per_depth.iter().sum::<usize>(),
                best_text(best)
            );
            ("limit", msg.clone(), best.as_ref(), Some(msg))
        }
    }
}

pub(crate) fn outcome_mix(o: &crate::engine::OutcomeCounts) -> String {
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

pub(crate) fn write_file(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}
