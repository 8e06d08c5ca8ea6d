//! The ranges a contact case's settings must lie in (the table is [`crate::mechanics::limits`]),
//! checked before any push: out-of-range or non-finite values are refused with an error naming
//! the setting by the caller's name for it (`name(field)`: a flag of the command line, a column
//! of a batch file), its range and the value.

use super::{Case, CaseError};
use crate::geometry::Polygon;
use crate::mechanics::limits::{self, in_range};

/// Refuse non-finite or out-of-range settings of a case (the ones that do not depend on the part)
/// with a message naming the setting by `name(field)` (the caller's name for the field of
/// [`Case`]: a flag, a CSV column), its range and the value.
pub fn check_inputs(c: &Case, name: &dyn Fn(&str) -> String) -> Result<(), CaseError> {
    use limits::*;
    in_range(
        &name("theta0"),
        c.theta0_deg,
        -THETA0_DEG,
        THETA0_DEG,
        "degrees",
    )?;
    if !c.d.is_finite() {
        return Err(CaseError::NotFinite {
            name: name("d"),
            value: c.d,
        });
    }
    in_range(
        &name("mu_c"),
        c.mu_c,
        MU_C.0,
        MU_C.1,
        "friction coefficient",
    )?;
    in_range(
        &name("mu_s"),
        c.mu_s,
        MU_S.0,
        MU_S.1,
        "support friction; it scales forces only",
    )?;
    if !(c.pin_radius.is_finite() && c.pin_radius >= 0.0) {
        return Err(CaseError::PinRadius {
            name: name("pin_radius"),
            value: c.pin_radius,
        });
    }
    check_flag_settings(c.pin_speed, c.pin_stop, c.tol, name)?;
    check_stop_after_touch(c.pin_stop_after_touch, name)
}

/// [`Case::pin_stop_after_touch`] T in [0, 1000] units of a, named `name("pin_stop_after_touch")`.
pub fn check_stop_after_touch(
    t: Option<f64>,
    name: &dyn Fn(&str) -> String,
) -> Result<(), CaseError> {
    if let Some(t) = t {
        in_range(
            &name("pin_stop_after_touch"),
            t,
            0.0,
            1e3,
            "units of a of belt travel after the first touch",
        )?;
    }
    Ok(())
}

/// The settings a batch takes from flags only (the pin's path and the tolerance), named by `name`.
pub fn check_flag_settings(
    pin_speed: f64,
    pin_stop: Option<f64>,
    tol: f64,
    name: &dyn Fn(&str) -> String,
) -> Result<(), CaseError> {
    use limits::*;
    in_range(
        &name("pin_speed"),
        pin_speed,
        -PIN_SPEED,
        PIN_SPEED,
        "fraction of the belt speed",
    )?;
    if let Some(s_stop) = pin_stop {
        in_range(
            &name("pin_stop_after"),
            s_stop,
            1e-9,
            1e3,
            "units of a of belt travel",
        )?;
    }
    in_range(
        &name("tol"),
        tol,
        TOL.0,
        TOL.1,
        "integration tolerance per step",
    )?;
    Ok(())
}

/// Largest |d| at which the pin of a case can touch the part: the disc's reach 1 + ρ/a, widened for
/// a moving pin by the lateral distance it covers while crossing the part (about 2.02·(a + ρ) of
/// belt travel at |w| per unit).
pub fn reach(c: &Case, a: f64) -> f64 {
    (1.0 + c.pin_radius / a) * (1.0 + 2.02 * c.pin_speed.abs())
}

/// Refuse settings of a case that are out of range relative to the part (`a` = its size): pin
/// radius, d beyond what can touch, fence length; named as by [`check_inputs`].
pub fn check_geometry(
    c: &Case,
    poly: &Polygon,
    name: &dyn Fn(&str) -> String,
) -> Result<(), CaseError> {
    use limits::*;
    let a = poly.radius();
    let rmax = PIN_RADIUS_A * a;
    if c.pin_radius > rmax {
        return Err(CaseError::PinRadiusForPart {
            name: name("pin_radius"),
            max: rmax,
            a,
            value: c.pin_radius,
        });
    }
    if let Some(r) = c.fence_tail {
        if c.fence.is_none() {
            return Err(CaseError::TailWithoutFence { name: name("tail") });
        }
        let (lo, hi) = (FENCE_TAIL_RADIUS_A.0 * a, FENCE_TAIL_RADIUS_A.1 * a);
        if !(r >= lo && r <= hi) {
            return Err(CaseError::FenceTail {
                name: name("tail"),
                lo,
                hi,
                a,
                value: r,
            });
        }
    }
    match c.fence {
        Some((_, length)) => {
            in_range(&name("d"), c.d, -FENCE_D, FENCE_D, "units of a")?;
            if let Some(l) = length {
                let (lo, hi) = (FENCE_LENGTH_A.0 * a, FENCE_LENGTH_A.1 * a);
                if !(l >= lo && l <= hi) {
                    return Err(CaseError::FenceLength {
                        name: name("fence"),
                        lo,
                        hi,
                        a,
                        value: l,
                    });
                }
            }
        }
        None => {
            let limit = reach(c, a);
            if c.d.abs() > limit {
                return Err(CaseError::Unreachable {
                    name: name("d"),
                    d: c.d,
                    limit,
                });
            }
        }
    }
    Ok(())
}
