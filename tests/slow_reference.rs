//! The independent slow reference (`tests/reference`) checked on its own, then compared with the
//! production contact model (`pinfeed::mechanics::push`, exact fidelity, default tolerance) over
//! random whole pushes (issue 11, "an independent slow reference inside the tests").
//!
//! Cases (seeded, deterministic): random convex polygons with 3–8 vertices (points on a random
//! ellipse, at a random scale), θ0 uniform, d uniform over the range that touches, μc ∈ [0, 1.5]
//! (a few exactly 0), point pins. Cases are skipped — counted, and the count bounded — when
//! (decided from the initial geometry, before either model runs):
//! * the first touch is within 0.002·a of a vertex (which edge is struck is ill-conditioned);
//! * Mason's vote is nearly a tie: the median of the centroid's signed distances from the lines of
//!   v_pin, f_L, f_R is below 0.01·a (a push nearly through the centroid: metastable, the sense of
//!   rotation is decided by rounding).
//!
//! Cases the production model does not finish with status `ok`, and cases the reference cannot
//! finish (travel limit, a pin hooked on a vertex, h and h/2 ending differently), are also skipped,
//! counted and bounded. Every other case must agree: final orientation within
//! max(3·(reference's error estimate), 0.05°), centroid within max(3·estimate, 1e-3·a).

mod common;
mod reference;

use pinfeed::geometry::{Polygon, Pose, Vec2};
use pinfeed::mechanics::{
    first_instant, mason_vote, push, ContactSettings, Fidelity, PartModel, Pin, Support,
};
use rayon::prelude::*;
use reference::{Part, RefStatus, Rng, Twist, V};
use std::f64::consts::PI;

/// A random convex polygon: 3–8 points on an ellipse (distinct directions at least 0.25 rad
/// apart), rotated and scaled at random.
fn random_polygon(rng: &mut Rng) -> Vec<V> {
    let n = 3 + (rng.next_u64() % 6) as usize;
    loop {
        let mut ang: Vec<f64> = (0..n).map(|_| rng.range(0.0, 2.0 * PI)).collect();
        ang.sort_by(|a, b| a.total_cmp(b));
        let gap_ok = (0..n).all(|i| {
            let next = if i + 1 < n {
                ang[i + 1]
            } else {
                ang[0] + 2.0 * PI
            };
            next - ang[i] > 0.25
        });
        if !gap_ok {
            continue;
        }
        let b = rng.range(0.35, 1.0);
        let rot = rng.range(0.0, 2.0 * PI);
        let scale = 10f64.powf(rng.range(-1.0, 1.0));
        let off = V::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        return ang
            .iter()
            .map(|&t| (V::new(t.cos(), b * t.sin()).rot(rot) + off) * scale)
            .collect();
    }
}

fn library_polygon(verts: &[V]) -> Polygon {
    let pts: Vec<Vec2> = verts.iter().map(|p| Vec2::new(p.x, p.y)).collect();
    Polygon::new(&pts).expect("a convex polygon is valid")
}

/// The reference part on exactly the library's (centred) vertices.
fn reference_part(poly: &Polygon) -> Part {
    let v: Vec<V> = poly.vertices().iter().map(|p| V::new(p.x, p.y)).collect();
    Part::new(&v).expect("convex CCW")
}

#[derive(Debug, Clone)]
struct Case {
    verts: Vec<V>,
    theta0: f64,
    d: f64,
    mu: f64,
}

fn random_case(seed: u64) -> Case {
    let mut rng = Rng(0x5EED_0000 + seed);
    let verts = random_polygon(&mut rng);
    let theta0 = rng.range(0.0, 2.0 * PI);
    let mu = if rng.uniform() < 0.05 {
        0.0
    } else {
        rng.range(0.0, 1.5)
    };
    // d uniform over the touching range of the part at θ0 (centroid at the origin).
    let part = reference_part(&library_polygon(&verts));
    let ys = part.verts.iter().map(|p| p.rot(theta0).y);
    let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
        (l.min(y), h.max(y))
    });
    let d = rng.range(lo, hi) / part.a;
    Case {
        verts,
        theta0,
        d,
        mu,
    }
}

/// Why a case is ill-conditioned for a fixed-step comparison, from the initial geometry only.
fn ill_conditioned(part: &Part, c: &Case) -> Option<&'static str> {
    let Some(t) = reference::first_touch(part, c.theta0, c.d * part.a) else {
        return Some("miss");
    };
    if t.ell.min(t.len - t.ell) < 0.002 * part.a {
        return Some("near_vertex");
    }
    let (a, e, _) = part.edge(t.edge);
    let p = a + e * t.ell;
    let vp = V::new(-1.0, 0.0).rot(-c.theta0);
    if reference::vote_median(p, e.perp(), vp, c.mu).abs() < 0.01 * part.a {
        return Some("near_central");
    }
    None
}

// ---------------------------------------------------------------------------------------------
// The reference on its own.

/// D by the reference's quadrature against a plain Monte Carlo integral (rejection sampling in the
/// bounding box), for CORs inside, near and far from the part and for pure translation; and against
/// the library's closed form, to show the quadrature's accuracy.
#[test]
fn dissipation_matches_monte_carlo_and_closed_form() {
    let mut rng = Rng(11);
    for case in 0..6 {
        let verts = random_polygon(&mut rng);
        let poly = library_polygon(&verts);
        let part = reference_part(&poly);
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let a = part.a;
        let (mut lo, mut hi) = (V::new(f64::MAX, f64::MAX), V::new(f64::MIN, f64::MIN));
        for p in &part.verts {
            lo = V::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = V::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        let inside = |x: V| {
            let n = part.n();
            (0..n).all(|k| (part.verts[(k + 1) % n] - part.verts[k]).cross(x - part.verts[k]) >= 0.0)
        };
        let samples: Vec<V> = std::iter::repeat_with(|| {
            V::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y))
        })
        .filter(|&x| inside(x))
        .take(200_000)
        .collect();
        for (i, cor) in [
            Some(V::new(0.1, -0.2) * a),
            Some(part.verts[0] * 0.999),
            Some(part.verts[1] * 1.3),
            Some(V::new(3.0, 1.0) * a),
            Some(V::new(-40.0, 25.0) * a),
            Some(V::new(1e5, -3e4) * a),
            None,
        ]
        .into_iter()
        .enumerate()
        {
            let xi = match cor {
                Some(r) => Twist {
                    v: r.perp() * (-0.7 / a),
                    w: 0.7 / a,
                },
                None => Twist {
                    v: V::new(0.3, -0.8),
                    w: 0.0,
                },
            };
            let q = part.dissipation(xi);
            let vals: Vec<f64> = samples.iter().map(|&x| xi.at(x).norm()).collect();
            let mean = vals.iter().sum::<f64>() / vals.len() as f64;
            let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / vals.len() as f64;
            let sigma = (var / vals.len() as f64).sqrt();
            assert!(
                (q - mean).abs() <= 5.0 * sigma + 1e-9 * mean,
                "case {case}/{i}: quadrature {q} vs Monte Carlo {mean} ± {sigma}"
            );
            // The library works in units of a: v unchanged, ω·a.
            let lib = model
                .dissipation([xi.v.x, xi.v.y, xi.w * a], false)
                .value;
            assert!(
                (q - lib).abs() <= 1e-8 * lib,
                "case {case}/{i}: quadrature {q} vs closed form {lib} (rel {:.1e})",
                (q - lib).abs() / lib
            );
        }
    }
}

/// A symmetric part pushed head-on at the middle of an edge translates (SPEC §2: the push through
/// the centroid stays smooth, ω = 0, v = v_pin), for μc = 0 (the point at infinity of the COR
/// search) and with friction (stick, by symmetry).
#[test]
fn central_push_translates() {
    for (verts, mu) in [
        (vec![(1.0, -0.5), (1.0, 0.5), (-1.0, 0.5), (-1.0, -0.5)], 0.0),
        (vec![(1.0, -0.5), (1.0, 0.5), (-1.0, 0.5), (-1.0, -0.5)], 0.4),
        (vec![(1.0, -0.5), (1.0, 0.5), (-1.0, 0.5), (-1.0, -0.5)], 1.5),
        (
            (0..6)
                .map(|i| {
                    let t = PI / 6.0 + i as f64 * PI / 3.0;
                    (t.cos(), t.sin())
                })
                .collect(),
            0.7,
        ),
    ] {
        let v: Vec<V> = verts.iter().map(|&(x, y)| V::new(x, y)).collect();
        let part = Part::new(&v).unwrap();
        // The rightmost edge's midpoint, pushed along −x.
        let k = (0..part.n())
            .max_by(|&i, &j| {
                let (a, e, l) = part.edge(i);
                let (b, f, m) = part.edge(j);
                (a + e * (l / 2.0)).x.total_cmp(&(b + f * (m / 2.0)).x)
            })
            .unwrap();
        let (a, e, l) = part.edge(k);
        let p = a + e * (l / 2.0);
        let (xi, mode) = reference::instant(
            &part,
            p,
            part.normal(k),
            V::new(-1.0, 0.0),
            mu,
            &mut reference::Warm::default(),
        )
        .unwrap();
        assert!(xi.w.abs() * part.a < 1e-7, "μ {mu}: ω = {} ({mode:?})", xi.w);
        assert!(
            (xi.v - V::new(-1.0, 0.0)).norm() < 1e-7,
            "μ {mu}: v = {:?}",
            xi.v
        );
        assert_eq!(
            mode,
            if mu == 0.0 {
                reference::RefMode::Slide
            } else {
                reference::RefMode::Stick
            }
        );
    }
}

/// Random instants: the sense of rotation agrees with Mason's vote (computed by the reference and
/// by the library) wherever the vote is not close to a tie.
#[test]
fn sense_of_rotation_follows_mason_vote() {
    let mut rng = Rng(7);
    let mut checked = 0;
    for _ in 0..300 {
        let part = reference_part(&library_polygon(&random_polygon(&mut rng)));
        let k = (rng.next_u64() as usize) % part.n();
        let (a, e, l) = part.edge(k);
        let p = a + e * (l * rng.range(0.02, 0.98));
        let n = part.normal(k);
        let vp = n.rot(rng.range(-1.4, 1.4));
        let mu = rng.range(0.0, 1.5);
        let med = reference::vote_median(p, n, vp, mu);
        if med.abs() < 0.02 * part.a {
            continue;
        }
        let lib = mason_vote(
            Vec2::new(-p.x, -p.y),
            Vec2::new(n.x, n.y),
            Vec2::new(vp.x, vp.y),
            mu,
        );
        assert_eq!(lib, med.signum() as i32, "library vote vs median rule");
        let (xi, mode) =
            reference::instant(&part, p, n, vp, mu, &mut reference::Warm::default()).unwrap();
        assert_eq!(
            xi.w.signum(),
            med.signum(),
            "ω {} against vote {med} ({mode:?})",
            xi.w
        );
        checked += 1;
    }
    assert!(checked > 200, "only {checked} instants checked");
}

/// The reference's instant against the production model's first instant at random contacts (same
/// mode, twists within 1e-5): the two algorithms agree where they overlap, before any integration.
#[test]
fn first_instant_agrees_with_production() {
    let mut compared = 0;
    for seed in 0..300u64 {
        let c = random_case(10_000 + seed);
        let poly = library_polygon(&c.verts);
        let part = reference_part(&poly);
        if ill_conditioned(&part, &c).is_some() {
            continue;
        }
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let a = part.a;
        let settings = ContactSettings {
            fidelity: Fidelity::Exact,
            mu_c: c.mu,
            ..ContactSettings::default()
        };
        let pose = Pose::new(0.0, 0.0, c.theta0);
        let start = Vec2::new(1.01 * a, c.d * a);
        let Some((g, inst)) = first_instant(&model, pose, start, &Pin::point(), &settings) else {
            continue;
        };
        let p = V::new(g.p.x, g.p.y) * a;
        let n = V::new(g.n.x, g.n.y);
        let vp = V::new(g.v_pin.x, g.v_pin.y);
        let (xi, mode) =
            reference::instant(&part, p, n, vp, c.mu, &mut reference::Warm::default()).unwrap();
        let want = [xi.v.x, xi.v.y, xi.w * a];
        let diff = (0..3)
            .map(|i| (inst.twist[i] - want[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            diff < 1e-5,
            "seed {seed}: production {:?} ({:?}) vs reference {want:?} ({mode:?})",
            inst.twist,
            inst.mode
        );
        compared += 1;
    }
    assert!(compared > 250, "only {compared} instants compared");
}

// ---------------------------------------------------------------------------------------------
// Whole pushes.

#[derive(Debug, Clone)]
enum Verdict {
    Skip(&'static str),
    Compared {
        /// |Δ rotation| (degrees), allowed (degrees), reference's estimate (degrees).
        dtheta: f64,
        tol_theta: f64,
        est_theta: f64,
        /// |Δ centroid| / a, allowed / a.
        dc: f64,
        tol_c: f64,
        reproducer: String,
    },
}

/// Step of the reference in units of a (the error estimate compares h and h/2).
const H: f64 = 0.04;

fn compare_case(seed: u64) -> Verdict {
    let c = random_case(seed);
    let poly = library_polygon(&c.verts);
    let part = reference_part(&poly);
    if let Some(why) = ill_conditioned(&part, &c) {
        return Verdict::Skip(why);
    }
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let settings = common::settings(Fidelity::Exact, c.mu);
    let prod = common::run(
        &model,
        &poly,
        c.theta0.to_degrees(),
        c.d,
        Pin::point(),
        &settings,
    );
    if !prod.status.is_ok() {
        return Verdict::Skip(prod.status.name());
    }
    let a = part.a;
    let (r, est) = reference::push_with_error(&part, c.theta0, c.d, c.mu, H * a, 40.0);
    match (r.status, est) {
        (RefStatus::Separated, Some(_)) => {}
        (RefStatus::Separated, None) => return Verdict::Skip("ref_h_vs_h2_differ"),
        (RefStatus::NoContact, _) => return Verdict::Skip("ref_no_contact"),
        (RefStatus::TravelLimit, _) => return Verdict::Skip("ref_travel_limit"),
        (RefStatus::VertexCycle, _) => return Verdict::Skip("ref_vertex_cycle"),
    }
    let (et, ec) = est.expect("matched above");
    let dtheta = (prod.rotation - (r.theta - c.theta0)).abs().to_degrees();
    let dc = (prod.pose_final.x - r.x).hypot(prod.pose_final.y - r.y) / a;
    let verts: Vec<String> = part
        .verts
        .iter()
        .map(|p| format!("{:.6},{:.6}", p.x, p.y))
        .collect();
    Verdict::Compared {
        dtheta,
        tol_theta: (3.0 * et.to_degrees()).max(0.05),
        est_theta: et.to_degrees(),
        dc,
        tol_c: (3.0 * ec / a).max(1e-3),
        reproducer: format!(
            "[seed {seed}] pinfeed contact --part 'vertices:{}' --theta0 {:.6} --d={:.6} --mu-c {:.6}  \
             (production rotation {:.3}°, reference {:.3}° ± {:.3}°)",
            verts.join(" "),
            c.theta0.to_degrees(),
            c.d,
            c.mu,
            prod.rotation.to_degrees(),
            (r.theta - c.theta0).to_degrees(),
            et.to_degrees()
        ),
    }
}

fn run_comparison(cases: u64) {
    let verdicts: Vec<Verdict> = (0..cases).into_par_iter().map(compare_case).collect();
    let mut skips: std::collections::BTreeMap<&str, usize> = Default::default();
    let mut compared = Vec::new();
    let mut failures = Vec::new();
    for v in &verdicts {
        match v {
            Verdict::Skip(why) => *skips.entry(why).or_default() += 1,
            Verdict::Compared {
                dtheta,
                tol_theta,
                est_theta,
                dc,
                tol_c,
                reproducer,
            } => {
                compared.push((*dtheta, *est_theta, *dc));
                if dtheta > tol_theta || dc > tol_c {
                    failures.push(format!(
                        "Δθ {dtheta:.4}° (allowed {tol_theta:.4}°), Δc {dc:.2e}·a (allowed {tol_c:.2e}·a): {reproducer}"
                    ));
                }
            }
        }
    }
    let pct = |mut v: Vec<f64>, q: f64| {
        v.sort_by(|a, b| a.total_cmp(b));
        v[((v.len() - 1) as f64 * q).round() as usize]
    };
    let dt: Vec<f64> = compared.iter().map(|c| c.0).collect();
    let es: Vec<f64> = compared.iter().map(|c| c.1).collect();
    let dcs: Vec<f64> = compared.iter().map(|c| c.2).collect();
    eprintln!(
        "slow reference vs production: {} cases, {} compared, skipped {:?}",
        cases,
        compared.len(),
        skips
    );
    if !compared.is_empty() {
        eprintln!(
            "  |Δθ| (deg): median {:.2e}, 90% {:.2e}, 99% {:.2e}, max {:.2e}",
            pct(dt.clone(), 0.5),
            pct(dt.clone(), 0.9),
            pct(dt.clone(), 0.99),
            pct(dt.clone(), 1.0)
        );
        eprintln!(
            "  reference's own error estimate (deg): median {:.2e}, 90% {:.2e}, max {:.2e}",
            pct(es.clone(), 0.5),
            pct(es.clone(), 0.9),
            pct(es, 1.0)
        );
        eprintln!(
            "  |Δc|/a: median {:.2e}, 99% {:.2e}, max {:.2e}",
            pct(dcs.clone(), 0.5),
            pct(dcs.clone(), 0.99),
            pct(dcs, 1.0)
        );
    }
    for f in &failures {
        eprintln!("  DISAGREE {f}");
    }
    let skipped: usize = skips.values().sum();
    assert!(
        compared.len() as u64 + skipped as u64 == cases,
        "every case is compared or skipped"
    );
    assert!(
        (skipped as f64) < 0.05 * cases as f64,
        "too many skipped cases: {skips:?}"
    );
    let non_geometric: usize = skips
        .iter()
        .filter(|(k, _)| !matches!(**k, "near_vertex" | "near_central" | "miss"))
        .map(|(_, v)| v)
        .sum();
    assert!(
        (non_geometric as f64) < 0.01 * cases as f64,
        "too many cases without a result from one of the models: {skips:?}"
    );
    assert!(
        failures.is_empty(),
        "{} of {} pushes disagree beyond the reference's accuracy:\n{}",
        failures.len(),
        compared.len(),
        failures.join("\n")
    );
}

/// The acceptance run: 1 000 random whole pushes.
#[test]
fn reference_agrees_with_production_over_random_pushes() {
    run_comparison(1000);
}

/// A single push, for debugging one case: `SLOW_REF_CASE=<seed> cargo test --release --test
/// slow_reference one_case -- --ignored --nocapture`.
#[test]
#[ignore]
fn one_case() {
    let seed: u64 = std::env::var("SLOW_REF_CASE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    eprintln!("{:?}", random_case(seed));
    eprintln!("{:?}", compare_case(seed));
    let c = random_case(seed);
    let part = reference_part(&library_polygon(&c.verts));
    for h in [0.04, 0.02, 0.01, 0.005] {
        let r = reference::push(&part, c.theta0, c.d, c.mu, h * part.a, 40.0);
        eprintln!("h {h}: rotation {:.4}° {r:?}", (r.theta - c.theta0).to_degrees());
    }
    let _ = push;
}

/// A deeper run: `SLOW_REF_CASES=5000 cargo test --release --test slow_reference many_cases --
/// --ignored --nocapture` (default 5 000 cases).
#[test]
#[ignore]
fn many_cases() {
    let n: u64 = std::env::var("SLOW_REF_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5000);
    run_comparison(n);
}
