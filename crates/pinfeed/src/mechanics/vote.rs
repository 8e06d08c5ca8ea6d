//! Mason's voting theorem (thesis §2.6): the sense of rotation of a pushed part from geometry alone.
//!
//! With c the vector from the contact point to the centroid, the three votes are the signs of
//! v_push × c, f_L × c and f_R × c, where v_push is the pin's velocity relative to the belt and
//! f_L, f_R the friction-cone edges. The majority gives the sense (+1 counter-clockwise, −1 clockwise);
//! 0 is a tie (metastable push). Independent of the pressure distribution, so every fidelity level
//! must agree with it.

use crate::geometry::Vec2;

/// Mason's vote: +1 (CCW), −1 (CW) or 0 (tie). `to_centroid` = centroid − contact point,
/// `n` the unit normal into the part, `v_push` the pin's velocity relative to the belt.
pub fn mason_vote(to_centroid: Vec2, n: Vec2, v_push: Vec2, mu_c: f64) -> i32 {
    let phi = mu_c.atan();
    let scale = to_centroid.norm() * v_push.norm();
    let sgn = |x: f64| -> i32 {
        if x > 1e-12 * scale {
            1
        } else if x < -1e-12 * scale {
            -1
        } else {
            0
        }
    };
    let v1 = sgn(v_push.cross(to_centroid));
    let v2 = sgn(n.rotate(phi).cross(to_centroid) * v_push.norm());
    let v3 = sgn(n.rotate(-phi).cross(to_centroid) * v_push.norm());
    (v1 + v2 + v3).signum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_above_centroid_turns_ccw() {
        // Pin moving −x strikes the right edge above the centroid.
        let v = mason_vote(
            Vec2::new(-0.5, -0.3),
            Vec2::new(-1.0, 0.0),
            Vec2::new(-1.0, 0.0),
            0.3,
        );
        assert_eq!(v, 1);
    }

    #[test]
    fn central_push_is_a_tie() {
        let v = mason_vote(
            Vec2::new(-0.5, 0.0),
            Vec2::new(-1.0, 0.0),
            Vec2::new(-1.0, 0.0),
            0.3,
        );
        assert_eq!(v, 0);
    }
}
