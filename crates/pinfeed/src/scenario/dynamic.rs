//! Dynamic pins and the controller that drives them (docs/physics.md#moving-and-retractable-pins;
//! docs/scenario-format.md#moving-and-retractable-pins, #controller-and-rules): the compiled
//! forms. Validation is in
//! [`super::dynamic_check`].

/// A moving pin's actuator: it translates along y within `travel`, in trapezoidal moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingSpec {
    /// Where it rests before any command (m).
    pub home: f64,
    /// The lateral range its centre may reach, [min, max] (m), over the belt.
    pub travel: [f64; 2],
    /// Speed limit (m/s, > 0).
    pub speed: f64,
    /// Acceleration limit (m/s², > 0).
    pub accel: f64,
    /// Time after a move before the pin counts as ready (s).
    pub settle: f64,
    /// Constant-speed pieces each acceleration phase is resolved into for the contact model.
    pub pieces: usize,
}

/// A retractable pin's actuator: raised or withdrawn per part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RetractSpec {
    /// Its state before any command.
    pub raised: bool,
    /// Time to rise (s).
    pub raise_time: f64,
    /// Time to withdraw (s).
    pub lower_time: f64,
}

/// What moves a pin, if anything does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Actuator {
    /// A pin that translates across the belt.
    Moving(MovingSpec),
    /// A pin that is raised or withdrawn per part.
    Retractable(RetractSpec),
}

/// Where a dynamic pin is asked to be for a part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// A moving pin's lateral position (m).
    Y(f64),
    /// A retractable pin raised (true) or withdrawn.
    Raised(bool),
}

/// What the controller does with a command it cannot carry out before the part arrives (written
/// as its [`OnLate::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OnLate {
    /// Leave the pin as it is for this part (counted as a late actuation).
    #[default]
    Skip,
    /// Move anyway: the part may meet a pin in motion, simulated with its true velocity (moving
    /// pins only; counted too).
    Move,
}

impl OnLate {
    /// The setting's name in the file: `"skip"` or `"move"`.
    pub fn name(self) -> &'static str {
        match self {
            OnLate::Skip => "skip",
            OnLate::Move => "move",
        }
    }
}

/// One rule: when `sensor` decides `decides` (a hypothesis index, `None` for no decision), bring
/// `pin` to `target` for that part.
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    /// The sensor pin whose decision triggers the rule (index into `Scene::obstacles`).
    pub sensor: usize,
    /// The decision that triggers it: an index into the sensor's hypotheses, `None` for "unknown".
    pub decides: Option<usize>,
    /// The dynamic pin the rule commands (index into `Scene::obstacles`).
    pub pin: usize,
    /// Where that pin is to be for the part.
    pub target: Target,
}

/// How the controller turns what the sensors said into commands.
#[derive(Debug, Clone, PartialEq)]
pub enum ControlMode {
    /// Look the decision up in the rules (`[[rules]]` and the policy file).
    Policy,
    /// Keep a belief per part and choose, when the sensors have spoken, the commands of the
    /// dynamic pins that maximise the predicted probability of the goal
    /// (docs/physics.md#belief-and-online-replanning).
    Online(BeliefSpec),
}

/// What the online controller considers possible about a part (`[controller.belief]`): its
/// hypotheses are stable state × lateral-offset bin × pin–part friction × support class.
#[derive(Debug, Clone, PartialEq)]
pub struct BeliefSpec {
    /// Pin–part friction values (each a hypothesis; the scene's μc when not declared).
    pub mu_c: Vec<f64>,
    /// Support classes (`uniform`, `tripod`: a random tripod, averaged over `samples` draws).
    pub support: Vec<super::raw::SupportKind>,
    /// Lateral-offset bins over the feed's lateral range.
    pub offsets: usize,
    /// Simulated members per hypothesis (orientation jitter, offset within its bin, tripods).
    pub samples: usize,
    /// Positions per moving pin on the action grid (its travel, evenly; plus home and the
    /// targets of any rules).
    pub targets: usize,
}

/// The controller: computation latency, rules, and what to do when late.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// Time from the end of a reading to the commands (s).
    pub latency: f64,
    /// A decision whose posterior is below this counts as no decision.
    pub min_posterior: f64,
    /// What a command that cannot finish before its part arrives does.
    pub on_late: OnLate,
    /// The rules, from `[[rules]]` and the policy file.
    pub rules: Vec<Rule>,
    /// Where the rules came from: "scenario" or the policy file's path.
    pub source: String,
    /// Rules or online replanning.
    pub mode: ControlMode,
    /// Where `[controller.belief]` (or, without it, `controller.mode`) is written, online mode
    /// only: the online controller's model is built after parsing (it runs the line; see
    /// `engine::prepare`), and an error in building it is located here.
    pub belief_at: Option<super::error::KeyLocation>,
}
