//! Part–part overlap (docs/physics.md#the-line): whenever a part's motion changes, its new motion is checked
//! against every other part on the belt over the time both motions are known (until the earlier
//! of their next events). A broad phase (`bounding_capsule`: capsules in the belt frame) skips
//! distant pairs; close pairs are resolved in time with [`super::overlap::first_touch`] on the
//! clearance between the two polygons (`first_overlap`). The first overlap schedules a
//! collision event.

use super::contact::ensure_trace;
use super::event_queue::EventKind;
use super::metrics::WorkCounters;
use super::motion::{Motion, PoseCursor};
use super::overlap::{first_touch, polygon_clearance, segment_distance};
use super::state::Belt;
use crate::geometry::Vec2;
use crate::scenario::Scene;

/// Check the motion part `index` has just started (at `now`) against every other part on the
/// belt, and schedule a collision at the first overlap of each pair. A held part whose push kept
/// no path gets it recorded here if the pair is close.
pub(super) fn check_pairs(
    scene: &Scene,
    belt: &mut Belt,
    work: &mut WorkCounters,
    index: u64,
    now: f64,
) {
    if !scene.effects.collisions || belt.active.len() < 2 {
        return;
    }
    // Broad phase over every other part (no part changes here), then the narrow phase of the
    // close pairs in the same order.
    let close: Vec<(u64, f64)> = {
        let active = &belt.active;
        let me = &active[&index].motion;
        let mut close = Vec::new();
        for (&other, part) in active.iter().filter(|(&k, _)| k != index) {
            work.part_part_checks += 1;
            let end = me.until().min(part.motion.until());
            if end < now {
                continue;
            }
            let (p0, p1, r1) = bounding_capsule(scene, me, now, end);
            let (q0, q1, r2) = bounding_capsule(scene, &part.motion, now, end);
            if segment_distance(p0, p1, q0, q1) <= r1 + r2 {
                close.push((other, end));
            }
        }
        close
    };
    let active = &mut belt.active;
    for (other, end) in close {
        work.part_part_narrow_checks += 1;
        for k in [index, other] {
            let part = active.get_mut(&k).expect("active part");
            if let Motion::Held(plan) = &mut part.motion {
                let model = part.model.as_ref().unwrap_or(&scene.part.model);
                ensure_trace(plan, model, work);
            }
        }
        let (pi, pj) = (&active[&index].motion, &active[&other].motion);
        let mut evals = 0;
        let hit = first_overlap(scene, pi, pj, now, end, &mut evals);
        work.clearance_evaluations += evals;
        if let Some(tc) = hit {
            belt.queue.schedule(
                tc,
                EventKind::Collision {
                    first: index.min(other),
                    second: index.max(other),
                },
            );
        }
    }
}

/// Broad phase, in the belt frame that is the world at `now`: a capsule (segment ends, radius, m)
/// that holds the part over [now, end]. A free part is a disc of radius a at rest; a held part
/// stays within 2a of the obstacle holding it — within 2a + ρ of a pin's centre, within
/// 2a + length/2 of a fence's midpoint — whose belt-frame path runs back along −x.
fn bounding_capsule(scene: &Scene, motion: &Motion, now: f64, end: f64) -> (Vec2, Vec2, f64) {
    let v = scene.belt.speed;
    let a = scene.part.radius;
    match motion {
        Motion::Free { .. } => {
            let c = motion.world_pose(now, v).position();
            (c, c, a)
        }
        Motion::Held(plan) => {
            let (p, q, r) = scene.obstacles[plan.obstacle].capsule();
            let x = (p + q) * 0.5;
            let reach = 2.0 * a + r + (q - p).norm() / 2.0;
            (x, x - Vec2::new(v * (end - now), 0.0), reach)
        }
    }
}

/// Narrow phase: the first time in [now, end] at which the parts moving along `first` and
/// `second` overlap (polygon clearance reaches zero, to 10⁻⁶ a), stepping at the recorded steps
/// of either push; `evals` counts the clearance evaluations.
fn first_overlap(
    scene: &Scene,
    first: &Motion,
    second: &Motion,
    now: f64,
    end: f64,
    evals: &mut u64,
) -> Option<f64> {
    let v = scene.belt.speed;
    let a = scene.part.radius;
    let mut breaks: Vec<f64> = Vec::new();
    for m in [first, second] {
        if let Motion::Held(plan) = m {
            breaks.extend(plan.step_times(v));
        }
    }
    breaks.sort_by(f64::total_cmp);
    let poly = &scene.part.polygon;
    // The walk asks each motion's pose at the ends of every piece, in order.
    let (first, second) = (PoseCursor::new(first, v), PoseCursor::new(second, v));
    let belt_motion = |m: &PoseCursor, ta: f64, tb: f64| -> f64 {
        let (p, q) = (m.at(ta), m.at(tb));
        let d = q.position() - p.position() - Vec2::new(v * (tb - ta), 0.0);
        d.norm() + a * (q.theta_rad - p.theta_rad).abs()
    };
    let (mut wa, mut wb) = (Vec::new(), Vec::new());
    first_touch(
        now,
        end,
        &breaks,
        &mut |tau| {
            poly.world_vertices_into(&first.at(tau), &mut wa);
            poly.world_vertices_into(&second.at(tau), &mut wb);
            polygon_clearance(&wa, &wb)
        },
        &|ta, tb| belt_motion(&first, ta, tb) + belt_motion(&second, ta, tb),
        1e-6 * a,
        evals,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::state::ActivePart;
    use crate::geometry::Pose;

    /// The quickstart's scene with two parts riding the belt from time 0 until time 1, their
    /// centroids `gap` part radii apart along the belt at the same orientation; the pair is checked as part
    /// 1's motion starts.
    fn check_two_parts(gap: f64) -> (Belt, WorkCounters) {
        let path = &crate::project_path("scenarios/quickstart.toml");
        let scene = crate::scenario::load(path).unwrap();
        assert!(scene.effects.collisions);
        let gap = gap * scene.part.radius;
        let mut belt = Belt::new();
        for (k, x) in [(0, 0.2), (1, 0.2 + gap)] {
            let mut part = ActivePart::entering(0.0, Pose::new(x, 0.0, 0.3), None, false);
            part.motion = Motion::Free {
                t0: 0.0,
                pose: Pose::new(x, 0.0, 0.3),
                until: 1.0,
            };
            belt.active.insert(k, part);
        }
        let mut work = WorkCounters::default();
        check_pairs(&scene, &mut belt, &mut work, 1, 0.0);
        (belt, work)
    }

    /// Two parts half a radius apart overlap from the start: one collision of the pair is
    /// scheduled then, lower index first.
    #[test]
    fn two_overlapping_parts_collide_at_once() {
        let (mut belt, work) = check_two_parts(0.5);
        assert_eq!(work.part_part_checks, 1);
        assert_eq!(work.part_part_narrow_checks, 1);
        let ev = belt.queue.pop().expect("a collision");
        assert_eq!(ev.time, 0.0);
        assert_eq!(
            ev.kind,
            EventKind::Collision {
                first: 0,
                second: 1
            }
        );
        assert!(belt.queue.pop().is_none());
    }

    /// Two parts four radii apart riding the belt together never touch: the broad phase skips
    /// the pair and nothing is scheduled.
    #[test]
    fn two_separated_parts_do_not_collide() {
        let (mut belt, work) = check_two_parts(4.0);
        assert_eq!(work.part_part_checks, 1);
        assert_eq!(work.part_part_narrow_checks, 0);
        assert!(belt.queue.pop().is_none());
    }

    /// Two parts 1.5 radii apart can touch (their vertices reach a from each centroid): the broad
    /// phase hands them to the narrow phase (capsules closer than the sum of their radii), and
    /// two parts 2.5 radii apart it skips.
    #[test]
    fn parts_closer_than_the_sum_of_their_reaches_reach_the_narrow_phase() {
        assert_eq!(check_two_parts(1.5).1.part_part_narrow_checks, 1);
        assert_eq!(check_two_parts(1.99).1.part_part_narrow_checks, 1);
        assert_eq!(check_two_parts(2.5).1.part_part_narrow_checks, 0);
    }

    /// A held part whose push kept no path (the engine records it only when something needs
    /// it) gets it recorded before a close pair is resolved, whichever part of the pair it is:
    /// the collision is where the recorded path puts it, not on the straight line between the
    /// push's ends. (A mutant that recorded only the path of the part whose motion just started
    /// passed every test.)
    #[test]
    fn a_held_part_s_path_is_recorded_whichever_part_of_the_pair_it_is() {
        let scene = scene_of("quickstart.toml");
        let v = scene.belt.speed;
        let mut tried = 0;
        for (j, y, theta) in entries(&scene) {
            let (Some(traced), Some(bare)) = (
                held_traced(&scene, j, y, theta, true),
                held_traced(&scene, j, y, theta, false),
            ) else {
                continue;
            };
            let Motion::Held(plan) = &traced else {
                unreachable!()
            };
            let (begin, end) = (plan.t_begin, plan.t_end);
            // A free part in the held one's pose at the end of the push, upstream before.
            let pose = traced.world_pose(end, v);
            let free = Motion::Free {
                t0: end,
                pose,
                until: end,
            };
            let expected = collisions_of(&scene, free.clone(), traced.clone(), begin);
            let Some(&first) = expected.first() else {
                continue;
            };
            if first <= begin {
                continue;
            }
            tried += 1;
            assert_eq!(
                collisions_of(&scene, free.clone(), bare.clone(), begin),
                expected,
                "obstacle {j}, y {y}: the held part is the other one"
            );
            assert_eq!(
                collisions_of(&scene, bare, free, begin),
                expected,
                "obstacle {j}, y {y}: the held part is the one checked"
            );
        }
        assert!(
            tried >= 2,
            "only {tried} configurations collided during the push"
        );
    }

    use proptest::prelude::*;

    fn scene_of(file: &str) -> Scene {
        crate::scenario::load(&crate::project_path(&format!("scenarios/{file}"))).unwrap()
    }

    /// The quickstart line with pins ten times as thick (radius 0.02 m, 0.73 a): a bound that
    /// forgets the pin's radius shows.
    fn thick_pins() -> Scene {
        let path = crate::project_path("scenarios/quickstart.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.matches("radius = 0.002").count(), 3);
        crate::scenario::parse(&path, &text.replace("radius = 0.002", "radius = 0.02")).unwrap()
    }

    /// Obstacle `j` of `scene` pushing a part that rides in at lateral offset `y` (m) and
    /// orientation `theta` (rad), from 3a upstream at time 0: its held motion (with the path
    /// recorded, as the narrow phase sees it), or None if the part passes untouched.
    fn held(scene: &Scene, j: usize, y: f64, theta: f64) -> Option<Motion> {
        held_traced(scene, j, y, theta, true)
    }

    /// [`held`], with the push's path recorded only if `traced` (the engine records it when
    /// something needs it: a close pair, a neighbouring obstacle).
    fn held_traced(scene: &Scene, j: usize, y: f64, theta: f64, traced: bool) -> Option<Motion> {
        let (v, a) = (scene.belt.speed, scene.part.radius);
        let ob = &scene.obstacles[j];
        let pose = Pose::new(ob.x_range()[0] - 3.0 * a, y, theta);
        let (pusher, settings) = super::super::contact::pusher_for(ob, &scene.contact, None);
        let outcome = pusher.push(&scene.part.model, pose, &settings, None);
        if !outcome.contact {
            return None;
        }
        let t_begin = outcome.travel_to_contact / v;
        let mut plan =
            super::super::contact::plan_of(j, (0.0, pose), pusher, settings, outcome, t_begin, v);
        if traced {
            plan.ensure_trace(&scene.part.model);
        }
        Some(Motion::Held(Box::new(plan)))
    }

    /// The largest amount (m) by which a vertex of the part moving along `motion` leaves the
    /// broad phase's capsule over [now, end] (≤ 0: never), at 200 times and at every step of a
    /// push. The capsule lives in the belt frame that is the world at `now`.
    fn excess(scene: &Scene, motion: &Motion, now: f64, end: f64) -> f64 {
        let v = scene.belt.speed;
        let (p0, p1, r) = bounding_capsule(scene, motion, now, end);
        let mut times: Vec<f64> = (0..=200)
            .map(|k| now + (end - now) * k as f64 / 200.0)
            .collect();
        if let Motion::Held(plan) = motion {
            times.extend(
                plan.step_times(v)
                    .into_iter()
                    .filter(|t| (now..=end).contains(t)),
            );
        }
        let mut worst = f64::NEG_INFINITY;
        for t in times {
            let shift = Vec2::new(v * (t - now), 0.0);
            for w in scene.part.polygon.world_vertices(&motion.world_pose(t, v)) {
                let b = w - shift;
                worst = worst.max(segment_distance(b, b, p0, p1) - r);
            }
        }
        worst
    }

    /// The first time in [now, end] at which the parts moving along `first` and `second`
    /// overlap, by brute force: the polygon clearance at 4000 even times and at every step of
    /// either push (None: never).
    fn first_overlap_sampled(
        scene: &Scene,
        first: &Motion,
        second: &Motion,
        now: f64,
        end: f64,
    ) -> Option<f64> {
        let v = scene.belt.speed;
        let mut times: Vec<f64> = (0..=4000)
            .map(|k| now + (end - now) * k as f64 / 4000.0)
            .collect();
        for m in [first, second] {
            if let Motion::Held(plan) = m {
                times.extend(
                    plan.step_times(v)
                        .into_iter()
                        .filter(|t| (now..=end).contains(t)),
                );
            }
        }
        times.sort_by(f64::total_cmp);
        let poly = &scene.part.polygon;
        times.into_iter().find(|&t| {
            let wa = poly.world_vertices(&first.world_pose(t, v));
            let wb = poly.world_vertices(&second.world_pose(t, v));
            polygon_clearance(&wa, &wb) <= 0.0
        })
    }

    /// The start and end of a push (s).
    struct Push {
        begin: f64,
        end: f64,
    }

    /// [`held`], with the start and end of its push.
    fn held_with_push(scene: &Scene, j: usize, y: f64, theta: f64) -> Option<(Motion, Push)> {
        let m = held(scene, j, y, theta)?;
        let Motion::Held(plan) = &m else {
            unreachable!()
        };
        let push = Push {
            begin: plan.t_begin,
            end: plan.t_end,
        };
        Some((m, push))
    }

    /// Ways for a part to ride into each obstacle of `scene`: (obstacle, lateral offset y in m,
    /// orientation in rad), the part's centroid 0.5 a to either side of the obstacle's line.
    fn entries(scene: &Scene) -> Vec<(usize, f64, f64)> {
        let a = scene.part.radius;
        (0..scene.obstacles.len())
            .flat_map(|j| {
                let y = scene.obstacles[j].capsule().0.y;
                [(0.3, 0.4), (-0.3, 1.9), (0.1, 3.5), (-0.5, 5.0)]
                    .map(|(dy, theta)| (j, y + dy * a, theta))
            })
            .collect()
    }

    /// Two parts on the belt: part 0 moving along `other`, part 1 along `me`, checked as part
    /// 1's motion starts at `now`; the collisions scheduled.
    fn collisions_of(scene: &Scene, me: Motion, other: Motion, now: f64) -> Vec<f64> {
        let mut belt = Belt::new();
        for (k, m) in [(0u64, other), (1u64, me)] {
            let mut part = ActivePart::entering(0.0, Pose::new(0.0, 0.0, 0.0), None, false);
            part.motion = m;
            belt.active.insert(k, part);
        }
        let mut work = WorkCounters::default();
        check_pairs(scene, &mut belt, &mut work, 1, now);
        std::iter::from_fn(|| belt.queue.pop())
            .map(|e| e.time)
            .collect()
    }

    /// A pair is checked over the time both motions are known, up to the earlier of their
    /// ends: a free part that would run into a held one only after its own motion ends (at its
    /// next event, where it is checked again) gets no collision; the same part moving until the
    /// push ends gets one, at the first overlap. (A mutant taking the later of the two ends
    /// passed every test.)
    #[test]
    fn a_pair_is_checked_only_until_the_earlier_of_the_two_motions_ends() {
        let scene = scene_of("quickstart.toml");
        let v = scene.belt.speed;
        let mut tried = 0;
        for (j, y, theta) in entries(&scene) {
            let Some((me, t)) = held_with_push(&scene, j, y, theta) else {
                continue;
            };
            // A free part overlapping the held one fully at the end of the push (the same
            // pose), upstream of it before: when does it first touch?
            let at_end = me.world_pose(t.end, v);
            let free = |until: f64| Motion::Free {
                t0: t.end,
                pose: at_end,
                until,
            };
            let Some(touch) = first_overlap_sampled(&scene, &me, &free(t.end), t.begin, t.end)
            else {
                continue;
            };
            if touch <= t.begin + 0.1 * (t.end - t.begin) {
                continue;
            }
            tried += 1;
            let hits = collisions_of(&scene, me.clone(), free(t.end), t.begin);
            assert_eq!(hits.len(), 1, "obstacle {j}, y {y}: {hits:?}");
            assert!(
                hits[0] <= touch + 1e-9 && hits[0] > t.begin,
                "{hits:?} vs {touch}"
            );
            // The free part's motion ends halfway to the touch: nothing to schedule yet.
            let until = 0.5 * (t.begin + touch);
            let hits = collisions_of(&scene, me.clone(), free(until), t.begin);
            assert!(hits.is_empty(), "obstacle {j}, y {y}: collision at {hits:?} after the free part's motion ended at {until}");
            // And with the roles swapped: the held part's motion is the one checked.
            let hits = collisions_of(&scene, free(until), me.clone(), t.begin);
            assert!(hits.is_empty(), "obstacle {j}, y {y} (swapped): {hits:?}");
        }
        assert!(
            tried >= 2,
            "only {tried} configurations ran into each other"
        );
    }
    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, rng_seed: proptest::test_runner::RngSeed::Fixed(57021), .. ProptestConfig::default() })]

        /// Issue 57 item 21: every vertex of a part held by a pin, held against a fence or in
        /// free travel stays inside the capsule the part–part broad phase gives it, from any
        /// moment of the motion to its end (a broad phase one part radius too small passed
        /// every test).
        #[test]
        fn every_vertex_stays_inside_the_broad_phase_capsule(
            y in -1.0f64..1.0,
            theta in 0.0f64..std::f64::consts::TAU,
            from in 0.0f64..1.0,
            fence in any::<bool>(),
            thick in any::<bool>(),
            j in 0usize..2,
        ) {
            let scene = match (fence, thick) {
                (true, _) => scene_of("tripoly1_fences.toml"),
                (false, false) => scene_of("quickstart.toml"),
                (false, true) => thick_pins(),
            };
            let a = scene.part.radius;
            let j = j % scene.obstacles.len();
            let (centre, _, _) = scene.obstacles[j].capsule();
            let y = (centre.y + y * 1.5 * a).clamp(-scene.belt.width / 2.0 + a, scene.belt.width / 2.0 - a);
            let free = Motion::Free { t0: 0.0, pose: Pose::new(0.1, y, theta), until: 2.0 };
            prop_assert!(excess(&scene, &free, 2.0 * from, 2.0) <= 1e-12 * a);
            if let Some(m) = held(&scene, j, y, theta) {
                let Motion::Held(plan) = &m else { unreachable!() };
                let now = plan.t_begin + from * (plan.t_end - plan.t_begin);
                let out = excess(&scene, &m, now, plan.t_end);
                prop_assert!(out <= 1e-9 * a, "a vertex leaves the capsule by {} a", out / a);
            }
        }

        /// The narrow phase finds the first overlap of a held part and a free part no later than
        /// dense sampling of their clearance does (a bound on how fast the clearance can fall
        /// without the part's rotation skipped pieces where a turning vertex reached the other
        /// part: a mutant passed every test), and only where they do overlap.
        #[test]
        fn the_narrow_phase_finds_the_first_overlap_that_sampling_finds(
            y in -1.0f64..1.0,
            theta in 0.0f64..std::f64::consts::TAU,
            at in 0.0f64..1.0,
            dist in 1.0f64..2.2,
            dir in 0.0f64..std::f64::consts::TAU,
            theta2 in 0.0f64..std::f64::consts::TAU,
            j in 0usize..3,
        ) {
            let scene = scene_of("quickstart.toml");
            let (v, a) = (scene.belt.speed, scene.part.radius);
            let j = j % scene.obstacles.len();
            let (centre, _, _) = scene.obstacles[j].capsule();
            let y = centre.y + y * a;
            let Some((me, t)) = held_with_push(&scene, j, y, theta) else {
                return Ok(());
            };
            // A free part placed `dist` radii from the held one at a moment of the push.
            let ts = t.begin + at * (t.end - t.begin);
            let p = me.world_pose(ts, v);
            let pose = Pose::new(p.x + dist * a * dir.cos(), p.y + dist * a * dir.sin(), theta2);
            let free = Motion::Free { t0: ts, pose, until: t.end };
            let sampled = first_overlap_sampled(&scene, &me, &free, t.begin, t.end);
            let tol = 1e-5 * a / v;
            // Either part first: the held one's steps are breaks of the walk either way.
            for (first, second) in [(&me, &free), (&free, &me)] {
                let mut evals = 0;
                let found = first_overlap(&scene, first, second, t.begin, t.end, &mut evals);
                match (found, sampled) {
                    (None, Some(s)) => prop_assert!(false, "missed the overlap at {s}"),
                    (Some(f), Some(s)) => prop_assert!(f <= s + tol, "found at {f}, sampled at {s}"),
                    (Some(f), None) => {
                        let poly = &scene.part.polygon;
                        let c = polygon_clearance(
                            &poly.world_vertices(&me.world_pose(f, v)),
                            &poly.world_vertices(&free.world_pose(f, v)),
                        );
                        prop_assert!(c <= 1e-5 * a, "an overlap at {f} where the clearance is {c}");
                    }
                    (None, None) => {}
                }
            }
        }
    }
}
