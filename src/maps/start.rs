//! Where a pin pass starts: the convention every map sample and `pinfeed contact` use.
//!
//! The part's centroid sits at the origin of the belt frame with orientation θ0; the pin centre
//! starts just clear of the part's circumscribed circle, at x = 1.01·a + ρ, y = d·a (SPEC §1:
//! d = (y_pin − y_com)/a, taken before contact), and travels in −x relative to the belt. Lengths
//! are in the part's units.

use crate::geometry::{Polygon, Pose, Vec2};

/// Initial pose of the part and initial pin centre for a pass at contact parameter `d`
/// (belt frame, the polygon's units; `theta0_deg` in degrees, `pin_radius` in the polygon's units).
pub fn pass_start(poly: &Polygon, theta0_deg: f64, d: f64, pin_radius: f64) -> (Pose, Vec2) {
    let a = poly.radius();
    let pose = Pose::new(0.0, 0.0, theta0_deg.to_radians());
    let start = Vec2::new(a * 1.01 + pin_radius, d * a);
    (pose, start)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pin_starts_outside_the_circumscribed_circle_at_height_d_a() {
        let poly = crate::geometry::part_from_spec("tripoly2").unwrap();
        let a = poly.radius();
        let (pose, pin) = pass_start(&poly, 30.0, -0.3, 0.2);
        assert_eq!((pose.x, pose.y), (0.0, 0.0));
        assert!((pose.theta - 30f64.to_radians()).abs() < 1e-15);
        assert!(pin.x - 0.2 > a, "pin disc must start clear of the part");
        assert!((pin.y - (-0.3 * a)).abs() < 1e-15);
    }
}
