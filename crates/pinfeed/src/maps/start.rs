//! Where a pin or fence pass starts: the convention every map sample and `pinfeed contact` use.
//!
//! The part's centroid sits at the origin of the belt frame with orientation θ0; the pin centre
//! starts just clear of the part's circumscribed circle, at x = 1.01·a + ρ, y = d·a (docs/physics.md#contact-parameter:
//! d = (y_pin − y_com)/a, taken before contact), and travels in −x relative to the belt. Lengths
//! are in the part's units.
//!
//! A fence (docs/physics.md#fences) at angle α is placed with its line 1.01·a from the centroid on the upstream
//! side (so it starts clear of the part) and its upstream end 1.5·a beyond the part's lateral band
//! on the side parts come from (y = −1.5a for α > 0, +1.5a for α < 0): the part meets the fence
//! with the whole fence length ahead of it, less the stretch needed to cross the band. The fence
//! line passes through y = d·a at the x that places it; since the line and the start are fixed by
//! the rules above, d does not change the fence relative to the part (a fence map has no contact
//! parameter; only the angle, length and friction matter).

use crate::geometry::{Polygon, Pose, Vec2};
use crate::mechanics::FenceSpec;

/// Initial pose of the part and initial pin centre for a pass at contact parameter `d`
/// (belt frame, the polygon's units; `theta0_deg` in degrees, `pin_radius` in the polygon's units).
pub fn pass_start(poly: &Polygon, theta0_deg: f64, d: f64, pin_radius: f64) -> (Pose, Vec2) {
    let a = poly.radius();
    let pose = Pose::new(0.0, 0.0, theta0_deg.to_radians());
    let start = Vec2::new(a * 1.01 + pin_radius, d * a);
    (pose, start)
}

/// The fence of a pass (see the module docs): angle `angle_deg` (degrees, |α| < 90), `length` in
/// the polygon's units (default 20a), friction `mu_f`. The part rests as in [`pass_start`].
pub fn fence_pass_start(
    poly: &Polygon,
    d: f64,
    angle_deg: f64,
    length: Option<f64>,
    mu_f: f64,
) -> FenceSpec {
    let a = poly.radius();
    let angle = angle_deg.to_radians();
    let e = Vec2::from_angle(angle);
    let mut n = e.perp();
    if n.x > 0.0 {
        n = -n;
    }
    let y = d * a;
    let x = (1.01 * a + y * n.y) / (-n.x);
    let cross = Vec2::new(x, y);
    let sin = angle.sin();
    let back = if sin.abs() > 1e-12 {
        (y + sin.signum() * 1.5 * a) / sin
    } else {
        0.0
    };
    FenceSpec {
        start: cross - e * back,
        angle_rad: angle,
        length: length.unwrap_or(20.0 * a),
        mu_f,
        tail_radius: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fence_starts_clear_beside_the_part_whatever_d() {
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        let a = poly.radius();
        for angle in [-60.0, 30.0, 45.0] {
            let f0 = fence_pass_start(&poly, 0.0, angle, None, 0.3);
            let e = Vec2::from_angle(f0.angle_rad);
            let sign = f64::signum(angle);
            assert!((f0.start.y + sign * 1.5 * a).abs() < 1e-12, "{f0:?}");
            // The line lies 1.01a from the centroid, upstream.
            let n = Vec2::new(-e.y.abs(), e.x * sign);
            assert!((f0.start.dot(n) + 1.01 * a).abs() < 1e-9, "{f0:?}");
            assert!((f0.length - 20.0 * a).abs() < 1e-12);
            for d in [-0.7, 0.4] {
                let f = fence_pass_start(&poly, d, angle, Some(3.0), 0.3);
                assert!((f.start - f0.start).norm() < 1e-9, "d = {d}: {f:?}");
                assert_eq!(f.length, 3.0);
            }
        }
    }

    #[test]
    fn pin_starts_outside_the_circumscribed_circle_at_height_d_a() {
        let poly = crate::geometry::part_from_spec("tripoly2").unwrap();
        let a = poly.radius();
        let (pose, pin) = pass_start(&poly, 30.0, -0.3, 0.2);
        assert_eq!((pose.x, pose.y), (0.0, 0.0));
        assert!((pose.theta_rad - 30f64.to_radians()).abs() < 1e-15);
        assert!(pin.x - 0.2 > a, "pin disc must start clear of the part");
        assert!((pin.y - (-0.3 * a)).abs() < 1e-15);
    }
}
