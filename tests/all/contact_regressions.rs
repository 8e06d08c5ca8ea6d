//! Named regressions for the contact model: issue 11's reproducers and the cases the independent
//! slow reference (the `slow_reference` module) and the contact fuzz (`pinfeed fuzz contacts`) found.
//! Each says what went wrong and asserts what must hold now, against an independent quantity: the
//! same contact at a 1000× tighter tolerance, the point pin, or the part's own geometry.

use crate::common::*;
use pinfeed::engine::{self, RunOptions};
use pinfeed::geometry::{part_from_spec, Polygon};
use pinfeed::mechanics::{ContactOutcome, ContactStatus, Fidelity, PartModel, Pin, Support};
use pinfeed::scenario;
use std::path::Path;

fn part(vertices: &str) -> Polygon {
    part_from_spec(&format!("vertices:{vertices}")).unwrap()
}

/// The CLI's contact (pin radius in part units) at a tolerance.
fn contact(
    p: &Polygon,
    support: &Support,
    th: f64,
    d: f64,
    mu: f64,
    r: f64,
    tol: f64,
) -> ContactOutcome {
    let m = PartModel::new(p, support).unwrap();
    let mut s = settings(Fidelity::Exact, mu);
    s.tol = tol;
    let pin = Pin {
        radius: r,
        lateral_speed: 0.0,
    };
    run(&m, p, th, d, pin, &s)
}

/// Both tolerances `ok` and within `deg` of each other.
fn agrees(a: &ContactOutcome, b: &ContactOutcome, deg: f64) {
    assert!(a.status.is_ok(), "default tolerance: {:?}", a.status);
    assert!(b.status.is_ok(), "tight tolerance: {:?}", b.status);
    let diff = (a.rotation_rad - b.rotation_rad).to_degrees();
    assert!(
        diff.abs() < deg,
        "{}° vs {}°",
        a.rotation_rad.to_degrees(),
        b.rotation_rad.to_degrees()
    );
}

/// Issue 11, item 5: a disc pin with μc 1.72 took one event-landing step of 1.7e-4 a that turned
/// the part by −900° and moved it 12.8 units, and reported `ok` (−880°; +91.1° at tol 1e-9). Now
/// no step may change θ or ℓ by more than 0.5 and landings use only trusted sub-steps.
#[test]
fn issue11_wild_landing_step_with_a_high_friction_disc_pin() {
    let p = part("-0.274376,-0.021917 0.125004,-0.527002 0.413130,0.192234");
    let a = contact(&p, &Support::Uniform, 20.5181, 0.3438, 1.7193, 0.2773, 1e-6);
    let b = contact(&p, &Support::Uniform, 20.5181, 0.3438, 1.7193, 0.2773, 1e-9);
    agrees(&a, &b, 1.0);
    assert!(a.rotation_rad.to_degrees().abs() < 180.0);
    let moved = a.pose_final.x.hypot(a.pose_final.y);
    assert!(
        moved < 5.0 * p.radius(),
        "the part moved {moved} (a = {})",
        p.radius()
    );
}

/// Issue 11, item 6: pin radii of 1e-13 a ended `step_too_small` where 0 and 1e-12 were fine. A
/// disc below 1e-9 a is now the point pin; above it the disc's ride converges to it.
#[test]
fn issue11_tiny_pin_radii_behave_like_a_point_pin() {
    for name in ["tripoly1", "tripoly2", "square", "lshape"] {
        let p = poly(name);
        for k in 0..12 {
            let th = 7.0 + 30.0 * k as f64;
            let point = contact(&p, &Support::Uniform, th, 0.3, 0.5, 0.0, 1e-6);
            for r in [1e-14, 1e-13, 1e-12, 1e-10, 1e-8] {
                let o = contact(&p, &Support::Uniform, th, 0.3, 0.5, r * p.radius(), 1e-6);
                assert_eq!(o.status.name(), point.status.name(), "{name} θ0={th} ρ={r}");
                assert!(
                    (o.rotation_rad - point.rotation_rad).abs() < 1e-4 + 1e3 * r,
                    "{name} θ0={th} ρ={r}: {} vs {}",
                    o.rotation_rad.to_degrees(),
                    point.rotation_rad.to_degrees()
                );
            }
        }
    }
}

fn quickstart_with(replace: &[(&str, &str)]) -> String {
    let mut text = std::fs::read_to_string("scenarios/quickstart.toml").unwrap();
    for (from, to) in replace {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, to);
    }
    text
}

/// Issue 11, item 6 in the line: a pin radius of 1e-14 m made 199 of 200 parts end `solver`. Now
/// the line with 1e-14 m pins gives exactly the outcomes of point pins.
#[test]
fn issue11_line_with_vanishing_pin_radius_has_no_solver_failures() {
    let run_with = |radius: &str| {
        let text = quickstart_with(&[("radius = 0.002", &format!("radius = {radius}"))]);
        let scene = scenario::parse(Path::new("q.toml"), &text).unwrap();
        let opts = RunOptions {
            parts: 200,
            ..RunOptions::from_scene(&scene)
        };
        engine::run(&scene, &opts, &mut |_| {}).unwrap().summary
    };
    let tiny = run_with("1e-14");
    let point = run_with("0.0");
    assert_eq!(tiny.outcomes.solver, 0);
    assert_eq!(tiny.outcomes, point.outcomes);
}

/// Issue 11, item 4: with `scale = 1e-9` a fence scenario took 63 s per part (1e-8: 6.2 s), because
/// a flush edge slid along a fence 10⁷–10⁸ a long in steps of 2a. A flush edge now translates in a
/// few steps whatever the length: the work per part at scale 1e-7 (fences 6·10⁵ a long) is within
/// a factor 2 of the work at 0.02 (fences 6 a long).
#[test]
fn issue11_fence_cost_does_not_grow_as_the_part_shrinks() {
    let evaluations = |scale: &str| {
        let text = std::fs::read_to_string("scenarios/tripoly1_fences.toml")
            .unwrap()
            .replace("scale = 0.02 ", &format!("scale = {scale} "));
        let scene = scenario::parse(Path::new("f.toml"), &text).unwrap();
        let opts = RunOptions {
            parts: 10,
            ..RunOptions::from_scene(&scene)
        };
        let s = engine::run(&scene, &opts, &mut |_| {}).unwrap().summary;
        assert_eq!(s.outcomes.success, 10, "scale {scale}");
        s.work.model_evaluations as f64
    };
    let (small, nominal) = (evaluations("1e-7"), evaluations("0.02"));
    assert!(small < 2.0 * nominal, "{small} vs {nominal} evaluations");
}

/// The triple point (a sliding contact that turns tangent to the pin's path just as it would
/// stick): tripoly1 on a random tripod turned −29.7° at the default tolerance and −5.0° at 1e-8,
/// both `ok` (and a square on a tripod ended `step_too_small`). The part now separates where the
/// push margin vanishes, converging with the tolerance; tripoly1 ends with its hypotenuse along
/// the pin's path (θ = 0, a rotation of exactly −5° from θ0 = 5°: geometry, not a recorded output).
#[test]
fn triple_point_of_sliding_sticking_and_separation() {
    for (name, seed, th, d, geometric_deg) in [
        ("tripoly1", 0, 5.0, -0.3, Some(-5.0)),
        ("square", 1, 310.82580073694925, 0.25691447551149293, None),
    ] {
        let p = poly(name);
        let sup = Support::parse(&format!("tripod:{seed}"), &p).unwrap();
        let a = contact(&p, &sup, th, d, 0.5, 0.0, 1e-6);
        let b = contact(&p, &sup, th, d, 0.5, 0.0, 1e-9);
        agrees(&a, &b, 0.01);
        if let Some(g) = geometric_deg {
            assert!((b.rotation_rad.to_degrees() - g).abs() < 1e-3, "{name}");
        }
    }
}

/// Found by the slow reference: after a stick contact let go with the pin moving along the edge,
/// the pin's path was cast again and "touched" the same edge further on, teleporting the part up to
/// 0.47 a along x with `ok` (6 contacts on a convex part). Now one contact, and the part ends where
/// the trace's last pose says.
#[test]
fn no_re_touch_along_an_edge_just_left() {
    use pinfeed::geometry::{Pose, Vec2};
    use pinfeed::mechanics::{push, TraceSample};
    let p = part("-0.065216,-0.286432 0.435680,-0.174833 0.473968,-0.105350 0.467308,-0.011927 0.176727,0.208931 -0.085953,0.256277 -0.346565,0.222868 -0.520636,0.087826");
    let m = model(&p);
    let a = p.radius();
    let mut trace: Vec<TraceSample> = Vec::new();
    let o = push(
        &m,
        Pose::new(0.0, 0.0, 148.184899f64.to_radians()),
        Vec2::new(1.01 * a, -0.671070 * a),
        &Pin::point(),
        &settings(Fidelity::Exact, 1.309833),
        Some(&mut trace),
    );
    assert!(o.status.is_ok(), "{:?}", o.status);
    assert_eq!(o.contacts, 1);
    let last = trace.last().unwrap().pose;
    assert!((last.x - o.pose_final.x).abs() < 1e-9 && (last.y - o.pose_final.y).abs() < 1e-9);
}

/// Found by the slow reference: a pin that runs past an edge's end and back within one step (ℓ
/// beyond the edge, then inside again) was missed at coarse tolerances: −73.5° `ok` where the
/// truth is −74.19°. The dense output now reveals such a dip and the step is shortened.
#[test]
fn edge_end_crossed_and_recrossed_within_one_step() {
    let p = part("0.360947,1.373581 -0.124181,1.019174 -0.379230,0.683607 -0.656518,-0.041566 -0.657246,-0.528447 -0.558923,-0.796685 -0.248343,-1.055143 0.645699,-0.770184");
    let at = |tol: f64| {
        contact(
            &p,
            &Support::Uniform,
            233.501682,
            -0.593081,
            0.032945,
            0.0,
            tol,
        )
    };
    let fine = at(1e-9);
    for tol in [1e-5, 1e-6] {
        agrees(&at(tol), &fine, 0.01);
    }
}

/// Found by the property tests: a disc pin sticking on a vertex slipped briefly (0.09 a of
/// travel) and stuck again inside one step, which coarse tolerances missed (0.17° off). The stages'
/// own mode margins now reveal a mode that breaks and recovers within a step.
#[test]
fn mode_switch_and_back_within_one_step() {
    let p = part("0.2521992509332431,0.6679098076444939 -0.6018217346783077,-0.06634127395201873 0.13579102556630226,-0.17429874141858762");
    let r = 0.19330293878496985 * p.radius();
    let (th, d, mu) = (189.27606353247435, 0.5392986588748061, 0.5657847435213283);
    let at = |tol: f64| contact(&p, &Support::Uniform, th, d, mu, r, tol);
    let fine = at(1e-9);
    for tol in [1e-5, 1e-6] {
        agrees(&at(tol), &fine, 0.01);
    }
}

/// A push through the centroid of a part whose struck point lies on the centroid's line rides an
/// unstable equilibrium: with rounding deciding which way it falls, the outcome is `metastable`
/// (not `ok`), at every fidelity.
#[test]
fn a_ride_on_an_unstable_equilibrium_is_metastable() {
    let p = part("0.12778508188490345,0.9687715695010212 -0.17026338367431126,-0.10493035871364531 0.9756713457574362,-0.20849578128221027");
    let m = model(&p);
    for fid in FIDELITIES {
        let o = run(
            &m,
            &p,
            163.2356845560627,
            0.0,
            Pin::point(),
            &settings(fid, 1.7257594566013241),
        );
        assert!(
            matches!(
                o.status,
                ContactStatus::Metastable { .. } | ContactStatus::TravelLimit { .. }
            ),
            "{fid}: {:?}",
            o.status
        );
    }
}

/// Found by `pinfeed fuzz scenarios` (case 36330): a 1.4 nm part (scale 1e-9) among 2 mm pins —
/// discs 10⁶ a wide, 10⁸ a away — hung the line: a grazing touch was stepped past by 1e-9 a,
/// below the travel's rounding at 1e8 a, and grazing touches were handed between obstacles for
/// ever at one instant. Steps past a graze are now relative and bounded, and a part that only
/// grazes 16 times in a row leaves as a `solver` outcome (`grazing_loop`).
#[test]
fn giant_pins_against_a_tiny_part_do_not_hang_the_line() {
    let text = quickstart_with(&[
        ("scale = 0.02 ", "scale = 1e-9 "),
        ("y = 0.004 ", "y = 1e-9 "),
    ]);
    let scene = scenario::parse(Path::new("q.toml"), &text).unwrap();
    let opts = RunOptions {
        parts: 3,
        ..RunOptions::from_scene(&scene)
    };
    let s = engine::run(&scene, &opts, &mut |_| {}).unwrap().summary;
    assert_eq!(s.outcomes.total(), 3);
    assert_eq!(
        s.outcomes.solver,
        s.causes.solver.get("grazing_loop").copied().unwrap_or(0)
    );
}

/// Found by `pinfeed fuzz contacts` (12 of 10⁶ `ok` contacts more than 1° apart between the
/// default tolerance and 1e-9, and 206 `ok` then `multi_contact`): a sticking pin lets go of an
/// edge by the edge turning parallel to its path, then runs on along the edge's line into a reflex
/// corner. Casting the path again decided by rounding whether it struck the next edge (−36.6°),
/// the corner (`multi_contact`) or nothing (−23.1°). The corner is now reported at every
/// tolerance, as when the pin slides into it in contact.
#[test]
fn tangential_release_into_a_reflex_corner_is_a_multi_contact() {
    let p = part("0.900114,0.061997 0.625824,0.193981 0.145756,0.933133 -0.797799,0.306426 -0.682673,-0.384111 -0.426394,-0.309059 -0.446985,-0.861307");
    let at = |tol: f64| {
        contact(
            &p,
            &Support::Uniform,
            260.083445,
            -0.385968,
            1.622616,
            0.0,
            tol,
        )
    };
    let fine = at(1e-10);
    for tol in [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10] {
        let o = at(tol);
        assert!(
            matches!(o.status, ContactStatus::MultiContact { .. }),
            "tol {tol}: {:?}",
            o.status
        );
        assert_eq!(o.contacts, 1, "tol {tol}");
        assert!(
            (o.rotation_rad - fine.rotation_rad).abs().to_degrees() < 0.01,
            "tol {tol}"
        );
    }
}
