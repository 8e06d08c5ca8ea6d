//! # pinfeed
//!
//! A simulator and planner for orienting planar parts on a conveyor belt with overhead pins and
//! fences. Data flows one way: a scenario is compiled into an immutable scene (part geometry with its
//! limit-surface data, obstacles, settings); a seeded stream of randomly posed parts runs through a
//! discrete-event engine, which calls the contact model — a pure function from (part, pose, obstacle,
//! settings) to a `ContactOutcome` — for each pin or fence encounter; metrics and reports come out
//! the other end. Physics and conventions are described in `docs/physics.md` (quasi-static pushing with Coulomb
//! friction; x along belt travel, y to the left, angles counter-clockwise, degrees at interfaces).
//!
//! Modules: [`geometry`] (polygons, stable states, first contact), [`mechanics`] (the contact
//! model), [`maps`] (configuration maps and their bands), [`scenario`] (TOML scenarios compiled to
//! an immutable scene), [`engine`] (the discrete-event feeder line and its metrics), [`report`]
//! (tables and figures), [`cli`] (the `pinfeed` command).

pub mod cli;
pub mod engine;
pub mod geometry;
pub mod input;
pub mod maps;
pub mod mechanics;
pub mod plan;
pub mod random;
pub mod report;
pub mod scenario;
pub mod sensing;
pub mod statistics;
pub mod study;
pub mod validate;
