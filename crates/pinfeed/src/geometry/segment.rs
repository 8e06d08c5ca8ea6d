//! Distances between points and segments, shared by the engine's overlap checks and the scenario's
//! neighbour lists (a lower layer than both, so neither imports the other).

pub use super::polygon::segments_intersect;
use super::Vec2;

/// Distance from point `p` to segment [a, b].
pub fn point_segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let e = b - a;
    let l2 = e.norm2();
    let t = if l2 > 0.0 {
        ((p - a).dot(e) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + e * t - p).norm()
}

/// Distance between segments [p1, p2] and [q1, q2] (0 if they intersect).
pub fn segment_distance(p1: Vec2, p2: Vec2, q1: Vec2, q2: Vec2) -> f64 {
    if segments_intersect(p1, p2, q1, q2) {
        return 0.0;
    }
    point_segment_distance(p1, q1, q2)
        .min(point_segment_distance(p2, q1, q2))
        .min(point_segment_distance(q1, p1, p2))
        .min(point_segment_distance(q2, p1, p2))
}
