//! The figure of one pass (`pinfeed contact --plot`): the part's poses along the pass with the
//! pin or the fence, titled with the case's settings ([`crate::report::plot_contact`]).

use super::{case_fence, case_geometry, Case};
use crate::geometry::{Polygon, Pose, Vec2};
use crate::mechanics::{ContactOutcome, TraceSample};
use crate::report::plot_contact::{plot_contact, PassObstacle};
use std::path::Path;

/// Draw the pass of case `c` over `poly` (its outcome `out` and `trace`) into the SVG file `path`.
pub fn plot(
    c: &Case,
    poly: &Polygon,
    out: &ContactOutcome,
    trace: &[TraceSample],
    path: &Path,
) -> anyhow::Result<()> {
    let (pose, obstacle) = pass_obstacle(poly, c);
    plot_contact(poly, pose, &obstacle, out, trace, &plot_title(c), path)
}

/// The initial pose of a case and its obstacle as the plot draws it: the pin (start, radius,
/// lateral speed) or the fence segment.
fn pass_obstacle(poly: &Polygon, c: &Case) -> (Pose, PassObstacle) {
    let (pose, start) = case_geometry(poly, c);
    let obstacle = match c.fence {
        Some((angle, length)) => {
            let fence = case_fence(poly, c, angle, length);
            PassObstacle::Fence {
                start: fence.start,
                end: fence.start + Vec2::from_angle(fence.angle_rad) * fence.length,
            }
        }
        None => PassObstacle::Pin {
            start,
            radius: c.pin_radius,
            lateral_speed: c.pin_speed,
        },
    };
    (pose, obstacle)
}

/// The plot's title: the part, θ0, d, the friction and the model (and the fence's angle).
fn plot_title(c: &Case) -> String {
    match c.fence {
        Some((angle, _)) => format!(
            "{} θ0={}° d={} fence α={}° μf={} ({})",
            c.part,
            c.theta0_deg,
            c.d,
            angle,
            c.mu_c,
            c.model.name()
        ),
        None => format!(
            "{} θ0={}° d={} μc={} ({})",
            c.part,
            c.theta0_deg,
            c.d,
            c.mu_c,
            c.model.name()
        ),
    }
}
