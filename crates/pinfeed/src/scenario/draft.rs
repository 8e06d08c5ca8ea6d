//! A scenario file read and checked, its scene not yet built: [`SceneDraft`].
//!
//! Reading ([`SceneDraft::parse`], [`SceneDraft::read`]) parses the TOML and checks every section,
//! the sensors' hypotheses and the controller's rules: every error about the file itself comes
//! from this step, located at its key. Building ([`SceneDraft::build`]) trains each sensor pin's
//! classifier on templates simulated for the scene (the costly step of a sensor scene; a scene
//! without sensors has nothing to train); a training error is located at the sensor's keys as
//! well.

use super::error::{Locator, ScenarioError};
use super::scene::{Obstacle, Scene};
use super::sensors::{self, SensorDraft};
use std::path::Path;
use std::sync::Arc;

/// A validated, compiled scenario whose sensor pins are not trained yet: the scene's pieces (its
/// sensor pins without a sensor) and the settings of each sensor to train.
/// [`SceneDraft::build`] turns it into the [`Scene`] the engine runs.
///
/// ```
/// use pinfeed::scenario::SceneDraft;
/// use std::path::Path;
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/tripoly1_sensor.toml");
/// let draft = SceneDraft::read(&path).unwrap(); // checks the file, trains nothing
/// assert_eq!(draft.sensors()[0].name, "probe");
/// assert_eq!(draft.sensors()[0].hypotheses.labels(), ["0°", "135°", "225°"]);
/// let scene = draft.build().unwrap(); // trains the probe
/// assert_eq!(scene.name, "tripoly1_sensor");
/// ```
#[derive(Debug, Clone)]
pub struct SceneDraft {
    /// The scene, its sensor pins still without their sensor.
    scene: Scene,
    /// The sensors to train, in obstacle order.
    sensors: Vec<SensorDraft>,
}

impl SceneDraft {
    /// A draft of `scene` (its sensor pins without a sensor) with the sensors to train.
    pub(super) fn new(scene: Scene, sensors: Vec<SensorDraft>) -> SceneDraft {
        SceneDraft { scene, sensors }
    }

    /// Parse and check scenario text. `file` names the file in messages, gives the scene's
    /// default name and the folder a policy file is read from.
    pub fn parse(file: &Path, source: &str) -> Result<SceneDraft, ScenarioError> {
        SceneDraft::parse_with_policy(file, source, None)
    }

    /// [`SceneDraft::parse`], with the text of the policy file the scenario names given in
    /// memory (`policy`; None: read from its file, as `parse` does): a design checked on the
    /// line before it is written. Messages about the policy name the file the scenario names.
    pub fn parse_with_policy(
        file: &Path,
        source: &str,
        policy: Option<&str>,
    ) -> Result<SceneDraft, ScenarioError> {
        let loc = Locator::new(file, source);
        let raw: super::raw::RawScenario = toml::from_str(source).map_err(|e| loc.from_toml(&e))?;
        let default_name = file
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scenario")
            .to_string();
        super::compile::compile(&raw, &loc, &default_name, policy)
    }

    /// Read, parse and check a scenario file.
    pub fn read(path: &Path) -> Result<SceneDraft, ScenarioError> {
        let source = crate::input::read_text(path).map_err(|error| ScenarioError::Io {
            path: path.to_path_buf(),
            error,
            hint: String::new(),
        })?;
        SceneDraft::parse(path, &source)
    }

    /// The scene's name (it names the results folder).
    pub fn name(&self) -> &str {
        &self.scene.name
    }

    /// The scene with its sensor pins still untrained (for drawings of the line: see
    /// [`Self::sensors`] for which pins carry a sensor).
    pub fn untrained(&self) -> &Scene {
        &self.scene
    }

    /// The sensor pins still to be trained, in obstacle order (none for a scene without sensors).
    pub fn sensors(&self) -> &[SensorDraft] {
        &self.sensors
    }

    /// Build the scene: train every sensor pin's classifier on templates simulated for this
    /// scene (the same file always trains the same classifiers) and give each pin its sensor.
    /// Errors are located at the sensor's keys in the file the draft was read from.
    pub fn build(&self) -> Result<Scene, ScenarioError> {
        let mut scene = self.scene.clone();
        for draft in &self.sensors {
            let trained = sensors::train(&self.scene, draft)?;
            if let Obstacle::Pin(pin) = &mut scene.obstacles[draft.obstacle] {
                pin.sensor = Some(Arc::new(trained));
            }
        }
        Ok(scene)
    }
}
