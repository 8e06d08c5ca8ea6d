//! The independent slow reference (module `reference`) checked on its own, then compared with the
//! production contact model (`pinfeed::mechanics::push`, exact fidelity, default tolerance) over
//! random whole pushes ("an independent slow reference inside the tests").
//!
//! Cases (seeded, deterministic): random convex polygons with 3–8 vertices (points on a random
//! ellipse, at a random scale), θ0 uniform, d uniform over the range that touches, μc ∈ [0, 1.5]
//! (a few exactly 0), point pins. Cases are skipped — counted, and the count bounded — when
//! (decided from the initial geometry, before either model runs):
//! * the first touch is within 5e-4·a of a vertex (which edge is struck is ill-conditioned);
//! * Mason's vote is nearly a tie: the median of the centroid's signed distances from the lines of
//!   v_pin, f_L, f_R is below 3e-3·a (a push nearly through the centroid: metastable, the sense of
//!   rotation is decided by rounding).
//!
//! Cases the production model does not finish with status `ok`, and cases the reference cannot
//! finish (travel limit, a pin hooked on a vertex, h and h/2 ending differently), are also skipped,
//! counted and bounded (< 1% of the cases; the geometric skips < 2%). Every other case must agree:
//! final orientation (signed total rotation) within max(3·(reference's error estimate), 0.05°),
//! final centroid within max(3·estimate, 1e-3·a + 2e-4·(contact travel)) — except the centroid of
//! the cases in [`KNOWN`] (none now: [`FIXED`] lists the defects this comparison found and that
//! were fixed).
//!
//! A control test runs the same comparison against the ellipsoid fidelity and requires most pushes
//! to disagree, so the comparison is shown to be able to fail.

use crate::common;
use crate::reference;

use pinfeed::geometry::{Polygon, Pose, Vec2};
use pinfeed::mechanics::{
    first_instant, mason_vote, ContactOutcome, ContactSettings, Fidelity, PartModel, Pin, Support,
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
    // μc ∈ [0, 1.5]; `SLOW_REF_MU_MAX` widens the range for deeper runs (the CI tests leave it unset).
    let mu_max = std::env::var("SLOW_REF_MU_MAX")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.5);
    let mu = if rng.uniform() < 0.05 {
        0.0
    } else {
        rng.range(0.0, mu_max)
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
    if t.ell.min(t.len - t.ell) < 5e-4 * part.a {
        return Some("near_vertex");
    }
    let (a, e, _) = part.edge(t.edge);
    let p = a + e * t.ell;
    let vp = V::new(-1.0, 0.0).rot(-c.theta0);
    if reference::vote_median(p, e.perp(), vp, c.mu).abs() < 3e-3 * part.a {
        return Some("near_central");
    }
    None
}

/// The production model on a case, the CLI's way (`common::run`).
fn run_production(c: &Case, poly: &Polygon, settings: &ContactSettings) -> ContactOutcome {
    let model = PartModel::new(poly, &Support::Uniform).unwrap();
    common::run(
        &model,
        poly,
        c.theta0.to_degrees(),
        c.d,
        Pin::point(),
        settings,
    )
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
            (0..n)
                .all(|k| (part.verts[(k + 1) % n] - part.verts[k]).cross(x - part.verts[k]) >= 0.0)
        };
        let samples: Vec<V> =
            std::iter::repeat_with(|| V::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y)))
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
            let lib = model.dissipation([xi.v.x, xi.v.y, xi.w * a], false).value;
            assert!(
                (q - lib).abs() <= 1e-7 * lib,
                "case {case}/{i}: quadrature {q} vs closed form {lib} (rel {:.1e})",
                (q - lib).abs() / lib
            );
        }
    }
}

/// A symmetric part pushed head-on at the middle of an edge translates (docs/physics.md#limit-surface: the push through
/// the centroid stays smooth, ω = 0, v = v_pin), for μc = 0 (the point at infinity of the COR
/// search) and with friction (stick, by symmetry).
#[test]
fn central_push_translates() {
    for (verts, mu) in [
        (
            vec![(1.0, -0.5), (1.0, 0.5), (-1.0, 0.5), (-1.0, -0.5)],
            0.0,
        ),
        (
            vec![(1.0, -0.5), (1.0, 0.5), (-1.0, 0.5), (-1.0, -0.5)],
            0.4,
        ),
        (
            vec![(1.0, -0.5), (1.0, 0.5), (-1.0, 0.5), (-1.0, -0.5)],
            1.5,
        ),
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
        assert!(
            xi.w.abs() * part.a < 1e-7,
            "μ {mu}: ω = {} ({mode:?})",
            xi.w
        );
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

/// The reference's instant against the production model's first instant at random contacts (the
/// twist within 1e-5 in units of a): the two algorithms agree where they overlap, before any
/// integration.
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
    Compared(Compared),
}

#[derive(Debug, Clone)]
struct Compared {
    /// |Δ rotation| (degrees), allowed (degrees), the reference's own error estimate (degrees).
    dtheta: f64,
    tol_theta: f64,
    est_theta: f64,
    /// |Δ centroid| / a, allowed / a.
    dc: f64,
    tol_c: f64,
    /// A known production defect excusing the centroid (see [`KNOWN`]).
    known: Option<&'static str>,
    reproducer: String,
}

/// Centroid excuses for known production defects: none. The defect once listed here (after the
/// pin stopped pushing in stick, `run_passes` struck the same edge again and every re-touch
/// shifted the centroid) is fixed; [`FIXED`] keeps its seeds and
/// [`former_defects_stay_fixed`] checks them in every run.
const KNOWN: &[(u64, &str)] = &[];

/// Cases this comparison once found wrong and that agree now, with what was wrong: re-touches
/// after a tangential separation (several contacts on a convex part struck by a point pin), and
/// orientation errors at the default tolerance.
const FIXED: &[(u64, &str)] = &[
    (37, "re-touch after tangential separation"),
    (4344, "re-touch after tangential separation"),
    (4794, "re-touch after tangential separation"),
    (6658, "re-touch after tangential separation"),
    (6803, "re-touch after tangential separation"),
    (18469, "re-touch after tangential separation"),
    (20404, "re-touch after tangential separation"),
    (
        12739,
        "rotation −73.466° at default tol, −74.194° in the reference (μc 0.033, 3 edges)",
    ),
    (
        17539,
        "rotation 38.034° at default tol, 38.099° in the reference (μc 1.24)",
    ),
];

/// The one push of `many_cases` (seeds 0..23000) whose final centroid at the default tolerance
/// (1e-6) lies outside the allowance while its orientation agrees: the local error control's
/// limit that docs/physics.md#integration-and-events states (errors add up along a slide, and the
/// slowly turning stick after it turns a small orientation error into a shift along the travel).
/// [`a_long_stick_after_a_slide_needs_a_tighter_tolerance_for_the_centroid`] checks it in every
/// run.
const SLOW_STICK: u64 = 7956;

impl Compared {
    fn agrees(&self) -> bool {
        self.dtheta <= self.tol_theta && (self.dc <= self.tol_c || self.known.is_some())
    }
    fn line(&self) -> String {
        format!(
            "Δθ {:.4}° (allowed {:.4}°), Δc {:.2e}·a (allowed {:.2e}·a){}: {}",
            self.dtheta,
            self.tol_theta,
            self.dc,
            self.tol_c,
            self.known
                .map(|k| format!(" [known: {k}]"))
                .unwrap_or_default(),
            self.reproducer
        )
    }
}

/// Step of the reference in units of a (the error estimate compares h and h/2).
const H: f64 = 0.04;
/// Contact-travel limit of the reference, in units of a.
const MAX_TRAVEL: f64 = 40.0;

/// One random push through both models. `fidelity` is the production model's (exact in the real
/// comparison; another one only to show that the comparison can fail). `geometric_skips` applies
/// the ill-conditioning criteria.
fn compare_case(seed: u64, fidelity: Fidelity, geometric_skips: bool) -> Verdict {
    compare_case_at(
        seed,
        fidelity,
        geometric_skips,
        ContactSettings::default().tol,
    )
}

/// [`compare_case`] with the production model at integration tolerance `tol`.
fn compare_case_at(seed: u64, fidelity: Fidelity, geometric_skips: bool, tol: f64) -> Verdict {
    let c = random_case(seed);
    let poly = library_polygon(&c.verts);
    let part = reference_part(&poly);
    match ill_conditioned(&part, &c) {
        Some("miss") => return Verdict::Skip("miss"),
        Some(why) if geometric_skips => return Verdict::Skip(why),
        _ => {}
    }
    let settings = ContactSettings {
        tol,
        ..common::settings(fidelity, c.mu)
    };
    let prod = run_production(&c, &poly, &settings);
    if !prod.status.is_ok() {
        return Verdict::Skip(prod.status.name());
    }
    let a = part.a;
    let (r, est) = reference::push_with_error(&part, c.theta0, c.d, c.mu, H * a, MAX_TRAVEL);
    match (r.status, est) {
        (RefStatus::Separated, Some(_)) => {}
        (RefStatus::Separated, None) => return Verdict::Skip("ref_h_vs_h2_differ"),
        (RefStatus::NoContact, _) => return Verdict::Skip("ref_no_contact"),
        (RefStatus::TravelLimit, _) => return Verdict::Skip("ref_travel_limit"),
        (RefStatus::VertexCycle, _) => return Verdict::Skip("ref_vertex_cycle"),
    }
    let (et, ec) = est.expect("matched above");
    let verts: Vec<String> = part
        .verts
        .iter()
        .map(|p| format!("{:.6},{:.6}", p.x, p.y))
        .collect();
    Verdict::Compared(Compared {
        dtheta: (prod.rotation_rad - (r.theta - c.theta0)).abs().to_degrees(),
        tol_theta: (3.0 * et.to_degrees()).max(0.05),
        est_theta: et.to_degrees(),
        dc: (prod.pose_final.x - r.x).hypot(prod.pose_final.y - r.y) / a,
        // 1e-3·a is what 0.05° is at a lever of a; plus 2e-4 per unit of contact travel, because
        // the production model's centroid error at its default tolerance grows with travel (seeds
        // 2763 and 4948: 1.1–1.4e-3·a after 4–7·a of sliding, and converging to the reference
        // when its tolerance is tightened).
        tol_c: (3.0 * ec / a).max(1e-3 + 2e-4 * r.contact_length / a),
        known: KNOWN.iter().find(|k| k.0 == seed).map(|k| k.1),
        reproducer: format!(
            "[seed {seed}] pinfeed contact --part 'vertices:{}' --theta0 {:.6} --d={:.6} --mu-c {:.6}  \
             (production rotation {:.3}°, reference {:.3}° ± {:.3}°)",
            verts.join(" "),
            c.theta0.to_degrees(),
            c.d,
            c.mu,
            prod.rotation_rad.to_degrees(),
            (r.theta - c.theta0).to_degrees(),
            et.to_degrees()
        ),
    })
}

/// What a comparison over many pushes found.
struct Summary {
    cases: u64,
    skips: std::collections::BTreeMap<&'static str, usize>,
    compared: Vec<Compared>,
}

impl Summary {
    fn disagreements(&self) -> Vec<&Compared> {
        self.compared.iter().filter(|c| !c.agrees()).collect()
    }
    fn skipped(&self, geometric: bool) -> usize {
        self.skips
            .iter()
            .filter(|(k, _)| matches!(**k, "near_vertex" | "near_central" | "miss") == geometric)
            .map(|(_, v)| v)
            .sum()
    }
    /// The distribution of the differences and of the reference's own error, on stderr.
    fn print(&self, what: &str, list_disagreements: bool) {
        let pct = |mut v: Vec<f64>, q: f64| {
            v.sort_by(|a, b| a.total_cmp(b));
            v[((v.len() - 1) as f64 * q).round() as usize]
        };
        eprintln!(
            "{what}: {} cases, {} compared, skipped {:?}",
            self.cases,
            self.compared.len(),
            self.skips
        );
        if self.compared.is_empty() {
            return;
        }
        let dt: Vec<f64> = self.compared.iter().map(|c| c.dtheta).collect();
        let es: Vec<f64> = self.compared.iter().map(|c| c.est_theta).collect();
        let dc: Vec<f64> = self.compared.iter().map(|c| c.dc).collect();
        eprintln!(
            "  |Δθ| (deg): median {:.1e}, 90% {:.1e}, 99% {:.1e}, max {:.1e}",
            pct(dt.clone(), 0.5),
            pct(dt.clone(), 0.9),
            pct(dt.clone(), 0.99),
            pct(dt, 1.0)
        );
        eprintln!(
            "  reference's own error estimate (deg): median {:.1e}, 90% {:.1e}, 99% {:.1e}, max {:.1e}; \
             {} of {} above the 0.05° floor",
            pct(es.clone(), 0.5),
            pct(es.clone(), 0.9),
            pct(es.clone(), 0.99),
            pct(es.clone(), 1.0),
            es.iter().filter(|&&e| 3.0 * e > 0.05).count(),
            es.len()
        );
        eprintln!(
            "  |Δc|/a: median {:.1e}, 99% {:.1e}, max {:.1e}",
            pct(dc.clone(), 0.5),
            pct(dc.clone(), 0.99),
            pct(dc, 1.0)
        );
        let worst = self
            .compared
            .iter()
            .max_by(|a, b| a.dtheta.total_cmp(&b.dtheta))
            .expect("not empty");
        eprintln!("  largest |Δθ|: {}", worst.line());
        let loosest = self
            .compared
            .iter()
            .max_by(|a, b| a.est_theta.total_cmp(&b.est_theta))
            .expect("not empty");
        eprintln!("  least accurate reference: {}", loosest.line());
        if list_disagreements {
            for d in self.disagreements() {
                eprintln!("  DISAGREE {}", d.line());
            }
            for k in self.compared.iter().filter(|c| c.known.is_some()) {
                let state = if k.dc <= k.tol_c {
                    "now agrees: take it off KNOWN"
                } else {
                    "still disagrees"
                };
                eprintln!("  KNOWN ({state}) {}", k.line());
            }
        }
    }
}

fn run_comparison(
    cases: std::ops::Range<u64>,
    fidelity: Fidelity,
    geometric_skips: bool,
) -> Summary {
    let verdicts: Vec<Verdict> = cases
        .clone()
        .into_par_iter()
        .map(|seed| compare_case(seed, fidelity, geometric_skips))
        .collect();
    let mut summary = Summary {
        cases: cases.end - cases.start,
        skips: Default::default(),
        compared: Vec::new(),
    };
    for v in verdicts {
        match v {
            Verdict::Skip(why) => *summary.skips.entry(why).or_default() += 1,
            Verdict::Compared(c) => summary.compared.push(c),
        }
    }
    summary
}

/// The acceptance checks on a comparison with the exact model.
fn assert_agreement(s: &Summary) {
    let n = s.cases as f64;
    assert!(
        (s.skipped(true) as f64) < 0.02 * n,
        "too many ill-conditioned cases: {:?}",
        s.skips
    );
    assert!(
        (s.skipped(false) as f64) < 0.01 * n,
        "too many cases without a result from one of the models: {:?}",
        s.skips
    );
    let bad = s.disagreements();
    assert!(
        bad.is_empty(),
        "{} of {} pushes disagree beyond the reference's accuracy:\n{}",
        bad.len(),
        s.compared.len(),
        bad.iter().map(|c| c.line()).collect::<Vec<_>>().join("\n")
    );
}

/// The acceptance run: random whole pushes against the exact model, seeds 0..300 in a plain
/// `cargo test` and 0..1000 with `PINFEED_DEEP_TESTS=1` (the skip shares are relative).
///
/// Measured (seeds 0..1000, 2026-11-23, step H = 0.04·a): 994 compared, skipped 5 near-central
/// and 1 near-vertex, none for a non-ok status or a reference failure; all 994 agree in
/// orientation and all but seed 37 (then a known defect, now in [`FIXED`]) in centroid. (With the geometric skips off,
/// all 1000 agree as well.) |Δθ| median 1.6e-4°, 90% 8.2e-4°,
/// 99% 2.8e-3°, max 7.3e-3° (seed 932, allowed 0.05°); the reference's own error estimate median
/// 4.5e-4°, 90% 3.5e-3°, max 3.5e-2°; |Δc|/a median 3.1e-6, 99% 4.4e-5, max 2.2e-2 (seed 37).
/// Over seeds 0..5000 the same holds (max |Δθ| 2.2e-2°). About 16 s of CPU in `--release`
/// (rayon over the cases; the order of the results does not depend on the threads).
#[test]
fn reference_agrees_with_production_over_random_pushes() {
    let s = run_comparison(
        0..u64::from(crate::support::cases(300, 1000)),
        Fidelity::Exact,
        true,
    );
    s.print("slow reference vs exact model", true);
    assert_agreement(&s);
}

/// The comparison can fail: the ellipsoidal approximation, which under-rotates (docs/physics.md#limit-surface), is
/// told apart from the exact model by this reference on most pushes.
#[test]
fn comparison_tells_the_ellipsoid_from_the_exact_model() {
    let s = run_comparison(5000..5060, Fidelity::Ellipsoid, true);
    s.print("slow reference vs ellipsoid model", false);
    let bad = s.disagreements().len();
    assert!(
        bad * 2 > s.compared.len(),
        "only {bad} of {} ellipsoid pushes differ from the exact reference",
        s.compared.len()
    );
}

/// A number from the environment, or the default.
fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// A single push, for debugging one case: `SLOW_REF_CASE=<seed> cargo test --release --test all
/// slow_reference::one_case -- --ignored --nocapture`.
#[test]
#[ignore]
fn one_case() {
    let seed: u64 = env_u64("SLOW_REF_CASE", 0);
    let c = random_case(seed);
    eprintln!("{c:?}");
    eprintln!("{:?}", compare_case(seed, Fidelity::Exact, false));
    let poly = library_polygon(&c.verts);
    let part = reference_part(&poly);
    for tol in [1e-6, 1e-8, 1e-10] {
        let settings = ContactSettings {
            tol,
            ..common::settings(Fidelity::Exact, c.mu)
        };
        let o = run_production(&c, &poly, &settings);
        eprintln!(
            "production tol {tol:e}: rotation {:.5}°, centroid ({}, {}), contacts {}, {}",
            o.rotation_rad.to_degrees(),
            o.pose_final.x,
            o.pose_final.y,
            o.contacts,
            o.status.name()
        );
    }
    for h in [0.04, 0.02, 0.01, 0.005] {
        let r = reference::push(&part, c.theta0, c.d, c.mu, h * part.a, MAX_TRAVEL);
        eprintln!(
            "h {h}·a: rotation {:.5}° {r:?}",
            (r.theta - c.theta0).to_degrees()
        );
    }
}

/// A deeper run: `SLOW_REF_CASES=5000 cargo test --release --test all slow_reference::many_cases --
/// --ignored --nocapture` (default 5 000 cases, seeds from `SLOW_REF_FIRST`, default 0;
/// `SLOW_REF_NO_SKIP=1` also compares the ill-conditioned cases, to see what the skips hide;
/// `SLOW_REF_MU_MAX=2` draws μc from [0, 2] instead of [0, 1.5]).
#[test]
#[ignore]
fn many_cases() {
    let n: u64 = env_u64("SLOW_REF_CASES", 5000);
    let first: u64 = env_u64("SLOW_REF_FIRST", 0);
    let skips = std::env::var("SLOW_REF_NO_SKIP").is_err();
    let s = run_comparison(first..first + n, Fidelity::Exact, skips);
    s.print("slow reference vs exact model", true);
    assert_agreement(&s);
}

/// The push [`SLOW_STICK`]: it starts nearly through the centroid; the slide before its stick
/// ends with θ off by 2.3·10⁻⁵ rad at the default tolerance (each step's error is controlled, their
/// sum over 1.1·a of slide is not), and the stick, turning 0.0094 rad per a of travel at first,
/// starts 8.8·10⁻⁴·a of travel later, so every later configuration is reached that much later: the
/// same final orientation at a place 4.3·10⁻³·a away (the allowance here is 2.3·10⁻³·a). At the
/// default tolerance the orientation agrees and the centroid stays within 1e-2·a (a change that
/// brings it within the allowance should move the seed to [`FIXED`]); at tolerance 1e-8 the
/// whole final pose agrees with the reference.
#[test]
fn a_long_stick_after_a_slide_needs_a_tighter_tolerance_for_the_centroid() {
    let compared = |tol: f64| match compare_case_at(SLOW_STICK, Fidelity::Exact, true, tol) {
        Verdict::Compared(cmp) => cmp,
        Verdict::Skip(w) => panic!("seed {SLOW_STICK} skipped at tol {tol:e}: {w}"),
    };
    let default = compared(ContactSettings::default().tol);
    assert!(default.dtheta <= default.tol_theta, "{}", default.line());
    assert!(default.dc <= 1e-2, "{}", default.line());
    let tight = compared(1e-8);
    assert!(
        tight.agrees() && tight.dc <= tight.tol_c,
        "at tol 1e-8: {}",
        tight.line()
    );
}

/// The cases in [`FIXED`] stay fixed: their final pose agrees with the reference in orientation
/// and centroid, and a former re-touch is a single contact again.
#[test]
fn former_defects_stay_fixed() {
    for &(seed, why) in FIXED {
        let c = random_case(seed);
        let poly = library_polygon(&c.verts);
        let o = run_production(&c, &poly, &common::settings(Fidelity::Exact, c.mu));
        if why.starts_with("re-touch") {
            assert_eq!(o.contacts, 1, "seed {seed} ({why}): contacts");
        }
        match compare_case(seed, Fidelity::Exact, true) {
            Verdict::Compared(cmp) => {
                assert!(cmp.agrees() && cmp.dc <= cmp.tol_c, "{why}: {}", cmp.line())
            }
            Verdict::Skip(w) => panic!("seed {seed} skipped: {w}"),
        }
    }
}
