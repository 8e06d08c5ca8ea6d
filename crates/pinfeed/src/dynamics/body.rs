//! Mass properties of a part from its polygon (docs/physics.md#dynamic-tier): uniform areal
//! density, centre of mass at the area centroid (the polygon's origin), moment of inertia about
//! it I = m · J / A with J = ∫|x|² dA the polygon's polar moment and A its area.

use super::{positive, InvalidInput};
use crate::geometry::Polygon;

/// How the part's mass is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassSpec {
    /// Areal density (mass per unit area, caller's units): m = ρ A.
    Density(f64),
    /// Total mass.
    Mass(f64),
}

/// A rigid planar body: mass and moment of inertia about its centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Mass m > 0.
    pub mass: f64,
    /// Moment of inertia about the centre of mass, I > 0.
    pub inertia: f64,
}

impl Body {
    /// A body of mass `mass` and inertia `inertia` about its centre of mass, both finite and
    /// positive (else the error names the field).
    pub fn new(mass: f64, inertia: f64) -> Result<Body, InvalidInput> {
        Ok(Body {
            mass: positive("mass", mass)?,
            inertia: positive("inertia", inertia)?,
        })
    }

    /// The body of a uniform lamina with the polygon's shape: m from the density or as given,
    /// I = m J / A (J the polar moment about the centroid, A the area).
    pub fn from_polygon(poly: &Polygon, spec: MassSpec) -> Result<Body, InvalidInput> {
        let mass = match spec {
            MassSpec::Density(rho) => positive("density", rho)? * poly.area(),
            MassSpec::Mass(m) => positive("mass", m)?,
        };
        Body::new(mass, mass * poly.polar_moment() / poly.area())
    }

    /// Radius of gyration k = √(I/m).
    pub fn radius_of_gyration(&self) -> f64 {
        (self.inertia / self.mass).sqrt()
    }

    /// Kinetic energy ½ m |v|² + ½ I ω² of the twist (vx, vy, ω) (centre-of-mass velocity).
    pub fn kinetic_energy(&self, qd: [f64; 3]) -> f64 {
        0.5 * self.mass * (qd[0] * qd[0] + qd[1] * qd[1]) + 0.5 * self.inertia * qd[2] * qd[2]
    }

    /// M⁻¹ g for a generalised force g = (fx, fy, moment about the centre of mass).
    pub fn inverse_mass_times(&self, g: [f64; 3]) -> [f64; 3] {
        [g[0] / self.mass, g[1] / self.mass, g[2] / self.inertia]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;

    #[test]
    fn a_rectangle_has_the_textbook_inertia() {
        // A W × H plate: I = m (W² + H²) / 12.
        let poly = part_from_spec("rect:3:2").unwrap();
        let b = Body::from_polygon(&poly, MassSpec::Density(2.0)).unwrap();
        assert!((b.mass - 12.0).abs() < 1e-12);
        assert!((b.inertia - 12.0 * 13.0 / 12.0).abs() < 1e-10);
        assert!((b.radius_of_gyration() - (13.0f64 / 12.0).sqrt()).abs() < 1e-12);
        let given = Body::from_polygon(&poly, MassSpec::Mass(3.0)).unwrap();
        assert!((given.inertia - 3.0 * 13.0 / 12.0).abs() < 1e-10);
    }

    #[test]
    fn a_triangle_has_the_textbook_inertia() {
        // Right isosceles triangle with legs L about its centroid: I = m L² / 9.
        let poly = Polygon::from_xy(&[(0.0, 0.0), (2.0, 0.0), (0.0, 2.0)]).unwrap();
        let b = Body::from_polygon(&poly, MassSpec::Mass(1.5)).unwrap();
        assert!((b.inertia - 1.5 * 4.0 / 9.0).abs() < 1e-12, "{b:?}");
    }

    #[test]
    fn bad_mass_properties_are_refused_by_name() {
        let poly = part_from_spec("square").unwrap();
        for (spec, field) in [
            (MassSpec::Mass(0.0), "mass"),
            (MassSpec::Mass(-1.0), "mass"),
            (MassSpec::Mass(f64::NAN), "mass"),
            (MassSpec::Density(-2.0), "density"),
            (MassSpec::Density(f64::INFINITY), "density"),
        ] {
            let e = Body::from_polygon(&poly, spec).unwrap_err();
            assert_eq!(e.field, field);
            assert!(e.to_string().contains("> 0"), "{e}");
        }
        assert_eq!(Body::new(1.0, 0.0).unwrap_err().field, "inertia");
        assert_eq!(Body::new(1.0, -3.0).unwrap_err().field, "inertia");
        assert_eq!(Body::new(f64::NAN, 1.0).unwrap_err().field, "mass");
    }
}
