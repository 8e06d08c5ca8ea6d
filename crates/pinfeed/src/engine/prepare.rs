//! What a scene needs built before it runs, beyond what parsing gives: the online controller's
//! model (`[controller] mode = "online"`; docs/physics.md#belief-and-online-replanning).
//!
//! Parsing a scenario never runs the line. The online model does, thousands of times, so it is
//! built here, from the scene as given, and kept per process: a process that runs the same
//! scene again (a fuzzer's unchanged scenario, the tests) builds it once. A caller that changes
//! a scene before running it — a study's samples draw their own physics, `compare` gives every
//! design one part stream — builds the model of the scene as written first and passes it in
//! [`RunOptions::online`](super::RunOptions), so that the controller never sees what it cannot
//! know.

use super::online::OnlineModel;
use crate::scenario::{ControlMode, ScenarioError, Scene};
use std::collections::HashMap;
use std::hash::Hasher;
use std::sync::{Arc, Mutex, OnceLock};

/// The online controller's model behind an `Arc` (cheap to clone into every run of a study).
/// Two handles are equal when they share the model.
#[derive(Clone)]
pub struct OnlineHandle(pub Arc<OnlineModel>);

impl PartialEq for OnlineHandle {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl std::fmt::Debug for OnlineHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "OnlineModel({} hypotheses)", self.0.hypotheses.len())
    }
}

/// Models kept per process (cleared when full: a bounded memory).
const MODEL_CACHE: usize = 8;

type ModelMap = HashMap<(u64, usize), Arc<OnlineModel>>;

fn model_cache() -> &'static Mutex<ModelMap> {
    static CACHE: OnceLock<Mutex<ModelMap>> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The scene's identity for the cache: a hash of everything the scene holds (its `Debug` text,
/// which prints every number exactly) and that text's length. The model is a pure function of
/// the scene, so equal scenes share one.
fn fingerprint(scene: &Scene) -> (u64, usize) {
    struct Hashing(std::collections::hash_map::DefaultHasher, usize);
    impl std::fmt::Write for Hashing {
        fn write_str(&mut self, s: &str) -> std::fmt::Result {
            self.0.write(s.as_bytes());
            self.1 += s.len();
            Ok(())
        }
    }
    let mut h = Hashing(Default::default(), 0);
    let _ = std::fmt::write(&mut h, format_args!("{scene:?}"));
    (h.0.finish(), h.1)
}

/// The online controller's model of `scene` (None unless its controller's mode is online),
/// built from the scene's nominal physics, or taken from this process's cache. An error is
/// located at the scene's `[controller.belief]`.
///
/// ```
/// use std::path::Path;
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/quickstart.toml");
/// let scene = pinfeed::scenario::load(&path).unwrap();
/// // A passive line has no controller, so nothing to build.
/// assert!(pinfeed::engine::prepare::online_model(&scene).unwrap().is_none());
/// ```
pub fn online_model(scene: &Scene) -> Result<Option<OnlineHandle>, ScenarioError> {
    let Some(ctl) = scene.controller.as_ref() else {
        return Ok(None);
    };
    let ControlMode::Online(spec) = &ctl.mode else {
        return Ok(None);
    };
    let key = fingerprint(scene);
    if let Some(m) = model_cache().lock().ok().and_then(|m| m.get(&key).cloned()) {
        return Ok(Some(OnlineHandle(m)));
    }
    let model = OnlineModel::build(scene, spec).map_err(|e| {
        let message = format!("the online controller's model cannot be built: {e}");
        match &ctl.belief_at {
            Some(at) => at.error(message),
            None => ScenarioError::Unlocated(message),
        }
    })?;
    let model = Arc::new(model);
    if let Ok(mut cache) = model_cache().lock() {
        if cache.len() >= MODEL_CACHE {
            cache.clear();
        }
        cache.insert(key, model.clone());
    }
    Ok(Some(OnlineHandle(model)))
}
