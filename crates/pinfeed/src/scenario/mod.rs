//! Scenario files: the TOML a user writes to describe a feeder line (belt, part, feed, obstacles,
//! goal, model, effects, output; docs/scenario-format.md), parsed with `deny_unknown_fields`,
//! validated with errors that name file, line, column, key and the allowed values, and compiled
//! into an immutable [`Scene`] (docs/physics.md#frames, #the-line).
//!
//! Loading a scenario takes two steps:
//!
//! 1. **reading** the file ([`SceneDraft::read`], or [`SceneDraft::parse`] for text): parse,
//!    validate and compile every section into a [`SceneDraft`]. Every error about the file
//!    itself comes from this step, including the sensors' hypotheses and the rules that name
//!    their labels; nothing is simulated;
//! 2. **building** the scene ([`SceneDraft::build`]): train each sensor pin's classifier on
//!    templates simulated for the scene. Its errors are located at the sensor's keys too.
//!
//! [`load`] (a path) and [`parse`] (text) do both and return the [`Scene`]: what a caller that
//! runs the scene wants. A caller that only checks a file, or reports on it, stops at the draft
//! and trains nothing.
//!
//! * [`raw`]: serde structs mirroring the file;
//! * [`compile`]: checks and conversion to a [`SceneDraft`], one function per section;
//! * [`draft`]: the checked, untrained scenario and the build step;
//! * [`checker`]: range checks and located errors, shared by every section;
//! * [`obstacles`]: pins and fences, their checks and neighbour lists;
//! * [`sensors`]: a sensor pin's settings and hypotheses, and its training;
//! * [`scene`]: the compiled types the engine reads;
//! * [`limits`]: the physically meaningful range of every number;
//! * [`location`], [`error`]: spans → line/column and key paths, and the located error;
//! * [`shared_feed`]: one reference scene's part stream imposed on others (`pinfeed compare`).

pub mod checker;
pub mod closed_loop;
pub mod compile;
pub mod draft;
pub mod dynamic;
pub mod dynamic_check;
pub mod error;
pub mod limits;
pub mod location;
pub mod obstacles;
pub mod raw;
pub mod scene;
pub mod sensors;
pub mod shared_feed;

pub use closed_loop::{ClosedLoop, LoopTime, Recirculation, RejectGate, RejectOn, WhenFull};
pub use draft::SceneDraft;
pub use dynamic::{
    Actuator, BeliefSpec, ControlMode, Controller, MovingSpec, OnLate, RetractSpec, Rule, Target,
};
pub use error::{InvalidScenario, KeyLocation, ScenarioError};
pub use scene::*;
pub use sensors::SensorDraft;
pub use shared_feed::{same_part, FeedMismatch, FeedOverrides, OverrideError};

use std::path::Path;

/// Parse, check and build scenario text: [`SceneDraft::parse`] then [`SceneDraft::build`], which
/// trains the sensor pins. `file` names the file in messages, gives the scene's default name and
/// the folder a policy file is read from.
pub fn parse(file: &Path, source: &str) -> Result<Scene, ScenarioError> {
    SceneDraft::parse(file, source)?.build()
}

/// Read, parse, check and build a scenario file: [`SceneDraft::read`] then
/// [`SceneDraft::build`], which trains the sensor pins.
///
/// ```
/// use std::path::Path;
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/quickstart.toml");
/// let scene = pinfeed::scenario::load(&path).unwrap();
/// assert_eq!(scene.name, "quickstart");
/// assert_eq!(scene.obstacles.len(), 3);
/// assert_eq!(scene.part.stable_states.len(), 3);
/// ```
pub fn load(path: &Path) -> Result<Scene, ScenarioError> {
    SceneDraft::read(path)?.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[belt]
speed = 0.05
width = 0.2
length = 1.0

[part]
shape = "tripoly2"
scale = 0.02

[feed]
parts = 10
arrival = "periodic"
headway = 2.0
orientation = "stable"

[[obstacles]]
kind = "pin"
x = 0.3
y = 0.0
radius = 0.002

[goal]
any = true
"#;

    fn err(src: &str) -> InvalidScenario {
        match parse(Path::new("t.toml"), src) {
            Ok(_) => panic!("accepted:\n{src}"),
            Err(e) => e.invalid().expect("located error").clone(),
        }
    }

    #[test]
    fn good_scenario_compiles() {
        let s = parse(Path::new("dir/good.toml"), GOOD).unwrap();
        assert_eq!(s.name, "good");
        assert_eq!(s.obstacles.len(), 1);
        assert_eq!(s.obstacles[0].name(), "pin1");
        assert!((s.part.radius - 0.02 * 1.374368).abs() < 1e-6);
        assert_eq!(s.feed.arrival, Arrival::Periodic { headway: 2.0 });
        assert_eq!(s.goal, Goal::Any);
    }

    #[test]
    fn unknown_key_is_located() {
        let e = err(&GOOD.replace("speed = 0.05", "sped = 0.05"));
        assert_eq!((e.line, e.column, e.key.as_str()), (3, 1, "belt.sped"));
        assert!(e.message.contains("`speed`"), "{}", e.message);
    }

    #[test]
    fn validation_errors_name_key_and_range() {
        let e = err(&GOOD.replace("speed = 0.05", "speed = -0.05"));
        assert_eq!((e.line, e.column, e.key.as_str()), (3, 9, "belt.speed"));
        assert!(
            e.message.contains("must lie in [0.0001, 10] (m/s)"),
            "{}",
            e.message
        );
        let e = err(&GOOD.replace("radius = 0.002", "radius = 0.002\nmu_c = -1"));
        assert_eq!(e.key, "obstacles[0].mu_c");
        let e = err(&GOOD.replace("kind = \"pin\"", "kind = \"moving_pin\""));
        assert_eq!(e.key, "obstacles[0]");
        assert!(e.message.contains("`travel` is missing"));
        let e = err(&GOOD.replace("x = 0.3", "x = 0.01"));
        assert_eq!(e.key, "obstacles[0].x");
        let e = err(&GOOD.replace(
            "orientation = \"stable\"",
            "orientation = \"stable\"\nweights = [1, 2]",
        ));
        assert!(
            e.message.contains("3 (0.000°, 90.000°, 206.565°)"),
            "{}",
            e.message
        );
    }

    #[test]
    fn fences_compile_beside_pins() {
        let fence =
            "\n[[obstacles]]\nkind = \"fence\"\nx = 0.4\ny = -0.09\nangle = -30\nlength = 0.1\n";
        // A fence at −30° from y = −0.09 runs to the right, off the belt: refused.
        let e = err(&GOOD.replace("[goal]", &format!("{fence}\n[goal]")));
        assert_eq!(e.key, "obstacles[1].length");
        assert!(e.message.contains("downstream end"), "{}", e.message);
        // At +30° it runs to the left, over the belt; μf defaults to the part's μc.
        let text = GOOD.replace("[goal]", &format!("{}\n[goal]", fence.replace("-30", "30")));
        let s = parse(Path::new("f.toml"), &text).unwrap();
        let Obstacle::Fence(f) = &s.obstacles[1] else {
            panic!("not a fence: {:?}", s.obstacles[1]);
        };
        assert_eq!(f.name, "fence2");
        assert_eq!(
            (f.start.x, f.start.y, f.length, f.mu_f),
            (0.4, -0.09, 0.1, 0.5)
        );
        assert!((f.angle_rad - 30f64.to_radians()).abs() < 1e-15);
        assert!((f.end().y - (-0.09 + 0.05)).abs() < 1e-12);
        assert_eq!(s.obstacles[1].x_range(), [0.4, f.end().x]);
        // The pin at (0.3, 0) is 0.107 m from the fence: beyond 2a = 0.055 m, not a neighbour.
        assert!(s.neighbours[0].is_empty() && s.neighbours[1].is_empty());
        // A pin's key on a fence, and a fence's key on a pin, are refused by name.
        let e = err(&text.replace("length = 0.1\n", "length = 0.1\nmu_c = 0.2\n"));
        assert_eq!(e.key, "obstacles[1].mu_c");
        assert!(
            e.message.contains("does not apply to a fence"),
            "{}",
            e.message
        );
        let e = err(&GOOD.replace("radius = 0.002", "radius = 0.002\nangle = 10"));
        assert_eq!(e.key, "obstacles[0].angle");
        assert!(
            e.message.contains("does not apply to a pin"),
            "{}",
            e.message
        );
        // Too close to the entry (x must exceed a = 0.0275 m).
        let e = err(&text.replace("x = 0.4", "x = 0.02"));
        assert_eq!(e.key, "obstacles[1].x");
    }

    #[test]
    fn a_fence_longer_than_a_million_part_sizes_is_refused() {
        // A 20 nm part (a = 27.5 nm) against a 0.1 m fence: a slide of 3.6·10⁶ a is refused by
        // name; a 1 µm part (a = 1.4 µm, 7·10⁴ a) is fine.
        let fence = |scale: &str| {
            GOOD.replace("scale = 0.02", &format!("scale = {scale}")).replace(
                "[goal]",
                "[[obstacles]]\nkind = \"fence\"\nx = 0.4\ny = -0.09\nangle = 30\nlength = 0.1\n\n[goal]",
            )
        };
        assert!(parse(Path::new("f.toml"), &fence("0.000001")).is_ok());
        let e = err(&fence("0.00000002"));
        assert_eq!(e.key, "obstacles[1].length");
        assert!(e.message.contains("10⁻⁶ a to 10⁶ a"), "{}", e.message);
    }

    #[test]
    fn missing_part_is_reported() {
        let src = GOOD.replace("[part]\nshape = \"tripoly2\"\nscale = 0.02\n", "");
        let e = err(&src);
        assert_eq!(e.key, "part");
        assert!(e.message.contains("missing section [part]"));
    }

    /// Sensors trained on this thread while `f` runs.
    fn trainings<T>(f: impl FnOnce() -> T) -> (T, usize) {
        let before = sensors::TRAINED.with(|n| n.get());
        let out = f();
        (out, sensors::TRAINED.with(|n| n.get()) - before)
    }

    #[test]
    fn a_refused_sensor_scene_trains_nothing() {
        let path = &crate::project_path("scenarios/tripoly1_sensing.toml");
        let text = include_str!("../../../../scenarios/tripoly1_sensing.toml");
        // The rules name the probe's labels: a wrong one is refused without training the probe.
        let bad = text.replacen("decides = \"0°\"", "decides = \"90°\"", 1);
        let (e, n) = trainings(|| parse(path, &bad).unwrap_err());
        let e = e.invalid().expect("located error").clone();
        assert_eq!(e.key, "rules[0].decides", "{e}");
        assert!(e.message.contains("0°, 135°, 225°"), "{e}");
        assert_eq!(n, 0, "a refused file trained {n} sensor(s)");
        // So is an error in a section before the rules.
        let bad = text.replacen("[output]", "[output]\nhistogram_bin = 7", 1);
        let (e, n) = trainings(|| parse(path, &bad).unwrap_err());
        assert_eq!(e.invalid().unwrap().key, "output.histogram_bin", "{e}");
        assert_eq!(n, 0);
        // Reading the good file trains nothing either; building it trains its one sensor.
        let (draft, n) = trainings(|| SceneDraft::parse(path, text).unwrap());
        assert_eq!((draft.sensors().len(), n), (1, 0));
        let (scene, n) = trainings(|| draft.build().unwrap());
        assert_eq!(n, 1);
        assert_eq!(scene.name, draft.name());
    }
}
