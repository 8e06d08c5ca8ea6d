//! `pinfeed plan`: maps its arguments to [`crate::plan::design`] (the design workflow: searches,
//! line checks, refinement, the line's headway) and prints the result; writes the chosen design.
//!
//! Exit status: 0 confirmed (the line check holds the target); 3 a design was written but the
//! line does not confirm it (or, with `--check-parts 0`, it was not checked); 4 no design (no
//! obstacle improves on the feed; nothing written); 1 an error, or a time limit that left no
//! confirmed design.

use super::stdout::print_result;
use crate::plan::design::{
    self, describe_obstacles, Candidate, Design, DesignOptions, FenceSettings, Layout, Mode,
    Objective, Status,
};
use crate::plan::{FeedKind, Problem};
use crate::report::shell_word;
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
    /// Metres per unit of the part's coordinates (0.001 for vertices in mm).
    #[arg(long, default_value_t = 0.02, allow_hyphen_values = true)]
    pub scale: f64,
    /// Name of the design: its scenario's name and its files' stem [default: from the part; a
    /// vertex list gets custom-HASH].
    #[arg(long)]
    pub name: Option<String>,
    /// Restrict the design to fixed pins (may be combined with --fences and --sensor).
    #[arg(long)]
    pub pins: bool,
    /// Restrict the design to fences (with --pins: also lines that mix pins and fences).
    #[arg(long)]
    pub fences: bool,
    /// Restrict the design to a sensor pin with moving pins.
    #[arg(long)]
    pub sensor: bool,
    /// What the best confirmed design minimises: belt-length, obstacles, actuators, throughput.
    #[arg(long, default_value = "belt-length")]
    pub objective: String,
    /// Feed orientation: stable (the stable states, equal weights, with --jitter) or uniform.
    #[arg(long, default_value = "stable")]
    pub feed: String,
    /// Orientation jitter of a stable feed: standard deviation (degrees).
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    pub jitter: f64,
    /// Lateral offset at entry: uniform in ±LATERAL metres.
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
    /// Pin radius in metres (0 = point pin); `contact`, `map` and `validate` take part units.
    #[arg(long, default_value_t = 0.002, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Belt width in metres [default: 0.1; without it fence designs may use a wider belt, reported].
    #[arg(long, allow_hyphen_values = true)]
    pub belt_width: Option<f64>,
    /// Distance between pins along the belt, in metres.
    #[arg(long, default_value_t = 0.15, allow_hyphen_values = true)]
    pub spacing: f64,
    /// Most obstacles in a line (the search depth).
    #[arg(long, alias = "depth", default_value_t = 8)]
    pub max_pins: usize,
    /// Goal: half-width of the orientation window (degrees).
    #[arg(long, default_value_t = 3.0, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// Goal: share of the parts inside one window, on the line.
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
    /// Stop a search after this many distinct states kept (each ≈ 16 bytes per particle).
    #[arg(long, default_value_t = 1_000_000)]
    pub max_states: usize,
    /// Expand every state, even those that cannot beat the best effort within the pins left
    /// (branch and bound off: same result, more work; for comparison).
    #[arg(long)]
    pub no_bound: bool,
    /// Wall-time limit of the whole command: searches, line checks and refinements (s).
    #[arg(long, default_value_t = 110.0, allow_hyphen_values = true)]
    pub time_limit: f64,
    /// Integration tolerance of the contact model while planning.
    #[arg(long, default_value_t = 1e-5, allow_hyphen_values = true)]
    pub contact_tol: f64,
    /// Seed of the particles and of the line checks.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write the design here (FILE.toml; its policy and drawing beside it) [default:
    /// pinfeed-out/plans/NAME.toml].
    #[arg(long, value_name = "FILE.toml")]
    pub out: Option<PathBuf>,
    /// Draw the design (SVG) [default: beside the scenario, NAME.svg].
    #[arg(long, value_name = "FILE.svg")]
    pub draw: Option<PathBuf>,
    /// Write nothing (print only).
    #[arg(long)]
    pub no_write: bool,
    /// Parts of the full line check, the verdict (0: no check; the design is unchecked).
    #[arg(long, default_value_t = 10_000)]
    pub check_parts: u64,
    /// Parts of each candidate's first line run and of each headway probe.
    #[arg(long, default_value_t = 2_000)]
    pub screen_parts: u64,
    /// Print one JSON document.
    #[arg(long)]
    pub json: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
    /// Sensor designs: most moving pins after the sensor.
    #[arg(long, default_value_t = 3)]
    pub max_moving: usize,
    /// Sensor designs: sensor positions tried.
    #[arg(long, default_value_t = 6)]
    pub sensor_candidates: usize,
    /// Fence designs: fence friction μf [default: --mu-c].
    #[arg(long)]
    pub mu_f: Option<f64>,
    /// Fence designs: downstream overhang of each fence past the parts' reach (units of a).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub fence_overhang: f64,
    /// Fence designs: largest |angle| tried (degrees; always below the jam limit).
    #[arg(long, default_value_t = 55.0, allow_hyphen_values = true)]
    pub max_fence_angle: f64,
    /// Fence designs: step between candidate angles (degrees; from ±15°).
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    pub fence_angle_step: f64,
    /// Search rounds after the first while the line does not hold the target, each with the
    /// parts the line got wrong added to the particles (0: never).
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
    if let Some(w) = args.belt_width {
        p.belt_width_m = w;
    }
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

/// The design options of the arguments.
pub fn options_of(args: &PlanArgs) -> Result<DesignOptions> {
    let problem = problem_of(args)?;
    let mut o = DesignOptions::new(problem);
    let mut modes = Vec::new();
    if args.pins {
        modes.push(Mode::Pins);
    }
    if args.fences {
        modes.push(Mode::Fences);
    }
    if args.pins && args.fences {
        modes.push(Mode::Hybrid);
    }
    if args.sensor {
        modes.push(Mode::Sensor);
    }
    if !modes.is_empty() {
        o.modes = modes;
    }
    o.objective = args
        .objective
        .parse::<Objective>()
        .map_err(|e| anyhow!("--objective {e}"))?;
    o.check_parts = args.check_parts;
    o.screen_parts = args.screen_parts.min(args.check_parts.max(1));
    o.refine = args.refine;
    o.time_limit_s = args.time_limit;
    o.fences = FenceSettings {
        mu_f: args.mu_f,
        overhang_a: args.fence_overhang,
        max_angle_deg: args.max_fence_angle,
        angle_step_deg: args.fence_angle_step,
    };
    o.max_moving = args.max_moving;
    o.sensor_candidates = args.sensor_candidates;
    o.belt_width_given = args.belt_width.is_some();
    o.name = match (&args.name, &args.out) {
        (Some(n), _) => n.clone(),
        (None, Some(out)) => out
            .file_stem()
            .map_or(o.name.clone(), |s| s.to_string_lossy().to_string()),
        (None, None) => o.name,
    };
    o.command = command_line(args);
    Ok(o)
}

/// The command line that reproduces a design: the part and every setting given (the output
/// options are not part of it).
pub fn command_line(args: &PlanArgs) -> String {
    let mut w = vec!["pinfeed plan --part".to_string(), shell_word(&args.part)];
    let d = Problem::new(&args.part);
    let mut opt = |flag: &str, v: String, default: String| {
        if v != default {
            w.push(format!("{flag} {}", shell_word(&v)));
        }
    };
    opt("--scale", args.scale.to_string(), d.scale.to_string());
    opt("--objective", args.objective.clone(), "belt-length".into());
    opt("--feed", args.feed.clone(), "stable".into());
    opt(
        "--jitter",
        args.jitter.to_string(),
        d.jitter_deg.to_string(),
    );
    opt(
        "--lateral",
        args.lateral.to_string(),
        d.lateral_m.to_string(),
    );
    opt(
        "--jitter-samples",
        args.jitter_samples.to_string(),
        "5".into(),
    );
    opt(
        "--offset-samples",
        args.offset_samples.to_string(),
        "5".into(),
    );
    opt(
        "--orientation-samples",
        args.orientation_samples.to_string(),
        "72".into(),
    );
    opt("--mu-c", args.mu_c.to_string(), d.mu_c.to_string());
    opt(
        "--mu-c-range",
        args.mu_c_range.clone().unwrap_or_default(),
        String::new(),
    );
    opt(
        "--pin-radius",
        args.pin_radius.to_string(),
        d.pin_radius_m.to_string(),
    );
    opt(
        "--belt-width",
        args.belt_width.map_or(String::new(), |b| b.to_string()),
        String::new(),
    );
    opt(
        "--spacing",
        args.spacing.to_string(),
        d.spacing_m.to_string(),
    );
    opt(
        "--max-pins",
        args.max_pins.to_string(),
        d.max_pins.to_string(),
    );
    opt(
        "--tolerance",
        args.tolerance.to_string(),
        d.tolerance_deg.to_string(),
    );
    opt("--target", args.target.to_string(), d.target.to_string());
    opt("--min-margin", args.min_margin.to_string(), "0.5".into());
    opt("--y-quantum", args.y_quantum.to_string(), "0.25".into());
    opt(
        "--theta-quantum",
        args.theta_quantum.to_string(),
        "0.25".into(),
    );
    opt("--coarse", args.coarse.to_string(), "4".into());
    opt("--refine", args.refine.to_string(), "2".into());
    opt(
        "--max-states",
        args.max_states.to_string(),
        d.max_states.to_string(),
    );
    opt("--time-limit", args.time_limit.to_string(), "110".into());
    opt(
        "--contact-tol",
        args.contact_tol.to_string(),
        d.contact_tol.to_string(),
    );
    opt("--seed", args.seed.to_string(), "1".into());
    opt(
        "--check-parts",
        args.check_parts.to_string(),
        "10000".into(),
    );
    opt(
        "--screen-parts",
        args.screen_parts.to_string(),
        "2000".into(),
    );
    opt(
        "--mu-f",
        args.mu_f.map_or(String::new(), |m| m.to_string()),
        String::new(),
    );
    opt(
        "--fence-overhang",
        args.fence_overhang.to_string(),
        "0".into(),
    );
    opt(
        "--max-fence-angle",
        args.max_fence_angle.to_string(),
        "55".into(),
    );
    opt(
        "--fence-angle-step",
        args.fence_angle_step.to_string(),
        "5".into(),
    );
    opt("--max-moving", args.max_moving.to_string(), "3".into());
    opt(
        "--sensor-candidates",
        args.sensor_candidates.to_string(),
        "6".into(),
    );
    for (on, flag) in [
        (args.tripod, "--tripod"),
        (args.fewest_sets, "--fewest-sets"),
        (args.no_bound, "--no-bound"),
        (args.pins, "--pins"),
        (args.fences, "--fences"),
        (args.sensor, "--sensor"),
    ] {
        if on {
            w.push(flag.into());
        }
    }
    w.join(" ")
}

/// The files a design writes: (scenario, policy if any, drawing).
fn paths(args: &PlanArgs, o: &DesignOptions, sensor: bool) -> (PathBuf, Option<PathBuf>, PathBuf) {
    let scenario = args.out.clone().unwrap_or_else(|| {
        PathBuf::from("pinfeed-out")
            .join("plans")
            .join(format!("{}.toml", o.name))
    });
    let policy = sensor.then(|| scenario.with_file_name(format!("{}.policy.toml", o.name)));
    let draw = args
        .draw
        .clone()
        .unwrap_or_else(|| scenario.with_extension("svg"));
    (scenario, policy, draw)
}

/// The JSON document of `pinfeed plan --json`.
#[derive(Debug, Serialize)]
struct PlanJson<'a> {
    schema_version: u32,
    pinfeed_version: &'static str,
    command: &'a str,
    /// confirmed | not_confirmed | unchecked | no_design
    status: Status,
    message: &'a str,
    name: &'a str,
    mode: Option<Mode>,
    predicted_success: Option<f64>,
    line_check: Option<&'a design::LineCheck>,
    uncertain_check: Option<&'a design::LineCheck>,
    obstacles: Option<&'a [design::ObstacleInfo]>,
    belt_length_m: Option<f64>,
    belt_width_m: Option<f64>,
    headway_s: Option<f64>,
    oriented_per_min: Option<f64>,
    files: Vec<String>,
    limit: Option<&'a str>,
    elapsed_s: f64,
    candidates: &'a [Candidate],
    /// The chosen candidate (also in `candidates`).
    chosen: Option<&'a Candidate>,
    problem: &'a Problem,
    objective: Objective,
    scenario: Option<&'a str>,
}

/// Run `pinfeed plan`.
pub fn run(args: &PlanArgs) -> Result<()> {
    let o = options_of(args)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("starting the worker threads")?;
    let bar = progress_bar(args.quiet || args.json);
    let tell = |p: &design::Progress| {
        if let Some(b) = &bar {
            b.set_message(format!(
                "{}{} · {} · {} candidate(s), {} line run(s)",
                p.mode.map_or("", |m| m.name()),
                if p.round > 0 {
                    format!(" round {}", p.round + 1)
                } else {
                    String::new()
                },
                p.stage,
                p.candidates,
                p.line_runs,
            ));
        }
    };
    let d = pool.install(|| design::design(&o, &tell))?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let sensor = d
        .chosen()
        .is_some_and(|c| matches!(c.layout, Layout::Contingent(_)));
    let (scenario, policy, draw) = paths(args, &o, sensor);
    let mut files = Vec::new();
    if let (Some(c), Some(toml), false) = (d.chosen(), &d.scenario_toml, args.no_write) {
        write(&scenario, toml)?;
        files.push(scenario.display().to_string());
        if let (Some(p), Some((_, text))) = (&policy, &d.policy_toml) {
            write(p, text)?;
            files.push(p.display().to_string());
        }
        draw_design(&o, c, &d, &draw)?;
        files.push(draw.display().to_string());
        if let Some(u) = &c.uncertain_check {
            let file = scenario
                .file_name()
                .map_or("plan.toml".into(), |f| f.to_string_lossy().to_string());
            let study_path = scenario.with_file_name(format!("{}.uncertain.toml", o.name));
            let study_file = study_path
                .file_name()
                .map_or(String::new(), |f| f.to_string_lossy().to_string());
            let kinds: Vec<&str> = c.obstacles.iter().map(|o| o.kind).collect();
            if let Some(study) = crate::plan::check::uncertainty_study(
                &c.problem,
                &kinds,
                o.fences.mu_f.is_some(),
                &file,
                &study_file,
                u.parts,
            ) {
                write(&study_path, &study)?;
                files.push(study_path.display().to_string());
            }
        }
    }
    let out = if args.json {
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
            obstacles: c.map(|c| c.obstacles.as_slice()),
            belt_length_m: c.map(|c| c.belt_length_m),
            belt_width_m: c.map(|c| c.belt_width_m),
            headway_s: c.map(|c| c.headway_s),
            oriented_per_min: c.map(|c| c.oriented_per_min),
            files,
            limit: d.limit.as_deref(),
            elapsed_s: d.elapsed_s,
            candidates: &d.candidates,
            chosen: c,
            problem: &o.problem,
            objective: o.objective,
            scenario: d.scenario_toml.as_deref(),
        };
        crate::report::versioned::pretty(&doc)?
    } else {
        text(&o, &d, &files)
    };
    print_result(&out)?;
    match (d.status, &d.limit) {
        (Status::Confirmed, _) => Ok(()),
        (_, Some(limit)) => Err(anyhow!("{limit}: no confirmed design")),
        (Status::NoDesign, None) => Err(super::Exit(4).into()),
        _ => Err(super::Exit(3).into()),
    }
}

fn write(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    crate::report::atomic::write_atomic(path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// A spinner on standard error when it is a terminal (and not `quiet`).
fn progress_bar(quiet: bool) -> Option<indicatif::ProgressBar> {
    super::progress::shown(quiet).then(|| super::progress::spinner("plan", quiet))
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

fn draw_design(o: &DesignOptions, c: &Candidate, d: &Design, path: &Path) -> Result<()> {
    let t = title(o, c, d);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    // The plots write whole files or none (report::atomic).
    match &c.layout {
        Layout::Sequence(plan) => crate::report::plot_plan::plot_plan(&c.problem, plan, &t, path),
        Layout::Contingent(plan) => {
            let mut planner = crate::plan::search::Planner::new(&c.problem)?;
            let stages = crate::plan::contingent::stage_states(&mut planner, plan)?;
            crate::report::plot_plan::plot_contingent(&c.problem, plan, &stages, &t, path)
        }
    }
    .with_context(|| format!("drawing {}", path.display()))
}

/// The printed result.
fn text(o: &DesignOptions, d: &Design, files: &[String]) -> String {
    let p = &o.problem;
    let mut t = format!("{}\n", o.command);
    t += &format!(
        "design      {}: modes {}; objective {:?}; goal ≥ {} of the parts in one ±{}° window, on the line\n",
        o.name,
        o.modes.iter().map(|m| m.name()).collect::<Vec<_>>().join(", "),
        o.objective,
        p.target,
        p.tolerance_deg
    );
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
                if c.line_check.is_some() {
                    ""
                } else {
                    " screen"
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
            format!("{} {:.1} s", c.search.result, c.search.elapsed_s),
            describe_obstacles(c),
            c.belt_length_m,
            c.belt_width_m,
            c.predicted_success
        );
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
                    "uncertain   {} samples under the planned μc range / tripods: success {:.4} (95% CI {:.4}–{:.4}); {} — the verdict\n",
                    u.parts,
                    u.success_rate,
                    u.ci95[0],
                    u.ci95[1],
                    outcome_mix(&u.outcomes)
                );
            }
            t += &format!(
                "headway     {} s, the shortest with no collision and no loss of success over {} probe(s), with a 25% reserve: {:.2} oriented parts per minute\n",
                design::line::fmt_headway(c.headway_s),
                c.headway_probes.len(),
                c.oriented_per_min
            );
        }
        t += &format!(
            "belt        length {:.3} m, width {:.3} m\n",
            c.belt_length_m, c.belt_width_m
        );
        for ob in &c.obstacles {
            t += &format!(
                "  {:<10} {:<8} x {:.3} m  y {:+7.2} mm{}{}\n",
                ob.kind,
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
    if let Some(l) = &d.limit {
        t += &format!("limit       {l}\n");
    }
    t += &format!("time        {:.1} s\n", d.elapsed_s);
    if !files.is_empty() {
        t += &format!("wrote       {}\n", files.join(", "));
    }
    t
}

/// "success 9987, wrong_orientation 13".
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
