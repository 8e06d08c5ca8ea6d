//! One part stream for several scenes (`pinfeed compare`; docs/physics.md#the-line "a run is a pure function of
//! (scenario, seed)").
//!
//! Part i of a run is drawn from its own random stream (seed, i) by the scene's feed and part
//! ([`crate::engine::part_stream`]): its arrival time, orientation, lateral offset and, for a
//! tripod support, its tripod. So two scenes with the same feed, seed, part polygon and support
//! see exactly the same parts, whatever their belts and obstacles. A [`FeedSource`] takes those
//! from a reference scene and imposes them on others:
//!
//! * the feed (number of parts, arrival process, orientation distribution, lateral distribution)
//!   and the seed replace the scene's own;
//! * the part must be the same polygon in metres (shape and scale, to 1e-12 relative) with the same
//!   support kind, or the scene is refused — another part would be another stream. Friction
//!   coefficients may differ: they belong to the obstacles as much as to the part;
//! * the reference's lateral offsets must fit on the scene's belt (within width/2 − a), or the scene
//!   is refused.

use super::scene::{Feed, Lateral, Orientation, Scene, SupportKind};
use crate::geometry::Polygon;
use thiserror::Error;

/// Why a scene cannot run on a reference's part stream.
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
    /// The reference feeds parts wider than this belt allows.
    #[error("the reference feed puts centroids up to {need:.6} m from the centre line, beyond this belt's {reach:.6} m (half its width minus the part's a)")]
    Lateral {
        /// The farthest centroid offset from the centre line the reference feeds (m).
        need: f64,
        /// The farthest this belt allows: half its width minus the part's a (m).
        reach: f64,
    },
}

/// The feed, seed and part of a reference scene.
#[derive(Debug, Clone, PartialEq)]
pub struct FeedSource {
    /// The reference's feed, which replaces each scene's own.
    pub feed: Feed,
    /// The reference's seed, which replaces each scene's own.
    pub seed: u64,
    polygon: Polygon,
    support: SupportKind,
    label: String,
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

impl FeedSource {
    /// The part stream of `scene`.
    pub fn from_scene(scene: &Scene) -> FeedSource {
        FeedSource {
            feed: scene.feed.clone(),
            seed: scene.seed,
            polygon: scene.part.polygon.clone(),
            support: scene.part.support,
            label: scene.part.label.clone(),
        }
    }

    /// Feed parts at orientations uniform on [0°, 360°) instead of the reference's distribution.
    pub fn with_uniform_orientation(mut self) -> FeedSource {
        self.feed.orientation = Orientation::Uniform;
        self
    }

    /// How far from the centre line the feed can put a centroid (m).
    fn lateral_reach(&self) -> f64 {
        match self.feed.lateral {
            Lateral::Fixed(y) => y.abs(),
            Lateral::Uniform { min, max } => min.abs().max(max.abs()),
            Lateral::Normal { lo, hi, .. } => lo.abs().max(hi.abs()),
        }
    }

    /// Make `scene` run on this part stream (see the module docs).
    pub fn apply(&self, scene: &mut Scene) -> Result<(), FeedMismatch> {
        let (a, b) = (self.polygon.vertices(), scene.part.polygon.vertices());
        let tol = 1e-12 * self.polygon.radius();
        let same_polygon =
            a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (*p - *q).norm() <= tol);
        if !same_polygon || scene.part.support != self.support {
            return Err(FeedMismatch::Part {
                reference: describe(&self.label, &self.polygon, self.support),
                found: describe(&scene.part.label, &scene.part.polygon, scene.part.support),
            });
        }
        let reach = scene.belt.width / 2.0 - scene.part.radius;
        let need = self.lateral_reach();
        if need > reach + 1e-12 {
            return Err(FeedMismatch::Lateral { need, reach });
        }
        scene.feed = self.feed.clone();
        scene.seed = self.seed;
        Ok(())
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
    fn the_reference_feed_and_seed_replace_the_scene_s() {
        let reference = scene(
            "shape = \"tripoly2\"\nscale = 0.02",
            0.1,
            "distribution = \"uniform\"\nmin = -0.004\nmax = 0.003",
            9,
        );
        let mut other = scene(
            "shape = \"tripoly2\"\nscale = 0.02\nmu_c = 0.2",
            0.2,
            "distribution = \"fixed\"\nvalue = 0.05",
            2,
        );
        let source = FeedSource::from_scene(&reference);
        source.apply(&mut other).unwrap();
        assert_eq!(other.feed, reference.feed);
        assert_eq!(other.seed, 9);
        // The same stream: part i is drawn identically.
        for i in 0..7 {
            let (p, q) = (
                crate::engine::part_stream::draw_part(&reference, 9, i).unwrap(),
                crate::engine::part_stream::draw_part(&other, 9, i).unwrap(),
            );
            assert_eq!((p.gap, p.theta_rad, p.y), (q.gap, q.theta_rad, q.y));
        }
        let uniform = source.clone().with_uniform_orientation();
        uniform.apply(&mut other).unwrap();
        assert_eq!(other.feed.orientation, Orientation::Uniform);
    }

    #[test]
    fn another_part_or_a_narrow_belt_is_refused() {
        let reference = scene(
            "shape = \"tripoly2\"\nscale = 0.02",
            0.2,
            "distribution = \"uniform\"\nmin = -0.04\nmax = 0.04",
            1,
        );
        let source = FeedSource::from_scene(&reference);
        let fixed = "distribution = \"fixed\"\nvalue = 0.0";
        let mut scaled = scene("shape = \"tripoly2\"\nscale = 0.021", 0.2, fixed, 1);
        assert!(matches!(
            source.apply(&mut scaled),
            Err(FeedMismatch::Part { .. })
        ));
        let mut tripod = scene(
            "shape = \"tripoly2\"\nscale = 0.02\nsupport = \"tripod\"",
            0.2,
            fixed,
            1,
        );
        assert!(matches!(
            source.apply(&mut tripod),
            Err(FeedMismatch::Part { .. })
        ));
        // Half-width 0.06 − a 0.0275 = 0.0325 m < 0.04 m.
        let mut narrow = scene("shape = \"tripoly2\"\nscale = 0.02", 0.12, fixed, 1);
        let e = source.apply(&mut narrow).unwrap_err();
        assert!(matches!(e, FeedMismatch::Lateral { .. }), "{e}");
        assert!(e.to_string().contains("0.040000"), "{e}");
    }
}
