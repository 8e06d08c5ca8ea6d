//! The physically meaningful range of every number in a scenario or study file (docs/scenario-format.md,
//! docs/study-format.md). A value outside its range is refused with a located error naming the
//! key, the range and the value, before any geometry or simulation sees it.
//!
//! Why ranges at all: the simulator is scale invariant in principle, but a number like
//! `belt.speed = 5e-324` or `part.scale = 1e-200` is not a feeder line, and its arithmetic leaves
//! f64 (event times of 1e308 s, areas that underflow to 0). The ranges below span every feeder
//! line one could build with many orders of magnitude to spare, and keep every derived quantity
//! (event times, areas, moments, histogram sizes) finite and representable:
//!
//! * lengths of the line (belt width and length) from 1 nm (the smallest part) to 1 km (10 km for
//!   the belt length);
//! * the part: `scale` from 1 nm to 1 km per unit, and the scaled part's circumradius a from 1 nm
//!   to 1 km; vertex coordinates (in the file's units) finite with the largest magnitude in
//!   [1e-9, 1e9], so that the polygon's area and moments stay normal floating-point numbers;
//! * belt speed from 0.1 mm/s to 10 m/s: with the longest belt, a part is on the belt at most
//!   10⁸ s;
//! * headway from 1 µs to 10⁶ s (rate from 10⁻⁶ to 10⁶ per second): with 10⁹ parts the last
//!   arrival is at most 10¹⁵ s;
//! * friction coefficients from 0 to 5 (measured values lie below about 2);
//! * angles: goal orientations within ±360°, tolerances and jitter up to 180°;
//! * integration tolerance from 1e-10 to 1e-2 (relative, in units of a);
//! * the orientation histogram's bin from 0.01° to 90° (at most 36 000 bins: bounded memory);
//! * a fence's length from 10⁻⁶ a to 10⁶ a (a flush edge slides any length in a few steps, but a
//!   vertex held on the fence line still steps at most 2a at a time).

/// Belt speed, m/s.
pub const BELT_SPEED: (f64, f64) = (1e-4, 10.0);
/// Belt width, m.
pub const BELT_WIDTH: (f64, f64) = (1e-9, 1e3);
/// Belt length, m.
pub const BELT_LENGTH: (f64, f64) = (1e-9, 1e4);
/// Metres per unit of the part's coordinates.
pub const PART_SCALE: (f64, f64) = (1e-9, 1e3);
/// The scaled part's circumradius a, m.
pub const PART_RADIUS: (f64, f64) = (1e-9, 1e3);
/// Largest magnitude of a vertex coordinate, in the file's units.
pub const VERTEX_MAGNITUDE: (f64, f64) = (1e-9, 1e9);
/// Friction coefficients (μc, μs, μf): the contact's range ([`crate::mechanics::limits::MU_C`]).
pub use crate::mechanics::limits::MU_C as FRICTION;
/// Part mass (kg): from a microgram to a tonne (sensor forces scale with it).
pub const MASS_KG: (f64, f64) = (1e-9, 1e3);
/// Seconds between arrivals.
pub const HEADWAY: (f64, f64) = (1e-6, 1e6);
/// Arrivals per second.
pub const RATE: (f64, f64) = (1e-6, 1e6);
/// Relative weight of a stable state.
pub const WEIGHT: (f64, f64) = (0.0, 1e6);
/// Orientation jitter (standard deviation), degrees.
pub const JITTER_DEG: (f64, f64) = (0.0, 180.0);
/// Goal orientations, degrees.
pub const ORIENTATION_DEG: (f64, f64) = (-360.0, 360.0);
/// Integration tolerance (relative): the contact's range ([`crate::mechanics::limits::TOL`]).
pub use crate::mechanics::limits::TOL;
/// Orientation histogram bin width, degrees.
pub const HISTOGRAM_BIN_DEG: (f64, f64) = (0.01, 90.0);
/// Fence length, in units of the part's a: the contact's range
/// ([`crate::mechanics::limits::FENCE_LENGTH_A`]).
pub use crate::mechanics::limits::FENCE_LENGTH_A as FENCE_LENGTH_OF_A;
/// A fence's tail radius, in units of the part's a
/// ([`crate::mechanics::limits::FENCE_TAIL_RADIUS_A`]).
pub use crate::mechanics::limits::FENCE_TAIL_RADIUS_A as FENCE_TAIL_RADIUS_OF_A;

/// Metres per millimetre: the scale a part drawn in millimetres needs.
pub const MM_SCALE: f64 = 1e-3;

/// The smallest a, in the part's own units, of a part that looks drawn in millimetres (a ≥ 5 mm);
/// the named parts have a of 1 to 2 units.
pub const MM_PART_UNITS: f64 = 5.0;

/// The likely cause of a part (circumradius `radius_m` at `scale` metres per unit) wider than its
/// belt (`belt_width`, m): vertices in millimetres read at a larger scale (a scenario's default 1,
/// `plan`'s 0.02). Returns the part's 2a (m) at [`MM_SCALE`] when the part looks drawn in mm (a
/// of at least [`MM_PART_UNITS`] units), that scale is smaller than `scale` and it fits the part
/// on the belt, else None (then the belt is the likelier culprit).
pub fn mm_scale_fit(radius_m: f64, scale: f64, belt_width: f64) -> Option<f64> {
    let two_a = 2.0 * radius_m * MM_SCALE / scale;
    let mm_like = radius_m / scale >= MM_PART_UNITS;
    (mm_like && scale > MM_SCALE && two_a <= belt_width).then_some(two_a)
}

/// The thinnest pin a warning lets pass without a word (m): 0.1 mm. Thinner pins are legal
/// (down to a point pin, radius 0) but no feeder's pin is that thin, so a radius below it is
/// most likely a length given in the wrong unit (metres where part units were asked).
pub const PIN_RADIUS_FLOOR_M: f64 = 1e-4;

/// A warning for a pin of radius `radius_m` (m) thinner than [`PIN_RADIUS_FLOOR_M`] but not a
/// point pin (0), with the radius in part units (`units`) and the metres per unit (`scale`).
pub fn thin_pin_warning(units: f64, scale: f64) -> Option<String> {
    let radius_m = units * scale;
    (radius_m > 0.0 && radius_m < PIN_RADIUS_FLOOR_M).then(|| {
        format!(
            "a pin of radius {} m ({} part units × scale {}) is thinner than 0.1 mm, thinner than any real pin: the radius is in part units (metres = part units × scale), so a radius in metres is read {} times too small; give 0 for a point pin",
            crate::mechanics::limits::short(radius_m),
            num(units),
            num(scale),
            crate::mechanics::limits::short(1.0 / scale)
        )
    })
}

/// A number as a message shows it: plain between 10⁻⁴ and 10¹⁵, else in exponent notation (so
/// 1e-300 is not printed with 300 zeros).
pub fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Human-readable `[lo, hi]`.
pub fn show(r: (f64, f64)) -> String {
    format!("[{}, {}]", num(r.0), num(r.1))
}

/// Does `v` lie in the closed range `r` (false for NaN and ±∞)?
pub fn contains(r: (f64, f64), v: f64) -> bool {
    v.is_finite() && v >= r.0 && v <= r.1
}

/// A moving pin's actuator speed limit (m/s); also at most [`max_pin_speed`] for the belt.
pub const ACTUATOR_SPEED: (f64, f64) = (1e-6, 1e3);

/// The one rule for how fast a moving pin may move: the contact model follows a pin whose
/// lateral speed is at most [`crate::mechanics::MAX_LATERAL_SPEED`] belt speeds, so a moving pin's
/// speed limit (m/s) may be at most that many times `belt_speed` (m/s) as well as within
/// [`ACTUATOR_SPEED`]. The scenario checker refuses a faster pin; the actuator's pin path never
/// exceeds the speed limit (see `engine::actuator`), so a valid file keeps the engine's invariant.
pub fn max_pin_speed(belt_speed: f64) -> f64 {
    ACTUATOR_SPEED
        .1
        .min(crate::mechanics::MAX_LATERAL_SPEED * belt_speed)
}
/// A moving pin's actuator acceleration limit (m/s²).
pub const ACTUATOR_ACCEL: (f64, f64) = (1e-6, 1e6);
/// Actuator and controller times: settle, raise and lower times, decision latency (s).
pub const ACTUATOR_TIME: (f64, f64) = (0.0, 1e4);

/// `[controller.belief] offsets`: lateral-offset bins over the feed's lateral range. The belief
/// limits bound the online controller's build time and memory.
pub const BELIEF_OFFSETS: (f64, f64) = (1.0, 41.0);
/// `[controller.belief] samples`: simulated members per hypothesis.
pub const BELIEF_SAMPLES: (f64, f64) = (1.0, 64.0);
/// `[controller.belief] targets`: positions per moving pin on the action grid.
pub const BELIEF_TARGETS: (f64, f64) = (2.0, 101.0);
/// `[controller.belief] mu_c`: the most friction values.
pub const BELIEF_MU_VALUES: usize = 16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_times_and_bins_stay_bounded() {
        // The longest stay on the belt, the latest arrival and the most histogram bins.
        assert!(BELT_LENGTH.1 / BELT_SPEED.0 <= 1e8);
        assert!(1e9 * HEADWAY.1 <= 1e15);
        assert!(360.0 / HISTOGRAM_BIN_DEG.0 <= 36_000.0 + 1e-9);
        assert!(!contains(BELT_SPEED, f64::NAN));
        assert!(!contains(BELT_SPEED, 5e-324));
        assert!(contains(BELT_SPEED, 0.05));
        assert_eq!(
            (num(1e-300), num(0.05), num(-1e308)),
            ("1e-300".into(), "0.05".into(), "-1e308".into())
        );
        assert_eq!(show(PART_SCALE), "[1e-9, 1000]");
    }
}
