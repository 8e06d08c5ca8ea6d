//! TEMPORARY stub (replaced by the limit-surface branch).
pub mod points;
pub mod uniform;
pub use uniform::Dissipation;
