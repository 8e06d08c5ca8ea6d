//! Simple polygons: validation, mass properties, convex hull, radius function and stable states.
//!
//! A part is a simple polygon (convex or concave) stored counter-clockwise in its own frame with the
//! origin at its area centroid (docs/physics.md#the-part). Construction validates the input and normalises it:
//!
//! * at least three vertices, all finite, no vertex repeating its predecessor (within 1e-12 of the
//!   part's size — an edge of 1e-9 of the size is kept), non-zero area, no self-intersection;
//! * clockwise input is reversed to counter-clockwise;
//! * a vertex lying *exactly* on the straight line through its neighbours (turn below 1e-15 of the
//!   edge lengths, so floating-point collinear) is dropped: it does not change the shape, and keeping
//!   it would split a flat side into two edges. Nearly collinear vertices are kept.
//!
//! Scale invariance: validation and the sums run on the vertices divided by a power of two that
//! brings the largest coordinate into [0.5, 1) — an exact division — so every test and every
//! tolerance is the same at any magnitude, and a copy scaled by a power of two gives bit-identical
//! results scaled back. The scaled-back size `a`, area (∝ a²) and polar moment (∝ a⁴) must be
//! finite, normal doubles; a part whose mass properties cannot be represented (a beyond about
//! 1e±75) is refused with [`PolygonError::NotRepresentable`] rather than carrying inf or NaN.
//!
//! Mass properties use the shoelace formulas; `a` is the largest centroid-to-vertex distance.
//! Stable states (docs/physics.md#stable-states) are the orientations θ at which an edge of the convex hull has its outward
//! normal along −y and the foot of the perpendicular from the centroid lies strictly inside that edge:
//! the local minima of the radius function ρ(φ) = max_v v·(cos φ, sin φ).

use super::vec2::{wrap_2pi, Vec2};
use serde::Serialize;
use thiserror::Error;

/// Why a vertex list is not a valid part.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PolygonError {
    /// Fewer than 3 vertices.
    #[error("a polygon needs at least 3 vertices, got {count}")]
    TooFewVertices {
        /// Vertices given.
        count: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate ({x}, {y}); every coordinate must be a finite number")]
    NonFinite {
        /// Index of the vertex.
        index: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// Two consecutive vertices coincide.
    #[error("vertex {index} repeats vertex {previous} (zero-length edge){hint}")]
    RepeatedVertex {
        /// Index of the repeated vertex.
        index: usize,
        /// Index of the vertex it repeats.
        previous: usize,
        /// Advice appended to the message (e.g. when the last vertex repeats the first), or empty.
        hint: &'static str,
    },
    /// All vertices are collinear, or the ring folds onto itself.
    #[error("the polygon has zero area (all vertices are collinear or it folds onto itself)")]
    ZeroArea,
    /// A mass property over- or underflows f64 at the part's size.
    #[error("the part's {quantity} {direction} double precision at this size (a ≈ {a}): give the vertices in a unit where a lies between about 1e-70 and 1e70")]
    NotRepresentable {
        /// Which quantity (e.g. `centroid`).
        quantity: &'static str,
        /// `overflows` or `underflows`.
        direction: &'static str,
        /// The part's size a, approximately, in decimal.
        a: String,
    },
    /// A scale factor that is not positive and finite.
    #[error("scale factor must be a positive finite number, got {0}")]
    BadScale(f64),
    /// Two non-adjacent edges intersect.
    #[error("the polygon is not simple: edge {edge_a} ({a0} -> {a1}) and edge {edge_b} ({b0} -> {b1}) intersect")]
    SelfIntersecting {
        /// Index of the first edge.
        edge_a: usize,
        /// Index of the second edge.
        edge_b: usize,
        /// First vertex of `edge_a`.
        a0: usize,
        /// Second vertex of `edge_a`.
        a1: usize,
        /// First vertex of `edge_b`.
        b0: usize,
        /// Second vertex of `edge_b`.
        b1: usize,
    },
}

/// A validated simple polygon in its own frame: counter-clockwise, centroid at the origin.
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    vertices: Vec<Vec2>,
    /// Where the centroid was in the caller's coordinates (the part frame is the input translated by −offset).
    offset: Vec2,
    area: f64,
    polar_moment: f64,
    radius: f64,
    convex: bool,
    hull: Vec<Vec2>,
    /// Per edge i (vertex i → i + 1): unit direction and length, computed once (the contact
    /// model asks for them at every right-hand side).
    edge_dirs: Vec<Vec2>,
    edge_lens: Vec<f64>,
}

/// Unit directions and lengths of the edges of a closed vertex list (edge i: vertex i → i + 1).
fn edge_data(vertices: &[Vec2]) -> (Vec<Vec2>, Vec<f64>) {
    let m = vertices.len();
    (0..m)
        .map(|i| {
            let d = vertices[(i + 1) % m] - vertices[i];
            (d.normalized(), d.norm())
        })
        .unzip()
}

/// A stable state of a part: orientation and the hull edge it rests on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StableState {
    /// Orientation θ in radians, in [0, 2π) (serialized as `theta`).
    #[serde(rename = "theta")]
    pub theta_rad: f64,
    /// Index of the hull edge (into [`Polygon::hull`]) whose outward normal points along −y.
    pub hull_edge: usize,
    /// Distance from the centroid to that edge (the radius function's local minimum).
    pub height: f64,
}

fn orient(a: Vec2, b: Vec2, c: Vec2) -> f64 {
    (b - a).cross(c - a)
}

fn on_segment(a: Vec2, b: Vec2, p: Vec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Do the closed segments \[p1,p2\] and \[q1,q2\] share a point?
pub fn segments_intersect(p1: Vec2, p2: Vec2, q1: Vec2, q2: Vec2) -> bool {
    let d1 = orient(q1, q2, p1);
    let d2 = orient(q1, q2, p2);
    let d3 = orient(p1, p2, q1);
    let d4 = orient(p1, p2, q2);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on_segment(q1, q2, p1))
        || (d2 == 0.0 && on_segment(q1, q2, p2))
        || (d3 == 0.0 && on_segment(p1, p2, q1))
        || (d4 == 0.0 && on_segment(p1, p2, q2))
}

/// Signed area (positive for counter-clockwise) computed relative to the first vertex.
/// Whether the ring turns the same way, by a clearly non-zero angle, at every vertex, and winds
/// exactly once: then no two of its edges can cross or touch.
fn strictly_convex_ring(points: &[Vec2]) -> bool {
    let n = points.len();
    let mut sign = 0.0_f64;
    let mut turning = 0.0;
    for i in 0..n {
        let e1 = points[(i + 1) % n] - points[i];
        let e2 = points[(i + 2) % n] - points[(i + 1) % n];
        let cross = e1.cross(e2);
        if cross.abs() <= 1e-9 * e1.norm() * e2.norm() || (sign != 0.0 && cross.signum() != sign) {
            return false;
        }
        sign = cross.signum();
        turning += cross.atan2(e1.dot(e2));
    }
    (turning.abs() - std::f64::consts::TAU).abs() < 1e-6
}

fn signed_area(v: &[Vec2]) -> f64 {
    let o = v[0];
    let mut s = 0.0;
    for i in 1..v.len() - 1 {
        s += (v[i] - o).cross(v[i + 1] - o);
    }
    0.5 * s
}

/// A polygon validated and measured in normalised coordinates (largest |coordinate| in [0.5, 1)).
struct Unit {
    /// Counter-clockwise, centroid at the origin.
    vertices: Vec<Vec2>,
    /// Centroid in the normalised input coordinates.
    centroid: Vec2,
    area: f64,
    polar: f64,
    radius: f64,
    convex: bool,
    hull: Vec<Vec2>,
}

/// Validate and measure a vertex list whose coordinates are at most 1 in magnitude (see
/// [`Polygon::new`]); every tolerance is relative to the list's size.
fn validated_unit(points: &[Vec2]) -> Result<Unit, PolygonError> {
    let n = points.len();
    // Size of the part, for relative tolerances.
    let (mut lo, mut hi) = (points[0], points[0]);
    for p in points {
        lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    let size = (hi - lo).norm();
    for i in 0..n {
        let j = (i + 1) % n;
        if (points[j] - points[i]).norm() <= 1e-12 * size {
            let (index, previous) = if j == 0 { (n - 1, 0) } else { (j, i) };
            return Err(PolygonError::RepeatedVertex {
                index,
                previous,
                hint: if j == 0 {
                    " — the ring closes itself; do not repeat the first vertex at the end"
                } else {
                    ""
                },
            });
        }
    }
    let area = signed_area(points);
    // All vertices on one line: say so before any talk of self-intersection.
    if convex_hull(points).len() < 3 {
        return Err(PolygonError::ZeroArea);
    }
    // Simplicity: non-adjacent edges must not touch; adjacent edges must not fold back. A
    // strictly convex ring is simple, and is recognised in O(n) (a 500-gon's hull is checked
    // for every random tripod a planner draws); any other ring gets the O(n²) pairwise test.
    for i in 0..if strictly_convex_ring(points) { 0 } else { n } {
        let (a0, a1) = (points[i], points[(i + 1) % n]);
        for j in i + 1..n {
            let (b0, b1) = (points[j], points[(j + 1) % n]);
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            let hit = if adjacent {
                // Shared vertex: they intersect elsewhere only if collinear and overlapping.
                let (shared, p, q) = if j == i + 1 {
                    (a1, a0, b1)
                } else {
                    (a0, a1, b0)
                };
                let u = p - shared;
                let w = q - shared;
                u.cross(w).abs() <= 1e-15 * u.norm() * w.norm() && u.dot(w) > 0.0
            } else {
                segments_intersect(a0, a1, b0, b1)
            };
            if hit {
                return Err(PolygonError::SelfIntersecting {
                    edge_a: i,
                    edge_b: j,
                    a0: i,
                    a1: (i + 1) % n,
                    b0: j,
                    b1: (j + 1) % n,
                });
            }
        }
    }
    if area.abs() <= 1e-12 * size * size {
        return Err(PolygonError::ZeroArea);
    }
    let mut v: Vec<Vec2> = points.to_vec();
    if area < 0.0 {
        v.reverse();
    }
    // Drop vertices that are exactly collinear with their neighbours.
    let mut k = 0;
    while k < v.len() && v.len() > 3 {
        let m = v.len();
        let prev = v[(k + m - 1) % m];
        let next = v[(k + 1) % m];
        let e1 = v[k] - prev;
        let e2 = next - v[k];
        if e1.cross(e2).abs() <= 1e-15 * e1.norm() * e2.norm() && e1.dot(e2) > 0.0 {
            v.remove(k);
            k = k.saturating_sub(1);
        } else {
            k += 1;
        }
    }
    // Centroid (relative to the first vertex for accuracy).
    let o = v[0];
    let mut a2 = 0.0;
    let mut cx = Vec2::ZERO;
    for i in 1..v.len() - 1 {
        let p = v[i] - o;
        let q = v[i + 1] - o;
        let c = p.cross(q);
        a2 += c;
        cx += (p + q) * c;
    }
    let centroid = o + cx / (3.0 * a2);
    for p in v.iter_mut() {
        *p -= centroid;
    }
    let m = v.len();
    let mut polar = 0.0;
    let mut radius: f64 = 0.0;
    let mut convex = true;
    for i in 0..m {
        let p = v[i];
        let q = v[(i + 1) % m];
        let r = v[(i + 2) % m];
        let c = p.cross(q);
        polar += c * (p.dot(p) + p.dot(q) + q.dot(q));
        radius = radius.max(p.norm());
        if (q - p).cross(r - q) < 0.0 {
            convex = false;
        }
    }
    polar /= 12.0;
    let hull = convex_hull(&v);
    Ok(Unit {
        vertices: v,
        centroid,
        area: area.abs(),
        polar,
        radius,
        convex,
        hull,
    })
}

/// `2^e` for any `e` in [−1022, 1023], exactly.
fn pow2(e: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&e));
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// `x · 2^e` for any `e` (in steps of representable powers of two, so the factor itself never
/// overflows or underflows). Exact unless the result is subnormal, zero or infinite.
fn ldexp(mut x: f64, mut e: i32) -> f64 {
    while e > 1000 {
        x *= pow2(1000);
        e -= 1000;
    }
    while e < -1000 {
        x *= pow2(-1000);
        e += 1000;
    }
    x * pow2(e)
}

/// The power of two `e` with every coordinate of `points` below 2^e in magnitude and the largest at
/// least 2^(e−1) (all points finite, not all zero).
fn magnitude_exponent(points: &[Vec2]) -> i32 {
    let m = points
        .iter()
        .map(|p| p.x.abs().max(p.y.abs()))
        .fold(0.0, f64::max);
    // log2 of a finite positive double is exact enough to pick the exponent; correct by one if
    // rounding landed on the wrong side.
    let mut e = m.log2().floor() as i32 + 1;
    while ldexp(m, -e) >= 1.0 {
        e += 1;
    }
    while e > -1100 && ldexp(m, -(e - 1)) < 1.0 {
        e -= 1;
    }
    e
}

/// `a ≈ r · 2^e` written as a decimal (for messages; never overflows).
fn approx_decimal(r: f64, e: i32) -> String {
    let l = r.log10() + f64::from(e) * std::f64::consts::LOG10_2;
    let exp = l.floor();
    format!("{:.2}e{}", 10f64.powf(l - exp), exp as i64)
}

/// A mass property scaled back from normalised units: it must be a normal, finite double.
fn representable(value: f64, quantity: &'static str, r: f64, e: i32) -> Result<f64, PolygonError> {
    if value.is_normal() {
        return Ok(value);
    }
    Err(PolygonError::NotRepresentable {
        quantity,
        direction: if value.is_infinite() || value.is_nan() {
            "overflows"
        } else {
            "underflows"
        },
        a: approx_decimal(r, e),
    })
}

impl Polygon {
    /// Build a part from a vertex list in any orientation and any unit.
    ///
    /// Every test and sum is computed on the vertices divided by a power of two that brings the
    /// largest coordinate into [0.5, 1) (exact), so validation and the results do not depend on
    /// the magnitude of the input; the mass properties are then scaled back and must be
    /// representable (finite and normal), else [`PolygonError::NotRepresentable`].
    pub fn new(points: &[Vec2]) -> Result<Polygon, PolygonError> {
        let n = points.len();
        if n < 3 {
            return Err(PolygonError::TooFewVertices { count: n });
        }
        for (i, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err(PolygonError::NonFinite {
                    index: i,
                    x: p.x,
                    y: p.y,
                });
            }
        }
        if points.iter().all(|p| p.x == 0.0 && p.y == 0.0) {
            return Err(PolygonError::RepeatedVertex {
                index: 1,
                previous: 0,
                hint: "",
            });
        }
        let e = magnitude_exponent(points);
        let q: Vec<Vec2> = points
            .iter()
            .map(|p| Vec2::new(ldexp(p.x, -e), ldexp(p.y, -e)))
            .collect();
        let unit = validated_unit(&q)?;
        // Scale back: lengths by 2^e, area by 4^e, polar moment by 16^e.
        let a = representable(ldexp(unit.radius, e), "size a", unit.radius, e)?;
        let area = representable(ldexp(ldexp(unit.area, e), e), "area (∝ a²)", unit.radius, e)?;
        let polar = representable(
            ldexp(ldexp(ldexp(ldexp(unit.polar, e), e), e), e),
            "polar moment (∝ a⁴)",
            unit.radius,
            e,
        )?;
        let back = |v: Vec2| Vec2::new(ldexp(v.x, e), ldexp(v.y, e));
        let offset = back(unit.centroid);
        if !offset.is_finite() {
            return Err(PolygonError::NotRepresentable {
                quantity: "centroid",
                direction: "overflows",
                a: approx_decimal(unit.radius, e),
            });
        }
        let vertices: Vec<Vec2> = unit.vertices.iter().map(|&v| back(v)).collect();
        let (edge_dirs, edge_lens) = edge_data(&vertices);
        Ok(Polygon {
            vertices,
            offset,
            area,
            polar_moment: polar,
            radius: a,
            convex: unit.convex,
            hull: unit.hull.iter().map(|&v| back(v)).collect(),
            edge_dirs,
            edge_lens,
        })
    }

    /// Build from `(x, y)` pairs.
    pub fn from_xy(points: &[(f64, f64)]) -> Result<Polygon, PolygonError> {
        let v: Vec<Vec2> = points.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
        Polygon::new(&v)
    }

    /// Vertices, counter-clockwise, in the part frame (centroid at the origin).
    pub fn vertices(&self) -> &[Vec2] {
        &self.vertices
    }
    /// Number of vertices (at least 3).
    pub fn len(&self) -> usize {
        self.vertices.len()
    }
    /// Always false: a valid polygon has at least 3 vertices.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }
    /// Vertex `i` (indices wrap around).
    #[inline]
    pub fn vertex(&self, i: usize) -> Vec2 {
        self.vertices[self.wrap(i)]
    }
    /// `i` modulo the vertex count (the callers' indices exceed it by at most a few turns; the
    /// common case, one past the end, costs no division).
    #[inline]
    fn wrap(&self, i: usize) -> usize {
        let m = self.vertices.len();
        if i < m {
            i
        } else if i < 2 * m {
            i - m
        } else {
            i % m
        }
    }
    /// Unit direction of edge `i` (vertex i → i + 1), the same as `(b − a).normalized()`.
    #[inline]
    pub fn edge_dir(&self, i: usize) -> Vec2 {
        self.edge_dirs[self.wrap(i)]
    }
    /// Length of edge `i`, the same as `(b − a).norm()`.
    #[inline]
    pub fn edge_len(&self, i: usize) -> f64 {
        self.edge_lens[self.wrap(i)]
    }
    /// Edge `i` runs from vertex `i` to vertex `i + 1`.
    #[inline]
    pub fn edge(&self, i: usize) -> (Vec2, Vec2) {
        (self.vertex(i), self.vertex(i + 1))
    }
    /// Unit inward normal of edge `i` (part frame): the edge direction rotated by +90°.
    #[inline]
    pub fn inward_normal(&self, i: usize) -> Vec2 {
        self.edge_dir(i).perp()
    }
    /// Is vertex `i` convex (interior angle < 180°)?
    pub fn vertex_is_convex(&self, i: usize) -> bool {
        let m = self.vertices.len();
        let prev = self.vertex(i + m - 1);
        let p = self.vertex(i);
        let next = self.vertex(i + 1);
        (p - prev).cross(next - p) > 0.0
    }
    /// Centroid of the input vertex list in the caller's coordinates.
    pub fn offset(&self) -> Vec2 {
        self.offset
    }
    /// Area (input units²).
    pub fn area(&self) -> f64 {
        self.area
    }
    /// Polar second moment of area about the centroid, ∫|x|² dA (input units⁴).
    pub fn polar_moment(&self) -> f64 {
        self.polar_moment
    }
    /// `a`: the largest centroid-to-vertex distance.
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// Is the polygon convex?
    pub fn is_convex(&self) -> bool {
        self.convex
    }
    /// Convex hull, counter-clockwise, part frame.
    pub fn hull(&self) -> &[Vec2] {
        &self.hull
    }

    /// The convex hull as a polygon **in this polygon's part frame**: its vertices are
    /// [`Self::hull`]'s, bit for bit, not re-centred on the hull's own centroid as
    /// [`Polygon::new`] would put them, so a point of the hull is the same point of the part (what
    /// a fence touches, pushing about the part's centroid). Its offset is zero (its frame is the
    /// part's); its area, polar moment and size are the hull's about the hull's own centroid.
    pub fn hull_polygon(&self) -> Result<Polygon, PolygonError> {
        let own = Polygon::new(&self.hull)?;
        let (edge_dirs, edge_lens) = edge_data(&self.hull);
        Ok(Polygon {
            vertices: self.hull.clone(),
            offset: Vec2::ZERO,
            hull: self.hull.clone(),
            edge_dirs,
            edge_lens,
            ..own
        })
    }

    /// The same polygon scaled by `k > 0` about its centroid, or why it cannot be: `k` not positive
    /// and finite ([`PolygonError::BadScale`]), or a scaled size, area or polar moment that a
    /// double cannot hold ([`PolygonError::NotRepresentable`]). Use this for factors that come
    /// from input (a scenario's `scale`).
    pub fn try_scaled(&self, k: f64) -> Result<Polygon, PolygonError> {
        if !(k.is_finite() && k > 0.0) {
            return Err(PolygonError::BadScale(k));
        }
        let v: Vec<Vec2> = self.vertices.iter().map(|&p| p * k).collect();
        match Polygon::new(&v) {
            Ok(p) => Ok(p),
            Err(e @ PolygonError::NotRepresentable { .. }) => Err(e),
            // Only rounding (or overflow / underflow of a coordinate) can make a scaled copy of a
            // valid polygon fail a shape test: scale the measured polygon directly instead.
            Err(_) => self.scaled_directly(k),
        }
    }

    /// Scale the stored vertices and mass properties by `k` without re-validating the shape.
    fn scaled_directly(&self, k: f64) -> Result<Polygon, PolygonError> {
        let e = magnitude_exponent(&self.vertices);
        let r = ldexp(self.radius, -e);
        // a·k ≈ r · (k / 2^l) · 2^(e + l), for the message.
        let l = k.log2().round() as i32;
        let (rk, ek) = (r * ldexp(k, -l), e + l);
        let check = |v: f64, q: &'static str| representable(v, q, rk, ek);
        let a = check(self.radius * k, "size a")?;
        let area = check(self.area * k * k, "area (∝ a²)")?;
        let polar = check(self.polar_moment * k * k * k * k, "polar moment (∝ a⁴)")?;
        let vertices: Vec<Vec2> = self.vertices.iter().map(|&p| p * k).collect();
        let (edge_dirs, edge_lens) = edge_data(&vertices);
        Ok(Polygon {
            vertices,
            offset: Vec2::ZERO,
            area,
            polar_moment: polar,
            radius: a,
            convex: self.convex,
            hull: self.hull.iter().map(|&p| p * k).collect(),
            edge_dirs,
            edge_lens,
        })
    }

    /// The same polygon scaled by `k` about its centroid, for factors known to be representable
    /// (such as `1 / a`, which scales any valid polygon to a = 1).
    ///
    /// # Panics
    /// If [`Polygon::try_scaled`] fails: `k` not positive and finite, or a scaled size, area or
    /// polar moment out of double range. Factors from input must go through `try_scaled`.
    pub fn scaled(&self, k: f64) -> Polygon {
        self.try_scaled(k).unwrap_or_else(|e| {
            panic!("Polygon::scaled({k}): {e} (use try_scaled for factors from input)")
        })
    }

    /// The mirror image about the part frame's x axis (y → −y), re-normalised counter-clockwise.
    pub fn mirrored_y(&self) -> Polygon {
        let v: Vec<Vec2> = self
            .vertices
            .iter()
            .map(|&p| Vec2::new(p.x, -p.y))
            .collect();
        Polygon::new(&v).expect("mirroring a valid polygon keeps it valid")
    }

    /// Vertices of the part placed at a pose, in world coordinates.
    pub fn world_vertices(&self, pose: &super::vec2::Pose) -> Vec<Vec2> {
        let mut out = Vec::with_capacity(self.vertices.len());
        self.world_vertices_into(pose, &mut out);
        out
    }

    /// [`Polygon::world_vertices`] into a buffer the caller reuses (one sine and cosine per call;
    /// the same values, bit for bit, as `pose.apply` of each vertex).
    pub fn world_vertices_into(&self, pose: &super::vec2::Pose, out: &mut Vec<Vec2>) {
        let (s, c) = super::vec2::sin_cos(pose.theta_rad);
        let at = pose.position();
        out.clear();
        out.extend(self.vertices.iter().map(|&p| p.rotate_sc(s, c) + at));
    }

    /// Radius (support) function: the extent of the part along the unit direction at angle `phi`.
    pub fn radius_function(&self, phi: f64) -> f64 {
        let u = Vec2::from_angle(phi);
        self.hull
            .iter()
            .map(|p| p.dot(u))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Extent of the part along −y at orientation θ, i.e. −min_v y(v): how far the part reaches below its centroid.
    pub fn depth_below(&self, theta: f64) -> f64 {
        self.radius_function(-std::f64::consts::FRAC_PI_2 - theta)
    }

    /// Stable states (docs/physics.md#stable-states), sorted by θ ascending in [0, 2π).
    pub fn stable_states(&self) -> Vec<StableState> {
        let h = &self.hull;
        let m = h.len();
        let mut out = Vec::new();
        for i in 0..m {
            let a = h[i];
            let b = h[(i + 1) % m];
            let e = b - a;
            let len2 = e.norm2();
            // Foot of the perpendicular from the centroid (origin) onto the edge line.
            let t = -a.dot(e) / len2;
            let tol = 1e-12;
            if t <= tol || t >= 1.0 - tol {
                continue;
            }
            let outward = Vec2::new(e.y, -e.x).normalized();
            // Rotate the outward normal onto −y: θ + angle(outward) = −π/2.
            let theta = wrap_2pi(-std::f64::consts::FRAC_PI_2 - outward.angle());
            let height = a.dot(outward);
            out.push(StableState {
                theta_rad: theta,
                hull_edge: i,
                height,
            });
        }
        out.sort_by(|x, y| x.theta_rad.total_cmp(&y.theta_rad));
        out
    }

    /// Does the part-frame point `p` lie strictly inside the polygon (crossing-number test)?
    pub fn contains(&self, p: Vec2) -> bool {
        ring_contains(&self.vertices, p)
    }

    /// Distance from a part-frame point to the polygon's boundary, with the nearest edge.
    pub fn distance_to_boundary(&self, p: Vec2) -> (f64, usize) {
        let m = self.vertices.len();
        let mut best = (f64::INFINITY, 0);
        for i in 0..m {
            let (a, b) = self.edge(i);
            let e = b - a;
            let t = ((p - a).dot(e) / e.norm2()).clamp(0.0, 1.0);
            let d = (a + e * t - p).norm();
            if d < best.0 {
                best = (d, i);
            }
        }
        best
    }
}

/// Is `p` strictly inside the simple polygon with vertices `ring` (any orientation; crossing-number
/// test)?
pub fn ring_contains(ring: &[Vec2], p: Vec2) -> bool {
    let m = ring.len();
    let mut inside = false;
    for i in 0..m {
        let a = ring[i];
        let b = ring[(i + 1) % m];
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Convex hull by Andrew's monotone chain, counter-clockwise, collinear points removed.
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut p: Vec<Vec2> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut lower: Vec<Vec2> = Vec::new();
    for &q in &p {
        while lower.len() >= 2 && orient(lower[lower.len() - 2], lower[lower.len() - 1], q) <= 0.0 {
            lower.pop();
        }
        lower.push(q);
    }
    let mut upper: Vec<Vec2> = Vec::new();
    for &q in p.iter().rev() {
        while upper.len() >= 2 && orient(upper[upper.len() - 2], upper[upper.len() - 1], q) <= 0.0 {
            upper.pop();
        }
        upper.push(q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deg(x: f64) -> f64 {
        x.to_degrees()
    }

    /// The hull polygon of a concave L stays in the L's frame (the hull's own centroid is
    /// elsewhere): each of its vertices is one of the L's, bit for bit, its edges are the hull's,
    /// and its area and size are those of the hull built on its own.
    #[test]
    fn a_hull_polygon_keeps_the_part_frame() {
        let l = Polygon::from_xy(&[
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.5),
            (0.0, 2.5),
        ])
        .unwrap();
        let own = Polygon::new(l.hull()).unwrap();
        let h = l.hull_polygon().unwrap();
        assert!(!l.is_convex() && h.is_convex());
        assert_eq!(h.len(), 5);
        assert_eq!(h.vertices(), l.hull());
        assert!(h.vertices().iter().all(|v| l.vertices().contains(v)));
        // Built on its own, the hull is re-centred: a fence touching it there would touch a point
        // (0.06, 0.07) away from the part's.
        assert!((own.vertex(0) - h.vertex(0)).norm() > 0.05);
        for k in 0..h.len() {
            assert!((h.edge_dir(k) - own.edge_dir(k)).norm() < 1e-15);
            assert_eq!(h.edge_len(k), own.edge_len(k));
        }
        assert_eq!((h.area(), h.radius()), (own.area(), own.radius()));
        assert_eq!(h.offset(), Vec2::ZERO);
    }

    #[test]
    fn world_vertices_are_each_vertex_posed_bit_for_bit() {
        let p = Polygon::from_xy(&[(-1.5, -0.5), (1.5, -0.5), (0.3, 1.0), (-0.2, 0.4)]).unwrap();
        let mut buf = vec![Vec2::new(9.0, 9.0); 7];
        for k in 0..2000 {
            let t = -7.0 + 0.00713 * k as f64;
            let pose = super::super::vec2::Pose::new(0.1 * t, -0.37 * t, t);
            p.world_vertices_into(&pose, &mut buf);
            assert_eq!(buf.len(), p.len());
            for (w, &v) in buf.iter().zip(&p.vertices) {
                let q = pose.apply(v);
                assert_eq!(
                    (w.x.to_bits(), w.y.to_bits()),
                    (q.x.to_bits(), q.y.to_bits())
                );
            }
        }
    }

    #[test]
    fn triangle_properties() {
        let p = Polygon::from_xy(&[(-1.5, -0.5), (1.5, -0.5), (0.0, 1.0)]).unwrap();
        assert!((p.area() - 2.25).abs() < 1e-12);
        assert!(p.offset().norm() < 1e-12);
        assert!(p.is_convex());
        assert!((p.radius() - (1.5f64.powi(2) + 0.25).sqrt()).abs() < 1e-12);
        let s: Vec<f64> = p.stable_states().iter().map(|s| deg(s.theta_rad)).collect();
        assert_eq!(s.len(), 3);
        for (got, want) in s.iter().zip([0.0, 135.0, 225.0]) {
            assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        }
    }

    #[test]
    fn convex_fast_path_accepts_convex_rings_and_leaves_stars_to_the_pairwise_test() {
        let ring = |n: usize, step: usize| -> Vec<Vec2> {
            (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * (k * step) as f64 / n as f64;
                    Vec2::new(t.cos(), t.sin())
                })
                .collect()
        };
        // A regular 500-gon, either way round: convex, simple, accepted.
        assert!(strictly_convex_ring(&ring(500, 1)));
        let mut cw = ring(500, 1);
        cw.reverse();
        assert!(strictly_convex_ring(&cw));
        assert_eq!(Polygon::new(&cw).unwrap().len(), 500);
        // A pentagram turns the same way at every vertex but winds twice: not taken as convex,
        // and the pairwise test finds its crossing edges.
        let star = ring(5, 2);
        assert!(!strictly_convex_ring(&star));
        assert!(matches!(
            Polygon::new(&star),
            Err(PolygonError::SelfIntersecting { .. })
        ));
        // A collinear vertex is left to the general path (which drops it).
        let sq = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        assert!(!strictly_convex_ring(&sq));
        assert_eq!(Polygon::new(&sq).unwrap().len(), 4);
    }

    #[test]
    fn clockwise_input_is_normalised() {
        let p = Polygon::from_xy(&[(0.0, 1.0), (1.5, -0.5), (-1.5, -0.5)]).unwrap();
        assert!(signed_area(p.vertices()) > 0.0);
    }

    #[test]
    fn polar_moment_of_square() {
        let p = Polygon::from_xy(&[(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]).unwrap();
        // ∫(x²+y²) over a 2x2 square about its centre = 2 * (2*2^3/12) = 8/3 * 2 = 5.333..
        assert!((p.polar_moment() - 2.0 * 2.0 * 8.0 / 12.0).abs() < 1e-12);
    }

    #[test]
    fn collinear_middle_vertex_dropped() {
        let p = Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)])
            .unwrap();
        assert_eq!(p.len(), 4);
    }

    #[test]
    fn rejections() {
        assert!(matches!(
            Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0)]),
            Err(PolygonError::TooFewVertices { count: 2 })
        ));
        assert!(matches!(
            Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]),
            Err(PolygonError::ZeroArea)
        ));
        assert!(matches!(
            Polygon::from_xy(&[(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)]),
            Err(PolygonError::SelfIntersecting { .. })
        ));
        assert!(matches!(
            Polygon::from_xy(&[(0.0, 0.0), (f64::NAN, 1.0), (1.0, 0.0)]),
            Err(PolygonError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            Polygon::from_xy(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 1.0)]),
            Err(PolygonError::RepeatedVertex { .. })
        ));
        // A spike: the ring runs out and straight back along the same line.
        assert!(Polygon::from_xy(&[(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)]).is_err());
    }

    #[test]
    fn ldexp_and_magnitude_exponent_are_exact_at_the_extremes() {
        assert_eq!(ldexp(1.0, 1023), 2f64.powi(1023));
        assert_eq!(ldexp(f64::MAX, -1024), f64::MAX / 2f64.powi(1023) / 2.0);
        assert_eq!(ldexp(5e-324, 1074), 1.0);
        assert_eq!(ldexp(1.0, -1076), 0.0);
        for m in [5e-324, 1e-310, 2.2e-308, 0.75, 1.0, 1e300, f64::MAX] {
            let e = magnitude_exponent(&[Vec2::new(-m, 0.0)]);
            let q = ldexp(m, -e);
            assert!((0.5..1.0).contains(&q), "{m:e}: e = {e}, q = {q}");
        }
    }

    #[test]
    fn power_of_two_copies_are_bit_identical() {
        let v = [(0.3, -0.1), (1.7, 0.2), (0.4, 1.1), (-0.2, 0.5)];
        let p = Polygon::from_xy(&v).unwrap();
        for e in [-250, -1, 7, 240] {
            let k = 2f64.powi(e);
            let s: Vec<(f64, f64)> = v.iter().map(|&(x, y)| (x * k, y * k)).collect();
            let q = Polygon::from_xy(&s).unwrap();
            assert_eq!(q.radius(), p.radius() * k);
            assert_eq!(q.area(), p.area() * k * k);
            assert_eq!(q.polar_moment(), p.polar_moment() * k * k * k * k);
            assert_eq!(q.offset(), p.offset() * k);
            let thetas = |x: &Polygon| {
                x.stable_states()
                    .iter()
                    .map(|s| s.theta_rad)
                    .collect::<Vec<_>>()
            };
            assert_eq!(thetas(&q), thetas(&p));
        }
    }

    #[test]
    fn concave_hull() {
        let l = Polygon::from_xy(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ])
        .unwrap();
        assert!(!l.is_convex());
        assert_eq!(l.hull().len(), 5);
        assert!((l.area() - 3.0).abs() < 1e-12);
        assert!(!l.vertex_is_convex(3));
        assert!(l.contains(Vec2::ZERO - l.offset() + Vec2::new(0.5, 0.5)));
        assert!(!l.contains(Vec2::ZERO - l.offset() + Vec2::new(1.5, 1.5)));
    }
}
