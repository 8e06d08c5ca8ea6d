//! Random polygons shared by the geometry and CLI fuzz tests.

use pinfeed::geometry::Vec2;
use proptest::prelude::*;

/// Star-shaped polygon about the origin with a vertex count in `vertices`: increasing angles (every
/// gap < 180°, so the ring is simple) with radii in [0.2, 1].
pub fn star_polygon(vertices: std::ops::Range<usize>) -> impl Strategy<Value = Vec<(f64, f64)>> {
    vertices
        .prop_flat_map(|n| {
            (
                prop::collection::vec(1.0f64..1.9, n),
                prop::collection::vec(0.2f64..1.0, n),
                0.0f64..std::f64::consts::TAU,
            )
        })
        .prop_map(|(gaps, radii, start)| {
            let total: f64 = gaps.iter().sum();
            let mut phi = start;
            gaps.iter()
                .zip(&radii)
                .map(|(g, r)| {
                    let v = Vec2::from_angle(phi) * *r;
                    phi += g / total * std::f64::consts::TAU;
                    (v.x, v.y)
                })
                .collect()
        })
}
