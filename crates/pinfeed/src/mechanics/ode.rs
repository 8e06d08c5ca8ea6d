//! The ODE scheme the contact integrator steps with: the Dormand–Prince 5(4) pair, its 4th-order
//! continuous extension, and the Illinois method for the roots of event functions along it.
//!
//! * [`dp_step`]: one explicit Runge–Kutta step of the 5th-order solution of y' = f(y) (Dormand &
//!   Prince 1980; Hairer, Nørsett & Wanner, *Solving ODEs I*, table II.5.2), with the embedded
//!   4th-order solution's difference as the error estimate (local error O(h⁵)). The last stage is
//!   evaluated at the new state (first same as last), so its rate starts the next step.
//! * [`dense`]: the continuous extension of `dopri5`'s `contd5` (4th order inside the step, equal to
//!   the step's ends at t = 0 and t = 1).
//! * [`illinois`]: the Illinois variant of regula falsi (Dowell & Jarratt 1971) on a sign change.
//!
//! The right-hand side is any closure giving the rates of an N-vector state; it may fail, and it is
//! told the stage's node c (the fraction of the step at which it is evaluated) so that a caller can
//! watch what happens inside a step. The state does not depend on the independent variable
//! explicitly: the contact model's rates are those of the state alone (the pin's travel enters
//! through piecewise constant path pieces, never inside a step).

/// The nodes c_i of the tableau (fractions of the step).
const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
/// The Runge–Kutta matrix; its last row holds the 5th-order weights (first same as last).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Differences of the 5th- and 4th-order weights: the embedded error estimate.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Dormand–Prince continuous extension (Hairer, Nørsett & Wanner, dopri5 `contd5`): 4th order.
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// A step produced a non-finite state or error estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NonFinite;

/// One accepted-or-not Dormand–Prince step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step<const N: usize> {
    /// The 5th-order state at the end of the step.
    pub y1: [f64; N],
    /// The seven stage rates; `k[6]` is the rate at `y1` (first same as last).
    pub k: [[f64; N]; 7],
    /// The embedded error estimate relative to the tolerance: max over components of |ŷ − y1| / tol
    /// (a step passes the error test when it is ≤ 1).
    pub err: f64,
}

impl<const N: usize> Step<N> {
    /// The rate at the end of the step (the next step's first stage).
    pub fn f1(&self) -> [f64; N] {
        self.k[6]
    }

    /// The state at fraction `t` ∈ [0, 1] of this step of size `h` from `y0` (see [`dense`]).
    pub fn dense(&self, y0: [f64; N], h: f64, t: f64) -> [f64; N] {
        dense(y0, self.y1, &self.k, h, t)
    }
}

/// One Dormand–Prince 5(4) step of size `h` from `y0`, whose rate `f0` is known, with absolute
/// tolerance `tol` for the error estimate. `rates(c, y)` gives the rates at a stage state `y`
/// evaluated at fraction `c` of the step (stages 6 and 7 both sit at c = 1; stage 7 is at the new
/// state). A failing right-hand side ends the step with its error; a non-finite result with
/// [`NonFinite`].
pub(crate) fn dp_step<const N: usize, E: From<NonFinite>>(
    mut rates: impl FnMut(f64, [f64; N]) -> Result<[f64; N], E>,
    y0: [f64; N],
    f0: [f64; N],
    h: f64,
    tol: f64,
) -> Result<Step<N>, E> {
    let mut k = [[0.0f64; N]; 7];
    k[0] = f0;
    for i in 1..7 {
        let mut yi = y0;
        for (j, kj) in k.iter().enumerate().take(i) {
            let a = A[i][j];
            if a != 0.0 {
                for c in 0..N {
                    yi[c] += h * a * kj[c];
                }
            }
        }
        k[i] = rates(C[i], yi)?;
    }
    // Stage 7 was evaluated at y1 (FSAL).
    let mut y1 = y0;
    for (j, kj) in k.iter().enumerate().take(6) {
        for c in 0..N {
            y1[c] += h * A[6][j] * kj[c];
        }
    }
    let mut err: f64 = 0.0;
    for c in 0..N {
        let mut e = 0.0;
        for (j, kj) in k.iter().enumerate() {
            e += E[j] * kj[c];
        }
        err = err.max((h * e).abs() / tol);
    }
    if !(y1.iter().all(|v| v.is_finite()) && err.is_finite()) {
        return Err(NonFinite.into());
    }
    Ok(Step { y1, k, err })
}

/// State at fraction `t` ∈ [0, 1] of a step of size `h` from `y0` that ended at `y1` with stages `k`
/// (the continuous extension: 4th order inside the step; `y0` at t = 0 and `y1` at t = 1, to
/// rounding).
pub(crate) fn dense<const N: usize>(
    y0: [f64; N],
    y1: [f64; N],
    k: &[[f64; N]; 7],
    h: f64,
    t: f64,
) -> [f64; N] {
    let mut out = [0.0; N];
    for c in 0..N {
        let ydiff = y1[c] - y0[c];
        let bspl = h * k[0][c] - ydiff;
        let r4 = ydiff - h * k[6][c] - bspl;
        let mut r5 = 0.0;
        for (j, kj) in k.iter().enumerate() {
            r5 += D[j] * kj[c];
        }
        r5 *= h;
        out[c] = y0[c] + t * (ydiff + (1.0 - t) * (bspl + t * (r4 + (1.0 - t) * r5)));
    }
    out
}

/// A bracket [a, b] ⊆ [0, 1] of a sign change of some g, g(a) ≥ 0 > g(b), narrowed by the Illinois
/// rule: regula falsi on the end values, halving the value kept at an end that stays put twice in
/// a row (Dowell & Jarratt 1971).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bracket {
    pub a: f64,
    pub b: f64,
    ga: f64,
    gb: f64,
    /// The end that moved last: −1 the upper, 1 the lower, 0 neither (at the start or after a cut).
    side: i8,
}

impl Bracket {
    /// The bracket [0, 1] with g(0) = `ga`, g(1) = `gb`.
    pub fn new(ga: f64, gb: f64) -> Bracket {
        Bracket {
            a: 0.0,
            b: 1.0,
            ga,
            gb,
            side: 0,
        }
    }

    pub fn width(&self) -> f64 {
        self.b - self.a
    }

    pub fn midpoint(&self) -> f64 {
        0.5 * (self.a + self.b)
    }

    /// The next point to try: the regula falsi point, or the midpoint when that is not strictly
    /// inside the bracket.
    pub fn next(&self) -> f64 {
        let c = (self.a * self.gb - self.b * self.ga) / (self.gb - self.ga);
        if !c.is_finite() || c <= self.a || c >= self.b {
            self.midpoint()
        } else {
            c
        }
    }

    /// Narrow the bracket with the value `gt` = g(t) at a point `t` inside it. Returns whether `t`
    /// became the lower end (g(t) not below zero).
    pub fn narrow(&mut self, t: f64, gt: f64) -> bool {
        if gt < 0.0 {
            self.b = t;
            self.gb = gt;
            if self.side == -1 {
                self.ga *= 0.5;
            }
            self.side = -1;
            false
        } else {
            self.a = t;
            self.ga = gt;
            if self.side == 1 {
                self.gb *= 0.5;
            }
            self.side = 1;
            true
        }
    }

    /// Move the upper end to `t`, where g has no trustworthy value (the end value is kept).
    pub fn cut_above(&mut self, t: f64) {
        self.b = t;
        self.side = 0;
    }
}

/// The Illinois root of `g` on [0, 1] given g(0) = `ga` ≥ 0 ≥ g(1) = `gb`: a t with |g(t)| ≤ `tol`
/// (or a bracket narrower than 1e-12; at most 80 evaluations). A root at an end (`ga` or `gb`
/// zero) is returned without evaluating `g`.
pub(crate) fn illinois(mut g: impl FnMut(f64) -> f64, ga: f64, gb: f64, tol: f64) -> f64 {
    if ga == 0.0 {
        return 0.0;
    }
    if gb == 0.0 {
        return 1.0;
    }
    let mut bracket = Bracket::new(ga, gb);
    let mut c = 1.0;
    for _ in 0..80 {
        c = bracket.next();
        let fc = g(c);
        if fc.abs() <= tol || bracket.width() <= 1e-12 {
            break;
        }
        bracket.narrow(c, fc);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = −diag(1, 2)·y: exponential decay, y(t) = (e^−t, e^−2t) from (1, 1).
    fn decay(_c: f64, y: [f64; 2]) -> Result<[f64; 2], NonFinite> {
        Ok([-y[0], -2.0 * y[1]])
    }
    fn decay_exact(t: f64) -> [f64; 2] {
        [(-t).exp(), (-2.0 * t).exp()]
    }

    /// y' = (−y₁, y₀): a rotation, y(t) = (cos t, sin t) from (1, 0).
    fn rotation(_c: f64, y: [f64; 2]) -> Result<[f64; 2], NonFinite> {
        Ok([-y[1], y[0]])
    }
    fn rotation_exact(t: f64) -> [f64; 2] {
        [t.cos(), t.sin()]
    }

    type Rhs = fn(f64, [f64; 2]) -> Result<[f64; 2], NonFinite>;
    type Exact = fn(f64) -> [f64; 2];

    /// The test problems: (name, right-hand side, exact solution).
    fn problems() -> [(&'static str, Rhs, Exact); 2] {
        [
            ("decay", decay, decay_exact),
            ("rotation", rotation, rotation_exact),
        ]
    }

    fn max_diff(a: [f64; 2], b: [f64; 2]) -> f64 {
        (a[0] - b[0]).abs().max((a[1] - b[1]).abs())
    }

    /// Global error at t = `t_end` after `n` fixed steps from `y0`.
    fn global_error(f: Rhs, exact: Exact, t_end: f64, n: usize) -> f64 {
        let h = t_end / n as f64;
        let mut y = exact(0.0);
        let mut f0 = f(0.0, y).unwrap();
        for _ in 0..n {
            let step = dp_step(f, y, f0, h, 1.0).unwrap();
            y = step.y1;
            f0 = step.f1();
        }
        max_diff(y, exact(t_end))
    }

    /// Every observed order — log2 of successive error ratios as the step halves — lies in `range`.
    fn assert_orders(name: &str, what: &str, errors: &[f64], range: std::ops::Range<f64>) {
        for w in errors.windows(2) {
            let p = (w[0] / w[1]).log2();
            assert!(range.contains(&p), "{name}: {what} {errors:?}, order {p}");
        }
    }

    #[test]
    fn global_error_is_fifth_order() {
        for (name, f, exact) in problems() {
            // Steps of 1/4 down to 1/32 over four time units (hλ within the asymptotic range).
            let errors: Vec<f64> = [16, 32, 64, 128]
                .iter()
                .map(|&n| global_error(f, exact, 4.0, n))
                .collect();
            assert_orders(name, "errors", &errors, 4.6..5.7);
            // And the error is small in absolute terms at the finest step.
            assert!(errors[3] < 1e-10, "{name}: {errors:?}");
        }
    }

    #[test]
    fn local_error_and_its_estimate_scale_as_expected() {
        // One step from t = 0: the true local error is O(h⁶) (a 5th-order method), the embedded
        // estimate (the 4th-order solution's difference) O(h⁵), and it bounds the true error.
        for (name, f, exact) in problems() {
            let y0 = exact(0.0);
            let f0 = f(0.0, y0).unwrap();
            let hs = [0.4, 0.2, 0.1, 0.05];
            let steps: Vec<Step<2>> = hs
                .iter()
                .map(|&h| dp_step(f, y0, f0, h, 1.0).unwrap())
                .collect();
            let estimates: Vec<f64> = steps.iter().map(|s| s.err).collect();
            let true_errors: Vec<f64> = steps
                .iter()
                .zip(hs)
                .map(|(s, h)| max_diff(s.y1, exact(h)))
                .collect();
            assert_orders(name, "estimates", &estimates, 4.6..5.4);
            assert_orders(name, "errors", &true_errors, 5.5..6.6);
            for (e, t) in estimates.iter().zip(&true_errors) {
                assert!(e > t, "{name}: estimate {e} below the true error {t}");
            }
            // The estimate is relative to the tolerance.
            let scaled = dp_step(f, y0, f0, 0.2, 1e-6).unwrap().err;
            assert!((scaled / estimates[1] - 1e6).abs() < 1e-3, "{name}");
        }
    }

    #[test]
    fn stages_are_told_their_nodes_and_the_last_is_at_the_new_state() {
        let mut nodes = Vec::new();
        let mut last = [0.0; 2];
        let step = dp_step(
            |c, y| {
                nodes.push(c);
                last = y;
                rotation(c, y)
            },
            [1.0, 0.0],
            [0.0, 1.0],
            0.3,
            1.0,
        )
        .unwrap();
        assert_eq!(nodes, C[1..].to_vec());
        assert_eq!(last, step.y1);
        assert_eq!(step.f1(), rotation(1.0, step.y1).unwrap());
    }

    #[test]
    fn a_failing_or_non_finite_right_hand_side_ends_the_step() {
        #[derive(Debug, PartialEq)]
        enum Fail {
            Rhs(u32),
            NonFinite,
        }
        impl From<NonFinite> for Fail {
            fn from(_: NonFinite) -> Fail {
                Fail::NonFinite
            }
        }
        let mut calls = 0;
        let r = dp_step(
            |_, y: [f64; 1]| {
                calls += 1;
                if calls == 3 {
                    Err(Fail::Rhs(calls))
                } else {
                    Ok(y)
                }
            },
            [1.0],
            [1.0],
            0.1,
            1.0,
        );
        assert_eq!(r.unwrap_err(), Fail::Rhs(3));
        assert_eq!(calls, 3);
        let r = dp_step(
            |_, _| Ok::<_, Fail>([f64::INFINITY]),
            [1.0],
            [1.0],
            0.1,
            1.0,
        );
        assert_eq!(r.unwrap_err(), Fail::NonFinite);
    }

    #[test]
    fn dense_output_matches_the_ends_and_is_fourth_order_inside() {
        for (name, f, exact) in problems() {
            let y0 = exact(0.0);
            let f0 = f(0.0, y0).unwrap();
            let hs = [0.8, 0.4, 0.2, 0.1];
            let mut errors = Vec::new();
            for h in hs {
                let step = dp_step(f, y0, f0, h, 1.0).unwrap();
                assert_eq!(step.dense(y0, h, 0.0), y0, "{name}");
                assert!(max_diff(step.dense(y0, h, 1.0), step.y1) <= 1e-15, "{name}");
                let worst = [0.1, 0.25, 0.5, 0.75, 0.9]
                    .iter()
                    .map(|&t| max_diff(step.dense(y0, h, t), exact(t * h)))
                    .fold(0.0, f64::max);
                errors.push(worst);
            }
            // Local error of a 4th-order interpolant: O(h⁵).
            assert_orders(name, "errors", &errors, 4.6..6.2);
            assert!(errors[3] < 1e-6, "{name}: {errors:?}");
        }
    }

    #[test]
    fn dense_output_reproduces_a_quartic_exactly() {
        // y' = 4t³ written as an autonomous system (t, y): the 5th-order step and its 4th-order
        // continuous extension are exact for y = t⁴.
        let f = |_: f64, y: [f64; 2]| Ok::<_, NonFinite>([1.0, 4.0 * y[0].powi(3)]);
        let (y0, h) = ([0.5, 0.0625], 0.7);
        let step = dp_step(f, y0, f(0.0, y0).unwrap(), h, 1.0).unwrap();
        for t in [0.0, 0.2, 0.5, 0.8, 1.0] {
            let x = 0.5 + t * h;
            let yt = step.dense(y0, h, t);
            assert!(
                (yt[0] - x).abs() < 1e-14 && (yt[1] - x.powi(4)).abs() < 1e-13,
                "{t}: {yt:?}"
            );
        }
    }

    /// Illinois on g with a counter of evaluations.
    fn solve(g: impl Fn(f64) -> f64, tol: f64) -> (f64, usize) {
        let mut n = 0;
        let t = illinois(
            |t| {
                n += 1;
                g(t)
            },
            g(0.0),
            g(1.0),
            tol,
        );
        (t, n)
    }

    /// A named function with its root on [0, 1].
    type RootCase = (&'static str, fn(f64) -> f64, f64);

    #[test]
    fn illinois_finds_known_roots_in_few_evaluations() {
        let cases: [RootCase; 5] = [
            ("linear", |t| 0.7 - t, 0.7),
            ("cosine", |t| (std::f64::consts::PI * t).cos(), 0.5),
            ("exponential", |t| (-3.0 * t).exp() - 0.2, 5f64.ln() / 3.0),
            ("quintic", |t| 0.3f64.powi(5) - t.powi(5), 0.3),
            ("near the end", |t| 0.999 - t * t, 0.999f64.sqrt()),
        ];
        for (name, g, root) in cases {
            let tol = 1e-12;
            let (t, n) = solve(g, tol);
            assert!(g(t).abs() <= tol, "{name}: g({t}) = {}", g(t));
            assert!((t - root).abs() < 1e-9, "{name}: {t} vs {root}");
            assert!(n <= 16, "{name}: {n} evaluations");
        }
        // A straight line needs one evaluation.
        assert_eq!(solve(|t| 0.7 - t, 1e-12).1, 1);
    }

    #[test]
    fn illinois_returns_a_root_at_an_end_without_evaluating() {
        let (t, n) = solve(|t| -t, 1e-12);
        assert_eq!((t, n), (0.0, 0));
        let (t, n) = solve(|t| 1.0 - t, 1e-12);
        assert_eq!((t, n), (1.0, 0));
    }

    #[test]
    fn illinois_stops_on_a_narrow_bracket_at_a_jump() {
        // No root, a sign change: the bracket closes on the jump.
        let (t, n) = solve(|t| if t < 0.375 { 1.0 } else { -1.0 }, 1e-12);
        assert!((t - 0.375).abs() < 1e-11, "{t}");
        assert!(n <= 80);
    }
}
