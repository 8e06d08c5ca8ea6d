//! One part for several scenes (`pinfeed compare`; docs/physics.md#the-line "a run is a pure
//! function of (scenario, seed)").
//!
//! Part i of a run is drawn from its own random stream (seed, i) by the scene's feed and part
//! ([`crate::engine::part_stream`]): its arrival time, orientation, lateral offset and, for a
//! tripod support, its tripod. So two scenes with the same seed, orientation and lateral
//! distributions, part polygon and support see exactly the same parts in the same order, whatever
//! their belts, obstacles and headways. `pinfeed compare` keeps each scene's own feed (a design is
//! measured at the rate and on the feed its file was made for, so the numbers do not depend on the
//! order of the files) and imposes only what the user names ([`FeedOverrides`]); the part must be
//! the same polygon in metres (shape and scale, to 1e-12 relative) with the same support kind, or
//! the scene is refused ([`same_part`]): another part would be another comparison. Friction
//! coefficients may differ: they belong to the obstacles as much as to the part.

use super::limits;
use super::scene::{Orientation, Scene, SupportKind};
use crate::geometry::Polygon;
use thiserror::Error;

/// Why a scene cannot be compared with a reference scene.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FeedMismatch {
    /// Another part: the stream would differ.
    #[error("its part ({found}) is not the reference's ({reference}): the same part stream needs the same shape, scale and support")]
    Part {
        /// The reference's part (label, a and support).
        reference: String,
        /// This scene's part, described the same way.
        found: String,
    },
}

fn describe(label: &str, polygon: &Polygon, support: SupportKind) -> String {
    format!(
        "{label}, a = {:.6} m, {} support",
        polygon.radius(),
        match support {
            SupportKind::Uniform => "uniform",
            SupportKind::Tripod => "tripod",
        }
    )
}

/// Is `scene`'s part the `reference`'s (same polygon in metres to 1e-12 relative, same support)?
pub fn same_part(reference: &Scene, scene: &Scene) -> Result<(), FeedMismatch> {
    let (p, q) = (&reference.part, &scene.part);
    let (a, b) = (p.polygon.vertices(), q.polygon.vertices());
    let tol = 1e-12 * p.polygon.radius();
    let same_polygon = a.len() == b.len() && a.iter().zip(b).all(|(u, v)| (*u - *v).norm() <= tol);
    if !same_polygon || p.support != q.support {
        return Err(FeedMismatch::Part {
            reference: describe(&p.label, &p.polygon, p.support),
            found: describe(&q.label, &q.polygon, q.support),
        });
    }
    Ok(())
}

/// What the user imposes on every scene's feed (None / false: each keeps its file's own).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FeedOverrides {
    /// The seed of every scene.
    pub seed: Option<u64>,
    /// The number of parts of every scene, in [1, 10⁹].
    pub parts: Option<u64>,
    /// The (mean) time between arrivals of every scene (s), in [`limits::HEADWAY`]; each keeps
    /// its arrival process (periodic or Poisson).
    pub headway: Option<f64>,
    /// Orientations uniform on [0°, 360°) instead of each file's distribution.
    pub uniform_orientation: bool,
}

/// An override out of its range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OverrideError {
    /// `--parts` out of range.
    #[error("--parts must lie in [1, 1000000000], got {0}")]
    Parts(u64),
    /// `--headway` out of range or not a number.
    #[error("--headway must lie in [{lo}, {hi}] s, got {0}", lo = limits::HEADWAY.0, hi = limits::HEADWAY.1)]
    Headway(f64),
}

impl FeedOverrides {
    /// Check the overrides' ranges.
    pub fn check(&self) -> Result<(), OverrideError> {
        if let Some(n) = self.parts.filter(|n| !(1..=1_000_000_000).contains(n)) {
            return Err(OverrideError::Parts(n));
        }
        if let Some(h) = self
            .headway
            .filter(|h| !(limits::HEADWAY.0..=limits::HEADWAY.1).contains(h))
        {
            return Err(OverrideError::Headway(h));
        }
        Ok(())
    }

    /// Impose the overrides on `scene` (their ranges checked by [`FeedOverrides::check`]).
    pub fn apply(&self, scene: &mut Scene) {
        scene.seed = self.seed.unwrap_or(scene.seed);
        let feed = &mut scene.feed;
        feed.parts = self.parts.unwrap_or(feed.parts);
        if let Some(h) = self.headway {
            feed.arrival = feed.arrival.with_headway(h);
        }
        if self.uniform_orientation {
            feed.orientation = Orientation::Uniform;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn scene(part: &str, width: f64, lateral: &str, seed: u64) -> Scene {
        let text = format!(
            "seed = {seed}\n[belt]\nspeed = 0.05\nwidth = {width}\nlength = 0.5\n[part]\n{part}\n\
             [feed]\nparts = 7\narrival = \"poisson\"\nheadway = 3.0\norientation = \"stable\"\n\
             jitter = 2.0\n[feed.lateral]\n{lateral}\n[goal]\nany = true\n"
        );
        super::super::parse(Path::new("t.toml"), &text).unwrap()
    }

    #[test]
    fn overrides_replace_only_what_they_name() {
        let lateral = "distribution = \"uniform\"\nmin = -0.004\nmax = 0.003";
        let reference = scene("shape = \"tripoly2\"\nscale = 0.02", 0.1, lateral, 9);
        let mut other = reference.clone();
        FeedOverrides::default().apply(&mut other);
        assert_eq!((&other.feed, other.seed), (&reference.feed, 9));
        let o = FeedOverrides {
            seed: Some(4),
            parts: Some(3),
            headway: Some(1.5),
            uniform_orientation: true,
        };
        o.apply(&mut other);
        assert_eq!(other.seed, 4);
        assert_eq!(other.feed.parts, 3);
        // The arrival process stays Poisson; only its mean changes.
        assert_eq!(
            other.feed.arrival,
            crate::scenario::Arrival::Poisson { headway: 1.5 }
        );
        assert_eq!(other.feed.orientation, Orientation::Uniform);
        assert_eq!(other.feed.lateral, reference.feed.lateral);
        for bad in [
            FeedOverrides {
                parts: Some(0),
                ..o
            },
            FeedOverrides {
                headway: Some(0.0),
                ..o
            },
            FeedOverrides {
                headway: Some(f64::NAN),
                ..o
            },
        ] {
            assert!(bad.check().is_err(), "{bad:?}");
        }
        assert!(o.check().is_ok());
    }

    #[test]
    fn another_part_is_refused() {
        let fixed = "distribution = \"fixed\"\nvalue = 0.0";
        let reference = scene("shape = \"tripoly2\"\nscale = 0.02", 0.2, fixed, 1);
        let friction = scene(
            "shape = \"tripoly2\"\nscale = 0.02\nmu_c = 0.2",
            0.3,
            fixed,
            2,
        );
        assert_eq!(same_part(&reference, &friction), Ok(()));
        let scaled = scene("shape = \"tripoly2\"\nscale = 0.021", 0.2, fixed, 1);
        assert!(matches!(
            same_part(&reference, &scaled),
            Err(FeedMismatch::Part { .. })
        ));
        let tripod = scene(
            "shape = \"tripoly2\"\nscale = 0.02\nsupport = \"tripod\"",
            0.2,
            fixed,
            1,
        );
        assert!(matches!(
            same_part(&reference, &tripod),
            Err(FeedMismatch::Part { .. })
        ));
    }
}
