//! Random contacts for fuzzing: a random star polygon (3–12 vertices) pushed by a point pin or a
//! disc pin (radius up to 0.3·a) at a random offset d ∈ [−1.2, 1.2] and orientation θ0, with
//! μc ∈ [0, 2], through [`crate::mechanics::push`] at the default tolerance and at a 1000× tighter
//! one (the same convention as `pinfeed contact`: [`crate::maps::pass_start`]).
//!
//! The status at the default tolerance is counted by the name its serialisation gives (so new
//! status variants show up without changes here). A contact `ok` at both tolerances whose
//! rotations differ by more than [`SELF_CHECK_DEG`] is a self-check disagreement; one `ok` at the
//! default tolerance but not at the tighter one is counted apart. Each problem is listed as a
//! one-line `pinfeed contact …` reproducer.

use super::{all_finite, CaseReport, Class};
use crate::geometry::{Polygon, Vec2};
use crate::mechanics::{push, ContactOutcome, ContactSettings, PartModel, Pin, Support};
use crate::random::ChaCha8Rng;
use rand::RngExt;
use std::f64::consts::TAU;

pub const DESCRIPTION: &str = "random star polygons (3–12 vertices at sorted random angles, radii in [0.1, 1]), μc ∈ [0, 2], d ∈ [−1.2, 1.2], θ0 ∈ [0°, 360°), half point pins and half disc pins of radius up to 0.3·a, each pushed at the default tolerance and at a 1000× tighter one";

/// The tighter tolerance: the default 1e-6 divided by 1000, written exactly as the reproducer's
/// `--tol 1e-9` parses (1e-6 / 1000 in floating point is 9.999999999999999e-10, and near a
/// sensitive contact that difference alone can change the result).
pub const TIGHT_TOL: f64 = 1e-9;

/// Largest rotation difference (degrees) between the two tolerances for an `ok` contact.
pub const SELF_CHECK_DEG: f64 = 1.0;

/// One generated contact.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactCase {
    pub vertices: Vec<Vec2>,
    pub theta0_deg: f64,
    pub d: f64,
    pub mu_c: f64,
    /// Pin radius in part units (0: a point pin).
    pub pin_radius: f64,
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
        ContactCase {
            vertices,
            theta0_deg,
            d,
            mu_c,
            pin_radius: if disc { u } else { 0.0 },
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
        o.pose_final.theta,
        o.rotation,
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
    let pin = Pin {
        radius: rho,
        lateral_speed: 0.0,
    };
    let base = ContactSettings {
        mu_c: c.mu_c,
        ..ContactSettings::default()
    };
    let tight = ContactSettings {
        tol: TIGHT_TOL,
        ..base
    };
    let a = push(&model, pose, start, &pin, &base, None);
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
    let b = push(&model, pose, start, &pin, &tight, None);
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
    let diff = (a.rotation - b.rotation).to_degrees();
    if diff.is_nan() || diff.abs() > SELF_CHECK_DEG {
        return report(
            Class::Disagreement,
            format!(
                "rotation {:.3}° at tol {:e} but {:.3}° at {:e} (add --tol {:e}): {}",
                a.rotation.to_degrees(),
                base.tol,
                b.rotation.to_degrees(),
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
