//! The dynamic tier (docs/physics.md#dynamic-tier): a part with inertia sliding on a moving or
//! still surface, meeting a fixed disc pin with an impact and then sustained contact.
//!
//! State (x, y, θ, ẋ, ẏ, θ̇) in the world frame, the caller's units (length L, time T, mass M;
//! SI in scenarios). The part's support friction is the quasi-static tier's limit surface used
//! as a force law ([`friction`]); impacts follow Stronge's energetic restitution ([`impact`]);
//! the motion between events is integrated by an embedded Runge–Kutta pair with event location
//! ([`integrate`]).
//!
//! * [`body`]: mass properties from the polygon ([`Body`]).
//! * [`friction`]: the surface ([`Surface`]: velocity, μs, gravity, incline) and the support's
//!   friction force and moment for a relative twist.
//! * [`contact`]: the contact frame of a part against a fixed disc pin or a straight fence line —
//!   gap, normal, Jacobians, the velocity-product terms of the contact accelerations, the inverse
//!   effective mass matrix.
//! * [`impact`]: Stronge's energetic impact law in closed form per regime (slip, stick, reversal).
//! * [`integrate`]: [`simulate_pin_contact`], the hybrid integration (free sliding, carried by the
//!   surface, sustained contact in stick or slide) and its [`DynamicOutcome`].

pub mod body;
pub mod contact;
pub mod friction;
pub mod impact;
pub mod integrate;
#[cfg(test)]
mod tests;

pub use body::{Body, MassSpec};
pub use contact::{ContactFrame, ContactKind, FixedPin};
pub use friction::Surface;
pub use impact::{apply_impact, stronge_impact, ImpactError, ImpactPhase, ImpactResult};
pub use integrate::{
    simulate_pin_contact, ContactEnd, ContactLog, DynamicOutcome, DynamicParams, DynamicPart,
    DynamicStatus, ImpactRecord, State,
};

/// An input the dynamic tier refuses: the field, its value and the range it must lie in.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field} = {value} is out of range; allowed: {allowed}")]
pub struct InvalidInput {
    /// The field's name (e.g. `mass`, `surface.incline`).
    pub field: &'static str,
    /// The value given.
    pub value: f64,
    /// The allowed range, in words (e.g. `(0, ∞)`, `[0, 1]`).
    pub allowed: &'static str,
}

/// `value` if it is finite and positive, else an [`InvalidInput`] naming `field`.
pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64, InvalidInput> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(InvalidInput {
            field,
            value,
            allowed: "finite and > 0",
        })
    }
}

/// `value` if it lies in [lo, hi] (and is not NaN), else an [`InvalidInput`] naming `field`.
pub(crate) fn within(
    field: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    allowed: &'static str,
) -> Result<f64, InvalidInput> {
    if value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(InvalidInput {
            field,
            value,
            allowed,
        })
    }
}
