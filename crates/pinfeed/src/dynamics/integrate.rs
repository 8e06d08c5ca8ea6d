//! The hybrid integration of a part with inertia meeting a fixed pin (docs/physics.md#dynamic-tier):
//! [`simulate_pin_contact`].
//!
//! The state y = (x, y, θ, ẋ, ẏ, θ̇) (world frame, caller's units) evolves in one of four modes:
//!
//! * **free**: M q̈ = F_s(ξ_rel) + F_g, support friction ([`super::friction`]) and gravity;
//! * **carried**: at rest on the surface (ξ_rel = 0), moving with it, while static friction
//!   holds gravity ([`Surface::holds_against_gravity`]); entered when the relative speed
//!   √(|v − V_s|² + k²ω²) (k the radius of gyration) falls to max(`rest_fraction`, 10·tol)·V_ref
//!   (above the integration's noise in the velocities), where the
//!   relative twist is then set to zero;
//! * **stick** / **slide ±** in contact with the pin: M q̈ = F + J_nᵀ λn + J_tᵀ λt with the
//!   contact's normal acceleration held at zero (and, sticking, its tangential one), λt = ∓μc λn
//!   while sliding. λ comes from the 1- or 2-dimensional linear system with the inverse effective
//!   mass matrix A ([`ContactFrame::delassus`]).
//!
//! Between events the motion is integrated with the Bogacki–Shampine 3(2) pair (Bogacki & Shampine
//! 1989; third-order solution, second-order error estimate, local error O(h⁴)) under an absolute
//! tolerance `tol` on x, y in units of a, θ in radians, and velocities in units of V_ref (and
//! V_ref/a for θ̇). V_ref is the largest of the surface speed and the initial speed relative to it
//! (|v − V_s| + a|ω|), or √(g a) when both are zero. Events are the zero crossings of
//! event functions at a step's end: the gap to the pin (free, carried), the relative speed (free),
//! λn (contact), the slip velocity (slide), μc λn ∓ λt (stick). A crossing is located by the
//! Illinois method on the step length, each trial a full step from the step's start, and the
//! integration lands just before it. At a touch the impact law ([`super::impact`]) acts; a contact
//! that closes slower than `zeno_fraction`·V_ref is taken as plastic (e = 0), which ends a
//! sequence of ever smaller bounces. After every step in contact the state is projected back onto
//! the contact (gap and normal velocity zero, and slip zero when sticking); the largest
//! correction is reported per contact.

use super::body::{Body, MassSpec};
use super::contact::{dot3, ContactFrame, ContactKind, FixedPin};
use super::friction::{support_friction, Surface};
use super::impact::{apply_impact, ImpactResult};
use super::{positive, within, InvalidInput};
use crate::geometry::{first_contact, Polygon, Pose, Vec2};
use crate::mechanics::{PartModel, PartModelError, Support};

/// A part for the dynamic tier: its polygon (caller's units), the compiled support model and its
/// mass properties.
#[derive(Debug, Clone)]
pub struct DynamicPart {
    poly: Polygon,
    model: PartModel,
    body: Body,
}

/// Why a [`DynamicPart`] could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DynamicPartError {
    /// A mass property out of range.
    #[error(transparent)]
    Input(#[from] InvalidInput),
    /// The support model could not be compiled.
    #[error(transparent)]
    Model(#[from] PartModelError),
}

impl DynamicPart {
    /// A uniform lamina of the polygon's shape on `support`, with mass from `mass`.
    pub fn new(
        poly: &Polygon,
        support: &Support,
        mass: MassSpec,
    ) -> Result<DynamicPart, DynamicPartError> {
        let body = Body::from_polygon(poly, mass)?;
        Self::with_body(poly, support, body)
    }

    /// A part with the given body (any mass and inertia).
    pub fn with_body(
        poly: &Polygon,
        support: &Support,
        body: Body,
    ) -> Result<DynamicPart, DynamicPartError> {
        let body = Body::new(body.mass, body.inertia)?;
        Ok(DynamicPart {
            poly: poly.clone(),
            model: PartModel::new(poly, support)?,
            body,
        })
    }

    /// The polygon (caller's units, part frame).
    pub fn polygon(&self) -> &Polygon {
        &self.poly
    }
    /// The mass properties.
    pub fn body(&self) -> &Body {
        &self.body
    }
}

/// Position and velocity of the part (world frame).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct State {
    /// (x, y, θ): centroid and orientation (radians).
    pub q: [f64; 3],
    /// (ẋ, ẏ, θ̇).
    pub qd: [f64; 3],
}

impl State {
    /// The pose (x, y, θ).
    pub fn pose(&self) -> Pose {
        Pose::new(self.q[0], self.q[1], self.q[2])
    }
    fn to_y(self) -> [f64; 6] {
        [
            self.q[0], self.q[1], self.q[2], self.qd[0], self.qd[1], self.qd[2],
        ]
    }
    fn from_y(y: [f64; 6]) -> State {
        State {
            q: [y[0], y[1], y[2]],
            qd: [y[3], y[4], y[5]],
        }
    }
}

/// The settings of a dynamic simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicParams {
    /// Pin–part friction μc ≥ 0.
    pub mu_c: f64,
    /// Stronge's energetic coefficient of restitution e ∈ [0, 1].
    pub restitution: f64,
    /// Absolute error tolerance per step (see the module docs), in (0, 0.01].
    pub tol: f64,
    /// The largest simulated time (T), > 0.
    pub max_time: f64,
    /// The largest number of step attempts (accepted, rejected and event trials), ≥ 1.
    pub max_steps: u64,
    /// Mode switches allowed per contact before [`DynamicStatus::ModeChatter`], ≥ 1.
    pub max_switches: u32,
    /// Relative speed, in units of V_ref, below which a part that friction can hold is carried
    /// by the surface (at least 10·tol is used); in (0, 0.1].
    pub rest_fraction: f64,
    /// Closing speed, in units of V_ref, below which an impact is plastic; in [0, 0.1].
    pub zeno_fraction: f64,
}

impl Default for DynamicParams {
    fn default() -> Self {
        DynamicParams {
            mu_c: 0.5,
            restitution: 0.0,
            tol: 1e-6,
            max_time: 1e3,
            max_steps: 2_000_000,
            max_switches: 200,
            rest_fraction: 1e-5,
            zeno_fraction: 1e-4,
        }
    }
}

impl DynamicParams {
    /// Check every field (the error names it and its range).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        within("mu_c", self.mu_c, 0.0, f64::MAX, "[0, ∞), finite")?;
        within("restitution", self.restitution, 0.0, 1.0, "[0, 1]")?;
        within("tol", self.tol, f64::MIN_POSITIVE, 0.01, "(0, 0.01]")?;
        positive("max_time", self.max_time)?;
        within("max_steps", self.max_steps as f64, 1.0, f64::MAX, "≥ 1")?;
        within(
            "max_switches",
            self.max_switches as f64,
            1.0,
            f64::MAX,
            "≥ 1",
        )?;
        within(
            "rest_fraction",
            self.rest_fraction,
            f64::MIN_POSITIVE,
            0.1,
            "(0, 0.1]",
        )?;
        within("zeno_fraction", self.zeno_fraction, 0.0, 0.1, "[0, 0.1]")?;
        Ok(())
    }
}

/// How a simulation ended.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum DynamicStatus {
    /// Carried by the moving surface with no further touch of the pin ahead: the final pose and
    /// orientation are the part's from then on (it moves with the surface).
    Settled,
    /// At rest on a still surface.
    Rest,
    /// The pin's disc overlaps the part at the start.
    PinInsidePart,
    /// `max_time` reached.
    TimeLimit,
    /// `max_steps` step attempts used.
    StepLimit,
    /// The step fell below 10⁻¹² of a/V_ref at time `t`.
    StepTooSmall {
        /// Time.
        t: f64,
    },
    /// More than `max_switches` mode switches in one contact, at time `t`.
    ModeChatter {
        /// Time.
        t: f64,
    },
    /// A sliding contact whose normal force has no consistent value (A_nn ∓ μ A_nt ≤ 0:
    /// Painlevé's paradox) at time `t`.
    Painleve {
        /// Time.
        t: f64,
    },
    /// A second feature of the part touched the pin during a contact, at time `t` (two contacts
    /// are not simulated).
    MultiContact {
        /// Time.
        t: f64,
    },
    /// An impact could not be resolved at time `t`.
    Impact {
        /// Time.
        t: f64,
        /// The impact law's message.
        message: String,
    },
    /// The state became non-finite at time `t`.
    NonFinite {
        /// Time.
        t: f64,
    },
}

/// One impact.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ImpactRecord {
    /// Time of the impact.
    pub t: f64,
    /// The feature struck.
    pub kind: ContactKind,
    /// Contact velocity before (u_n, u_t).
    pub u_before: (f64, f64),
    /// The coefficient used (e, or 0 below the Zeno speed).
    pub restitution: f64,
    /// Kinetic energy before and after (world frame).
    pub energy: (f64, f64),
    /// The resolved impact.
    pub result: ImpactResult,
}

/// How a contact ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ContactEnd {
    /// The impact left the part moving away.
    Bounced,
    /// The normal force fell to zero and the part left the pin.
    Separated,
    /// The simulation stopped during the contact (see the status).
    Stopped,
}

/// The record of one contact with the pin, from its first touch to its end.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ContactLog {
    /// Time of the touch.
    pub t_start: f64,
    /// Time the contact ended.
    pub t_end: f64,
    /// The feature first touched.
    pub kind: ContactKind,
    /// The impact at the touch, if the part arrived closing.
    pub impact: Option<ImpactRecord>,
    /// Tangential impacts (impacts without collision) where a slide reached Painlevé's point.
    pub tangential_impacts: Vec<ImpactRecord>,
    /// Accepted steps in contact.
    pub steps: u64,
    /// Rejected steps in contact.
    pub rejected: u64,
    /// Event-location iterations in contact.
    pub event_iterations: u64,
    /// Mode switches (stick ↔ slide, slip reversals) in contact.
    pub switches: u32,
    /// Accepted steps spent sliding and sticking.
    pub slide_steps: u64,
    /// Accepted steps spent sticking.
    pub stick_steps: u64,
    /// Largest projection back onto the contact: gap in units of a.
    pub max_gap_correction: f64,
    /// Largest projection back onto the contact: normal velocity in units of V_ref.
    pub max_velocity_correction: f64,
    /// How it ended.
    pub end: ContactEnd,
}

/// The result of [`simulate_pin_contact`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DynamicOutcome {
    /// How the simulation ended.
    pub status: DynamicStatus,
    /// Time at the end.
    pub time: f64,
    /// State at the end.
    pub state: State,
    /// The contacts with the pin, in order.
    pub contacts: Vec<ContactLog>,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (error or motion guard).
    pub rejected: u64,
    /// Event-location iterations.
    pub event_iterations: u64,
    /// Limit-surface evaluations.
    pub evaluations: u64,
    /// The reference speed V_ref the tolerances are scaled by.
    pub v_ref: f64,
}

/// A slide whose A_nn ∓ μc A_nt falls to this fraction of A_nn is near Painlevé's point, where the
/// normal force grows without bound: the contact takes a tangential impact there.
const PAINLEVE_MARGIN: f64 = 1e-3;

/// The smallest pin radius the dynamic tier simulates, in units of a: a point pin (and any
/// thinner one) is a disc of this radius, whose normal at a vertex of the part is defined (the
/// direction from its centre to the vertex) and turns as the disc rides round the vertex.
pub const MIN_PIN_RADIUS: f64 = 1e-4;

/// The motion modes (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Free,
    Carried,
    Stick,
    Slide(f64),
}

/// Rates of the state and the contact quantities at one state.
#[derive(Debug, Clone, Copy)]
struct Rates {
    yd: [f64; 6],
    lam_n: f64,
    lam_t: f64,
    u_t: f64,
    /// A_nn ∓ μc A_nt over A_nn while sliding (its zero is Painlevé's point); 1 otherwise.
    den: f64,
}

/// A right-hand side that cannot be evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Trouble {
    Painleve,
    NonFinite,
}

/// The contact's unconstrained accelerations and matrices at a state.
struct Pieces {
    frame: ContactFrame,
    qdd0: [f64; 3],
    a0: (f64, f64),
    a: [f64; 3],
    u: (f64, f64),
}

struct Sim<'a> {
    part: &'a DynamicPart,
    surface: &'a Surface,
    pin: &'a FixedPin,
    params: &'a DynamicParams,
    v_ref: f64,
    a: f64,
    evals: u64,
    /// The feature in contact (while a contact lasts).
    feature: ContactKind,
}

impl Sim<'_> {
    /// Accelerations without contact: friction and gravity over M.
    fn free_accel(&mut self, y: &[f64; 6]) -> [f64; 3] {
        let m = self.part.body.mass;
        let (f, mo) = support_friction(
            &self.part.model,
            self.surface,
            m,
            y[2],
            Vec2::new(y[3], y[4]),
            y[5],
            &mut self.evals,
        );
        let f = f + self.surface.gravity_force(m);
        self.part.body.inverse_mass_times([f.x, f.y, mo])
    }

    /// The frame of the feature in contact at `y`.
    fn frame(&self, y: &[f64; 6]) -> ContactFrame {
        ContactFrame::pin_feature(&self.part.poly, [y[0], y[1], y[2]], self.pin, self.feature)
    }

    fn pieces(&mut self, y: &[f64; 6]) -> Pieces {
        let qd = [y[3], y[4], y[5]];
        let frame = self.frame(y);
        let qdd0 = self.free_accel(y);
        let (jn, jt) = frame.jacobian();
        let (bn, bt) = frame.bias(qd);
        Pieces {
            a0: (dot3(jn, qdd0) + bn, dot3(jt, qdd0) + bt),
            a: frame.delassus(&self.part.body),
            u: frame.velocity(qd),
            frame,
            qdd0,
        }
    }

    /// The contact forces of `mode` at `p`.
    fn forces(&self, p: &Pieces, mode: Mode) -> Result<(f64, f64), Trouble> {
        let [ann, ant, att] = p.a;
        let (a0n, a0t) = p.a0;
        let mu = self.params.mu_c;
        match mode {
            Mode::Free | Mode::Carried => Ok((0.0, 0.0)),
            Mode::Slide(s) => {
                let den = ann - s * mu * ant;
                if den <= 1e-12 * ann {
                    return Err(Trouble::Painleve);
                }
                let ln = -a0n / den;
                Ok((ln, -s * mu * ln))
            }
            Mode::Stick => {
                let det = ann * att - ant * ant;
                Ok((
                    (-att * a0n + ant * a0t) / det,
                    (-ann * a0t + ant * a0n) / det,
                ))
            }
        }
    }

    fn rates(&mut self, y: &[f64; 6], mode: Mode) -> Result<Rates, Trouble> {
        let out = match mode {
            Mode::Carried => Rates {
                yd: [
                    self.surface.velocity.x,
                    self.surface.velocity.y,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                ],
                lam_n: 0.0,
                lam_t: 0.0,
                u_t: 0.0,
                den: 1.0,
            },
            Mode::Free => {
                let acc = self.free_accel(y);
                Rates {
                    yd: [y[3], y[4], y[5], acc[0], acc[1], acc[2]],
                    lam_n: 0.0,
                    lam_t: 0.0,
                    u_t: 0.0,
                    den: 1.0,
                }
            }
            Mode::Stick | Mode::Slide(_) => {
                let p = self.pieces(y);
                let (ln, lt) = self.forces(&p, mode)?;
                let dq = self
                    .part
                    .body
                    .inverse_mass_times(p.frame.generalised(ln, lt));
                Rates {
                    yd: [
                        y[3],
                        y[4],
                        y[5],
                        p.qdd0[0] + dq[0],
                        p.qdd0[1] + dq[1],
                        p.qdd0[2] + dq[2],
                    ],
                    lam_n: ln,
                    lam_t: lt,
                    u_t: p.u.1,
                    den: match mode {
                        Mode::Slide(s) => (p.a[0] - s * self.params.mu_c * p.a[1]) / p.a[0],
                        _ => 1.0,
                    },
                }
            }
        };
        if out.yd.iter().all(|v| v.is_finite()) && out.lam_n.is_finite() {
            Ok(out)
        } else {
            Err(Trouble::NonFinite)
        }
    }

    /// One Bogacki–Shampine step: the new state, the error estimate and the rates there.
    fn step(
        &mut self,
        y: &[f64; 6],
        h: f64,
        mode: Mode,
    ) -> Result<([f64; 6], [f64; 6], Rates), Trouble> {
        let add = |y: &[f64; 6], k: &[(f64, &[f64; 6])]| -> [f64; 6] {
            let mut o = *y;
            for (c, kk) in k {
                for i in 0..6 {
                    o[i] += h * c * kk[i];
                }
            }
            o
        };
        let k1 = self.rates(y, mode)?.yd;
        let k2 = self.rates(&add(y, &[(0.5, &k1)]), mode)?.yd;
        let k3 = self.rates(&add(y, &[(0.75, &k2)]), mode)?.yd;
        let y1 = add(y, &[(2.0 / 9.0, &k1), (1.0 / 3.0, &k2), (4.0 / 9.0, &k3)]);
        let r4 = self.rates(&y1, mode)?;
        let k4 = r4.yd;
        let mut err = [0.0; 6];
        for i in 0..6 {
            err[i] = h
                * (-5.0 / 72.0 * k1[i] + 1.0 / 12.0 * k2[i] + 1.0 / 9.0 * k3[i]
                    - 1.0 / 8.0 * k4[i]);
        }
        Ok((y1, err, r4))
    }

    /// The error of a step relative to the tolerance (≤ 1 accepts).
    fn error_norm(&self, err: &[f64; 6]) -> f64 {
        let sc = [
            self.a,
            self.a,
            1.0,
            self.v_ref,
            self.v_ref,
            self.v_ref / self.a,
        ];
        (0..6)
            .map(|i| err[i].abs() / (self.params.tol * sc[i]))
            .fold(0.0, f64::max)
    }

    fn gap(&self, y: &[f64; 6]) -> f64 {
        ContactFrame::pin(&self.part.poly, [y[0], y[1], y[2]], self.pin).gap
    }

    /// The relative speed below which a part friction can hold is carried: `rest_fraction`·V_ref,
    /// and at least 10·tol·V_ref, above the integration's own noise in the velocities.
    fn rest_speed(&self) -> f64 {
        self.params.rest_fraction.max(10.0 * self.params.tol) * self.v_ref
    }

    fn rel_speed(&self, y: &[f64; 6]) -> f64 {
        let k = self.part.body.radius_of_gyration();
        let dv = Vec2::new(y[3], y[4]) - self.surface.velocity;
        (dv.norm2() + k * k * y[5] * y[5]).sqrt()
    }

    /// The event functions of `mode` at state `y` with rates `r` (+∞: unused). A crossing from
    /// ≥ 0 to < 0 is an event.
    fn events(&self, y: &[f64; 6], r: &Rates, mode: Mode) -> [f64; 4] {
        let inf = f64::INFINITY;
        let mu = self.params.mu_c;
        // The gap fires a hair inside contact, so that a part leaving the pin with zero gap
        // rate is not caught again by rounding.
        let gap = || self.gap(y) + 1e-10 * self.a;
        match mode {
            Mode::Free => {
                let rest = if self.surface.holds_against_gravity() {
                    self.rel_speed(y) - self.rest_speed()
                } else {
                    inf
                };
                [gap(), rest, inf, inf]
            }
            Mode::Carried => [gap(), inf, inf, inf],
            Mode::Slide(s) => [r.lam_n, s * r.u_t, r.den - PAINLEVE_MARGIN, self.region(y)],
            Mode::Stick => [
                r.lam_n,
                mu * r.lam_n - r.lam_t,
                mu * r.lam_n + r.lam_t,
                self.region(y),
            ],
        }
    }

    /// The contact feature's region function (≥ 0 while it is the feature touching).
    fn region(&self, y: &[f64; 6]) -> f64 {
        let q = [y[0], y[1], y[2]];
        self.frame(y).region(&self.part.poly, q, self.pin).0
    }

    /// The largest distance any point of the part moves from `y0` to `y1`, bounded above.
    fn motion(&self, y0: &[f64; 6], y1: &[f64; 6]) -> f64 {
        let d = Vec2::new(y1[0] - y0[0], y1[1] - y0[1]).norm();
        d + self.part.poly.radius() * (y1[2] - y0[2]).abs()
    }

    /// Choose the contact mode at a state touching the pin with u_n ≈ 0 (the contact LCP):
    /// free if the unconstrained normal acceleration is ≥ 0, else stick if its forces lie in
    /// the friction cone, else the slide whose slip grows in its own direction.
    fn choose_mode(&mut self, y: &[f64; 6]) -> Result<Mode, Trouble> {
        let p = self.pieces(y);
        let tiny = 1e-9 * self.v_ref;
        if p.u.1.abs() > tiny {
            let s = p.u.1.signum();
            if p.a0.0 >= 0.0 {
                return Ok(Mode::Free);
            }
            let den = (p.a[0] - s * self.params.mu_c * p.a[1]) / p.a[0];
            if den <= PAINLEVE_MARGIN {
                return Err(Trouble::Painleve);
            }
            let (ln, _) = self.forces(&p, Mode::Slide(s))?;
            return Ok(if ln > 0.0 { Mode::Slide(s) } else { Mode::Free });
        }
        if p.a0.0 >= 0.0 {
            return Ok(Mode::Free);
        }
        let (ln, lt) = self.forces(&p, Mode::Stick)?;
        if ln >= 0.0 && lt.abs() <= self.params.mu_c * ln {
            return Ok(Mode::Stick);
        }
        let mut trouble = None;
        for s in [-lt.signum(), lt.signum()] {
            match self.forces(&p, Mode::Slide(s)) {
                Ok((ln, lt)) => {
                    let slip_acc = p.a0.1 + p.a[1] * ln + p.a[2] * lt;
                    if ln >= 0.0 && s * slip_acc >= 0.0 {
                        return Ok(Mode::Slide(s));
                    }
                }
                Err(t) => trouble = Some(t),
            }
        }
        Err(trouble.unwrap_or(Trouble::Painleve))
    }

    /// [`Sim::choose_mode`], resolving a slide at Painlevé's point by a tangential impact (the
    /// energetic law from u_n = 0), recorded in `log`.
    fn settle(
        &mut self,
        y: &mut [f64; 6],
        t: f64,
        log: &mut ContactLog,
    ) -> Result<Mode, DynamicStatus> {
        for _ in 0..4 {
            match self.choose_mode(y) {
                Ok(m) => return Ok(m),
                Err(Trouble::NonFinite) => return Err(DynamicStatus::NonFinite { t }),
                Err(Trouble::Painleve) => {
                    self.project(y, false);
                    let frame = self.frame(y);
                    let qd = [y[3], y[4], y[5]];
                    let u = frame.velocity(qd);
                    let body = self.part.body;
                    let e = self.params.restitution;
                    let Ok((qd1, result)) = apply_impact(&body, &frame, qd, self.params.mu_c, e)
                    else {
                        return Err(DynamicStatus::Painleve { t });
                    };
                    if result.p_n == 0.0 {
                        return Err(DynamicStatus::Painleve { t });
                    }
                    y[3..6].copy_from_slice(&qd1);
                    log.tangential_impacts.push(ImpactRecord {
                        t,
                        kind: frame.kind,
                        u_before: u,
                        restitution: e,
                        energy: (body.kinetic_energy(qd), body.kinetic_energy(qd1)),
                        result,
                    });
                    if frame.velocity(qd1).0 > 1e-9 * self.v_ref {
                        return Ok(Mode::Free);
                    }
                }
            }
        }
        Err(DynamicStatus::Painleve { t })
    }

    /// Project `y` onto the contact: gap 0, u_n = 0 (and u_t = 0 when sticking). Returns the
    /// corrections (|gap|/a, |u|/V_ref).
    fn project(&self, y: &mut [f64; 6], stick: bool) -> (f64, f64) {
        let f = self.frame(y);
        y[0] -= f.gap * f.normal.x;
        y[1] -= f.gap * f.normal.y;
        let f2 = self.frame(y);
        let qd = [y[3], y[4], y[5]];
        let (un, ut) = f2.velocity(qd);
        let [ann, ant, att] = f2.delassus(&self.part.body);
        let (ln, lt) = if stick {
            let det = ann * att - ant * ant;
            ((-att * un + ant * ut) / det, (-ann * ut + ant * un) / det)
        } else {
            (-un / ann, 0.0)
        };
        let dq = self.part.body.inverse_mass_times(f2.generalised(ln, lt));
        for i in 0..3 {
            y[3 + i] += dq[i];
        }
        let du = if stick { un.hypot(ut) } else { un.abs() };
        (f.gap.abs() / self.a, du / self.v_ref)
    }
}

/// Simulate a part (`part`, starting at `start`) on `surface` meeting the fixed pin `pin`, until it
/// is carried by the surface with no touch of the pin ahead ([`DynamicStatus::Settled`]), rests on
/// a still surface, or a limit or a numerical trouble stops it (reported in the status, never a
/// panic). Errors: an input out of range (the field named).
pub fn simulate_pin_contact(
    part: &DynamicPart,
    surface: &Surface,
    start: State,
    pin: &FixedPin,
    params: &DynamicParams,
) -> Result<DynamicOutcome, InvalidInput> {
    surface.validate()?;
    params.validate()?;
    for (field, v) in [
        ("start.x", start.q[0]),
        ("start.y", start.q[1]),
        ("start.theta", start.q[2]),
        ("start.vx", start.qd[0]),
        ("start.vy", start.qd[1]),
        ("start.omega", start.qd[2]),
        ("pin.x", pin.centre.x),
        ("pin.y", pin.centre.y),
    ] {
        within(field, v, f64::MIN, f64::MAX, "finite")?;
    }
    within("pin.radius", pin.radius, 0.0, f64::MAX, "[0, ∞), finite")?;
    let a = part.poly.radius();
    // A point pin has no normal at a vertex: it is a disc of radius MIN_PIN_RADIUS·a.
    let pin = &FixedPin {
        centre: pin.centre,
        radius: pin.radius.max(MIN_PIN_RADIUS * a),
    };
    let rel = Vec2::new(start.qd[0], start.qd[1]) - surface.velocity;
    let mut v_ref = surface
        .velocity
        .norm()
        .max(rel.norm() + a * start.qd[2].abs());
    if v_ref == 0.0 {
        v_ref = (surface.gravity * a).sqrt();
    }
    let mut sim = Sim {
        part,
        surface,
        pin,
        params,
        v_ref,
        a,
        evals: 0,
        feature: ContactKind::VertexOnPin(0),
    };
    let mut out = DynamicOutcome {
        status: DynamicStatus::TimeLimit,
        time: 0.0,
        state: start,
        contacts: Vec::new(),
        steps: 0,
        rejected: 0,
        event_iterations: 0,
        evaluations: 0,
        v_ref,
    };
    let mut y = start.to_y();
    if sim.gap(&y) < 0.0 {
        out.status = DynamicStatus::PinInsidePart;
        return Ok(out);
    }
    let t_ref = a / v_ref;
    let h_min = 1e-12 * t_ref;
    let mut h = 1e-3 * t_ref;
    let mut t = 0.0;
    let mut mode = if rel == Vec2::ZERO && start.qd[2] == 0.0 && surface.holds_against_gravity() {
        Mode::Carried
    } else {
        Mode::Free
    };
    let mut attempts: u64 = 0;
    let mut open: Option<ContactLog> = None;
    let mut check_carried = mode == Mode::Carried;
    let status =
        'run: loop {
            if check_carried {
                check_carried = false;
                if let Some(st) = carried_end(&sim, &y) {
                    break 'run st;
                }
            }
            if t >= params.max_time {
                break 'run DynamicStatus::TimeLimit;
            }
            if attempts >= params.max_steps {
                break 'run DynamicStatus::StepLimit;
            }
            if h < h_min {
                break 'run DynamicStatus::StepTooSmall { t };
            }
            if mode == Mode::Free
                && surface.holds_against_gravity()
                && sim.rel_speed(&y) < sim.rest_speed()
            {
                // Slow enough to be held (entered so, e.g. leaving the pin while moving with the
                // surface): carried from here.
                mode = Mode::Carried;
                y[3] = surface.velocity.x;
                y[4] = surface.velocity.y;
                y[5] = 0.0;
                check_carried = true;
                continue;
            }
            let h_try = h.min(params.max_time - t);
            attempts += 1;
            let r0 = match sim.rates(&y, mode) {
                Ok(r) => r,
                Err(Trouble::Painleve) => break 'run DynamicStatus::Painleve { t },
                Err(Trouble::NonFinite) => break 'run DynamicStatus::NonFinite { t },
            };
            let e0 = sim.events(&y, &r0, mode);
            let (y1, err, r1) = match sim.step(&y, h_try, mode) {
                Ok(s) => s,
                Err(_) => {
                    reject(&mut out, &mut open);
                    h = h_try * 0.25;
                    continue;
                }
            };
            let norm = sim.error_norm(&err);

            let guard = match mode {
                Mode::Free | Mode::Carried => 0.05 * a + 0.5 * sim.gap(&y).max(0.0),
                _ => 0.05 * a,
            };
            let moved = sim.motion(&y, &y1);
            if norm.is_nan() || norm > 1.0 || moved > guard {
                reject(&mut out, &mut open);
                let shrink = if norm.is_finite() && norm > 0.0 {
                    (0.9 * norm.powf(-1.0 / 3.0)).clamp(0.2, 0.9)
                } else {
                    0.25
                };
                h = h_try
                    * shrink.min(if moved > guard {
                        0.5 * guard / moved
                    } else {
                        1.0
                    });
                continue;
            }
            let e1 = sim.events(&y1, &r1, mode);
            let crossed: Vec<usize> = (0..4).filter(|&i| e0[i] >= 0.0 && e1[i] < 0.0).collect();
            let grow = if norm > 0.0 {
                (0.9 * norm.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
            } else {
                5.0
            };
            if crossed.is_empty() {
                y = y1;
                t += h_try;
                accept(&mut out, &mut open, mode);
                // Carried: is a touch still ahead? (one ray cast)
                check_carried = mode == Mode::Carried;
                if matches!(mode, Mode::Stick | Mode::Slide(_)) {
                    let (dg, dv) = sim.project(&mut y, mode == Mode::Stick);
                    if let Some(log) = open.as_mut() {
                        log.max_gap_correction = log.max_gap_correction.max(dg);
                        log.max_velocity_correction = log.max_velocity_correction.max(dv);
                    }
                    if let Some(st) = second_touch(&sim, &y, t) {
                        break 'run st;
                    }
                }
                h = h_try * grow;
                continue;
            }
            // Locate the earliest crossing among those that crossed: Illinois on the step length.
            let phi =
                |sim: &mut Sim, hh: f64| -> Option<([f64; 6], f64, usize)> {
                    let (yy, _, rr) = sim.step(&y, hh, mode).ok()?;
                    let e = sim.events(&yy, &rr, mode);
                    let (i, v) = crossed.iter().map(|&i| (i, e[i])).fold(
                        (crossed[0], f64::INFINITY),
                        |b, c| if c.1 < b.1 { c } else { b },
                    );
                    Some((yy, v, i))
                };
            let (mut lo, mut hi) = (0.0, h_try);
            let mut f_lo = crossed.iter().map(|&i| e0[i]).fold(f64::INFINITY, f64::min);
            let mut f_hi = crossed.iter().map(|&i| e1[i]).fold(f64::INFINITY, f64::min);
            let mut y_lo = y;
            let mut which = crossed[0];
            let mut side = 0i8;
            let mut iterations = 0;
            while hi - lo > 1e-13 * t_ref.max(t) && iterations < 100 {
                iterations += 1;
                let mid = {
                    let m = lo + f_lo * (hi - lo) / (f_lo - f_hi);
                    if m > lo && m < hi {
                        m
                    } else {
                        0.5 * (lo + hi)
                    }
                };
                let Some((ym, fm, i)) = phi(&mut sim, mid) else {
                    hi = mid;
                    continue;
                };
                if fm >= 0.0 {
                    lo = mid;
                    f_lo = fm;
                    y_lo = ym;
                    if side == 1 {
                        f_hi *= 0.5;
                    }
                    side = 1;
                } else {
                    hi = mid;
                    f_hi = fm;
                    which = i;
                    if side == -1 {
                        f_lo *= 0.5;
                    }
                    side = -1;
                }
            }
            out.event_iterations += iterations;
            attempts += iterations;
            if let Some(log) = open.as_mut() {
                log.event_iterations += iterations;
            }
            y = y_lo;
            t += lo;
            accept(&mut out, &mut open, mode);
            // Handle the event.
            let next: Result<Mode, DynamicStatus> = match (mode, which) {
                (Mode::Free | Mode::Carried, 0) => touch(&mut sim, &mut y, t, &mut open, &mut out),
                (Mode::Free, 1) => {
                    y[3] = surface.velocity.x;
                    y[4] = surface.velocity.y;
                    y[5] = 0.0;
                    Ok(Mode::Carried)
                }
                (Mode::Stick | Mode::Slide(_), 0) => {
                    close(&mut open, &mut out, t, ContactEnd::Separated);
                    Ok(Mode::Free)
                }
                (Mode::Stick | Mode::Slide(_), 3) => {
                    // The contact passes to the neighbouring feature (continuous in the pose).
                    let q = [y[0], y[1], y[2]];
                    let (_, next) = sim.frame(&y).region(&sim.part.poly, q, pin);
                    match next {
                        ContactKind::VertexOnPin(i) if !sim.part.poly.vertex_is_convex(i) => {
                            Err(DynamicStatus::MultiContact { t })
                        }
                        _ => {
                            sim.feature = next;
                            match open.as_mut() {
                                Some(log) => sim.settle(&mut y, t, log),
                                None => sim.choose_mode(&y).map_err(|e| trouble(e, t)),
                            }
                        }
                    }
                }
                (Mode::Slide(_), _) => match open.as_mut() {
                    Some(log) => sim.settle(&mut y, t, log),
                    None => sim.choose_mode(&y).map_err(|e| trouble(e, t)),
                },
                (Mode::Stick, i) => {
                    // |λt| reached μc λn: slip starts against the friction force.
                    let s = if i == 1 { -1.0 } else { 1.0 };
                    let p = sim.pieces(&y);
                    match sim.forces(&p, Mode::Slide(s)) {
                        Ok((ln, _)) if ln > 0.0 => Ok(Mode::Slide(s)),
                        Ok(_) => Ok(Mode::Free),
                        Err(e) => Err(trouble(e, t)),
                    }
                }
                _ => Ok(mode),
            };
            let new_mode = match next {
                Ok(m) => m,
                Err(st) => break 'run st,
            };
            if let Some(log) = open.as_mut() {
                if new_mode != mode {
                    log.switches += 1;
                    if log.switches > params.max_switches {
                        break 'run DynamicStatus::ModeChatter { t };
                    }
                }
            }
            if new_mode == Mode::Free && matches!(mode, Mode::Stick | Mode::Slide(_)) {
                close(&mut open, &mut out, t, ContactEnd::Separated);
            }
            if matches!(new_mode, Mode::Stick | Mode::Slide(_)) {
                sim.project(&mut y, new_mode == Mode::Stick);
            }
            check_carried = new_mode == Mode::Carried;
            mode = new_mode;
            h = h_try.max(1e3 * h_min);
        };
    close(&mut open, &mut out, t, ContactEnd::Stopped);
    out.status = status;
    out.time = t;
    out.state = State::from_y(y);
    out.evaluations = sim.evals;
    Ok(out)
}

/// The status of a right-hand side's trouble at time `t`.
fn trouble(e: Trouble, t: f64) -> DynamicStatus {
    match e {
        Trouble::Painleve => DynamicStatus::Painleve { t },
        Trouble::NonFinite => DynamicStatus::NonFinite { t },
    }
}

/// Count an accepted step (in the open contact too).
fn accept(out: &mut DynamicOutcome, open: &mut Option<ContactLog>, mode: Mode) {
    out.steps += 1;
    if let Some(log) = open.as_mut() {
        log.steps += 1;
        match mode {
            Mode::Stick => log.stick_steps += 1,
            Mode::Slide(_) => log.slide_steps += 1,
            _ => {}
        }
    }
}

/// Count a rejected step (in the open contact too).
fn reject(out: &mut DynamicOutcome, open: &mut Option<ContactLog>) {
    out.rejected += 1;
    if let Some(log) = open.as_mut() {
        log.rejected += 1;
    }
}

/// Close the open contact, if any, at time `t`.
fn close(open: &mut Option<ContactLog>, out: &mut DynamicOutcome, t: f64, end: ContactEnd) {
    if let Some(mut log) = open.take() {
        log.t_end = t;
        log.end = end;
        out.contacts.push(log);
    }
}

/// A part carried by the surface: at rest for good on a still surface, settled if the surface
/// carries it past the pin without a touch, or `None` (a touch ahead).
fn carried_end(sim: &Sim, y: &[f64; 6]) -> Option<DynamicStatus> {
    let v = sim.surface.velocity;
    if v == Vec2::ZERO {
        return Some(DynamicStatus::Rest);
    }
    let pose = Pose::new(y[0], y[1], y[2]);
    // Touching the pin now (just left it): a touch ahead if the surface drives the part into
    // it, else look past this touch.
    let mut min_travel = 0.0;
    let frame = ContactFrame::pin(&sim.part.poly, [y[0], y[1], y[2]], sim.pin);
    if frame.gap <= 1e-9 * sim.a {
        if frame.velocity([v.x, v.y, 0.0]).0 < -1e-9 * sim.v_ref {
            return None;
        }
        min_travel = 1e-9 * sim.a;
    }
    // The pin travels along −V relative to the part; grazing touches push nothing.
    let dir = -v.normalized();
    for _ in 0..8 {
        match first_contact(
            &sim.part.poly,
            &pose,
            sim.pin.centre,
            dir,
            sim.pin.radius,
            min_travel,
        ) {
            None => return Some(DynamicStatus::Settled),
            Some(hit) if hit.grazing => {
                min_travel = hit.travel + 1e-9 * (1.0 + hit.travel.abs());
            }
            Some(_) => return None,
        }
    }
    Some(DynamicStatus::Settled)
}

/// During a contact, does another part of the boundary overlap the pin (a second contact)?
fn second_touch(sim: &Sim, y: &[f64; 6], t: f64) -> Option<DynamicStatus> {
    let poly = &sim.part.poly;
    let local = (sim.pin.centre - Vec2::new(y[0], y[1])).rotate(-y[2]);
    let f = sim.frame(y);
    let c = (f.point - Vec2::new(y[0], y[1])).rotate(-y[2]);
    for j in 0..poly.len() {
        let (p0, p1) = poly.edge(j);
        let e = p1 - p0;
        let s = ((local - p0).dot(e) / e.norm2()).clamp(0.0, 1.0);
        let foot = p0 + e * s;
        if (foot - c).norm() > 1e-6 * sim.a && (foot - local).norm() < sim.pin.radius - 1e-6 * sim.a
        {
            return Some(DynamicStatus::MultiContact { t });
        }
    }
    None
}

/// The part touches the pin at `y` (gap ≈ 0): the impact if it arrives closing, then the mode the
/// contact goes on in (or free if it bounces or leaves at once).
fn touch(
    sim: &mut Sim,
    y: &mut [f64; 6],
    t: f64,
    open: &mut Option<ContactLog>,
    out: &mut DynamicOutcome,
) -> Result<Mode, DynamicStatus> {
    let frame = ContactFrame::pin(&sim.part.poly, [y[0], y[1], y[2]], sim.pin);
    sim.feature = frame.kind;
    y[0] -= frame.gap * frame.normal.x;
    y[1] -= frame.gap * frame.normal.y;
    let frame = sim.frame(y);
    let qd = [y[3], y[4], y[5]];
    let u = frame.velocity(qd);
    let tiny = 1e-9 * sim.v_ref;
    let mut log = ContactLog {
        t_start: t,
        t_end: t,
        kind: frame.kind,
        impact: None,
        tangential_impacts: Vec::new(),
        steps: 0,
        rejected: 0,
        event_iterations: 0,
        switches: 0,
        slide_steps: 0,
        stick_steps: 0,
        max_gap_correction: 0.0,
        max_velocity_correction: 0.0,
        end: ContactEnd::Stopped,
    };
    if u.0 < -tiny {
        let e = if -u.0 < sim.params.zeno_fraction * sim.v_ref {
            0.0
        } else {
            sim.params.restitution
        };
        let body = sim.part.body;
        let (qd1, result) = apply_impact(&body, &frame, qd, sim.params.mu_c, e).map_err(|err| {
            DynamicStatus::Impact {
                t,
                message: err.to_string(),
            }
        })?;
        y[3..6].copy_from_slice(&qd1);
        let bounce = result.u_after.0 > tiny;
        log.impact = Some(ImpactRecord {
            t,
            kind: frame.kind,
            u_before: u,
            restitution: e,
            energy: (body.kinetic_energy(qd), body.kinetic_energy(qd1)),
            result,
        });
        if bounce {
            log.end = ContactEnd::Bounced;
            out.contacts.push(log);
            return Ok(Mode::Free);
        }
    }
    sim.project(y, false);
    let mode = sim.settle(y, t, &mut log)?;
    if mode == Mode::Free {
        log.end = ContactEnd::Separated;
        out.contacts.push(log);
    } else {
        *open = Some(log);
    }
    Ok(mode)
}
