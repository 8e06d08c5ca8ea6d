//! The support's friction on a part with inertia (docs/physics.md#dynamic-tier), from the
//! quasi-static tier's limit surface used as a force law.
//!
//! For the part's twist relative to the surface, ξ_rel = (v − V_s, ω) (the surface translates at
//! V_s and does not turn), the support's friction load on the part is
//!
//! ```text
//! F = −μs N ∇D(ξ̂_rel)  (force, world axes),   M = −μs N a ∇D_ω(ξ̂_rel)  (moment about the centroid),
//! ```
//!
//! where ∇D is [`PartModel::dissipation`]'s gradient for unit load (normalised units, a = 1, part
//! axes), ξ̂_rel the relative twist in those units, (R(−θ)(v − V_s)/a, ω), and N = m g cos α the
//! normal load on an incline of angle α. ∇D is homogeneous of degree zero: the load depends only on
//! the direction of ξ_rel, exactly Coulomb friction integrated over the support (uniform pressure,
//! points, tripods, smooth densities, whatever the [`PartModel`] was compiled with). At ξ_rel = 0
//! the load is not a function of the twist (static friction): the integrator never evaluates it
//! there but switches the part to being carried by the surface ([`Surface::holds_against_gravity`]).
//!
//! Gravity on an incline adds the in-plane force m g sin α along the downhill direction, acting
//! at the centroid.

use super::{positive, within, InvalidInput};
use crate::geometry::Vec2;
use crate::mechanics::PartModel;

/// The surface the part rests on: a belt or board moving at constant velocity, its friction,
/// gravity and incline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Velocity V_s of the surface (world frame, L/T); it translates without turning.
    pub velocity: Vec2,
    /// Support friction coefficient μs > 0.
    pub mu_s: f64,
    /// Gravitational acceleration g > 0 (L/T²).
    pub gravity: f64,
    /// Incline α of the surface, radians in [0, π/2).
    pub incline: f64,
    /// Direction of steepest descent in the surface's plane (world angle, radians); unused at
    /// α = 0.
    pub downhill: f64,
}

impl Surface {
    /// A level surface moving at `velocity` with friction `mu_s` under gravity `gravity`.
    pub fn level(velocity: Vec2, mu_s: f64, gravity: f64) -> Surface {
        Surface {
            velocity,
            mu_s,
            gravity,
            incline: 0.0,
            downhill: 0.0,
        }
    }

    /// Check every field: finite velocity, μs > 0, g > 0, 0 ≤ α < π/2, finite downhill angle.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        within(
            "surface.velocity.x",
            self.velocity.x,
            f64::MIN,
            f64::MAX,
            "finite",
        )?;
        within(
            "surface.velocity.y",
            self.velocity.y,
            f64::MIN,
            f64::MAX,
            "finite",
        )?;
        positive("surface.mu_s", self.mu_s)?;
        positive("surface.gravity", self.gravity)?;
        if !(self.incline >= 0.0 && self.incline < std::f64::consts::FRAC_PI_2) {
            return Err(InvalidInput {
                field: "surface.incline",
                value: self.incline,
                allowed: "[0, π/2) radians (below 90°)",
            });
        }
        within(
            "surface.downhill",
            self.downhill,
            f64::MIN,
            f64::MAX,
            "finite",
        )?;
        Ok(())
    }

    /// Normal load N = m g cos α.
    pub fn normal_load(&self, mass: f64) -> f64 {
        mass * self.gravity * self.incline.cos()
    }

    /// The in-plane gravity force m g sin α along the downhill direction (world frame).
    pub fn gravity_force(&self, mass: f64) -> Vec2 {
        Vec2::from_angle(self.downhill) * (mass * self.gravity * self.incline.sin())
    }

    /// Can static friction hold the part still on the surface against gravity alone (tan α < μs)?
    /// Exact for every support whose centre of pressure is the centroid (all of pinfeed's): a
    /// translation's friction load is then a unit force with no moment, so the limit surface's
    /// zero-moment section is the circle of radius μs N, and gravity's pure force lies strictly
    /// inside it iff m g sin α < μs m g cos α.
    pub fn holds_against_gravity(&self) -> bool {
        self.incline.tan() < self.mu_s
    }
}

/// The support's friction on the part (force in world axes, moment about the centroid) when it
/// moves at twist (v, ω) (world frame) at orientation θ over `surface`; zero at zero relative
/// twist. `evals` counts limit-surface evaluations.
pub fn support_friction(
    model: &PartModel,
    surface: &Surface,
    mass: f64,
    theta: f64,
    v: Vec2,
    omega: f64,
    evals: &mut u64,
) -> (Vec2, f64) {
    let a = model.scale();
    let rel = (v - surface.velocity).rotate(-theta) / a;
    if rel.x == 0.0 && rel.y == 0.0 && omega == 0.0 {
        return (Vec2::ZERO, 0.0);
    }
    *evals += 1;
    let g = model.dissipation([rel.x, rel.y, omega], false).grad;
    let load = surface.mu_s * surface.normal_load(mass);
    (
        Vec2::new(-g[0], -g[1]).rotate(theta) * load,
        -g[2] * a * load,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::Support;

    fn model(spec: &str, scale: f64) -> PartModel {
        let poly = part_from_spec(spec).unwrap().scaled(scale);
        PartModel::new(&poly, &Support::Uniform).unwrap()
    }

    #[test]
    fn a_translation_feels_mu_n_against_its_relative_velocity() {
        let m = model("tripoly2", 0.03);
        let s = Surface::level(Vec2::new(0.2, 0.0), 0.4, 9.81);
        let mut evals = 0;
        let v = Vec2::new(0.2, 0.0) + Vec2::new(-0.3, 0.4);
        let (f, mo) = support_friction(&m, &s, 2.0, 0.7, v, 0.0, &mut evals);
        let expect = Vec2::new(0.3, -0.4) / 0.5 * (0.4 * 2.0 * 9.81);
        assert!(
            (f - expect).norm() < 1e-9 * expect.norm(),
            "{f:?} {expect:?}"
        );
        assert!(mo.abs() < 1e-9 * 0.4 * 2.0 * 9.81 * 0.03, "{mo}");
        assert_eq!(evals, 1);
        // Zero relative twist: no load and no evaluation.
        let (f0, m0) = support_friction(&m, &s, 2.0, 0.7, s.velocity, 0.0, &mut evals);
        assert_eq!((f0, m0, evals), (Vec2::ZERO, 0.0, 1));
    }

    #[test]
    fn a_disc_like_spin_feels_the_uniform_pressure_moment() {
        // A regular 200-gon of radius R spinning about its centroid: M = −μs N (2/3) R sgn ω, no force.
        let m = model("ngon:200", 0.05);
        let s = Surface::level(Vec2::ZERO, 0.5, 9.81);
        let mut evals = 0;
        let (f, mo) = support_friction(&m, &s, 1.0, 0.3, Vec2::ZERO, 2.0, &mut evals);
        let r = 0.05;
        let expect = -0.5 * 9.81 * 2.0 / 3.0 * r;
        assert!((mo - expect).abs() < 1e-3 * expect.abs(), "{mo} {expect}");
        assert!(f.norm() < 1e-9, "{f:?}");
    }

    #[test]
    fn the_load_is_the_negative_gradient_of_the_dissipation_power() {
        // F·v_rel + M ω = −μs N D(ξ_rel) (power dissipated), at a general twist and pose.
        let m = model("lshape", 0.02);
        let s = Surface::level(Vec2::new(0.1, -0.05), 0.3, 9.81);
        let mut evals = 0;
        let (v, om, th) = (Vec2::new(0.03, 0.2), -1.7, 1.1);
        let (f, mo) = support_friction(&m, &s, 0.5, th, v, om, &mut evals);
        let rel = v - s.velocity;
        let xi = rel.rotate(-th) / m.scale();
        let d = m.dissipation([xi.x, xi.y, om], false).value * m.scale();
        let power = f.dot(rel) + mo * om;
        let expect = -0.3 * 0.5 * 9.81 * d;
        assert!(
            (power - expect).abs() < 1e-12 * expect.abs(),
            "{power} {expect}"
        );
    }

    #[test]
    fn a_bad_surface_is_refused_by_name() {
        let good = Surface::level(Vec2::new(1.0, 0.0), 0.3, 9.81);
        assert!(good.validate().is_ok());
        let cases = [
            (
                Surface {
                    incline: std::f64::consts::FRAC_PI_2,
                    ..good
                },
                "surface.incline",
            ),
            (
                Surface {
                    incline: -0.1,
                    ..good
                },
                "surface.incline",
            ),
            (
                Surface {
                    incline: f64::NAN,
                    ..good
                },
                "surface.incline",
            ),
            (Surface { mu_s: 0.0, ..good }, "surface.mu_s"),
            (
                Surface {
                    gravity: -9.81,
                    ..good
                },
                "surface.gravity",
            ),
            (
                Surface {
                    velocity: Vec2::new(f64::NAN, 0.0),
                    ..good
                },
                "surface.velocity.x",
            ),
        ];
        for (s, field) in cases {
            assert_eq!(s.validate().unwrap_err().field, field);
        }
        let steep = Surface {
            incline: 0.5f64.atan() + 1e-9,
            ..good
        };
        assert!(!Surface { mu_s: 0.5, ..steep }.holds_against_gravity());
        assert!(Surface {
            mu_s: 0.5 + 1e-6,
            ..steep
        }
        .holds_against_gravity());
    }
}
