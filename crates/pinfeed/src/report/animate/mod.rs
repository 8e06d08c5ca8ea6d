//! `pinfeed run --animate FILE.svg`: the line seen from above as an animated SVG (SMIL
//! `<animate>`, `<animateTransform>`; browsers such as Chromium play it), to scale with equal
//! metres on both axes (world frame of docs/physics.md#frames: x along travel, y to the left, drawn upwards).
//!
//! The renderer works over plain data, [`Animation`]: the belt, the part's outline in its own
//! frame, the obstacles (a pin's lateral position and raised/withdrawn state as knots in time, so
//! moving and retractable pins need nothing new here), the sample parts' world poses in time, and
//! timed marks (sensor readings, controller decisions, actuations, late commands). [`from_run`]
//! fills it from what a run records today; a controller can fill `track` and `marks` later.
//!
//! Time: simulated time [t_start, t_end] plays in `dur = (t_end − t_start) / speedup` seconds and
//! loops. Every animation runs over the whole loop (`dur`, `repeatCount="indefinite"`) with
//! `keyTimes` u = (t − t_start)/(t_end − t_start) ∈ [0, 1], so all of them restart together.
//! Between recorded poses a part moves linearly (exact for a free ride; a push is recorded at the
//! contact model's steps) and rotates about its centroid: the outer group translates to the
//! centroid, an inner group rotates by −θ (the SVG y axis points down, so a counter-clockwise
//! world turn is a clockwise SVG one). Poses are thinned (Douglas–Peucker in time, keeping the
//! drawing within [`POSE_TOLERANCE_PX`] of the recorded motion) to at most [`MAX_KEYS`] keyframes
//! per part, and numbers are written with limited precision, so a dozen parts stay well under
//! 1 MB. A part is drawn neutral while it rides, takes its outcome colour
//! ([`super::plot_line::outcome_colour`]) when it ends, and stays there [`END_HOLD_S`] before it
//! goes.
//!
//! * [`model`]: the data, its limits and the loop's length;
//! * [`extract`]: the data from a line run ([`from_run`]);
//! * `keyframes`: poses to SVG keyframes, thinned;
//! * `layout`: the world → SVG mapping and number formatting;
//! * `svg`: the document ([`render`]).

pub mod extract;
mod keyframes;
mod layout;
pub mod model;
mod svg;

pub use extract::{from_run, DEFAULT_PARTS};
pub use model::*;
pub use svg::render;
