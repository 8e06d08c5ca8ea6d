//! TEMPORARY stub (replaced by the limit-surface branch).
use crate::geometry::{Polygon, Vec2};
#[derive(Debug, Clone, Copy)]
pub struct Dissipation {
    pub value: f64,
    pub grad: [f64; 3],
    pub hess: [[f64; 3]; 3],
}
pub struct UniformSurface {
    c: f64,
}
impl UniformSurface {
    pub fn new(poly: &Polygon) -> Self {
        let _ = poly;
        UniformSurface { c: 0.5 }
    }
    pub fn i0_g(&self, _r: Vec2) -> (f64, Vec2) {
        unimplemented!()
    }
    pub fn k_matrix(&self, _r: Vec2) -> [f64; 3] {
        unimplemented!()
    }
    pub fn eval(&self, _xi: [f64; 3], _hessian: bool) -> Dissipation {
        unimplemented!()
    }
    pub fn ellipsoid_c(&self) -> f64 {
        self.c
    }
}
