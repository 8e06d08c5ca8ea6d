//! Ranges of the numeric settings of a contact (docs/commands.md#one-contact-pinfeed-contact). Lengths relative to the part
//! are in units of `a`, so the ranges mean the same at any magnitude of the part.

/// |θ0| in degrees: any angle within it is represented to better than 1e-11 rad.
pub const THETA0_DEG: f64 = 1e6;
/// Pin–part (or fence) friction μc.
pub const MU_C: (f64, f64) = (0.0, 10.0);
/// Part–belt friction μs (it scales forces only).
pub const MU_S: (f64, f64) = (1e-6, 100.0);
/// Pin radius in units of a.
pub const PIN_RADIUS_A: f64 = 10.0;
/// |w|: lateral pin speed as a fraction of the belt speed.
pub const PIN_SPEED: f64 = 10.0;
/// Integration tolerance per step.
pub const TOL: (f64, f64) = (1e-12, 1e-2);
/// Fence length in units of a.
pub const FENCE_LENGTH_A: (f64, f64) = (1e-3, 1e3);
/// |d| for a fence pass (the fence's placement does not depend on d; beyond this its start
/// would lose precision).
pub const FENCE_D: f64 = 100.0;
