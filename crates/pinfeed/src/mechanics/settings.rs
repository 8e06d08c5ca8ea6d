//! What the caller says about a contact: the pin ([`Pin`]) and the model's settings
//! ([`ContactSettings`]: fidelity, friction, tolerance and budgets).

use super::part_model::Fidelity;
use serde::Serialize;

/// A pin as the contact model sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pin {
    /// Radius in the caller's units (0: the thesis's point pin).
    pub radius: f64,
    /// Lateral velocity as a fraction of the belt speed (0 for a fixed pin): v_pin = (−V, w·V).
    pub lateral_speed: f64,
}

impl Pin {
    /// A fixed point pin (radius 0, no lateral speed): the thesis's pin.
    pub fn point() -> Pin {
        Pin {
            radius: 0.0,
            lateral_speed: 0.0,
        }
    }
}

/// Settings of the contact model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ContactSettings {
    /// Which model computes the push (exact, ellipsoid or tip).
    pub fidelity: Fidelity,
    /// Pin–part (contact) friction coefficient μc ≥ 0.
    pub mu_c: f64,
    /// Part–belt (support) friction coefficient μs > 0: scales forces only.
    pub mu_s: f64,
    /// Absolute local error tolerance per step on θ (radians) and on contact coordinates (units of a).
    pub tol: f64,
    /// Largest pin travel in contact, in units of a, before reporting
    /// [`super::ContactStatus::TravelLimit`].
    pub max_travel: f64,
    /// Work budget per pass: limit-surface evaluations plus right-hand sides of the integrator.
    pub max_evaluations: u64,
    /// Event budget per pass.
    pub max_events: u32,
}

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            fidelity: Fidelity::Exact,
            mu_c: 0.5,
            mu_s: 0.3,
            tol: 1e-6,
            max_travel: 50.0,
            max_evaluations: 2_000_000,
            max_events: 200,
        }
    }
}

/// Disc pins below this radius (units of a) are point pins: the disc's ride round a vertex
/// (φ turning at a rate ∝ 1/ρ) then lasts less than 1e-9 a of travel and changes the pose by
/// O(ρ), far below any tolerance, while resolving it would need steps below the integrator's
/// floor. So the model is continuous in ρ down to 0 (to O(ρ)).
pub const POINT_PIN_RADIUS: f64 = 1e-9;
