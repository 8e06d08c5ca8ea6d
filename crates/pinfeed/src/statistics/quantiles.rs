//! Quantiles of the standard normal and of Student's t distribution.
//!
//! [`t_quantile`] starts from the Cornish–Fisher expansion of t about the normal quantile
//! (Abramowitz & Stegun 1964, 26.7.5; the expansion Hill 1970, "Algorithm 396: Student's
//! t-quantiles", CACM 13(10), builds on) and, for up to [`EXACT_DOF_LIMIT`] degrees of freedom,
//! polishes it by safeguarded Newton steps on the exact distribution function of t with an integer
//! number of degrees of freedom (Abramowitz & Stegun 26.7.3–26.7.4: a finite sum in
//! θ = atan(t/√ν)); one and two degrees of freedom have closed forms. Above the limit the
//! expansion's error, of order ν⁻⁵, is far below a double's resolution of the result.

use std::f64::consts::PI;

/// Inverse of the standard normal CDF (Acklam's rational approximation, |error| < 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    let p = p.clamp(1e-12, 1.0 - 1e-12);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// The standard normal distribution function Φ(x) = erfc(−x/√2)/2.
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// Degrees of freedom up to which [`t_quantile`] polishes the expansion on the exact distribution
/// function (whose sum has ν/2 terms); above it the expansion alone is exact to rounding.
pub const EXACT_DOF_LIMIT: u64 = 100_000;

/// P(|T| ≤ |t|) for Student's t with `dof` ≥ 1 degrees of freedom (Abramowitz & Stegun 26.7.3 for
/// odd ν, 26.7.4 for even ν), by a sum of about ν/2 terms.
fn t_central(t: f64, dof: u64) -> f64 {
    let nu = dof as f64;
    let theta = (t.abs() / nu.sqrt()).atan();
    let (s, c) = theta.sin_cos();
    let c2 = c * c;
    if dof % 2 == 0 {
        // sin θ (1 + ½cos²θ + (1·3)/(2·4)cos⁴θ + … + (1·3⋯(ν−3))/(2·4⋯(ν−2)) cos^(ν−2)θ)
        let (mut term, mut sum) = (1.0, 1.0);
        for j in 1..dof / 2 {
            let j = j as f64;
            term *= (2.0 * j - 1.0) / (2.0 * j) * c2;
            sum += term;
        }
        s * sum
    } else {
        // (2/π)(θ + sin θ (cos θ + (2/3)cos³θ + … + (2·4⋯(ν−3))/(3·5⋯(ν−2)) cos^(ν−2)θ))
        let mut sum = 0.0;
        if dof > 1 {
            let mut term = c;
            sum = c;
            for j in 1..(dof - 1) / 2 {
                let j = j as f64;
                term *= 2.0 * j / (2.0 * j + 1.0) * c2;
                sum += term;
            }
        }
        2.0 / PI * (theta + s * sum)
    }
}

/// The distribution function of Student's t with `dof` ≥ 1 degrees of freedom, exact to rounding
/// (Abramowitz & Stegun 26.7.3–26.7.4); `dof` = 0 is taken as 1.
pub fn t_cdf(t: f64, dof: u64) -> f64 {
    let a = t_central(t, dof.max(1));
    if t >= 0.0 {
        0.5 + 0.5 * a
    } else {
        0.5 - 0.5 * a
    }
}

/// The density of Student's t with `dof` degrees of freedom at `t`.
fn t_density(t: f64, nu: f64) -> f64 {
    let log_norm = libm::lgamma(0.5 * (nu + 1.0)) - libm::lgamma(0.5 * nu) - 0.5 * (nu * PI).ln();
    (log_norm - 0.5 * (nu + 1.0) * (t * t / nu).ln_1p()).exp()
}

/// The `p` quantile of Student's t distribution with `dof` degrees of freedom: the t with
/// P(T ≤ t) = p. Accurate to about 1e-12 (relative) for p in [1e-10, 1 − 1e-10]; NaN for p outside
/// (0, 1) or NaN, or `dof` = 0. Bounded work: at most 60 Newton steps of at most ν/2 terms each.
pub fn t_quantile(p: f64, dof: u64) -> f64 {
    if !(p > 0.0 && p < 1.0) || dof == 0 {
        return f64::NAN;
    }
    if p == 0.5 {
        return 0.0;
    }
    // Work in the upper half and mirror.
    let (upper, sign) = if p > 0.5 { (p, 1.0) } else { (1.0 - p, -1.0) };
    let tail = 1.0 - upper;
    let nu = dof as f64;
    let t = match dof {
        // Cauchy: t = tan(π(p − ½)) = cot(π·tail).
        1 => 1.0 / (PI * tail).tan(),
        // t = (2p − 1)/√(2p(1 − p)).
        2 => (2.0 * upper - 1.0) / (2.0 * upper * tail).sqrt(),
        _ => {
            // The normal quantile, polished by one Newton step on Φ (Acklam's is good to 1e-9).
            let mut z = -normal_quantile(tail);
            let phi = (-0.5 * z * z).exp() / (2.0 * PI).sqrt();
            z -= (normal_cdf(-z) - tail) / -phi;
            let mut t = cornish_fisher(z, nu);
            if dof <= EXACT_DOF_LIMIT {
                t = polish(t, tail, dof);
            }
            t
        }
    };
    sign * t
}

/// The Cornish–Fisher expansion of the t quantile about the normal quantile `z`, to ν⁻⁴
/// (Abramowitz & Stegun 26.7.5).
fn cornish_fisher(z: f64, nu: f64) -> f64 {
    let z2 = z * z;
    let g1 = (z2 + 1.0) * z / 4.0;
    let g2 = ((5.0 * z2 + 16.0) * z2 + 3.0) * z / 96.0;
    let g3 = (((3.0 * z2 + 19.0) * z2 + 17.0) * z2 - 15.0) * z / 384.0;
    let g4 = ((((79.0 * z2 + 776.0) * z2 + 1482.0) * z2 - 1920.0) * z2 - 945.0) * z / 92160.0;
    z + (g1 + (g2 + (g3 + g4 / nu) / nu) / nu) / nu
}

/// Newton steps on the upper tail P(T > t) = `tail`, t > 0, kept inside a shrinking bracket
/// (bisection when a step would leave it); at most 60 steps.
fn polish(start: f64, tail: f64, dof: u64) -> f64 {
    let nu = dof as f64;
    let upper_tail = |t: f64| 0.5 - 0.5 * t_central(t, dof);
    // The tail falls with t: lo has a tail above the target, hi below.
    let (mut lo, mut hi) = (0.0_f64, f64::INFINITY);
    let mut t = start.max(f64::MIN_POSITIVE);
    for _ in 0..60 {
        let f = upper_tail(t) - tail;
        if f > 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let next = t + f / t_density(t, nu);
        let next = if next > lo && next < hi {
            next
        } else if hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            2.0 * t
        };
        if (next - t).abs() <= 1e-15 * t {
            return next;
        }
        t = next;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantile_inverts_the_normal_cdf() {
        for p in [1e-6, 0.01, 0.1, 0.5, 0.8, 0.975, 0.999] {
            let x = normal_quantile(p);
            // Acklam's relative error in x is below 1.15e-9, so the CDF is off by at most that
            // times |x| times the density.
            let density = (-0.5 * x * x).exp() / (2.0 * PI).sqrt();
            let bound = 1.2e-9 * x.abs().max(1e-3) * density + 1e-16;
            assert!((normal_cdf(x) - p).abs() < bound, "{p}: {x}");
        }
    }

    /// Tabulated quantiles (Abramowitz & Stegun table 26.10 to its digits; here to nine decimals,
    /// checked by Simpson quadrature of the density).
    #[test]
    fn t_quantiles_match_the_tables() {
        let table: [(f64, u64, f64); 14] = [
            (0.975, 1, 12.706_204_736),
            (0.975, 2, 4.302_652_730),
            (0.975, 3, 3.182_446_305),
            (0.975, 4, 2.776_445_105),
            (0.975, 5, 2.570_581_836),
            (0.975, 9, 2.262_157_163),
            (0.975, 10, 2.228_138_852),
            (0.975, 19, 2.093_024_054),
            (0.975, 30, 2.042_272_456),
            (0.975, 100, 1.983_971_519),
            (0.995, 4, 4.604_094_871),
            (0.95, 20, 1.724_718_243),
            (0.9, 9, 1.383_028_738),
            (0.999, 7, 4.785_289_629),
        ];
        for (p, dof, want) in table {
            let got = t_quantile(p, dof);
            assert!(
                (got - want).abs() < 1e-8,
                "t({p}, {dof}) = {got}, want {want}"
            );
            // The lower tail mirrors the upper.
            assert!((t_quantile(1.0 - p, dof) + want).abs() < 1e-8);
        }
        // Many degrees of freedom: the normal's quantile.
        assert!((t_quantile(0.975, 10_000_000) - 1.959_964_2).abs() < 1e-6);
        assert!((t_quantile(0.975, 200_000) - 1.959_975_8).abs() < 1e-6);
    }

    #[test]
    fn t_quantile_inverts_the_exact_cdf() {
        for dof in [1, 2, 3, 6, 7, 50, 333] {
            for p in [0.001, 0.05, 0.3, 0.5, 0.7, 0.9, 0.99] {
                let t = t_quantile(p, dof);
                assert!((t_cdf(t, dof) - p).abs() < 1e-12, "{p} {dof}: {t}");
            }
        }
    }

    #[test]
    fn t_quantile_refuses_what_it_cannot_answer() {
        for p in [0.0, 1.0, -0.1, f64::NAN] {
            assert!(t_quantile(p, 5).is_nan());
        }
        assert!(t_quantile(0.9, 0).is_nan());
        assert_eq!(t_quantile(0.5, 3), 0.0);
    }
}
