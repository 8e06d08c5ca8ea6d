//! Ranges of the numeric settings of a contact (docs/commands.md#one-contact-pinfeed-contact). Lengths relative to the part
//! are in units of `a`, so the ranges mean the same at any magnitude of the part.
//!
//! This is the one table of the ranges a contact, a scenario (`scenario::limits` re-exports
//! [`MU_C`], [`TOL`] and [`FENCE_LENGTH_A`]), a study and the planner share: μc and μf, the
//! integration tolerance and a fence's length are refused alike by every command and file.

/// |θ0| in degrees: any angle within it is represented to better than 1e-11 rad.
pub const THETA0_DEG: f64 = 1e6;
/// Pin–part (or fence) friction μc (and μf): measured values lie below about 2.
pub const MU_C: (f64, f64) = (0.0, 5.0);
/// Part–belt friction μs (it scales forces only).
pub const MU_S: (f64, f64) = (1e-6, 100.0);
/// Pin radius in units of a.
pub const PIN_RADIUS_A: f64 = 10.0;
/// |w|: lateral pin speed as a fraction of the belt speed.
pub const PIN_SPEED: f64 = 10.0;
/// Integration tolerance per step (relative, in units of a): tighter than 1e-10 buys no accuracy
/// in f64 and multiplies the steps.
pub const TOL: (f64, f64) = (1e-10, 1e-2);
/// Fence length in units of a: shorter is a point. A flush edge translates along the fence in a
/// handful of steps whatever its length, but a vertex held on the fence line is integrated in
/// steps of at most 2a: 10⁶ a (a 0.1 mm part along a 100 m fence) bounds that worst case to
/// 5·10⁵ steps.
pub const FENCE_LENGTH_A: (f64, f64) = (1e-6, 1e6);
/// A fence's tail radius in units of a: a tail sharper than a hundredth of the part is its
/// corner (the straight fence's end does that), one wider than a thousand parts turns the fence
/// over more than a thousand part sizes.
pub const FENCE_TAIL_RADIUS_A: (f64, f64) = (1e-2, 1e3);
/// |d| for a fence pass (the fence's placement does not depend on d; beyond this its start
/// would lose precision).
pub const FENCE_D: f64 = 100.0;

/// A number for a message: plain when moderate, in exponent notation when huge or tiny (so that
/// 1e308 does not print as 309 digits).
pub fn num(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// [`num`] rounded to 6 significant digits first, for a number computed from others (a ratio of
/// limits, a plotted coordinate): `27.48737083745107` prints as `27.4874`, `9.999999999999999e-6`
/// as `1e-5`, `0.39999999999999997` as `0.4`.
pub fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return num(v);
    }
    num(format!("{v:.5e}").parse().unwrap_or(v))
}

/// A value outside its closed range (or not finite).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{name} must be {}in [{}, {}] ({what}), got {}", if value.is_finite() { "" } else { "a finite number " }, num(*lo), num(*hi), num(*value))]
pub struct OutOfRange {
    /// The setting (a flag such as `--mu-c`, or `column mu_c`).
    pub name: String,
    /// The value given.
    pub value: f64,
    /// The lower end of the range.
    pub lo: f64,
    /// The upper end of the range.
    pub hi: f64,
    /// What the number is (its unit or meaning).
    pub what: String,
}

/// `name must lie in [lo, hi] (what), got v` unless `lo ≤ v ≤ hi` (and v finite).
pub fn in_range(name: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<(), OutOfRange> {
    if !(v.is_finite() && v >= lo && v <= hi) {
        return Err(OutOfRange {
            name: name.to_string(),
            value: v,
            lo,
            hi,
            what: what.to_string(),
        });
    }
    Ok(())
}
