//! **Designs the line confirms**: the workflow behind `pinfeed plan`. Given a part and a goal, it
//! searches each kind of line it is allowed — fixed pins, fences, pins and fences mixed in one
//! line (the hybrid), a sensor pin with moving pins — runs every candidate on the line, and
//! returns the best design *the line confirmed*, with the number.
//!
//! For every mode ([`Mode`]):
//! 1. the search over the particle abstraction ([`mod@super::search`], [`super::contingent`]) gives a
//!    plan (or its best effort) and a *prediction*: the share of particles in one window;
//! 2. the plan is emitted as a scenario ([`super::emit`]) and run on the line with the parts far
//!    apart (the *screen*: `screen_parts` parts, no part can meet another);
//! 3. while the screen holds less than the target (and `refine` allows), the parts the line got
//!    wrong join the particle set at their own feed orientation and lateral offset (the
//!    abstraction grows where the line says it is wrong, not blindly) and the mode searches again;
//!    every round's candidate is kept with its screen.
//!
//! Then the candidates the screen holds at the target are taken in the order of the objective
//! ([`Objective`]); for each, the line's own spacing of parts is found by simulation
//! (`line::shortest_headway`: the shortest headway without collisions, with a reserve) and the
//! full line check (`check_parts` parts at that headway) decides: the first that holds the target
//! is **confirmed** and chosen. If none is, the best the line measured is chosen and reported as
//! **not confirmed**, with its number; with no plan at all the result is **no design**.
//!
//! The whole workflow — searches, screens, headway searches and checks — runs within
//! `time_limit_s` (searches stop early enough to leave time for the checks; a check that would
//! not fit runs fewer parts and says how many).

pub mod line;
pub mod reject;
pub mod survey;

pub use super::check::{Uncertainty, UncertaintySet};
use super::contingent::{self, ContingentOutcome, ContingentPlan};
use super::emit::{self, LineSpec, BELT_SPEED};
use super::fences::{FenceOptions, FenceTransition};
use super::search::{Outcome, Plan, Planner, SearchStats};
use super::{Action, Limit, PlanError, Problem};
use crate::engine::OutcomeCounts;
use line::{HeadwayProbe, Line, LineError, Runnable};
use serde::Serialize;
use std::time::Instant;

/// A kind of line the designer may build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Fixed pins only.
    Pins,
    /// Fences only.
    Fences,
    /// Pins and fences in one search: a line may mix them.
    Hybrid,
    /// A sensor pin that reads the stable state, then per-decision moving pins.
    Sensor,
}

impl Mode {
    /// The modes asked for by choosing pins, fences (both: also hybrid) and a sensor, in that
    /// order (empty: none chosen).
    pub fn selected(pins: bool, fences: bool, sensor: bool) -> Vec<Mode> {
        [
            (pins, Mode::Pins),
            (fences, Mode::Fences),
            (pins && fences, Mode::Hybrid),
            (sensor, Mode::Sensor),
        ]
        .into_iter()
        .filter_map(|(on, m)| on.then_some(m))
        .collect()
    }

    /// The mode's name in outputs and options: `pins`, `fences`, `hybrid` or `sensor`.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Pins => "pins",
            Mode::Fences => "fences",
            Mode::Hybrid => "hybrid",
            Mode::Sensor => "sensor",
        }
    }
}

/// What "best" means among confirmed designs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// The shortest belt (then the fewest obstacles).
    BeltLength,
    /// The fewest obstacles (then the shortest belt).
    Obstacles,
    /// The fewest actuated obstacles: sensors and moving pins (then obstacles, then belt).
    Actuators,
    /// The most oriented parts per minute at the line's own headway.
    Throughput,
}

impl std::str::FromStr for Objective {
    type Err = ObjectiveError;
    fn from_str(s: &str) -> Result<Self, ObjectiveError> {
        match s.trim() {
            "belt-length" | "belt_length" | "length" => Ok(Objective::BeltLength),
            "obstacles" => Ok(Objective::Obstacles),
            "actuators" => Ok(Objective::Actuators),
            "throughput" => Ok(Objective::Throughput),
            o => Err(ObjectiveError(o.to_string())),
        }
    }
}

/// An objective name that is none of the known ones (the [`Objective`] parser); holds the name
/// as given, trimmed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{0}': expected belt-length, obstacles, actuators or throughput")]
pub struct ObjectiveError(pub String);

/// Fence settings of the fence and hybrid modes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FenceSettings {
    /// Fence friction μf (None: the part's μc).
    pub mu_f: Option<f64>,
    /// Downstream overhang past the parts' reach (units of a).
    pub overhang_a: f64,
    /// Largest |angle| tried (degrees).
    pub max_angle_deg: f64,
    /// Step between candidate angles (degrees, from ±15°).
    pub angle_step_deg: f64,
    /// Curved tails ([`TailChoice`]).
    pub tails: TailChoice,
}

impl Default for FenceSettings {
    fn default() -> Self {
        FenceSettings {
            mu_f: None,
            overhang_a: 0.0,
            max_angle_deg: 55.0,
            angle_step_deg: 5.0,
            tails: TailChoice::Auto,
        }
    }
}

/// Whether fence designs try curved tails (`pinfeed plan --tail-max A`; docs/physics.md, "Curved
/// tails"). With tails every candidate angle is tried straight and with the largest tail that
/// fits the belt, from [`super::fences::TAIL_MIN_A`]·a up to the most allowed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TailChoice {
    /// Tails up to [`super::fences::TAIL_MAX_A`]·a where the uncertainty planned against has
    /// random tripod supports (`--robust`, `--tripod`): there a straight fence's exit
    /// orientation spreads by degrees with the support, a tail's by less than 0.5°. On a uniform
    /// support the exit off a straight fence's end depends on friction alone and varies little,
    /// and tails, which double the actions of every fence, are not tried.
    Auto,
    /// Straight fences only.
    Off,
    /// Tails up to this radius (units of a, in [`super::fences::TAIL_MIN_A`], 1000]).
    UpTo(f64),
}

/// Everything a design needs. [`DesignOptions::new`] gives the defaults.
#[derive(Debug, Clone)]
pub struct DesignOptions {
    /// The part, feed, goal and search settings the designs are planned for.
    pub problem: Problem,
    /// The modes tried, in this order.
    pub modes: Vec<Mode>,
    /// What "best" means among the confirmed designs.
    pub objective: Objective,
    /// Parts of the full line check (0: no check; the design is then unchecked).
    pub check_parts: u64,
    /// Parts of each candidate's screen and of each headway probe.
    pub screen_parts: u64,
    /// Search rounds after the first, each with the line's failures added to the particles.
    pub refine: usize,
    /// Wall-time limit of the whole design (s).
    pub time_limit_s: f64,
    /// Fence settings of the fence and hybrid modes.
    pub fences: FenceSettings,
    /// Sensor mode: most moving pins.
    pub max_moving: usize,
    /// Sensor mode: sensor positions tried.
    pub sensor_candidates: usize,
    /// Was the belt width given? If not, the fence and hybrid modes may use a wider belt.
    pub belt_width_given: bool,
    /// Measure the chosen design's margins ([`super::margins`]) once it is confirmed.
    pub margins: bool,
    /// The uncertainty the designs are planned and checked against ([`UncertaintyChoice`];
    /// [`DesignOptions::uncertainty`] gives it as values).
    pub uncertainty: UncertaintyChoice,
    /// The design's name: its scenario's `name` and its files' stem.
    pub name: String,
    /// The command line that asked for it (written into the scenario's header).
    pub command: String,
    /// `--reject`: after the design, try a gauge pin, a reject gate and a return path around the
    /// chosen line ([`reject`]); None: the open line only.
    pub reject: Option<reject::RejectOptions>,
}

impl DesignOptions {
    /// The defaults for a problem: every mode, the shortest belt, 10⁴ parts checked.
    pub fn new(problem: Problem) -> DesignOptions {
        let name = design_name(&problem.part);
        let command = format!("pinfeed plan --part {}", problem.part);
        DesignOptions {
            problem,
            modes: vec![Mode::Pins, Mode::Fences, Mode::Hybrid, Mode::Sensor],
            objective: Objective::BeltLength,
            check_parts: 10_000,
            screen_parts: 2_000,
            refine: 2,
            time_limit_s: 110.0,
            fences: FenceSettings::default(),
            max_moving: 3,
            sensor_candidates: 6,
            belt_width_given: false,
            margins: true,
            uncertainty: UncertaintyChoice::Default,
            command,
            name,
            reject: None,
        }
    }
}

/// Which uncertainty a design is planned against (`pinfeed plan`'s default, `--robust`,
/// `--nominal`, `--uncertain FILE`). The problem's own [`Problem::mu_c_range`] and
/// [`Problem::tripod`] (`--mu-c-range`, `--tripod`) replace the set's friction range at the pins
/// (and at the fences whose μf is the pins' μc) and its support.
#[derive(Debug, Clone, PartialEq)]
pub enum UncertaintyChoice {
    /// [`Uncertainty::default_around`] the problem's μc and the fences' μf.
    Default,
    /// [`Uncertainty::robust`].
    Robust,
    /// Nominal physics.
    Nominal,
    /// These values (a file's tables).
    Given(Box<Uncertainty>),
}

impl DesignOptions {
    /// The uncertainty the designs are planned and checked against, as values.
    pub fn uncertainty(&self) -> Uncertainty {
        let p = &self.problem;
        let mu_f = self.fences.mu_f.unwrap_or(p.mu_c);
        let mut u = match &self.uncertainty {
            UncertaintyChoice::Default => Uncertainty::default_around(p.mu_c, mu_f),
            UncertaintyChoice::Robust => Uncertainty::robust(),
            UncertaintyChoice::Nominal => {
                return Uncertainty::custom(p.mu_c_range, p.tripod, self.fences.mu_f.is_some())
            }
            UncertaintyChoice::Given(u) => (**u).clone(),
        };
        if let Some((min, max)) = p.mu_c_range {
            let d = crate::random::distribution::Distribution::Uniform { min, max };
            u.perturbations.mu_c = Some(d);
            if self.fences.mu_f.is_none() {
                u.perturbations.fence_mu_f = Some(d);
            }
        }
        if p.tripod {
            u.perturbations.support = crate::mechanics::support::SupportChoice::Tripod;
        }
        u
    }

    /// The options the workflow runs: the uncertainty resolved to values, and the problem's
    /// particles robust against what of it they can carry (the friction ranges, tripods).
    /// The uncertainty of options [`Self::resolved`] has resolved (or resolves them).
    fn planned(&self) -> Uncertainty {
        match &self.uncertainty {
            UncertaintyChoice::Given(u) => (**u).clone(),
            _ => self.uncertainty(),
        }
    }

    fn resolved(&self) -> DesignOptions {
        let u = self.uncertainty();
        let mut o = self.clone();
        if o.fences.tails == TailChoice::Auto {
            o.fences.tails = if u.tripod() {
                TailChoice::UpTo(super::fences::TAIL_MAX_A)
            } else {
                TailChoice::Off
            };
        }
        o.problem.mu_c_range = u.pins_friction();
        o.problem.mu_f_range = u.fences_friction();
        o.problem.fence_angle_range = u.fences_angle();
        o.problem.tripod = u.tripod();
        o.uncertainty = UncertaintyChoice::Given(Box::new(u));
        o
    }
}

/// A design's name from its part: a named part's own name (`rect:2:1` → `rect-2-1`), a vertex
/// list `custom-` and a hash of its text, so that different parts never share files.
pub fn design_name(part: &str) -> String {
    let p = part.trim();
    if p.to_lowercase().starts_with("vertices:") {
        return crate::geometry::named::custom_name(p);
    }
    // A part file: its name without folder and extension.
    let stem = std::path::Path::new(p)
        .file_stem()
        .map(|s| s.to_string_lossy());
    let p = match stem {
        Some(s) if crate::geometry::cad::is_part_file(p) => s.into_owned(),
        _ => p.to_string(),
    };
    p.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// The verdict of a design.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The full line check holds the target.
    Confirmed,
    /// The best design the line measured holds less than the target.
    NotConfirmed,
    /// Designed but not run on the line (`check_parts` 0).
    Unchecked,
    /// No mode produced a design (no obstacle improves on the feed).
    NoDesign,
}

impl Status {
    /// The verdict in words: `confirmed`, `not confirmed`, `unchecked` or `no design`.
    pub fn word(self) -> &'static str {
        match self {
            Status::Confirmed => "confirmed",
            Status::NotConfirmed => "not confirmed",
            Status::Unchecked => "unchecked",
            Status::NoDesign => "no design",
        }
    }
}

/// A run of the line.
#[derive(Debug, Clone, Serialize)]
pub struct LineCheck {
    /// Parts run.
    pub parts: u64,
    /// Parts that ended in success.
    pub success: u64,
    /// `success` / `parts`.
    pub success_rate: f64,
    /// 95% Wilson interval of the success rate.
    pub ci95: [f64; 2],
    /// One-sided 95% Wilson lower bound of the success rate: what designs are ranked by.
    pub lower95: f64,
    /// Parts per final outcome.
    pub outcomes: OutcomeCounts,
    /// Seconds between parts.
    pub headway_s: f64,
    /// Wall time the run took (s).
    pub elapsed_s: f64,
}

/// What an obstacle of a design is (written as `pin`, `fence`, `sensor_pin`, `moving_pin`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleKind {
    /// A fixed pin.
    Pin,
    /// A fence.
    Fence,
    /// A sensorised pin.
    SensorPin,
    /// A pin that moves to a target per decision.
    MovingPin,
}

impl ObstacleKind {
    /// The kind's name in outputs: `pin`, `fence`, `sensor_pin` or `moving_pin`.
    pub fn name(self) -> &'static str {
        match self {
            ObstacleKind::Pin => "pin",
            ObstacleKind::Fence => "fence",
            ObstacleKind::SensorPin => "sensor_pin",
            ObstacleKind::MovingPin => "moving_pin",
        }
    }
}

impl std::fmt::Display for ObstacleKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// How a search ended (written as `found`, `none_up_to_depth`, `exhausted`, `limit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SearchResult {
    /// A plan was found.
    Found,
    /// No plan up to the depth limit.
    NoneUpToDepth,
    /// No plan at any depth (no new state appeared).
    Exhausted,
    /// A limit (time, states) stopped the search.
    Limit,
}

impl SearchResult {
    /// The result's name in outputs.
    pub fn name(self) -> &'static str {
        match self {
            SearchResult::Found => "found",
            SearchResult::NoneUpToDepth => "none_up_to_depth",
            SearchResult::Exhausted => "exhausted",
            SearchResult::Limit => "limit",
        }
    }
}

impl std::fmt::Display for SearchResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// One obstacle of a design, as placed on the belt.
#[derive(Debug, Clone, Serialize)]
pub struct ObstacleInfo {
    /// What the obstacle is.
    pub kind: ObstacleKind,
    /// The obstacle's name in the emitted scenario.
    pub name: String,
    /// Along the belt (m; a fence's upstream end).
    pub x_m: f64,
    /// Across the belt (m; a fence's upstream end, a moving pin's home).
    pub y_m: f64,
    /// A fence's angle from the belt direction (degrees; None for pins).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// A fence's length (m; None for pins).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub length_m: Option<f64>,
    /// A fence's tail radius (m; None for pins and straight fences).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tail_radius_m: Option<f64>,
    /// A moving pin's lateral targets, one per decision (m).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub targets_m: Vec<f64>,
}

/// What a search ended with.
#[derive(Debug, Clone, Serialize)]
pub struct SearchSummary {
    /// How the search ended.
    pub result: SearchResult,
    /// One sentence on how the search ended.
    pub message: String,
    /// Particles searched over.
    pub particles: u32,
    /// Search levels (obstacles placed) completed.
    pub depth_completed: usize,
    /// Wall time of the search (s).
    pub elapsed_s: f64,
    /// A sequence search's work (pins, fences and hybrid modes; none for the sensor mode).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub work: Option<SearchWork>,
}

/// What a sequence search did: the numbers behind its time and memory.
#[derive(Debug, Clone, Serialize)]
pub struct SearchWork {
    /// States expanded.
    pub expanded: u64,
    /// Successors generated (before deduplication).
    pub generated: u64,
    /// Actions and states the branch and bound cut.
    pub pruned: u64,
    /// Contact passes computed (the memo's misses).
    pub passes_computed: u64,
    /// Peak resident memory of the process when the search ended (Linux), if readable.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_rss_bytes: Option<u64>,
}

impl SearchWork {
    /// The work counted in a sequence search's statistics.
    fn of(stats: &SearchStats) -> SearchWork {
        SearchWork {
            expanded: stats.expanded,
            generated: stats.generated,
            pruned: stats.pruned,
            passes_computed: stats.pushes.computed,
            peak_rss_bytes: stats.peak_rss_bytes,
        }
    }
}

/// The plan behind a candidate.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// A fixed sequence of pins and fences.
    Sequence(Plan),
    /// A sensor pin and per-decision moving pins.
    Contingent(ContingentPlan),
}

/// One design the workflow produced and ran on the line.
#[derive(Debug, Clone, Serialize)]
pub struct Candidate {
    /// The kind of line.
    pub mode: Mode,
    /// Refinement round (0: the first search).
    pub round: usize,
    /// How the search for it ended.
    pub search: SearchSummary,
    /// The particle abstraction's prediction.
    pub predicted_success: f64,
    /// Sensor mode: the prediction with the classifier's confusion measured on the line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_with_confusion: Option<f64>,
    /// Sensor mode: the classifier's accuracy measured on the line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_accuracy: Option<f64>,
    /// The obstacles as placed, upstream first.
    pub obstacles: Vec<ObstacleInfo>,
    /// Sensors and moving pins.
    pub actuators: usize,
    /// Length of the emitted belt (m).
    pub belt_length_m: f64,
    /// The belt width the design uses (m): what its obstacles and parts reach, with a margin.
    pub belt_width_m: f64,
    /// The line with the parts far apart.
    pub screen: Option<LineCheck>,
    /// The earlier candidate (its index in the design's candidates) that is the same line — the
    /// same scenario, screened at the same headway, parts and seed — and whose screen this one
    /// shares instead of running it again (a hybrid search that placed only fences, say).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub screen_shared_with: Option<usize>,
    /// The headway probes (s, parts, collisions, success).
    pub headway_probes: Vec<HeadwayProbe>,
    /// The headway chosen on the line (s).
    pub headway_s: f64,
    /// The full check at `headway_s`.
    pub line_check: Option<LineCheck>,
    /// The verdict check's 95% interval still holds the target after the parts the time and
    /// the cap (8× the check's parts) allowed: the verdict is its number's, undecided.
    pub undecided: bool,
    /// A problem planned against uncertainty (a μc range, tripods): the full check is also run
    /// under it, as a Monte Carlo study of `check_parts` samples (one part through a freshly
    /// perturbed line each); the verdict is then this run's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uncertain_check: Option<LineCheck>,
    /// Oriented parts per minute at `headway_s` (the full check's success, else the screen's).
    pub oriented_per_min: f64,
    /// How far friction and placement may drift before the line fails (the chosen design, once
    /// confirmed, unless the options turn it off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margins: Option<super::margins::Margins>,
    /// The plan, as searched.
    pub layout: Layout,
    /// The problem the candidate was searched with (its belt width and particles).
    #[serde(skip)]
    pub problem: Problem,
    /// The emitted scenario with its headway as a parameter, and its policy file.
    #[serde(skip)]
    pub runnable: Runnable,
}

/// A mode's plan as its search emitted it: the line, before the line has run it.
#[derive(Debug)]
struct Emitted {
    /// How the search ended.
    search: SearchSummary,
    /// The plan.
    layout: Layout,
    /// The problem the plan was searched with, its belt width the line's.
    problem: Problem,
    /// The emitted scenario and its policy file.
    runnable: Runnable,
    /// The obstacles as placed, upstream first.
    obstacles: Vec<ObstacleInfo>,
    /// Length of the emitted belt (m).
    belt_length_m: f64,
}

impl SearchSummary {
    /// How a search over `planner`'s particles ended, after `depth_completed` levels in
    /// `elapsed_s` seconds, with a sequence search's `work`.
    fn new(
        result: SearchResult,
        message: String,
        planner: &Planner,
        depth_completed: usize,
        elapsed_s: f64,
        work: Option<SearchWork>,
    ) -> SearchSummary {
        SearchSummary {
            result,
            message,
            particles: planner.initial.total(),
            depth_completed,
            elapsed_s,
            work,
        }
    }
}

impl Candidate {
    /// The candidate of mode `mode` that refinement round `round` emitted, before the line
    /// has run it (no screen, headway or check yet): its prediction is the plan's, its belt width
    /// the problem's and its actuators the sensor and moving pins among its obstacles.
    fn emitted(mode: Mode, round: usize, e: Emitted) -> Candidate {
        let predicted_success = match &e.layout {
            Layout::Sequence(p) => p.predicted_success,
            Layout::Contingent(p) => p.predicted_success,
        };
        let actuators = e
            .obstacles
            .iter()
            .filter(|o| matches!(o.kind, ObstacleKind::SensorPin | ObstacleKind::MovingPin))
            .count();
        Candidate {
            mode,
            round,
            search: e.search,
            predicted_success,
            predicted_with_confusion: None,
            sensor_accuracy: None,
            obstacles: e.obstacles,
            actuators,
            belt_length_m: e.belt_length_m,
            belt_width_m: e.problem.belt_width_m,
            screen: None,
            screen_shared_with: None,
            headway_probes: Vec::new(),
            headway_s: 0.0,
            line_check: None,
            undecided: false,
            uncertain_check: None,
            oriented_per_min: 0.0,
            margins: None,
            layout: e.layout,
            problem: e.problem,
            runnable: e.runnable,
        }
    }

    /// The line's best word on it: the check under uncertainty, else the full check, else the
    /// screen.
    pub fn measured(&self) -> Option<&LineCheck> {
        self.verdict_check().or(self.screen.as_ref())
    }

    /// The check the verdict is read from: under the planned uncertainty if there is one, else
    /// the full check.
    pub fn verdict_check(&self) -> Option<&LineCheck> {
        self.uncertain_check.as_ref().or(self.line_check.as_ref())
    }

    /// The ordering key of an objective (smaller is better).
    fn key(&self, o: Objective) -> (f64, f64, f64) {
        let n = self.obstacles.len() as f64;
        match o {
            Objective::BeltLength => (self.belt_length_m, n, 0.0),
            Objective::Obstacles => (n, self.belt_length_m, 0.0),
            Objective::Actuators => (self.actuators as f64, n, self.belt_length_m),
            Objective::Throughput => (-self.oriented_per_min, self.belt_length_m, n),
        }
    }
}

/// What became of a mode the design was asked to try.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModeOutcome {
    /// Searched to the end: its candidates are in the design's list.
    Searched,
    /// Searched, with no plan that improves on the feed (the reason says why).
    NoPlan,
    /// Not searched: no line of this mode can beat one the screen already holds.
    NotNeeded,
    /// Its search was stopped by its share of the time limit (any candidate is the best so far).
    Stopped,
    /// Not tried: the search time was used up before it started.
    NotTried,
    /// Not searched: a [`super::certificate::Certificate`] proves that no line of this mode
    /// reaches the target.
    Impossible,
}

impl ModeOutcome {
    /// The outcome in words: `searched`, `no plan`, `not needed`, `stopped`, `not tried`.
    pub fn word(self) -> &'static str {
        match self {
            ModeOutcome::Searched => "searched",
            ModeOutcome::NoPlan => "no plan",
            ModeOutcome::NotNeeded => "not needed",
            ModeOutcome::Stopped => "stopped",
            ModeOutcome::NotTried => "not tried",
            ModeOutcome::Impossible => "impossible",
        }
    }
}

/// A mode the design was asked to try, with what became of it: every mode asked for has one,
/// whether or not it produced a candidate.
#[derive(Debug, Clone, Serialize)]
pub struct ModeReport {
    /// The mode.
    pub mode: Mode,
    /// What became of it.
    pub outcome: ModeOutcome,
    /// Candidates it produced (they are in the design's list).
    pub candidates: usize,
    /// Why it produced no candidate, or what cut it short; None for a search that ran to its end.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// A finished design.
#[derive(Debug, Clone, Serialize)]
pub struct Design {
    /// The verdict.
    pub status: Status,
    /// One sentence: what was found and what the line says.
    pub message: String,
    /// Goal: share of the parts to end in the window, in [0, 1].
    pub target: f64,
    /// Goal: half-width of the orientation window (degrees).
    pub tolerance_deg: f64,
    /// Every candidate, in the order produced.
    pub candidates: Vec<Candidate>,
    /// The candidate chosen (written).
    pub chosen: Option<usize>,
    /// A confirmed candidate of another mode than the chosen one that is simpler (fewer sensors
    /// and moving pins) or gives more oriented parts per minute: what the objective traded away.
    pub runner_up: Option<usize>,
    /// Every mode asked for, in the order tried, with what became of it.
    pub modes: Vec<ModeReport>,
    /// A limit that cut the work short (the time limit), if any.
    pub limit: Option<Limit>,
    /// Why lines that touch only the part's convex hull cannot reach the target, if they cannot
    /// (the modes it covers were not searched).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub certificate: Option<super::certificate::Certificate>,
    /// Wall time of the whole design (s).
    pub elapsed_s: f64,
    /// The chosen design's scenario text (with its header).
    #[serde(skip)]
    pub scenario_toml: Option<String>,
    /// The chosen design's policy file, if any: (file name, text).
    #[serde(skip)]
    pub policy_toml: Option<(String, String)>,
    /// `--reject`: the gauge, gate and return path tried around the chosen line, verified; when
    /// a gauge was placed, `scenario_toml` is the loop's scenario.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reject: Option<reject::RejectDesign>,
}

impl Design {
    /// The chosen candidate, if any.
    pub fn chosen(&self) -> Option<&Candidate> {
        self.chosen.map(|i| &self.candidates[i])
    }

    /// The runner-up of another mode, if any (see [`Design::runner_up`]).
    pub fn runner_up(&self) -> Option<&Candidate> {
        self.runner_up.map(|i| &self.candidates[i])
    }
}

/// Where a design stands, for a progress display.
#[derive(Debug, Clone)]
pub struct Progress {
    /// The mode being worked on (None before the first).
    pub mode: Option<Mode>,
    /// Refinement round (0: the first search).
    pub round: usize,
    /// What runs now ("searching 125 particles", "line check 3 (2000 parts)", …).
    pub stage: String,
    /// Candidates produced so far.
    pub candidates: usize,
    /// Line runs so far.
    pub line_runs: usize,
}

impl std::fmt::Display for Progress {
    /// "pins round 2 · line check 3 (2000 parts) · 4 candidate(s), 3 line run(s)".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}{} · {} · {} candidate(s), {} line run(s)",
            self.mode.map_or("", |m| m.name()),
            if self.round > 0 {
                format!(" round {}", self.round + 1)
            } else {
                String::new()
            },
            self.stage,
            self.candidates,
            self.line_runs,
        )
    }
}

/// Why a design could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DesignError {
    /// The planner failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
    /// A candidate could not be run on the line.
    #[error(transparent)]
    Line(#[from] LineError),
    /// A design option out of range; `field` names it as [`PlanError::Input`] does.
    #[error("{field} {value}: {reason}")]
    Input {
        /// The option's name (as on the command line).
        field: &'static str,
        /// The value given.
        value: String,
        /// Why it is refused.
        reason: String,
    },
}

impl DesignError {
    /// The field a bad input names (its message starts with it), from the design options or the
    /// problem.
    pub fn field(&self) -> Option<&'static str> {
        match self {
            DesignError::Input { field, .. } => Some(field),
            DesignError::Plan(p) => p.field(),
            DesignError::Line(_) => None,
        }
    }
}

fn input(field: &'static str, value: impl ToString, reason: impl ToString) -> DesignError {
    DesignError::Input {
        field,
        value: value.to_string(),
        reason: reason.to_string(),
    }
}

/// Refuse goals no design can meet before any search: a window finer than the orientation
/// quantum, a target above 1, a belt narrower than the part, an empty mode set, …
pub fn check_goal(o: &DesignOptions) -> Result<(), DesignError> {
    let p = &o.problem;
    p.compile()?;
    if p.tolerance_deg < p.theta_quantum_deg {
        return Err(input(
            "tolerance",
            p.tolerance_deg,
            format!(
                "the window ±{}° is finer than the planner's orientation quantum {}°: it cannot tell orientations that close apart; use a tolerance ≥ the quantum",
                p.tolerance_deg, p.theta_quantum_deg
            ),
        ));
    }
    if o.modes.is_empty() {
        return Err(input("modes", "", "no mode left to try"));
    }
    if !(o.time_limit_s.is_finite() && o.time_limit_s > 0.0 && o.time_limit_s <= 86_400.0) {
        return Err(input(
            "time_limit",
            o.time_limit_s,
            "must lie in (0, 86400] seconds",
        ));
    }
    if o.check_parts > 10_000_000 {
        return Err(input("check_parts", o.check_parts, "must lie in 0..=10⁷"));
    }
    if !(1..=1_000_000).contains(&o.screen_parts) {
        return Err(input("screen_parts", o.screen_parts, "must lie in 1..=10⁶"));
    }
    if o.refine > 10 {
        return Err(input("refine", o.refine, "must lie in 0..=10"));
    }
    if o.max_moving > 8 {
        return Err(input("max_moving", o.max_moving, "must lie in 0..=8"));
    }
    if !(1..=64).contains(&o.sensor_candidates) {
        return Err(input(
            "sensor_candidates",
            o.sensor_candidates,
            "must lie in 1..=64",
        ));
    }
    // The emitted scenario's `name`, which allows these only (it names a results folder).
    if o.name.is_empty()
        || o.name.len() > 100
        || !o
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_".contains(c))
    {
        return Err(input(
            "name",
            &o.name,
            "must be 1–100 characters of letters, digits, '-' or '_' (it is the scenario's name)",
        ));
    }
    fence_options(o, p.mu_c)?;
    if let Some(r) = &o.reject {
        r.check()?;
    }
    Ok(())
}

/// The fence actions of the fence and hybrid modes.
fn fence_options(o: &DesignOptions, mu_c: f64) -> Result<FenceOptions, DesignError> {
    let f = &o.fences;
    let mu_f = f.mu_f.unwrap_or(mu_c);
    let mu_range = crate::mechanics::limits::MU_C;
    if !crate::scenario::limits::contains(mu_range, mu_f) {
        let range = crate::scenario::limits::show(mu_range);
        return Err(input("mu_f", mu_f, format!("must lie in {range}")));
    }
    if !(f.overhang_a.is_finite() && (0.0..=10.0).contains(&f.overhang_a)) {
        return Err(input(
            "fence_overhang",
            f.overhang_a,
            "must lie in [0, 10] (units of a)",
        ));
    }
    if !(f.max_angle_deg.is_finite() && (15.0..90.0).contains(&f.max_angle_deg)) {
        return Err(input(
            "max_fence_angle",
            f.max_angle_deg,
            "must lie in [15, 90) degrees",
        ));
    }
    if !(f.angle_step_deg.is_finite() && (0.5..=45.0).contains(&f.angle_step_deg)) {
        return Err(input(
            "fence_angle_step",
            f.angle_step_deg,
            "must lie in [0.5, 45] degrees",
        ));
    }
    // Robust against the fences' friction, every fence stays below the jam limit of the
    // range's highest μf.
    let jam_mu_f = o.problem.mu_f_range.map_or(mu_f, |(_, hi)| hi.max(mu_f));
    let mut opts = FenceOptions::grid(jam_mu_f, f.angle_step_deg, f.max_angle_deg);
    // Robust against an error in the fences' angles, every fence stays below the jam limit
    // turned by the largest error.
    if let Some((lo, hi)) = o.problem.fence_angle_range {
        let jam = 90.0 - jam_mu_f.atan().to_degrees() - lo.abs().max(hi.abs());
        opts.angles_deg.retain(|a| a.abs() < jam - 1e-9);
    }
    opts.mu_f = mu_f;
    opts.overhang_a = f.overhang_a;
    opts.tail_max_a = match f.tails {
        TailChoice::Off => None,
        TailChoice::Auto => Some(super::fences::TAIL_MAX_A),
        TailChoice::UpTo(r) => {
            let lo = super::fences::TAIL_MIN_A;
            if !(r.is_finite() && (lo..=1000.0).contains(&r)) {
                return Err(input(
                    "tail_max",
                    r,
                    format!("must lie in [{lo}, 1000] (units of a; 0 turns tails off)"),
                ));
            }
            Some(r)
        }
    };
    if opts.angles_deg.is_empty() && o.modes.contains(&Mode::Fences) {
        return Err(input(
            "max_fence_angle",
            f.max_angle_deg,
            format!(
                "no candidate angle (from ±15°, below the jam limit {:.1}° for μf {jam_mu_f}) is left",
                90.0 - jam_mu_f.atan().to_degrees()
            ),
        ));
    }
    Ok(opts)
}

/// The belt width a mode searches with: the given one; without one, fences (which sweep parts
/// across the belt) get room for the parts' reach and a sweep either way.
fn mode_width(o: &DesignOptions, mode: Mode, a: f64) -> f64 {
    let p = &o.problem;
    if o.belt_width_given || matches!(mode, Mode::Pins | Mode::Sensor) {
        return p.belt_width_m;
    }
    let room = 2.0 * p.lateral_m + 6.0 * a;
    p.belt_width_m.max((room * 100.0).ceil() / 100.0)
}

/// Run the design workflow. `progress` is told what runs (it must be cheap).
pub fn design(
    o: &DesignOptions,
    progress: &(dyn Fn(&Progress) + Sync),
) -> Result<Design, DesignError> {
    check_goal(o)?;
    let resolved = o.resolved();
    let o = &resolved;
    let started = Instant::now();
    let deadline = started + std::time::Duration::from_secs_f64(o.time_limit_s);
    // Searches stop early enough to leave the line checks their time.
    let search_end = started + std::time::Duration::from_secs_f64(o.time_limit_s * 0.6);
    let mut w = Work {
        o,
        progress,
        deadline,
        started,
        candidates: Vec::new(),
        modes: Vec::new(),
        line_runs: 0,
        limit: None,
    };
    let modes = o.modes.clone();
    // A certificate that lines touching only the hull cannot reach the target: the modes it
    // covers are not searched.
    let certificate = o
        .problem
        .compile()
        .ok()
        .and_then(|c| super::certificate::of(&o.problem, &c))
        .filter(|c| c.bound < o.problem.target);
    for (i, &mode) in modes.iter().enumerate() {
        if let Some(c) = certificate
            .as_ref()
            .filter(|c| mode == Mode::Fences || c.covers_pins())
        {
            w.modes.push(ModeReport {
                mode,
                outcome: ModeOutcome::Impossible,
                candidates: 0,
                reason: Some(format!(
                    "no {} line can hold more than {:.1}% (the certificate), target {}",
                    mode.name(),
                    c.bound * 100.0,
                    o.problem.target,
                )),
            });
            continue;
        }
        let now = Instant::now();
        if now >= search_end {
            for &m in &modes[i..] {
                w.modes.push(ModeReport {
                    mode: m,
                    outcome: ModeOutcome::NotTried,
                    candidates: 0,
                    reason: Some(format!(
                        "the search time ({:.1} s, 60% of the time limit) was used up before it started",
                        o.time_limit_s * 0.6
                    )),
                });
            }
            w.cut(Limit::Time {
                seconds: o.time_limit_s,
                left_undone: Some(format!(
                    "{} not tried",
                    modes[i..]
                        .iter()
                        .map(|m| m.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            });
            break;
        }
        // An equal share of the search time left for each mode left (a fast mode leaves its
        // unused share to the next).
        let share = (search_end - now) / (modes.len() - i) as u32;
        w.modes.push(ModeReport {
            mode,
            outcome: ModeOutcome::Searched,
            candidates: 0,
            reason: None,
        });
        w.run_mode(mode, now + share)?;
    }
    let w_line_runs = w.line_runs;
    let mut design = w.finish(started)?;
    if let Some(c) = &certificate {
        let ruled_out = design
            .modes
            .iter()
            .all(|m| m.outcome == ModeOutcome::Impossible);
        if ruled_out && design.status == Status::NoDesign {
            design.message = format!(
                "no design: no line of the kinds asked for can bring more than {:.1}% of the parts into one window (the certificate), target {}",
                c.bound * 100.0,
                o.problem.target
            );
        }
    }
    design.certificate = certificate;
    if let Some(ro) = o.reject {
        progress(&Progress {
            mode: None,
            round: 0,
            stage: "reject: measuring the exit states, verifying the loop".into(),
            candidates: design.candidates.len(),
            line_runs: w_line_runs,
        });
        let r = reject::design_reject(o, design.chosen(), ro)?;
        if let (Some(body), Some(c)) = (r.loop_toml(), design.chosen()) {
            let mut lines = r.header_lines();
            lines.extend(header_lines(o, c, design.status));
            let file = format!("{}.toml", o.name);
            design.scenario_toml = Some(emit::header(&lines, &file) + &body);
        }
        design.reject = Some(r);
        design.elapsed_s = started.elapsed().as_secs_f64();
    }
    Ok(design)
}

struct Work<'a> {
    o: &'a DesignOptions,
    progress: &'a (dyn Fn(&Progress) + Sync),
    deadline: Instant,
    started: Instant,
    candidates: Vec<Candidate>,
    /// The modes begun or passed over so far; the last one is the mode being worked on.
    modes: Vec<ModeReport>,
    line_runs: usize,
    limit: Option<Limit>,
}

impl Work<'_> {
    /// A search's limit as the design states it: a search's time limit is the design's, and
    /// the search of `mode` stopped at its share of it, this far into the design.
    fn design_limit(&self, mode: Mode, limit: Limit) -> Limit {
        match limit {
            Limit::Time { .. } => Limit::Time {
                seconds: self.o.time_limit_s,
                left_undone: Some(format!(
                    "the {} search stopped at its share of it, {:.1} s into the design",
                    mode.name(),
                    self.started.elapsed().as_secs_f64()
                )),
            },
            l => l,
        }
    }

    /// Record a limit that cut the work short: the first one, with what every later cut of the
    /// time limit left undone said after it (`the pins search stopped …; the line check ran
    /// 3229 of 10000 parts`).
    fn cut(&mut self, l: Limit) {
        match (&mut self.limit, l) {
            (None, l) => self.limit = Some(l),
            (
                Some(Limit::Time {
                    left_undone: Some(said),
                    ..
                }),
                Limit::Time {
                    left_undone: Some(more),
                    ..
                },
            ) if !said.contains(&more) => *said = format!("{said}; {more}"),
            (
                Some(Limit::Time { left_undone, .. }),
                Limit::Time {
                    left_undone: more, ..
                },
            ) if left_undone.is_none() => {
                *left_undone = more;
            }
            _ => {}
        }
    }

    /// Record what became of the mode being worked on (the last one begun).
    fn mode_ended(&mut self, outcome: ModeOutcome, reason: String) {
        if let Some(m) = self.modes.last_mut() {
            m.outcome = outcome;
            m.reason = Some(reason);
        }
    }

    fn tell(&self, mode: Option<Mode>, round: usize, stage: String) {
        (self.progress)(&Progress {
            mode,
            round,
            stage,
            candidates: self.candidates.len(),
            line_runs: self.line_runs,
        });
    }

    /// An earlier candidate, screened on its own run, that is the same line as `cand` screened at
    /// headway `h`: a fixed sequence with the same scenario (the contingent plans' screens also
    /// feed their confusion predictions, which depend on the plan, so they are not shared).
    fn screened_line(&self, cand: &Candidate, h: f64) -> Option<usize> {
        if !matches!(cand.layout, Layout::Sequence(_)) {
            return None;
        }
        self.candidates.iter().position(|c| {
            matches!(c.layout, Layout::Sequence(_))
                && c.screen.is_some()
                && c.screen_shared_with.is_none()
                && c.runnable == cand.runnable
                && isolation_headway(c.belt_length_m) == h
        })
    }

    /// One mode: search, screen, and refine with the line's failures.
    fn run_mode(&mut self, mode: Mode, until: Instant) -> Result<(), DesignError> {
        let o = self.o;
        let mut problem = o.problem.clone();
        let a = problem.compile()?.radius;
        problem.belt_width_m = mode_width(o, mode, a);
        // A mixed line that cannot beat the best one the screen already holds is not searched
        // for: by obstacles, one with more of them; by belt length, one whose belt is at least
        // as long — k obstacles take at least one spacing in and k times the smaller of the pin
        // spacing and the gap after a fence (see `emit::layout`).
        if mode == Mode::Hybrid && !problem.fewest_sets {
            let target = problem.target;
            let held: Vec<&Candidate> = self
                .candidates
                .iter()
                .filter(|c| c.screen.as_ref().is_some_and(|s| s.success_rate >= target))
                .collect();
            let step = problem.spacing_m.min(super::fences::fence_gap_m(a));
            let most = match o.objective {
                Objective::Obstacles => held.iter().map(|c| c.obstacles.len()).min(),
                Objective::BeltLength => held
                    .iter()
                    .map(|c| {
                        (((c.belt_length_m - problem.spacing_m) / step).ceil() as usize)
                            .saturating_sub(1)
                    })
                    .min(),
                _ => None,
            };
            match most {
                Some(0) => {
                    self.mode_ended(
                        ModeOutcome::NotNeeded,
                        format!(
                            "a mixed line cannot beat, by {}, a line the screen already holds",
                            match o.objective {
                                Objective::Obstacles => "obstacles",
                                _ => "belt length",
                            }
                        ),
                    );
                    return Ok(());
                }
                Some(n) => problem.max_pins = problem.max_pins.min(n),
                None => {}
            }
        }
        for round in 0..=o.refine {
            let now = Instant::now();
            if now >= until {
                if round == 0 {
                    let l = self.design_limit(mode, Limit::time(o.time_limit_s));
                    self.cut(l);
                    self.mode_ended(
                        ModeOutcome::Stopped,
                        "its share of the search time was used up before its first search".into(),
                    );
                }
                return Ok(());
            }
            problem.deadline = Some(until);
            problem.time_limit_s = (until - now).as_secs_f64().max(1e-3);
            let mut planner = Planner::new(&problem)?;
            self.tell(
                Some(mode),
                round,
                format!("searching ({} particles)", planner.initial.total()),
            );
            let Some(mut cand) = self.search(mode, round, &problem, &mut planner)? else {
                return Ok(());
            };
            if o.check_parts == 0 {
                self.candidates.push(cand);
                return Ok(());
            }
            let h = isolation_headway(cand.belt_length_m);
            cand.headway_s = h;
            if let Some(k) = self.screened_line(&cand, h) {
                // The same scenario at the same headway, parts and seed runs the same: its screen
                // is this one's. It is run again only when this mode will refine from its
                // failures, which need the run's parts.
                let screen = self.candidates[k]
                    .screen
                    .clone()
                    .expect("a screened candidate");
                if screen.success_rate >= problem.target || round == o.refine {
                    self.tell(
                        Some(mode),
                        round,
                        format!(
                            "line screen: the line of candidate {}, screened already",
                            k + 1
                        ),
                    );
                    cand.oriented_per_min = screen.success_rate * 60.0 / h;
                    cand.screen = Some(screen);
                    cand.screen_shared_with = Some(k);
                    self.candidates.push(cand);
                    return Ok(());
                }
            }
            self.tell(
                Some(mode),
                round,
                format!("line screen ({} parts)", o.screen_parts),
            );
            let (screen, res) = cand.runnable.run(h, o.screen_parts, problem.seed, true)?;
            self.line_runs += 1;
            if let Layout::Contingent(plan) = &cand.layout {
                let (acc, with) = confusion_prediction(plan, &res.summary);
                cand.sensor_accuracy = acc;
                cand.predicted_with_confusion = with;
            }
            // Planned against an uncertainty, the screen is a Monte Carlo run under it (the
            // nominal run above keeps the sensor's confusion and the failures to refine with).
            let screen = match self.uncertain_screen(&cand, h)? {
                Some(u) => u,
                None => screen,
            };
            cand.oriented_per_min = screen.success_rate * 60.0 / h;
            let held = screen.success_rate >= problem.target;
            cand.screen = Some(screen);
            self.candidates.push(cand);
            if held || round == o.refine {
                return Ok(());
            }
            // Refine: the sensor mode, and any mode planned against an uncertainty (whose
            // failures come from physics the particles did not draw), with more particles
            // everywhere; the others with the parts the line got wrong.
            if mode == Mode::Sensor || !o.planned().is_nominal() {
                problem.jitter_samples += 2;
                problem.offset_samples += 2;
                if mode == Mode::Sensor {
                    continue;
                }
            }
            let base = (problem.jitter_samples * problem.offset_samples).max(25);
            let mut added = 0;
            for r in res
                .records
                .iter()
                .filter(|r| r.outcome != crate::engine::PartOutcome::Success)
            {
                if added >= base * 2 {
                    break;
                }
                let s = (r.theta_in_deg, r.y_in_m);
                if !problem.extra_samples.contains(&s) {
                    problem.extra_samples.push(s);
                    added += 1;
                }
            }
            if added == 0 && o.planned().is_nominal() {
                return Ok(());
            }
        }
        Ok(())
    }

    /// Candidate `cand`'s screen under the planned uncertainty at headway `h` (a Monte Carlo
    /// run of the screen's parts); None when nothing uncertain reaches its line.
    fn uncertain_screen(
        &mut self,
        cand: &Candidate,
        h: f64,
    ) -> Result<Option<LineCheck>, DesignError> {
        let o = self.o;
        let kinds: Vec<&str> = cand.obstacles.iter().map(|o| o.kind.name()).collect();
        let Some(perturbations) = o.planned().for_line(&kinds) else {
            return Ok(None);
        };
        self.tell(
            Some(cand.mode),
            cand.round,
            format!(
                "line screen under the uncertainty ({} samples)",
                o.screen_parts
            ),
        );
        let mut line = Line::new(&cand.runnable);
        let scene = line.scene(h)?;
        let started = Instant::now();
        let (outcomes, n) =
            super::check::check_uncertain(scene, perturbations, o.problem.seed, o.screen_parts)
                .map_err(|e| input("uncertain", "", e))?;
        self.line_runs += 1;
        Ok(Some(LineCheck::of(&outcomes, n, h, started)))
    }

    /// Search one mode and emit its plan (found or best effort) as a candidate; None when no
    /// plan improves on the feed.
    fn search(
        &mut self,
        mode: Mode,
        round: usize,
        problem: &Problem,
        planner: &mut Planner,
    ) -> Result<Option<Candidate>, DesignError> {
        let o = self.o;
        let line = LineSpec {
            name: o.name.clone(),
            headway_s: 4.0,
            belt_width_m: problem.belt_width_m,
            parts: o.check_parts.max(1),
        };
        let emitted = if mode == Mode::Sensor {
            self.search_sensor(mode, round, problem, planner, line)?
        } else {
            self.search_sequence(mode, round, problem, planner, line)?
        };
        Ok(emitted.map(|e| Candidate::emitted(mode, round, e)))
    }

    /// The sensor mode of [`Self::search`]: a contingent plan (a sensor pin and moving pins).
    fn search_sensor(
        &mut self,
        mode: Mode,
        round: usize,
        problem: &Problem,
        planner: &mut Planner,
        line: LineSpec,
    ) -> Result<Option<Emitted>, DesignError> {
        let o = self.o;
        let compiled = planner.compiled.clone();
        let res = contingent::search(planner, o.max_moving, o.sensor_candidates);
        let (outcome, stats) = match res {
            Ok(x) => x,
            // A part the sensor cannot tell apart (one stable state, no position) is not an
            // error of the design: the mode has no plan.
            Err(e) => {
                if o.modes == [Mode::Sensor] {
                    return Err(e.into());
                }
                self.tell(Some(mode), round, format!("no sensing plan: {e}"));
                self.mode_ended(ModeOutcome::NoPlan, e.to_string());
                return Ok(None);
            }
        };
        let (result, message, plan) = match outcome {
            ContingentOutcome::Found(p) => (
                SearchResult::Found,
                format!(
                    "a contingent plan: a sensor pin and {} moving pin(s), the fewest for its action set",
                    p.k
                ),
                p,
            ),
            ContingentOutcome::NoneUpTo { depth } => {
                let why = format!("no contingent plan up to {depth} moving pins");
                self.tell(Some(mode), round, why.clone());
                if round == 0 {
                    self.mode_ended(ModeOutcome::NoPlan, why);
                }
                return Ok(None);
            }
            ContingentOutcome::LimitHit { limit, .. } => {
                let l = self.design_limit(mode, limit);
                self.mode_ended(ModeOutcome::Stopped, format!("{l}"));
                self.cut(l);
                return Ok(None);
            }
        };
        let policy_name = format!("{}.policy.toml", o.name);
        let (body, policy) = emit::contingent_toml(
            problem,
            &plan,
            compiled.stable_deg.len(),
            compiled.symmetry,
            &line,
            &policy_name,
        );
        let obstacles = contingent_obstacles(problem, &plan);
        let belt_length_m = problem.spacing_m * (plan.k as f64 + 2.0);
        Ok(Some(Emitted {
            search: SearchSummary::new(
                result,
                message,
                planner,
                stats.depth_completed,
                stats.elapsed_s,
                None,
            ),
            layout: Layout::Contingent(plan),
            problem: problem.clone(),
            runnable: Runnable {
                toml: body,
                policy: Some((policy_name, policy)),
            },
            obstacles,
            belt_length_m,
        }))
    }

    /// The pins, fences and hybrid modes of [`Self::search`]: a sequence of obstacles.
    fn search_sequence(
        &mut self,
        mode: Mode,
        round: usize,
        problem: &Problem,
        planner: &mut Planner,
        line: LineSpec,
    ) -> Result<Option<Emitted>, DesignError> {
        let o = self.o;
        let compiled = planner.compiled.clone();
        if matches!(mode, Mode::Fences | Mode::Hybrid) {
            planner.fences = Some(FenceTransition::new(fence_options(o, problem.mu_c)?));
            planner.hybrid = mode == Mode::Hybrid;
        }
        let (outcome, stats) = planner.search();
        let (result, message, plan) = match outcome {
            Outcome::Found(p) => (
                SearchResult::Found,
                "a shortest plan for its action set".into(),
                Some(p),
            ),
            Outcome::NoneUpTo { depth, best } => (
                SearchResult::NoneUpToDepth,
                format!("no plan up to depth {depth} reaches the goal; the best effort is kept"),
                best,
            ),
            Outcome::Exhausted { depth, best } => (
                SearchResult::Exhausted,
                format!(
                    "no plan at any depth (no new state after {depth}); the best effort is kept"
                ),
                best,
            ),
            Outcome::LimitHit {
                limit,
                depth_completed,
                best,
            } => {
                let said = format!(
                    "stopped by its {limit} after depth {depth_completed}; the best so far is kept"
                );
                let l = self.design_limit(mode, limit);
                self.mode_ended(ModeOutcome::Stopped, format!("{l}"));
                self.cut(l);
                (SearchResult::Limit, said, best)
            }
        };
        let Some(plan) = plan else {
            self.tell(Some(mode), round, "no obstacle improves on the feed".into());
            if result != SearchResult::Limit && round == 0 {
                self.mode_ended(
                    ModeOutcome::NoPlan,
                    format!(
                        "no obstacle improves on the feed (the search ended {})",
                        result.name()
                    ),
                );
            }
            return Ok(None);
        };
        let a = compiled.radius;
        let width = sequence_width(problem, &plan, a);
        let line = LineSpec {
            belt_width_m: width,
            ..line
        };
        let body = emit::sequence_toml(
            problem,
            &plan,
            compiled.stable_deg.len(),
            compiled.symmetry,
            &line,
        );
        let (xs, belt_length_m) = emit::layout(problem, &plan, a);
        let obstacles = sequence_obstacles(&plan, &xs);
        let mut problem = problem.clone();
        problem.belt_width_m = width;
        Ok(Some(Emitted {
            search: SearchSummary::new(
                result,
                message,
                planner,
                stats.depth_completed,
                stats.elapsed_s,
                Some(SearchWork::of(&stats)),
            ),
            layout: Layout::Sequence(plan),
            problem,
            runnable: Runnable {
                toml: body,
                policy: None,
            },
            obstacles,
            belt_length_m,
        }))
    }

    /// Find candidate `i`'s headway and run its full check.
    fn confirm(&mut self, i: usize) -> Result<(), DesignError> {
        let o = self.o;
        let seed = o.problem.seed;
        let c = &self.candidates[i];
        let (mode, round) = (c.mode, c.round);
        let poly = c.problem.compile()?.polygon;
        let lo = crate::study::compare::part_length(&poly) / BELT_SPEED;
        let hi = c.headway_s;
        let per_part = c
            .screen
            .as_ref()
            .map_or(1e-3, |s| s.elapsed_s / s.parts.max(1) as f64);
        // Leave the full check its time.
        let check_s = per_part * o.check_parts as f64;
        let probe_end = self
            .deadline
            .checked_sub(std::time::Duration::from_secs_f64(check_s * 1.1))
            .unwrap_or_else(Instant::now);
        self.tell(Some(mode), round, "finding the line's headway".into());
        let runnable = c.runnable.clone();
        let target = o.problem.target;
        let mut on_line = Line::new(&runnable);
        let (h, probes) = line::shortest_headway(
            &mut on_line,
            (lo, hi),
            target,
            o.screen_parts.min(1000),
            seed,
            7,
            probe_end,
        )?;
        self.line_runs += probes.len();
        let left = (self.deadline - Instant::now().min(self.deadline)).as_secs_f64();
        let mut parts = o.check_parts;
        if per_part * parts as f64 > left {
            parts = ((left / per_part) as u64).max(o.screen_parts.min(o.check_parts));
            self.cut(Limit::Time {
                seconds: o.time_limit_s,
                left_undone: Some(format!(
                    "the line check ran {parts} of {} parts",
                    o.check_parts
                )),
            });
        }
        self.tell(
            Some(mode),
            round,
            format!("line check ({parts} parts at {h:.1} s)"),
        );
        let kinds: Vec<&str> = self.candidates[i]
            .obstacles
            .iter()
            .map(|o| o.kind.name())
            .collect();
        let uncertain = o.planned().for_line(&kinds);
        let (mut check, mut res) = on_line.run(h, parts, seed, false)?;
        self.line_runs += 1;
        // A verdict near its threshold is decided by more evidence, not by a seed: while the
        // check's interval straddles the target, run twice the parts (up to 8× the check) if
        // the time left allows.
        let mut n = parts;
        while uncertain.is_none() && straddles(&check, target) && n < 8 * o.check_parts {
            let next = (2 * n).min(8 * o.check_parts);
            if !self.fits(check.elapsed_s / n.max(1) as f64 * next as f64) {
                break;
            }
            self.tell(
                Some(mode),
                round,
                format!("line check straddles the target: {next} parts"),
            );
            (check, res) = on_line.run(h, next, seed, false)?;
            self.line_runs += 1;
            n = next;
        }
        let c = &mut self.candidates[i];
        if let Layout::Contingent(plan) = &c.layout {
            let (acc, with) = confusion_prediction(plan, &res.summary);
            c.sensor_accuracy = acc;
            c.predicted_with_confusion = with;
        }
        c.headway_probes = probes;
        c.headway_s = h;
        c.oriented_per_min = check.success_rate * 60.0 / h;
        c.undecided = straddles(&check, target);
        c.line_check = Some(check);
        if let Some(perturbations) = uncertain {
            // The verdict is a Monte Carlo study of at least the check's parts under the
            // uncertainty. It starts with a screen's worth of samples: a line the uncertainty
            // clearly breaks (the 95% interval below the target) is decided there; otherwise the
            // samples double up to the check's, and beyond it (to 8×) while the interval holds
            // the target.
            // Each step runs only the samples it adds (the study's samples are its shards').
            let scene = on_line.scene(h)?;
            let mut samples = o.screen_parts.clamp(1, parts);
            let (mut outcomes, mut n, mut spent) = (OutcomeCounts::default(), 0u64, 0.0);
            loop {
                self.tell(
                    Some(mode),
                    round,
                    format!("line check under the planned uncertainty ({samples} samples)"),
                );
                let started = Instant::now();
                let (more, m) = super::check::check_uncertain_from(
                    scene,
                    perturbations.clone(),
                    seed,
                    n,
                    samples,
                )
                .map_err(|e| input("uncertain", "", e))?;
                outcomes.absorb(&more);
                n += m;
                spent += started.elapsed().as_secs_f64();
                self.line_runs += 1;
                let mut u = LineCheck::of(&outcomes, n, h, started);
                u.elapsed_s = spent;
                let fails = u.ci95[1] < target;
                let next = if samples < parts {
                    (2 * samples).min(parts)
                } else {
                    (2 * samples).min(8 * o.check_parts)
                };
                let wanted = !fails && (samples < parts || straddles(&u, target));
                let more = wanted
                    && samples < next
                    && self.fits(u.elapsed_s / n.max(1) as f64 * (next - samples) as f64);
                let c = &mut self.candidates[i];
                c.oriented_per_min = outcomes.success as f64 / n.max(1) as f64 * 60.0 / h;
                c.undecided = straddles(&u, target);
                c.uncertain_check = Some(u);
                if !more {
                    if wanted && samples < parts {
                        self.cut(Limit::Time {
                            seconds: o.time_limit_s,
                            left_undone: Some(format!(
                                "the check under the uncertainty ran {samples} of {parts} samples"
                            )),
                        });
                    }
                    break;
                }
                samples = next;
            }
        }
        Ok(())
    }

    /// Does work of `seconds` (with a 20% reserve) fit in the time left?
    fn fits(&self, seconds: f64) -> bool {
        let left = (self.deadline - Instant::now().min(self.deadline)).as_secs_f64();
        seconds * 1.2 <= left
    }

    fn finish(mut self, started: Instant) -> Result<Design, DesignError> {
        let o = self.o;
        let target = o.problem.target;
        let mut chosen = None;
        let mut status = Status::NoDesign;
        if !self.candidates.is_empty() && o.check_parts == 0 {
            chosen = self.best_by(|_| true);
            status = Status::Unchecked;
        } else if !self.candidates.is_empty() {
            // Screen-held candidates in the objective's order; the first the full check holds.
            let mut tried = Vec::new();
            loop {
                let next = self.best_by(|c| {
                    c.line_check.is_none()
                        && c.screen.as_ref().is_some_and(|s| s.success_rate >= target)
                });
                let Some(i) = next else { break };
                if !tried.is_empty() && Instant::now() >= self.deadline {
                    break;
                }
                self.confirm(i)?;
                tried.push(i);
                if self.candidates[i]
                    .verdict_check()
                    .is_some_and(|c| c.success_rate >= target)
                {
                    chosen = Some(i);
                    status = Status::Confirmed;
                    break;
                }
            }
            if chosen.is_none() {
                // The best the line measured, by the one-sided 95% Wilson lower bound of its
                // success (a rate measured on few parts ranks below the same rate on many):
                // confirm it (if not yet) so its number is the full check's.
                let best = (0..self.candidates.len()).max_by(|&a, &b| {
                    let (x, y) = (&self.candidates[a], &self.candidates[b]);
                    let r = |c: &Candidate| c.measured().map_or(-1.0, |m| m.lower95);
                    r(x).total_cmp(&r(y)).then(
                        y.key(o.objective)
                            .partial_cmp(&x.key(o.objective))
                            .unwrap_or(std::cmp::Ordering::Equal),
                    )
                });
                if let Some(i) = best {
                    if self.candidates[i].line_check.is_none() {
                        self.confirm(i)?;
                    }
                    let held = self.candidates[i]
                        .verdict_check()
                        .is_some_and(|c| c.success_rate >= target);
                    status = if held {
                        Status::Confirmed
                    } else {
                        Status::NotConfirmed
                    };
                    chosen = Some(i);
                }
            }
        }
        if let (Status::Confirmed, Some(i), true) = (status, chosen, o.margins) {
            self.margins(i)?;
        }
        let runner_up = match (status, chosen) {
            (Status::Confirmed, Some(i)) => self.runner_up(i)?,
            _ => None,
        };
        for m in &mut self.modes {
            m.candidates = self.candidates.iter().filter(|c| c.mode == m.mode).count();
        }
        let message = self.message(status, chosen);
        let (scenario_toml, policy_toml) = match chosen {
            Some(i) => {
                let c = &self.candidates[i];
                let text =
                    c.runnable
                        .with_headway(if c.headway_s > 0.0 { c.headway_s } else { 4.0 });
                let file = format!("{}.toml", o.name);
                let head = emit::header(&header_lines(o, c, status), &file);
                (Some(head + &text), c.runnable.policy.clone())
            }
            None => (None, None),
        };
        Ok(Design {
            status,
            message,
            target,
            tolerance_deg: o.problem.tolerance_deg,
            candidates: self.candidates,
            chosen,
            runner_up,
            modes: self.modes,
            limit: self.limit,
            certificate: None,
            elapsed_s: started.elapsed().as_secs_f64(),
            scenario_toml,
            policy_toml,
            reject: None,
        })
    }

    /// Measure candidate `i`'s margins on its line at its headway, under the uncertainty it was
    /// planned against: as many parts per step as its check ran, at most 2000.
    fn margins(&mut self, i: usize) -> Result<(), DesignError> {
        let o = self.o;
        let c = &self.candidates[i];
        let Some(check) = c.verdict_check() else {
            return Ok(());
        };
        let samples = check.parts.min(2000);
        self.tell(
            Some(c.mode),
            c.round,
            format!("margins: friction and placement sweeps (up to {samples} parts a step)"),
        );
        let kinds: Vec<&str> = c.obstacles.iter().map(|o| o.kind.name()).collect();
        let base = o.planned().for_line(&kinds);
        let runnable = c.runnable.clone();
        let h = c.headway_s;
        let mut line = Line::new(&runnable);
        let scene = line.scene(h)?;
        let m = super::margins::measure(
            scene,
            base.as_ref(),
            o.problem.target,
            o.problem.seed,
            samples,
            self.deadline,
        )
        .map_err(|e| input("margins", "", e))?;
        self.line_runs += m.friction.len() + m.placement.len();
        self.candidates[i].margins = Some(m);
        Ok(())
    }

    /// The runner-up of another mode than the confirmed candidate `chosen`: among the candidates
    /// of other modes the screen holds at the target, the simplest (fewest sensors and moving
    /// pins, then the objective's order), confirmed on the line if the time left allows, and
    /// kept if the line confirms it and it is simpler than the chosen one or gives more oriented
    /// parts per minute. None otherwise.
    fn runner_up(&mut self, chosen: usize) -> Result<Option<usize>, DesignError> {
        let o = self.o;
        let target = o.problem.target;
        let mode = self.candidates[chosen].mode;
        let obj = o.objective;
        let Some(i) = (0..self.candidates.len())
            .filter(|&i| {
                let c = &self.candidates[i];
                c.mode != mode
                    && c.screen_shared_with.is_none()
                    && c.screen.as_ref().is_some_and(|s| s.success_rate >= target)
            })
            .min_by(|&a, &b| {
                let (x, y) = (&self.candidates[a], &self.candidates[b]);
                x.actuators
                    .cmp(&y.actuators)
                    .then(
                        x.key(obj)
                            .partial_cmp(&y.key(obj))
                            .unwrap_or(std::cmp::Ordering::Equal),
                    )
                    .then(a.cmp(&b))
            })
        else {
            return Ok(None);
        };
        if self.candidates[i].line_check.is_none() {
            // Its headway probes and full check, at the screen's pace, with room to spare: the
            // runner-up never makes the design overrun its limit or cut a check short.
            let c = &self.candidates[i];
            let per_part = c
                .screen
                .as_ref()
                .map_or(1e-3, |s| s.elapsed_s / s.parts.max(1) as f64);
            let probes = 7 * o.screen_parts.min(1000);
            let need = 2.0 * per_part * (o.check_parts + probes) as f64;
            let left = (self.deadline - Instant::now().min(self.deadline)).as_secs_f64();
            if need > left {
                return Ok(None);
            }
            let limit = self.limit.clone();
            self.confirm(i)?;
            if self.limit != limit {
                // The check ran short after all: its number is not comparable; say nothing.
                self.limit = limit;
                return Ok(None);
            }
        }
        let (c, best) = (&self.candidates[i], &self.candidates[chosen]);
        let held = c.verdict_check().is_some_and(|v| v.success_rate >= target);
        let better = c.actuators < best.actuators || c.oriented_per_min > best.oriented_per_min;
        Ok((held && better).then_some(i))
    }

    /// The best candidate by the objective among those `keep` accepts.
    fn best_by(&self, keep: impl Fn(&Candidate) -> bool) -> Option<usize> {
        let obj = self.o.objective;
        (0..self.candidates.len())
            .filter(|&i| keep(&self.candidates[i]))
            .min_by(|&a, &b| {
                self.candidates[a]
                    .key(obj)
                    .partial_cmp(&self.candidates[b].key(obj))
                    .unwrap_or(std::cmp::Ordering::Equal)
                    .then(a.cmp(&b))
            })
    }

    fn message(&self, status: Status, chosen: Option<usize>) -> String {
        let target = self.o.problem.target;
        let tol = self.o.problem.tolerance_deg;
        let Some(c) = chosen.map(|i| &self.candidates[i]) else {
            let names = |keep: &dyn Fn(ModeOutcome) -> bool| {
                self.modes
                    .iter()
                    .filter(|m| keep(m.outcome))
                    .map(|m| m.mode.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let cut = names(&|o| matches!(o, ModeOutcome::Stopped | ModeOutcome::NotTried));
            let none = names(&|o| !matches!(o, ModeOutcome::Stopped | ModeOutcome::NotTried));
            return match (none.is_empty(), cut.is_empty()) {
                (_, true) => format!(
                    "no design: no mode ({none}) produced a line that brings more parts into one window than the feed"
                ),
                (true, false) => format!(
                    "no design: the time limit stopped {cut} before any line improved on the feed"
                ),
                (false, false) => format!(
                    "no design: no mode ({none}) produced a line that improves on the feed, and the time limit stopped {cut} first"
                ),
            };
        };
        let what = describe_obstacles(c);
        let under = if c.uncertain_check.is_some() {
            " under the planned uncertainty"
        } else {
            ""
        };
        match (status, c.verdict_check()) {
            (Status::Unchecked, _) | (_, None) => format!(
                "{what} ({} mode), predicted {:.4}; not run on the line (0 parts were asked for the check): unchecked",
                c.mode.name(),
                c.predicted_success
            ),
            (_, Some(l)) => format!(
                "{} — {what} ({} mode): the line{under} holds {:.4} (95% CI {:.4}–{:.4}) of {} parts in one ±{tol}° window, target {target}; predicted {:.4}{}",
                status.word(),
                c.mode.name(),
                l.success_rate,
                l.ci95[0],
                l.ci95[1],
                l.parts,
                c.predicted_success,
                if c.undecided {
                    format!("; undecided: the interval still holds the target after {} parts, as many as the time and the cap (8× the check) allowed", l.parts)
                } else {
                    String::new()
                }
            ),
        }
    }
}

/// Does the check's 95% interval hold the target inside it (its verdict undecided)?
fn straddles(check: &LineCheck, target: f64) -> bool {
    check.ci95[0] < target && target <= check.ci95[1]
}

/// "3 pin(s)", "2 fence(s) and 1 pin(s)", "a sensor pin and 2 moving pin(s)".
pub fn describe_obstacles(c: &Candidate) -> String {
    let count = |k: &str| c.obstacles.iter().filter(|o| o.kind.name() == k).count();
    let (pins, fences, sensors, movers) = (
        count("pin"),
        count("fence"),
        count("sensor_pin"),
        count("moving_pin"),
    );
    let mut parts = Vec::new();
    if sensors > 0 {
        parts.push(format!("{sensors} sensor pin(s)"));
    }
    if movers > 0 {
        parts.push(format!("{movers} moving pin(s)"));
    }
    if pins > 0 {
        parts.push(format!("{pins} pin(s)"));
    }
    if fences > 0 {
        parts.push(format!("{fences} fence(s)"));
    }
    if parts.is_empty() {
        "no obstacle".into()
    } else {
        parts.join(", ")
    }
}

/// The headway that keeps parts apart whatever the line does to them: twice the belt's transit
/// time plus 10 s (s).
fn isolation_headway(belt_length_m: f64) -> f64 {
    (2.0 * belt_length_m / BELT_SPEED + 10.0).ceil()
}

/// The scenario header of a design: the command, the verdict with the line's number, the
/// prediction beside it, the headway and what it gives.
pub fn header_lines(o: &DesignOptions, c: &Candidate, status: Status) -> Vec<String> {
    let mut l = vec![
        format!("Written by `pinfeed plan` ({} mode):", c.mode.name()),
        String::new(),
        format!("  {}", o.command),
        String::new(),
    ];
    let p = &o.problem;
    if let (Some(u), Some(k)) = (&c.uncertain_check, &c.line_check) {
        l.push(format!(
            "Line check under the planned uncertainty ({} samples, `pinfeed mc` on a study of this file): {} — {} ({:.4}, 95% CI {:.4}–{:.4}); at nominal physics {} of {} ({:.4}).",
            u.parts,
            status.word().to_uppercase(),
            u.success,
            u.success_rate,
            u.ci95[0],
            u.ci95[1],
            k.success,
            k.parts,
            k.success_rate
        ));
    }
    match c.line_check.as_ref().filter(|_| c.uncertain_check.is_none()) {
        Some(k) => l.push(format!(
            "Line check: {} — {} of {} parts ({:.4}, 95% CI {:.4}–{:.4}) in one ±{}° window; target {}.",
            status.word().to_uppercase(),
            k.success,
            k.parts,
            k.success_rate,
            k.ci95[0],
            k.ci95[1],
            p.tolerance_deg,
            p.target
        )),
        None if c.line_check.is_none() => {
            l.push("Line check: none (0 parts were asked for the check): UNCHECKED.".into())
        }
        None => {}
    }
    if let Some(k) = &c.line_check {
        l.push(format!(
            "Headway {} s: the shortest with no collision and no loss of success in {} probes of the line, with a 25% reserve; {:.2} oriented parts per minute.",
            line::fmt_headway(k.headway_s),
            c.headway_probes.len(),
            c.oriented_per_min
        ));
    }
    if let Some(m) = &c.margins {
        l.push(format!(
            "Margins (`pinfeed plan` swept them on the line, {} parts a step): {}.",
            m.parts_per_step(),
            m.describe()
        ));
    }
    match &c.layout {
        Layout::Sequence(plan) => l.extend(emit::prediction_lines(&c.problem, plan)),
        Layout::Contingent(plan) => {
            l.push(format!(
                "Prediction: a sensor pin and {} moving pin(s), the fewest for their action set: {:.4} with a perfect classifier within {:.2}° ± {}°{}.",
                plan.k,
                plan.predicted_success,
                plan.centre_deg,
                p.tolerance_deg,
                c.predicted_with_confusion
                    .map_or(String::new(), |w| format!(", {w:.4} with the classifier's confusion on the line"))
            ));
        }
    }
    l
}

/// The sensor's accuracy on the line and the contingent prediction with the confusion the line
/// measured (rows and columns matched to the branches by label).
fn confusion_prediction(
    plan: &ContingentPlan,
    summary: &crate::engine::Summary,
) -> (Option<f64>, Option<f64>) {
    let Some(s) = summary.sensors.first() else {
        return (None, None);
    };
    let acc = Some(s.confusion.accuracy());
    let idx: Option<Vec<usize>> = plan
        .branches
        .iter()
        .map(|b| s.confusion.labels.iter().position(|l| *l == b.label))
        .collect();
    let Some(idx) = idx else {
        return (acc, None);
    };
    let counts: Vec<Vec<u64>> = idx
        .iter()
        .map(|&i| {
            let row = &s.confusion.counts[i];
            let mut r: Vec<u64> = idx.iter().map(|&j| row[j]).collect();
            r.push(row[row.len() - 1]);
            r
        })
        .collect();
    (acc, Some(plan.with_confusion(&counts)))
}

/// The belt width a sequence plan needs (m; `a`: the part's size).
fn sequence_width(problem: &Problem, plan: &Plan, a: f64) -> f64 {
    // The width the design needs (within the searched one): its obstacles, and the parts'
    // centroids with a margin of a/2, rounded up to 5 mm.
    let mut reach: f64 = problem.lateral_m + a / 2.0;
    for s in std::iter::once(&plan.initial).chain(plan.steps.iter().map(|s| &s.state)) {
        for q in &s.particles {
            reach = reach.max((q.y_q as f64 * problem.y_quantum_m).abs() + a / 2.0);
        }
    }
    for s in &plan.steps {
        match s.action {
            Action::Pin(p) => reach = reach.max(p.y_m.abs() + problem.pin_radius_m),
            Action::Fence(f) => {
                reach = reach
                    .max(f.y0_m.abs())
                    .max(f.y1_m.abs())
                    .max(f.far_y_m().abs())
            }
        }
    }
    // At least 2(a + lateral): the scenario parser refuses a belt on which the fed part
    // does not fit.
    let fits = a + problem.lateral_m;
    ((2.0 * reach.max(fits) / 0.005).ceil() * 0.005).min(problem.belt_width_m)
}

/// The obstacles of a sequence plan at their positions `xs` along the belt, named in order.
fn sequence_obstacles(plan: &Plan, xs: &[f64]) -> Vec<ObstacleInfo> {
    let (mut pins, mut fences) = (0, 0);
    plan.steps
        .iter()
        .zip(xs)
        .map(|(s, &x)| match s.action {
            Action::Pin(p) => {
                pins += 1;
                ObstacleInfo {
                    kind: ObstacleKind::Pin,
                    name: format!("pin{pins}"),
                    x_m: x,
                    y_m: p.y_m,
                    angle_deg: None,
                    length_m: None,
                    tail_radius_m: None,
                    targets_m: Vec::new(),
                }
            }
            Action::Fence(f) => {
                fences += 1;
                ObstacleInfo {
                    kind: ObstacleKind::Fence,
                    name: format!("fence{fences}"),
                    x_m: x,
                    y_m: f.y0_m,
                    angle_deg: Some(f.angle_deg),
                    length_m: Some(f.length_m),
                    tail_radius_m: f.tail_radius_m,
                    targets_m: Vec::new(),
                }
            }
        })
        .collect()
}

/// The obstacles of a contingent plan: the sensor pin, then a pin per step (moving where the
/// branches' targets differ).
fn contingent_obstacles(problem: &Problem, plan: &ContingentPlan) -> Vec<ObstacleInfo> {
    let mut obstacles = vec![ObstacleInfo {
        kind: ObstacleKind::SensorPin,
        name: "probe".into(),
        x_m: problem.spacing_m,
        y_m: plan.sensor.y_m,
        angle_deg: None,
        length_m: None,
        tail_radius_m: None,
        targets_m: Vec::new(),
    }];
    for j in 0..plan.k {
        let ys: Vec<f64> = plan.branches.iter().map(|b| b.targets_m[j]).collect();
        let fixed = ys.iter().all(|&y| (y - ys[0]).abs() < 1e-12);
        obstacles.push(ObstacleInfo {
            kind: if fixed {
                ObstacleKind::Pin
            } else {
                ObstacleKind::MovingPin
            },
            name: if fixed {
                format!("pin{}", j + 2)
            } else {
                format!("mover{}", j + 1)
            },
            x_m: problem.spacing_m * (j as f64 + 2.0),
            y_m: ys[0],
            angle_deg: None,
            length_m: None,
            tail_radius_m: None,
            targets_m: if fixed { Vec::new() } else { ys },
        });
    }
    obstacles
}
