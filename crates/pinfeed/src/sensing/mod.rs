//! Sensing (docs/physics.md#sensing; thesis ch. 5, app. C, D, F): what a sensorised pin measures during a push and
//! what can be told from it.
//!
//! * [`settings`]: the sensor (force/torque or contact timing) and its noise model, with defaults
//!   from the ATI Nano the thesis used;
//! * [`signal`]: the clean force/torque signal of a pass, taken from the push itself;
//! * [`reading`]: sampling, noise, bias, drift, low-pass and quantisation, or contact instants;
//! * [`templates`]: hypotheses and their simulated template ensembles under declared uncertainty;
//! * [`classify`]: classifiers behind one interface;
//! * [`confusion`]: confusion matrices, accuracy and mutual information;
//! * [`evaluate`]: classifiers scored on simulated trials (confusion, accuracy, mutual information);
//! * [`placement`]: which pin offset and sensor kind tell the hypotheses apart best.

pub mod belief;
pub mod classify;
pub mod confusion;
pub mod evaluate;
pub mod experiment;
pub mod placement;
pub mod reading;
pub mod settings;
pub mod signal;
pub mod templates;

pub use reading::{read, ContactTimes, Reading, Sampled};
pub use settings::{SensorKind, SensorSettings, CHANNELS, CHANNEL_NAMES};
pub use signal::{ContactSignal, KnotRecorder, SignalScale};
