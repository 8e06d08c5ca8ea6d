//! TEMPORARY stub (replaced by the limit-surface branch).
use super::Dissipation;
use crate::geometry::Vec2;
pub struct PointSupport {
    pub points: Vec<Vec2>,
    pub weights: Vec<f64>,
}
impl PointSupport {
    pub fn new(points: Vec<Vec2>, weights: Vec<f64>) -> Result<Self, String> {
        Ok(PointSupport { points, weights })
    }
    pub fn eval(&self, _xi: [f64; 3], _hessian: bool) -> Dissipation {
        unimplemented!()
    }
    pub fn ellipsoid_c(&self) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(p, w)| p.norm() * w)
            .sum()
    }
}
