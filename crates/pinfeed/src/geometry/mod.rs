//! Plane geometry of parts: vectors and poses, validated polygons with their mass properties, convex
//! hull, radius function and stable states, named parts, and the first-contact query between a part
//! and a pin.

pub mod cad;
pub mod first_contact;
pub mod named;
pub mod polygon;
pub mod segment;
pub mod vec2;

pub use first_contact::{first_contact, first_contact_travelling_x, Feature, FirstContact};
pub use named::{part_from_spec, part_from_spec_with, PartSpecError};
pub use polygon::{Polygon, PolygonError, StableState};
pub use vec2::{sin_cos, wrap_2pi, wrap_deg, wrap_pi, Pose, Vec2};
