//! A small 2-D vector type and rigid transforms of the plane.
//!
//! Everything pinfeed computes lives in the plane z = 0 (docs/physics.md#frames): x along belt travel, y to the left.
//! Angles are radians inside the library; the CLI and files speak degrees. The scalar cross product
//! `a.cross(b) = a.x b.y − a.y b.x` is the z component of the 3-D cross product, so for a moment arm
//! `r` and force `f`, `r.cross(f)` is the counter-clockwise moment.

use serde::{Deserialize, Serialize};
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// (sin φ, cos φ), the one sine-and-cosine every rotation in pinfeed uses.
///
/// It is the `libm` crate's `sincos` (the Rust port of musl's, from FreeBSD's msun: below one
/// unit in the last place, the same kernels as its `sin` and `cos`), not the platform's: glibc's
/// saves and restores the floating-point rounding mode on every call, which made it an eighth of
/// a contact's time (the integrator turns vectors by the part's orientation at every stage); this
/// one takes about half as long (`results/line-speed.md`). Being plain Rust, it gives the same bits
/// on every platform.
#[inline]
pub fn sin_cos(phi: f64) -> (f64, f64) {
    libm::sincos(phi)
}

/// A vector (or point) in the plane.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vec2 {
    /// x coordinate (along the belt in the world frame).
    pub x: f64,
    /// y coordinate (to the left of the belt's travel in the world frame).
    pub y: f64,
}

impl Vec2 {
    /// The zero vector (the origin).
    pub const ZERO: Vec2 = Vec2 { x: 0.0, y: 0.0 };

    /// The vector (x, y).
    #[inline]
    pub const fn new(x: f64, y: f64) -> Self {
        Vec2 { x, y }
    }
    /// Unit vector at angle `phi` (radians, counter-clockwise from +x).
    #[inline]
    pub fn from_angle(phi: f64) -> Self {
        let (s, c) = sin_cos(phi);
        Vec2 { x: c, y: s }
    }
    /// Dot product.
    #[inline]
    pub fn dot(self, o: Vec2) -> f64 {
        self.x * o.x + self.y * o.y
    }
    /// z component of the 3-D cross product `self × o`.
    #[inline]
    pub fn cross(self, o: Vec2) -> f64 {
        self.x * o.y - self.y * o.x
    }
    /// `ẑ × self`: the vector rotated by +90°.
    #[inline]
    pub fn perp(self) -> Vec2 {
        Vec2 {
            x: -self.y,
            y: self.x,
        }
    }
    /// Euclidean length (plain √(x²+y²): `hypot` is several times slower and pinfeed's lengths are
    /// far from overflow).
    #[inline]
    pub fn norm(self) -> f64 {
        (self.x * self.x + self.y * self.y).sqrt()
    }
    /// Squared length (no square root).
    #[inline]
    pub fn norm2(self) -> f64 {
        self.x * self.x + self.y * self.y
    }
    /// Unit vector in the same direction (returns the input unchanged if it is zero).
    #[inline]
    pub fn normalized(self) -> Vec2 {
        let n = self.norm();
        if n > 0.0 {
            self / n
        } else {
            self
        }
    }
    /// Rotate counter-clockwise by `phi` radians.
    #[inline]
    pub fn rotate(self, phi: f64) -> Vec2 {
        let (s, c) = sin_cos(phi);
        self.rotate_sc(s, c)
    }
    /// Rotate by the angle whose sine and cosine are given.
    #[inline]
    pub fn rotate_sc(self, s: f64, c: f64) -> Vec2 {
        Vec2 {
            x: c * self.x - s * self.y,
            y: s * self.x + c * self.y,
        }
    }
    /// Angle of the vector, radians in (−π, π].
    #[inline]
    pub fn angle(self) -> f64 {
        self.y.atan2(self.x)
    }
    /// Are both coordinates finite?
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    #[inline]
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}
impl AddAssign for Vec2 {
    #[inline]
    fn add_assign(&mut self, o: Vec2) {
        self.x += o.x;
        self.y += o.y;
    }
}
impl Sub for Vec2 {
    type Output = Vec2;
    #[inline]
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}
impl SubAssign for Vec2 {
    #[inline]
    fn sub_assign(&mut self, o: Vec2) {
        self.x -= o.x;
        self.y -= o.y;
    }
}
impl Mul<f64> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn mul(self, k: f64) -> Vec2 {
        Vec2::new(self.x * k, self.y * k)
    }
}
impl Mul<Vec2> for f64 {
    type Output = Vec2;
    #[inline]
    fn mul(self, v: Vec2) -> Vec2 {
        Vec2::new(self * v.x, self * v.y)
    }
}
impl Div<f64> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn div(self, k: f64) -> Vec2 {
        Vec2::new(self.x / k, self.y / k)
    }
}
impl Neg for Vec2 {
    type Output = Vec2;
    #[inline]
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}

/// A planar pose: position of the part's centroid and rotation θ of the part frame (radians;
/// serialized as `theta`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// x of the centroid (along the belt in the world frame).
    pub x: f64,
    /// y of the centroid (to the left in the world frame).
    pub y: f64,
    /// Rotation of the part frame (radians, counter-clockwise).
    #[serde(rename = "theta")]
    pub theta_rad: f64,
}

impl Pose {
    /// The pose (x, y, θ in radians).
    pub const fn new(x: f64, y: f64, theta_rad: f64) -> Self {
        Pose { x, y, theta_rad }
    }
    /// The centroid's position (x, y).
    #[inline]
    pub fn position(&self) -> Vec2 {
        Vec2::new(self.x, self.y)
    }
    /// Map a point from the part frame to the world frame.
    #[inline]
    pub fn apply(&self, p: Vec2) -> Vec2 {
        p.rotate(self.theta_rad) + self.position()
    }
    /// Map a point from the world frame to the part frame.
    #[inline]
    pub fn apply_inverse(&self, q: Vec2) -> Vec2 {
        (q - self.position()).rotate(-self.theta_rad)
    }
}

/// Wrap an angle in radians to [0, 2π).
pub fn wrap_2pi(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = a.rem_euclid(t);
    if r >= t {
        0.0
    } else {
        r
    }
}

/// Wrap an angle in degrees to [0, 360).
pub fn wrap_deg(a: f64) -> f64 {
    let r = a.rem_euclid(360.0);
    if r >= 360.0 {
        0.0
    } else {
        r
    }
}

/// Wrap an angle in radians to (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = wrap_2pi(a);
    if r > std::f64::consts::PI {
        r - t
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_is_written_and_read_with_the_key_theta() {
        let p = Pose::new(1.0, 2.0, 0.5);
        let v = serde_json::to_value(p).unwrap();
        assert_eq!(v, serde_json::json!({"x": 1.0, "y": 2.0, "theta": 0.5}));
        assert_eq!(serde_json::from_value::<Pose>(v).unwrap(), p);
    }

    #[test]
    fn pose_round_trip() {
        let pose = Pose::new(1.5, -2.0, 0.7);
        let p = Vec2::new(0.3, 4.0);
        let q = pose.apply_inverse(pose.apply(p));
        assert!((q - p).norm() < 1e-14);
    }

    #[test]
    fn wrapping() {
        assert_eq!(wrap_deg(-90.0), 270.0);
        assert_eq!(wrap_deg(720.0), 0.0);
        assert!((wrap_pi(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!(wrap_deg(-1e-20) < 360.0);
    }

    #[test]
    fn cross_is_ccw_moment() {
        // A force +y applied at +x turns the body counter-clockwise.
        assert!(Vec2::new(1.0, 0.0).cross(Vec2::new(0.0, 1.0)) > 0.0);
        assert_eq!(Vec2::new(1.0, 0.0).perp(), Vec2::new(0.0, 1.0));
    }
}
