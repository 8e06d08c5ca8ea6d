//! Shared helpers for the contact-model tests.
#![allow(dead_code)]

use pinfeed::geometry::{part_from_spec, Polygon, Pose, Vec2};
use pinfeed::mechanics::{
    push, ContactOutcome, ContactSettings, Fidelity, PartModel, Pin, Support,
};

pub const FIDELITIES: [Fidelity; 3] = [Fidelity::Tip, Fidelity::Ellipsoid, Fidelity::Exact];

pub fn poly(name: &str) -> Polygon {
    part_from_spec(name).unwrap()
}

pub fn model(p: &Polygon) -> PartModel {
    PartModel::new(p, &Support::Uniform).unwrap()
}

pub fn settings(fid: Fidelity, mu_c: f64) -> ContactSettings {
    ContactSettings {
        fidelity: fid,
        mu_c,
        ..ContactSettings::default()
    }
}

/// The CLI's convention: centroid at the origin, pin just clear of the part at y = d·a.
pub fn run(
    m: &PartModel,
    p: &Polygon,
    theta0_deg: f64,
    d: f64,
    pin: Pin,
    s: &ContactSettings,
) -> ContactOutcome {
    let a = p.radius();
    let pose = Pose::new(0.0, 0.0, theta0_deg.to_radians());
    let start = Vec2::new(a * 1.01 + pin.radius, d * a);
    push(m, pose, start, &pin, s, None)
}

/// Everything a caller reads is finite.
pub fn assert_finite(o: &ContactOutcome, what: &str) {
    let p = o.pose_final;
    assert!(
        p.x.is_finite() && p.y.is_finite() && p.theta_rad.is_finite(),
        "{what}: non-finite pose {p:?}"
    );
    assert!(o.rotation_rad.is_finite(), "{what}: rotation");
    assert!(
        o.contact_length.is_finite() && o.contact_length >= 0.0,
        "{what}: length"
    );
    for s in &o.segments {
        assert!(s.s_begin.is_finite() && s.s_end.is_finite() && s.s_end >= s.s_begin - 1e-12);
    }
}

/// Angle difference in degrees, wrapped to [−180, 180).
pub fn ang_diff_deg(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}
