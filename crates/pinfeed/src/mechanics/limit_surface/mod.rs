//! Limit surfaces of planar sliding (docs/physics.md#limit-surface): the support's frictional dissipation
//! D(ξ) = ∫ p(x) |u(x)| dA, u(x) = v + ω ẑ×x, as a function of the part twist ξ = [vx, vy, ω]
//! (part frame, centroid at the origin), with its gradient and Hessian.
//!
//! D is convex and 1-homogeneous; its gradient ∇D(ξ) = ∫ p Jᵀ û dA, J(x) = `[[1, 0, −y], [0, 1,
//! x]]`, is the friction load the part exerts on the support, i.e. the friction LOAD on the part is
//! −∇D, and the image of ξ ↦ ∇D is the limit surface. Everything here is for unit total load and μs
//! = 1: callers multiply by μs m g.
//!
//! * [`uniform`] — uniform pressure over a simple polygon (convex or concave): closed form per edge
//!   near the part, Gauss quadrature of the twist-form integrand far from it (and at pure
//!   translation).
//! * [`points`] — a finite set of weighted support points (e.g. a tripod): exact sums.

pub mod points;
pub mod uniform;

pub use points::PointSupport;
pub use uniform::UniformSurface;

/// Dissipation D(ξ) and its derivatives for normalised load (total load 1, μs = 1).
///
/// * `value` = D(ξ) = ∫ p |u| dA (units: velocity).
/// * `grad` = ∇D = ∫ p Jᵀ û dA = [fx, fy, m]: force (dimensionless) and moment about the centroid
///   (length) that the part's friction exerts on the support; the load on the part is −`grad`.
/// * `hess` = ∫ p Jᵀ (I − ûûᵀ) J / |u| dA: symmetric, positive semidefinite, `hess · ξ = 0`;
///   all zeros when it was not requested.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dissipation {
    /// D(ξ) (units: velocity).
    pub value: f64,
    /// ∇D = [fx, fy, m] (see above).
    pub grad: [f64; 3],
    /// The Hessian of D (zeros when not requested).
    pub hess: [[f64; 3]; 3],
}

impl Dissipation {
    /// D = 0, ∇D = 0, H = 0.
    pub const ZERO: Dissipation = Dissipation {
        value: 0.0,
        grad: [0.0; 3],
        hess: [[0.0; 3]; 3],
    };
}
