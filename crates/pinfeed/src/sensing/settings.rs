//! Sensor settings (docs/physics.md#sensing; thesis ch. 5 and app. C, F) and their physical ranges.
//!
//! Two kinds of sensor sit on a pin:
//! * **force/torque** (`ft`): six channels (Fx, Fy, Fz in N; Tx, Ty, Tz in N·mm) of the force the part
//!   puts on the pin, in world axes, about the sensor origin on the pin's axis at height `height`
//!   above the contact (docs/physics.md#sensing: T = r × F with r = (p − c_pin, −h)), sampled at `rate` Hz;
//! * **timing** (`timing`): the instants at which |F| rises above and falls below `threshold`
//!   (a contact or strain-gauge switch), each stamped with Gaussian jitter.
//!
//! The reading model, per F/T channel and sample k at time t_k (seconds since the pass began):
//!   x_k = LP(clean(t_k) + bias + drift·t_k + N(0, σ²)),   reading_k = resolution · round(x_k / resolution)
//! where LP is an optional first-order low-pass (cut-off `lowpass` Hz, discretised exactly for the
//! sample period: y_k = y_{k−1} + (1 − e^{−2π f_c / rate}) (x_k − y_{k−1})) and the sampling phase
//! (the time of the first sample within one period) is drawn uniformly per reading.
//!
//! Defaults (each documented where it comes from):
//! * resolution 0.025 N (Fx, Fy), 0.05 N (Fz), 0.125 N·mm (torques): ATI Nano, 25/250 calibration
//!   (thesis app. C, table C-1; docs/physics.md#sensing) — the calibration the thesis's chapter 5 used;
//! * noise σ = 0.0125 N and 0.0625 N·mm: half a count of that calibration (ATI quotes noise of the
//!   order of the resolution; the thesis shows raw profiles with a few counts of jitter);
//! * rate 1000 Hz: a common DAQ rate for a Nano (the thesis states none);
//! * height 0.02 m: the sensor's origin 2 cm above the contact (thesis fig. 5-2; its value is
//!   not given);
//! * no bias, no drift, no low-pass (a freshly tared sensor read raw);
//! * timing threshold 0.05 N (two counts of the F/T resolution) and jitter 1 ms.

use serde::{Deserialize, Serialize};

/// Which quantity a sensor reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SensorKind {
    /// Six-axis force/torque signal.
    #[default]
    Ft,
    /// Contact begin and end instants.
    Timing,
}

impl SensorKind {
    /// The kind's name in files and reports (`ft`, `timing`).
    pub fn name(self) -> &'static str {
        match self {
            SensorKind::Ft => "ft",
            SensorKind::Timing => "timing",
        }
    }
}

/// Number of F/T channels: Fx, Fy, Fz (N), Tx, Ty, Tz (N·mm).
pub const CHANNELS: usize = 6;
/// Channel names, in order.
pub const CHANNEL_NAMES: [&str; CHANNELS] = ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"];

/// Everything about one sensor. Units: N, N·mm, m, s, Hz.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SensorSettings {
    /// Force/torque signal or contact timing.
    pub kind: SensorKind,
    /// Sampling rate (Hz) of the F/T signal.
    pub rate: f64,
    /// Height (m) of the sensor origin above the contact plane.
    pub height: f64,
    /// White-noise standard deviation per force channel (N) and per torque channel (N·mm).
    pub noise_force: f64,
    /// White-noise standard deviation per torque channel (N·mm).
    pub noise_torque: f64,
    /// Constant offset per force channel (N) and per torque channel (N·mm).
    pub bias_force: f64,
    /// Constant offset per torque channel (N·mm).
    pub bias_torque: f64,
    /// Linear drift per second of the force channels (N/s) and torque channels (N·mm/s).
    pub drift_force: f64,
    /// Linear drift per second of the torque channels (N·mm/s).
    pub drift_torque: f64,
    /// Quantisation step of Fx/Fy (N), of Fz (N) and of the torques (N·mm); 0: no quantisation.
    pub resolution_force: f64,
    /// Quantisation step of Fz (N); 0: none.
    pub resolution_force_z: f64,
    /// Quantisation step of the torques (N·mm); 0: none.
    pub resolution_torque: f64,
    /// Cut-off (Hz) of a first-order low-pass applied before quantisation; `None`: none.
    pub lowpass: Option<f64>,
    /// Timing sensor: |F| threshold (N) that marks contact.
    pub threshold: f64,
    /// Timing sensor: standard deviation (s) of each reported instant.
    pub jitter: f64,
}

impl Default for SensorSettings {
    fn default() -> Self {
        SensorSettings {
            kind: SensorKind::Ft,
            rate: 1000.0,
            height: 0.02,
            noise_force: 0.0125,
            noise_torque: 0.0625,
            bias_force: 0.0,
            bias_torque: 0.0,
            drift_force: 0.0,
            drift_torque: 0.0,
            resolution_force: 0.025,
            resolution_force_z: 0.05,
            resolution_torque: 0.125,
            lowpass: None,
            threshold: 0.05,
            jitter: 1e-3,
        }
    }
}

/// A setting out of its physical range: the field's name and the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingError {
    /// The setting's field name.
    pub field: &'static str,
    /// Why the value is refused.
    pub message: String,
}

impl std::fmt::Display for SettingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

use crate::mechanics::limits::num;

fn check(field: &'static str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<(), SettingError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(SettingError {
            field,
            message: format!(
                "must lie in [{}, {}] ({unit}), got {}",
                num(lo),
                num(hi),
                num(v)
            ),
        })
    }
}

impl SensorSettings {
    /// Checks every setting against its physical range (the bounds keep sample counts and memory
    /// bounded: at most 10⁵ Hz; noise, bias and drift below 10⁶ N).
    pub fn validate(&self) -> Result<(), SettingError> {
        check("rate", self.rate, 1.0, 1e5, "Hz, > 0")?;
        check("height", self.height, 0.0, 10.0, "m, ≥ 0")?;
        check("noise_force", self.noise_force, 0.0, 1e6, "N, ≥ 0")?;
        check("noise_torque", self.noise_torque, 0.0, 1e9, "N·mm, ≥ 0")?;
        check("bias_force", self.bias_force, -1e6, 1e6, "N")?;
        check("bias_torque", self.bias_torque, -1e9, 1e9, "N·mm")?;
        check("drift_force", self.drift_force, -1e6, 1e6, "N/s")?;
        check("drift_torque", self.drift_torque, -1e9, 1e9, "N·mm/s")?;
        check(
            "resolution_force",
            self.resolution_force,
            0.0,
            1e3,
            "N, ≥ 0",
        )?;
        check(
            "resolution_force_z",
            self.resolution_force_z,
            0.0,
            1e3,
            "N, ≥ 0",
        )?;
        check(
            "resolution_torque",
            self.resolution_torque,
            0.0,
            1e6,
            "N·mm, ≥ 0",
        )?;
        if let Some(fc) = self.lowpass {
            check("lowpass", fc, 1e-3, 1e6, "Hz, > 0")?;
        }
        check("threshold", self.threshold, 1e-9, 1e6, "N, > 0")?;
        check("jitter", self.jitter, 0.0, 10.0, "s, ≥ 0")?;
        Ok(())
    }

    /// Noise standard deviation of channel `c` (0–2 forces, 3–5 torques).
    pub fn noise(&self, c: usize) -> f64 {
        if c < 3 {
            self.noise_force
        } else {
            self.noise_torque
        }
    }

    /// Bias of channel `c`.
    pub fn bias(&self, c: usize) -> f64 {
        if c < 3 {
            self.bias_force
        } else {
            self.bias_torque
        }
    }

    /// Drift per second of channel `c`.
    pub fn drift(&self, c: usize) -> f64 {
        if c < 3 {
            self.drift_force
        } else {
            self.drift_torque
        }
    }

    /// Quantisation step of channel `c` (0: none).
    pub fn resolution(&self, c: usize) -> f64 {
        match c {
            0 | 1 => self.resolution_force,
            2 => self.resolution_force_z,
            _ => self.resolution_torque,
        }
    }

    /// The same sensor with no noise, bias, drift, quantisation, low-pass or jitter: its reading is
    /// the clean signal sampled.
    pub fn ideal(&self) -> SensorSettings {
        SensorSettings {
            noise_force: 0.0,
            noise_torque: 0.0,
            bias_force: 0.0,
            bias_torque: 0.0,
            drift_force: 0.0,
            drift_torque: 0.0,
            resolution_force: 0.0,
            resolution_force_z: 0.0,
            resolution_torque: 0.0,
            lowpass: None,
            jitter: 0.0,
            ..*self
        }
    }

    /// The same sensor with every noise figure (white noise σ and timing jitter) multiplied by
    /// `factor` (a noise sweep's knob; quantisation, bias and drift unchanged).
    pub fn with_noise_factor(&self, factor: f64) -> SensorSettings {
        SensorSettings {
            noise_force: self.noise_force * factor,
            noise_torque: self.noise_torque * factor,
            jitter: self.jitter * factor,
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_name_their_field() {
        assert!(SensorSettings::default().validate().is_ok());
        let bad = SensorSettings {
            rate: 0.0,
            ..SensorSettings::default()
        };
        assert_eq!(bad.validate().unwrap_err().field, "rate");
        let bad = SensorSettings {
            noise_force: -1.0,
            ..SensorSettings::default()
        };
        assert_eq!(bad.validate().unwrap_err().field, "noise_force");
        let bad = SensorSettings {
            height: f64::NAN,
            ..SensorSettings::default()
        };
        assert_eq!(bad.validate().unwrap_err().field, "height");
        let bad = SensorSettings {
            threshold: 0.0,
            ..SensorSettings::default()
        };
        assert_eq!(bad.validate().unwrap_err().field, "threshold");
    }
}
