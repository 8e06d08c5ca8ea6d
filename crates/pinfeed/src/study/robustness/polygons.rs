//! Random and mutated vertex lists for fuzzing: stars at magnitudes 10⁻³⁰⁰ … 10³⁰⁰, far from the
//! origin, near-collinear, near-duplicate vertices, self-intersecting orders and random points,
//! through [`Polygon::new`] and the part description (area, centroid, a, polar moment, stable
//! states, the contact model). A refusal must name its cause; an accepted part must have finite,
//! positive area, a and polar moment, finite vertices and stable states.

use super::{all_finite, CaseReport, Class};
use crate::geometry::{Polygon, Vec2};
use crate::mechanics::{PartModel, Support};
use crate::random::ChaCha8Rng;
use rand::RngExt;
use std::f64::consts::TAU;

/// What a case of the polygons target is (in the fuzz report).
pub const DESCRIPTION: &str = "vertex lists of 3–12 vertices: stars at magnitudes 10^-300…10^300, stars offset far from the origin, near-collinear triangles, near-duplicate vertices, self-intersecting orders and random points, through Polygon::new and the part description (area, centroid, a, polar moment, stable states, contact model)";

/// A generated vertex list.
pub fn vertices(rng: &mut ChaCha8Rng) -> Vec<Vec2> {
    let mag = 10f64.powf(rng.random_range(-300.0..300.0));
    let n = rng.random_range(3..=12usize);
    let star = |rng: &mut ChaCha8Rng, n: usize| -> Vec<Vec2> {
        let mut angles: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * TAU).collect();
        angles.sort_by(f64::total_cmp);
        angles
            .iter()
            .map(|&t| {
                let r = 0.1 + 0.9 * rng.random::<f64>();
                Vec2::new(r * t.cos(), r * t.sin())
            })
            .collect()
    };
    let mut v = match rng.random_range(0..6u32) {
        0 => star(rng, n),
        1 => {
            let off = Vec2::new(1.0, 1.0) * 10f64.powf(rng.random_range(0.0..300.0));
            star(rng, n).into_iter().map(|p| p + off).collect()
        }
        2 => {
            let eps = 10f64.powf(rng.random_range(-20.0..-1.0));
            vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.5, eps),
            ]
        }
        3 => {
            let mut s = star(rng, n);
            let i = rng.random_range(0..s.len());
            let eps = 10f64.powf(rng.random_range(-18.0..-6.0));
            let p = s[i] + Vec2::new(eps, -eps);
            s.insert(i + 1, p);
            s
        }
        4 => {
            let mut s = star(rng, n.max(4));
            let i = rng.random_range(0..s.len());
            let j = rng.random_range(0..s.len());
            s.swap(i, j);
            s
        }
        _ => (0..n)
            .map(|_| Vec2::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5))
            .collect(),
    };
    for p in v.iter_mut() {
        *p = *p * mag;
    }
    v
}

/// `pinfeed part --vertices "…"` for a vertex list.
pub fn command(v: &[Vec2]) -> String {
    let vs = v
        .iter()
        .map(|p| format!("{:e},{:e}", p.x, p.y))
        .collect::<Vec<_>>()
        .join(" ");
    format!("pinfeed part --vertices \"{vs}\"")
}

/// Check a vertex list.
pub fn run(v: &[Vec2]) -> CaseReport {
    let poly = match Polygon::new(v) {
        Ok(p) => p,
        Err(e) => {
            return if e.to_string().trim().is_empty() {
                CaseReport::with(Class::Unlocated, command(v))
            } else {
                CaseReport::new(Class::Named)
            }
        }
    };
    let mut numbers = vec![
        poly.area(),
        poly.radius(),
        poly.polar_moment(),
        poly.offset().x,
        poly.offset().y,
    ];
    numbers.extend(poly.vertices().iter().flat_map(|p| [p.x, p.y]));
    numbers.extend(poly.stable_states().iter().map(|s| s.theta_rad));
    let positive = poly.area() > 0.0 && poly.radius() > 0.0 && poly.polar_moment() > 0.0;
    if !all_finite(&numbers) || !positive {
        return CaseReport::with(
            Class::NonFinite,
            format!(
                "accepted with area {:e}, a {:e}, polar moment {:e}, centroid ({:e}, {:e}): {}",
                poly.area(),
                poly.radius(),
                poly.polar_moment(),
                poly.offset().x,
                poly.offset().y,
                command(v)
            ),
        );
    }
    match PartModel::new(&poly, &Support::Uniform) {
        Ok(_) => CaseReport::new(Class::Success),
        Err(e) if e.to_string().trim().is_empty() => CaseReport::with(Class::Unlocated, command(v)),
        Err(_) => CaseReport::new(Class::Named),
    }
}

/// One polygon case.
pub fn case(rng: &mut ChaCha8Rng) -> CaseReport {
    run(&vertices(rng))
}

/// The case as a command line.
pub fn input(rng: &mut ChaCha8Rng) -> String {
    command(&vertices(rng))
}
