//! Random contacts for fuzzing: a random star polygon (3–12 vertices) pushed by a point pin or a
//! disc pin (radius up to 0.3·a) at a random offset d ∈ [−1.2, 1.2] and orientation θ0, with
//! μc ∈ [0, 2], through [`crate::mechanics::push_path`] at the default tolerance and at a 1000×
//! tighter one (the same convention as `pinfeed contact`: [`crate::maps::pass_start`]). Half the
//! pins move across the belt ([`Motion`]): lateral speed |w| log-uniform in [0.01, 10] belt speeds
//! of either sign, moving throughout, stopping S ∈ (0, 3] units of a after the start
//! (`--pin-stop-after`) or T ∈ [0, 2] units of a after the first touch
//! (`--pin-stop-after-touch`), a third each.
//!
//! The status at the default tolerance is counted by the name its serialisation gives (so new
//! status variants show up without changes here). A contact `ok` at both tolerances whose
//! rotations differ by more than [`SELF_CHECK_DEG`] is a self-check disagreement; one `ok` at the
//! default tolerance but not at the tighter one is counted apart. Each problem is listed as a
//! one-line `pinfeed contact …` reproducer.

use super::{all_finite, CaseReport, Class};
use crate::geometry::{Polygon, Vec2};
use crate::mechanics::{
    push_path, stop_after_touch, ContactOutcome, ContactSettings, PartModel, PinPath, Support, Turn,
};
use crate::random::ChaCha8Rng;
use rand::RngExt;
use std::f64::consts::TAU;

/// What a case of the contacts target is (in the fuzz report).
pub const DESCRIPTION: &str = "random star polygons (3–12 vertices at sorted random angles, radii in [0.1, 1]), μc ∈ [0, 2], d ∈ [−1.2, 1.2], θ0 ∈ [0°, 360°), half point pins and half disc pins of radius up to 0.3·a; half the pins still, half moving across the belt at |w| log-uniform in [0.01, 10] belt speeds (either sign), a third of those moving throughout, a third stopping S ∈ (0, 3]·a after the start, a third T ∈ [0, 2]·a after the first touch; each pushed at the default tolerance and at a 1000× tighter one";

/// The tighter tolerance: the default 1e-6 divided by 1000, written exactly as the reproducer's
/// `--tol 1e-9` parses (1e-6 / 1000 in floating point is 9.999999999999999e-10, and near a
/// sensitive contact that difference alone can change the result).
pub const TIGHT_TOL: f64 = 1e-9;

/// Largest rotation difference (degrees) between the two tolerances for an `ok` contact.
pub const SELF_CHECK_DEG: f64 = 1.0;

/// How a generated pin moves across the belt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// A still pin.
    Still,
    /// Lateral speed w (belt speeds), moving throughout.
    Moving {
        /// Lateral speed, in belt speeds (either sign).
        w: f64,
    },
    /// Moving at w, stopping after S units of a of belt travel from the start.
    StopAfter {
        /// Lateral speed, in belt speeds (either sign).
        w: f64,
        /// Belt travel from the start after which the pin stops, in units of a.
        s: f64,
    },
    /// Moving at w, stopping T units of a of belt travel after the first touch.
    StopAfterTouch {
        /// Lateral speed, in belt speeds (either sign).
        w: f64,
        /// Belt travel after the first touch after which the pin stops, in units of a.
        t: f64,
    },
}

impl Motion {
    /// Draw a motion: still half the time.
    fn random(rng: &mut ChaCha8Rng) -> Motion {
        if rng.random::<bool>() {
            return Motion::Still;
        }
        let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
        let w = round6(sign * 10f64.powf(-2.0 + 3.0 * rng.random::<f64>()));
        match rng.random_range(0..3u32) {
            0 => Motion::Moving { w },
            1 => Motion::StopAfter {
                w,
                s: round6(1e-6 + 3.0 * rng.random::<f64>()),
            },
            _ => Motion::StopAfterTouch {
                w,
                t: round6(2.0 * rng.random::<f64>()),
            },
        }
    }

    /// The kind of case in the report.
    pub fn kind(&self) -> &'static str {
        match self {
            Motion::Still => "still pin",
            Motion::Moving { .. } => "moving pin, moving throughout",
            Motion::StopAfter { .. } => "moving pin, stopping S after its start",
            Motion::StopAfterTouch { .. } => "moving pin, stopping T after its first touch",
        }
    }

    /// The pin's path (travels in the part's units, `a` its size).
    fn path(
        &self,
        model: &PartModel,
        pose: crate::geometry::Pose,
        start: Vec2,
        rho: f64,
        a: f64,
    ) -> PinPath {
        let still = PinPath::constant(0.0);
        match *self {
            Motion::Still => still,
            Motion::Moving { w } => PinPath::new(w, Vec::new()).unwrap_or(still),
            Motion::StopAfter { w, s } => {
                PinPath::new(w, vec![Turn { s: s * a, w: 0.0 }]).unwrap_or(still)
            }
            Motion::StopAfterTouch { w, t } => {
                stop_after_touch(model, pose, start, rho, w, t * a).unwrap_or(still)
            }
        }
    }

    /// The flags of `pinfeed contact` that give this motion.
    fn flags(&self) -> String {
        match *self {
            Motion::Still => String::new(),
            Motion::Moving { w } => format!(" --pin-speed={w}"),
            Motion::StopAfter { w, s } => format!(" --pin-speed={w} --pin-stop-after {s}"),
            Motion::StopAfterTouch { w, t } => {
                format!(" --pin-speed={w} --pin-stop-after-touch {t}")
            }
        }
    }
}

/// One generated contact.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactCase {
    /// The part's vertices (part units, counter-clockwise star polygon).
    pub vertices: Vec<Vec2>,
    /// Entry orientation of the part (degrees, in [0, 360)).
    pub theta0_deg: f64,
    /// Lateral offset of the pin against the part, in units of a (in [−1.2, 1.2]), as `pinfeed
    /// contact --d`.
    pub d: f64,
    /// Pin–part friction coefficient μc (in [0, 2]).
    pub mu_c: f64,
    /// Pin radius in part units (0: a point pin).
    pub pin_radius: f64,
    /// How the pin moves across the belt.
    pub motion: Motion,
}

impl ContactCase {
    /// Draw a case.
    pub fn random(rng: &mut ChaCha8Rng) -> ContactCase {
        // A star with an angular gap over 180° can fold onto itself: redraw (from the same
        // stream, so the case stays a function of its index) until the polygon is valid.
        let mut vertices: Vec<Vec2> = Vec::new();
        for _ in 0..1000 {
            let n = rng.random_range(3..=12usize);
            let mut angles: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * TAU).collect();
            angles.sort_by(f64::total_cmp);
            vertices = angles
                .iter()
                .map(|&t| {
                    let r = 0.1 + 0.9 * rng.random::<f64>();
                    let v = Vec2::new(r * t.cos(), r * t.sin());
                    // Six decimals: the reproducer then gives exactly this polygon.
                    Vec2::new(round6(v.x), round6(v.y))
                })
                .collect();
            if Polygon::new(&vertices).is_ok() {
                break;
            }
        }
        let theta0_deg = round6(360.0 * rng.random::<f64>());
        let d = round6(-1.2 + 2.4 * rng.random::<f64>());
        let mu_c = round6(2.0 * rng.random::<f64>());
        let disc = rng.random::<bool>();
        let u = rng.random::<f64>();
        // Drawn last: the still-pin cases keep the draws they had before pins moved.
        let motion = Motion::random(rng);
        ContactCase {
            vertices,
            theta0_deg,
            d,
            mu_c,
            pin_radius: if disc { u } else { 0.0 },
            motion,
        }
    }

    /// `pinfeed contact …` for this case (the pin radius in part units), at tolerance `tol`.
    pub fn command(&self, pin_radius: f64, tol: Option<f64>) -> String {
        let vs = self
            .vertices
            .iter()
            .map(|v| format!("{},{}", v.x, v.y))
            .collect::<Vec<_>>()
            .join(" ");
        let mut c = format!(
            "pinfeed contact --part 'vertices:{vs}' --theta0={} --d={} --mu-c {} --pin-radius {}",
            self.theta0_deg, self.d, self.mu_c, pin_radius
        );
        c.push_str(&self.motion.flags());
        if let Some(t) = tol {
            c.push_str(&format!(" --tol {t:e}"));
        }
        c
    }
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

fn outcome_numbers(o: &ContactOutcome) -> Vec<f64> {
    vec![
        o.pose_final.x,
        o.pose_final.y,
        o.pose_final.theta_rad,
        o.rotation_rad,
        o.travel_to_contact,
        o.contact_length,
    ]
}

/// The status's name as its serialisation spells it.
pub fn status_name(o: &ContactOutcome) -> String {
    serde_json::to_value(o.status)
        .ok()
        .and_then(|v| v.get("kind").and_then(|k| k.as_str()).map(str::to_string))
        .unwrap_or_else(|| o.status.name().to_string())
}

/// Run a generated case.
pub fn run(c: &ContactCase) -> CaseReport {
    let mut r = run_unlabelled(c);
    r.kind = Some(c.motion.kind().to_string());
    r
}

fn run_unlabelled(c: &ContactCase) -> CaseReport {
    let poly = match Polygon::new(&c.vertices) {
        Ok(p) => p,
        Err(e) => {
            let mut r = CaseReport::with(Class::Named, e.to_string());
            r.status = Some("invalid_polygon".into());
            return r;
        }
    };
    let model = match PartModel::new(&poly, &Support::Uniform) {
        Ok(m) => m,
        Err(_) => {
            let mut r = CaseReport::new(Class::Named);
            r.status = Some("invalid_part_model".into());
            return r;
        }
    };
    // Disc pins up to 0.3·a; the fraction is kept in `pin_radius` until the part's a is known.
    let rho = round6(c.pin_radius * 0.3 * poly.radius());
    let (pose, start) = crate::maps::pass_start(&poly, c.theta0_deg, c.d, rho);
    let path = c.motion.path(&model, pose, start, rho, poly.radius());
    let base = ContactSettings {
        mu_c: c.mu_c,
        ..ContactSettings::default()
    };
    let tight = ContactSettings {
        tol: TIGHT_TOL,
        ..base
    };
    let a = push_path(&model, pose, start, rho, &path, &base, None);
    let status = status_name(&a);
    let report = |class: Class, detail: String| {
        let mut r = CaseReport::with(class, detail);
        r.status = Some(status.clone());
        r
    };
    if !a.status.is_ok() {
        return report(Class::Status, String::new());
    }
    if !all_finite(&outcome_numbers(&a)) {
        return report(
            Class::NonFinite,
            format!("status ok with a non-finite pose: {}", c.command(rho, None)),
        );
    }
    let b = push_path(&model, pose, start, rho, &path, &tight, None);
    if !b.status.is_ok() {
        return report(
            Class::OkThenFailed,
            format!(
                "ok at tol {:e}, {} at {:e} (add --tol {:e}): {}",
                base.tol,
                status_name(&b),
                tight.tol,
                tight.tol,
                c.command(rho, None)
            ),
        );
    }
    let diff = (a.rotation_rad - b.rotation_rad).to_degrees();
    if diff.is_nan() || diff.abs() > SELF_CHECK_DEG {
        return report(
            Class::Disagreement,
            format!(
                "rotation {:.3}° at tol {:e} but {:.3}° at {:e} (add --tol {:e}): {}",
                a.rotation_rad.to_degrees(),
                base.tol,
                b.rotation_rad.to_degrees(),
                tight.tol,
                tight.tol,
                c.command(rho, None)
            ),
        );
    }
    report(Class::Success, String::new())
}

/// One contact case.
pub fn case(rng: &mut ChaCha8Rng) -> CaseReport {
    run(&ContactCase::random(rng))
}

/// The case as a command line.
pub fn input(rng: &mut ChaCha8Rng) -> String {
    let c = ContactCase::random(rng);
    match Polygon::new(&c.vertices) {
        Ok(p) => c.command(round6(c.pin_radius * 0.3 * p.radius()), None),
        Err(e) => format!("{} (invalid polygon: {e})", c.command(0.0, None)),
    }
}
