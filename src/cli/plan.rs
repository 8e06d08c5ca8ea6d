//! `pinfeed plan`: maps its arguments to [`pinfeed::plan::design`] (the design workflow: searches,
//! line checks, refinement, the line's headway) and prints the result; writes the chosen design.
//!
//! Exit status: 0 confirmed (the line check holds the target, or with `--reject` the loop's
//! purity); 3 a design was written but the
//! line does not confirm it (or, with `--check-parts 0`, it was not checked); 4 no design (no
//! obstacle improves on the feed; nothing written); 1 an error, or a time limit that left no
//! confirmed design.

use super::stdout::print_result;
use anyhow::{anyhow, Context, Result};
use clap::Args;
use pinfeed::plan::design::reject::{self, RejectOptions, RejectVerdict};
use pinfeed::plan::design::{
    self, DesignOptions, FenceSettings, Layout, Mode, Objective, Status, TailChoice,
    UncertaintyChoice,
};
use pinfeed::plan::problem::parse_mu_c_range;
use pinfeed::plan::{FeedKind, PlanError, Problem};
use pinfeed::report::plan_summary::{self as summary, write_design, DesignPaths};
use std::path::PathBuf;

/// Arguments of `pinfeed plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Part: tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, random:SEED[:N],
    /// vertices:"x,y x,y ...", or a part file FILE.dxf or FILE.csv (in mm; docs/cad.md).
    #[arg(long)]
    pub part: String,
    /// Metres per unit of the part's coordinates (0.001 for vertices in mm) [default: 0.02; a
    /// part file, in mm: 0.001].
    #[arg(long, allow_hyphen_values = true)]
    pub scale: Option<f64>,
    #[command(flatten)]
    pub file: super::part::PartFileArgs,
    /// Also write the design's line as a fabrication drawing (DXF, in mm; docs/outputs.md).
    #[arg(long, value_name = "FILE.dxf", conflicts_with = "no_write")]
    pub dxf: Option<PathBuf>,
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
    /// What the best confirmed design optimises, and what it trades: belt-length, the shortest
    /// belt (may choose a sensor and moving pins over a longer passive line); obstacles, the
    /// fewest obstacles (may need a longer belt); actuators, the fewest sensors and moving pins
    /// (passive lines first: more obstacles or belt); throughput, the most oriented parts per
    /// minute at the line's own headway (may need more belt or actuators). A confirmed design of
    /// another kind that is simpler or faster is printed as the runner-up.
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
    /// Design against the harsh uncertainty: friction uniform in [0.3, 0.7] at pins and fences
    /// and a random tripod support per part, with the default's placement and angle errors
    /// (docs/commands.md#plan).
    #[arg(long, conflicts_with_all = ["nominal", "uncertain"])]
    pub robust: bool,
    /// Design for the nominal physics only (no uncertainty; the verdict is the line at nominal
    /// friction and support).
    #[arg(long, conflicts_with = "uncertain")]
    pub nominal: bool,
    /// Design against the `[uncertain.*]` tables of FILE.toml, as a study declares them
    /// (docs/study-format.md) [default: friction ±0.1 at pins and fences, pins and fences ±0.5 mm,
    /// fence angles ±0.5°].
    #[arg(long, value_name = "FILE.toml")]
    pub uncertain: Option<PathBuf>,
    /// The pins' friction (and the fences', without --mu-f) uniform in LO:HI instead of the
    /// uncertainty's (with --nominal: only this).
    #[arg(long, value_name = "LO:HI")]
    pub mu_c_range: Option<String>,
    /// A random tripod support per part, added to the uncertainty (with --nominal: only this).
    #[arg(long)]
    pub tripod: bool,
    /// Pin radius in part units, like the part's vertices and as in every command (0 = point pin;
    /// metres = part units × --scale) [default: 2 mm, i.e. 0.002/--scale part units].
    #[arg(long, allow_hyphen_values = true)]
    pub pin_radius: Option<f64>,
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
    /// The exit orientation the next station needs (degrees, modulo the part's symmetry): the
    /// goal window is centred there (see `pinfeed part` for the part's stable states) [default:
    /// the planner chooses].
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub goal: Option<f64>,
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
    /// Do not measure the confirmed design's margins (the friction interval and the placement
    /// error over which it holds, swept on the line after the check).
    #[arg(long)]
    pub no_margins: bool,
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
    /// Fence designs: largest curved tail tried (units of a; 0: straight fences only) [default:
    /// 40 on random tripods (--robust, --tripod), else 0]; each angle is also tried with the
    /// largest tail from 4a up to this that fits the belt.
    #[arg(long, allow_hyphen_values = true)]
    pub tail_max: Option<f64>,
    /// Search rounds after the first while the line does not hold the target, each with the
    /// parts the line got wrong added to the particles (0: never).
    #[arg(long, default_value_t = 2)]
    pub refine: usize,
    /// After the design, try a check station: a gauge pin that only the wrong states touch, a
    /// reject gate commanded by its touch and a return path, verified by running the loop under
    /// the uncertainty (docs/commands.md, "A check station and a reject gate").
    #[arg(long)]
    pub reject: bool,
    /// With --reject: the required purity of the delivered parts, in (0, 1) [default: 0.995].
    #[arg(long, requires = "reject", allow_hyphen_values = true)]
    pub purity: Option<f64>,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// The problem described by the arguments.
pub fn problem_of(args: &PlanArgs) -> Result<Problem> {
    let file_part = pinfeed::geometry::cad::is_part_file(&args.part);
    // A part file is read here once, for its warnings; the planner reads it again by its path,
    // made absolute so that the design's scenario finds it from any folder.
    let part = if file_part {
        super::part::read_file_part(&args.part, &args.file)?;
        std::path::absolute(args.part.trim())
            .with_context(|| format!("--part '{}'", args.part))?
            .to_string_lossy()
            .into_owned()
    } else {
        args.part.clone()
    };
    let scale = args.scale.unwrap_or(if file_part { 0.001 } else { 0.02 });
    let mut p = Problem::new(&part);
    p.part_file = args.file.options()?;
    p.scale = scale;
    p.feed = FeedKind::from_name(&args.feed).ok_or_else(|| {
        anyhow!(
            "--feed '{}': expected 'stable' or 'uniform'",
            args.feed.trim()
        )
    })?;
    p.jitter_deg = args.jitter;
    p.lateral_m = args.lateral;
    p.jitter_samples = args.jitter_samples;
    p.offset_samples = args.offset_samples;
    p.orientation_samples = args.orientation_samples;
    p.mu_c = args.mu_c;
    p.mu_c_range = args
        .mu_c_range
        .as_deref()
        .map(parse_mu_c_range)
        .transpose()
        .map_err(|e| anyhow!("--mu-c-range {e}"))?;
    p.tripod = args.tripod;
    if let Some(r) = args.pin_radius {
        p.set_pin_radius_units(r).map_err(|e| flagged(e.into()))?;
        super::warn_thin_pin(r, scale);
    }
    if let Some(w) = args.belt_width {
        p.belt_width_m = w;
    }
    p.spacing_m = args.spacing;
    p.max_pins = args.max_pins;
    p.tolerance_deg = args.tolerance;
    p.target = args.target;
    p.fewest_sets = args.fewest_sets;
    p.goal_deg = args.goal;
    p.bound = !args.no_bound;
    p.min_margin_m = args.min_margin * 1e-3;
    p.y_quantum_m = args.y_quantum * 1e-3;
    p.theta_quantum_deg = args.theta_quantum;
    p.coarse = args.coarse;
    p.max_states = args.max_states;
    p.time_limit_s = args.time_limit;
    p.contact_tol = args.contact_tol;
    p.seed = args.seed;
    match p.compile() {
        Err(PlanError::Input { field, .. })
            if field == "pin_radius" && args.pin_radius.is_none() =>
        {
            Err(anyhow!(
                "the default pin radius, 2 mm, is larger than the part at --scale {} (its largest \
                 centroid–vertex distance a); give --pin-radius in part units, at most a",
                scale
            ))
        }
        r => r.map(|_| p).map_err(|e| flagged(e.into())),
    }
}

/// The flag of a planner field the library names in its errors (`tolerance` → `--tolerance`,
/// `modes` → `--pins/--fences/--sensor`).
fn flag_of(field: &str) -> String {
    match field {
        "modes" => "--pins/--fences/--sensor".into(),
        f => f.split('/').map(super::flag).collect::<Vec<_>>().join("/"),
    }
}

/// A planner error with the field it names replaced by the flag that set it.
fn flagged(e: anyhow::Error) -> anyhow::Error {
    let field = match e.downcast_ref::<design::DesignError>() {
        Some(d) => d.field(),
        None => e.downcast_ref::<PlanError>().and_then(PlanError::field),
    };
    match field {
        // The message is "FIELD VALUE: REASON".
        Some(f) => anyhow!("{}{}", flag_of(f), &e.to_string()[f.len()..]),
        None => e,
    }
}

/// The design options of the arguments; `recorded` is the command line the design's files record.
pub fn options_of(args: &PlanArgs, recorded: &str) -> Result<DesignOptions> {
    let problem = problem_of(args)?;
    let mut o = DesignOptions::new(problem);
    let modes = Mode::selected(args.pins, args.fences, args.sensor);
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
        tails: match args.tail_max {
            None => TailChoice::Auto,
            Some(0.0) => TailChoice::Off,
            Some(r) => TailChoice::UpTo(r),
        },
    };
    o.max_moving = args.max_moving;
    o.sensor_candidates = args.sensor_candidates;
    o.belt_width_given = args.belt_width.is_some();
    o.margins = !args.no_margins;
    o.uncertainty = if args.robust {
        UncertaintyChoice::Robust
    } else if args.nominal {
        UncertaintyChoice::Nominal
    } else if let Some(path) = &args.uncertain {
        let text = pinfeed::input::read_text(path)
            .with_context(|| format!("--uncertain: reading {}", path.display()))?;
        UncertaintyChoice::Given(Box::new(
            design::Uncertainty::from_file(path, &text).map_err(|e| anyhow!("--uncertain: {e}"))?,
        ))
    } else {
        UncertaintyChoice::Default
    };
    o.name = match (&args.name, &args.out) {
        (Some(n), _) => n.clone(),
        // The scenario's name must be letters, digits, '-' and '_': a file `line_1.5.toml`
        // names the design `line_1-5`.
        (None, Some(out)) => out.file_stem().map_or(o.name.clone(), |s| {
            s.to_string_lossy()
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                        c
                    } else {
                        '-'
                    }
                })
                .collect()
        }),
        (None, None) => o.name,
    };
    o.command = recorded.to_string();
    o.reject = args.reject.then(|| {
        RejectOptions::new(
            args.purity.unwrap_or(reject::DEFAULT_PURITY),
            args.check_parts,
        )
    });
    if let Some(r) = &o.reject {
        r.check().map_err(|e| flagged(e.into()))?;
    }
    Ok(o)
}

/// Run `pinfeed plan`; `recorded` is the command line the design's files record.
pub fn run(args: &PlanArgs, recorded: &str) -> Result<()> {
    let o = options_of(args, recorded)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("starting the worker threads")?;
    let bar = progress_bar(args.quiet || args.json);
    let tell = |p: &design::Progress| {
        if let Some(b) = &bar {
            b.set_message(p.to_string());
        }
    };
    let d = pool
        .install(|| design::design(&o, &tell))
        .map_err(|e| flagged(e.into()))?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let sensor = d
        .chosen()
        .is_some_and(|c| matches!(c.layout, Layout::Contingent(_)));
    let paths = DesignPaths::new(args.out.as_deref(), args.draw.as_deref(), &o, sensor);
    let mut files = if args.no_write {
        Vec::new()
    } else {
        write_design(&o, &d, &paths)?
    };
    if let (Some(path), Some(toml)) = (&args.dxf, &d.scenario_toml) {
        let policy = d.policy_toml.as_ref().map(|(_, text)| text.as_str());
        let draft = pinfeed::scenario::SceneDraft::parse_with_policy(&paths.scenario, toml, policy)
            .context("reading the design's scenario for --dxf")?;
        let sensors: Vec<usize> = draft.sensors().iter().map(|s| s.obstacle).collect();
        pinfeed::report::layout_dxf::write_layout_dxf(draft.untrained(), &sensors, path)?;
        files.push(path.display().to_string());
    }
    let out = if args.json {
        summary::json(&o, &d, files)?
    } else {
        summary::text(&o, &d, &files)
    };
    print_result(&out)?;
    // A confirmed loop is the design's answer whatever the open line holds.
    if d.reject
        .as_ref()
        .is_some_and(|r| r.verdict == RejectVerdict::Confirmed)
    {
        return Ok(());
    }
    match (d.status, &d.limit) {
        (Status::Confirmed, _) => Ok(()),
        (status, Some(limit)) => Err(anyhow!(
            "{limit} ({}): {}",
            super::flag(limit.field()),
            match status {
                Status::NoDesign => "no design found within it",
                _ => "no confirmed design",
            }
        )),
        (Status::NoDesign, None) => Err(super::Exit(4).into()),
        _ => Err(super::Exit(3).into()),
    }
}

/// A spinner on standard error when it is a terminal (and not `quiet`).
fn progress_bar(quiet: bool) -> Option<indicatif::ProgressBar> {
    super::progress::shown(quiet).then(|| super::progress::spinner("plan", quiet))
}
