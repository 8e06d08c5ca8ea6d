//! Fences on the line: a long fence delivers every part in the orientation it leaves a
//! flush edge in; a fence at the jam angle jams parts (and just below it does not, but holds them
//! so long that the next part catches up: a collision); a fence that carries parts over the belt's
//! edge drops them; a pin beside a fence is a second contact; the per-obstacle counters include
//! fences.

use pinfeed::engine::{self, PartRecord, RunOptions, RunResult};
use pinfeed::geometry::{part_from_spec, wrap_deg, Pose};
use pinfeed::maps::fence_pass_start;
use pinfeed::mechanics::{push_fence, ContactSettings, PartModel, Support};
use pinfeed::scenario::{self, Scene};
use std::path::Path;

/// tripoly2 (2 cm per unit, a = 2.75 cm) fed at any orientation within ±2 mm of the centre line
/// of a 20 cm belt, one part every 12 s (never two near each other), and one fence from
/// (0.1, −0.09) m: `fence` holds its angle, length and friction lines.
fn scenario_text(fence: &str, extra: &str) -> String {
    format!(
        r#"name = "fence-test"
[belt]
speed = 0.05
width = 0.2
length = 0.6

[part]
shape = "tripoly2"
scale = 0.02

[feed]
parts = 48
arrival = "periodic"
headway = 12.0
orientation = "uniform"

[feed.lateral]
distribution = "uniform"
min = -0.002
max = 0.002

[[obstacles]]
kind = "fence"
x = 0.1
y = -0.09
{fence}

{extra}
[goal]
any = true
"#
    )
}

fn scene(text: &str) -> Scene {
    scenario::parse(Path::new("fence-test.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

fn run(scene: &Scene) -> RunResult {
    let mut opts = RunOptions::from_scene(scene);
    opts.keep_records = true;
    let r = engine::run(scene, &opts, &mut |_| {}).unwrap();
    assert_eq!(
        r.summary.outcomes.total(),
        r.summary.parts_in,
        "conservation"
    );
    assert_eq!(r.records.len() as u64, r.summary.parts_in);
    r
}

fn ang_diff(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

/// The orientations in which tripoly2 leaves a long fence at `angle_deg` (friction `mu_f`), from
/// the contact model alone: for each hull edge, start with that edge flush (θ = α − 90° − the
/// edge's outward-normal angle) and push to the fence's end.
fn exit_orientations(angle_deg: f64, mu_f: f64) -> Vec<f64> {
    let poly = part_from_spec("tripoly2").unwrap();
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let fence = fence_pass_start(&poly, 0.0, angle_deg, None, mu_f);
    let hull = model.hull();
    (0..hull.len())
        .map(|j| {
            let out = -hull.inward_normal(j);
            let flush = angle_deg - 90.0 - out.angle().to_degrees();
            let o = push_fence(
                &model,
                Pose::new(0.0, 0.0, flush.to_radians()),
                &fence,
                &ContactSettings::default(),
                None,
            );
            assert!(o.status.is_ok(), "flush {flush}°: {:?}", o.status);
            wrap_deg(o.pose_final.theta_rad.to_degrees())
        })
        .collect()
}

#[test]
fn a_long_fence_leaves_every_part_as_a_flush_edge_leaves_its_end() {
    let angle = 45.0;
    // Length 0.15·√2 m: the fence ends at (0.25, 0.06), 2a beyond every part's band.
    let s = scene(&scenario_text(
        "angle = 45.0\nlength = 0.212132\nmu_f = 0.3",
        "",
    ));
    let r = run(&s);
    let expected = exit_orientations(angle, 0.3);
    assert_eq!(r.summary.outcomes.success, r.summary.parts_in);
    let mut used = vec![0; expected.len()];
    for rec in &r.records {
        assert_eq!(rec.contacts, 1, "{rec:?}");
        let (k, miss) = expected
            .iter()
            .enumerate()
            .map(|(k, &e)| (k, ang_diff(rec.theta_out_deg, e).abs()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        assert!(
            miss < 0.01,
            "part {} left at {}°, expected one of {expected:?}",
            rec.part,
            rec.theta_out_deg
        );
        used[k] += 1;
        // Carried across the belt to the fence's end (y = 0.06 m).
        assert!(rec.y_out_m > 0.05, "{rec:?}");
    }
    assert!(
        used.iter().filter(|&&n| n > 0).count() >= 2,
        "uniform feed should use several flush edges: {used:?}"
    );
    let fence = &r.summary.obstacles[0];
    assert_eq!(fence.name, "fence1");
    assert_eq!(fence.contacts, r.summary.parts_in);
    assert!(fence.busy_fraction > 0.0 && fence.busy_fraction < 1.0);
    assert_eq!(r.summary.contacts_per_part, 1.0);
}

#[test]
fn a_fence_at_the_jam_angle_jams_parts_and_just_below_it_does_not() {
    // μf = 0.5: atan μf = 26.57°, so the critical angle is 63.43°.
    let jam = run(&scene(&scenario_text(
        "angle = 65.0\nlength = 0.15\nmu_f = 0.5",
        "",
    )));
    let o = jam.summary.outcomes;
    assert_eq!(o.jam, jam.summary.parts_in, "{o:?}");
    assert_eq!(
        jam.summary.causes.jam.get("fence_angle"),
        Some(&jam.summary.parts_in)
    );
    // Jammed parts leave the line where they stopped, long before they could reach the exit.
    let exit_time = 0.6 / 0.05;
    for rec in &jam.records {
        let rec: &PartRecord = rec;
        assert!(rec.end_s - rec.arrival_s < exit_time, "{rec:?}");
    }
    // Just below the angle the parts slide, slowly (about 45 s on the fence against 12 s of free
    // travel): a part every 60 s so that none catches up with the one before.
    let slide = run(&scene(
        &scenario_text("angle = 62.0\nlength = 0.15\nmu_f = 0.5", "")
            .replace("headway = 12.0", "headway = 60.0"),
    ));
    assert_eq!(slide.summary.outcomes.jam, 0);
    assert_eq!(slide.summary.outcomes.success, slide.summary.parts_in);
    let latency = slide.summary.latency_s.unwrap();
    assert!(latency.p50 > 2.0 * exit_time, "{latency:?}");
    // Fed every 12 s instead, each part is caught on the fence by the next one: collisions between
    // a part held by a fence and a free part are found.
    let crowded = run(&scene(&scenario_text(
        "angle = 62.0\nlength = 0.15\nmu_f = 0.5",
        "",
    )));
    let o = crowded.summary.outcomes;
    assert!(o.collision * 2 > crowded.summary.parts_in, "{o:?}");
    assert_eq!(o.collision % 2, 0, "collisions take two parts off: {o:?}");
}

#[test]
fn a_fence_that_reaches_the_edge_drops_parts_off_the_belt() {
    // 45° from (0.1, −0.09) to the left edge y = 0.1: the parts' centroids cross the edge while
    // the fence still carries them.
    let r = run(&scene(&scenario_text(
        "angle = 45.0\nlength = 0.2687\nmu_f = 0.3",
        "",
    )));
    assert_eq!(r.summary.outcomes.off_belt, r.summary.parts_in);
    for rec in &r.records {
        assert!((rec.y_out_m - 0.1).abs() < 1e-6, "{rec:?}");
    }
    assert!(r.summary.work.traces_recorded >= r.summary.parts_in);
}

#[test]
fn a_pin_beside_a_fence_is_a_second_contact() {
    // A pin 10 mm off the fence, on the parts' side, two thirds of the way along it: parts sliding
    // along the fence run into it.
    let pin = "[[obstacles]]\nkind = \"pin\"\nx = 0.1990\ny = 0.0232\nradius = 0.002\n";
    let s = scene(&scenario_text(
        "angle = 45.0\nlength = 0.212132\nmu_f = 0.3",
        pin,
    ));
    assert_eq!(s.neighbours[0], vec![1]);
    let r = run(&s);
    let o = r.summary.outcomes;
    assert!(o.multi_contact * 2 > r.summary.parts_in, "{o:?}");
    assert_eq!(
        r.summary.causes.multi_contact.get("second_obstacle"),
        Some(&o.multi_contact)
    );
    // Without the sweep the same parts pass (the check is what finds them).
    let off = run(&scene(&scenario_text(
        "angle = 45.0\nlength = 0.212132\nmu_f = 0.3",
        &format!("{pin}\n[effects]\nobstacle_sweeps = false\n"),
    )));
    assert_eq!(off.summary.outcomes.multi_contact, 0);
}

/// Issue 57 item 15: `busy 102%` for a fence was explained nowhere. It is the fence's push time
/// summed over the parts it pushes, per second of the run: above 100% when parts slide along it
/// together, and the table says so then (and only then).
#[test]
fn a_fence_busy_above_100_percent_is_parts_sliding_along_it_together() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/tripoly1_fences.toml");
    let mut s = scenario::load(&path).unwrap();
    s.feed.parts = 60;
    let note = pinfeed::report::line_table::BUSY_ABOVE_100;
    let busy = |s: &Scene| {
        let r = engine::run(s, &RunOptions::from_scene(s), &mut |_| {}).unwrap();
        let table = pinfeed::report::line_table::table(&r.summary);
        (r.summary.obstacles[0].busy_fraction, table.contains(note))
    };
    // At the bundled 6 s headway one part at a time slides along the first fence.
    let (b, noted) = busy(&s);
    assert!(b < 1.0 && !noted, "busy {b}, noted {noted}");
    // At 3 s two parts are on it at times: more than a second of pushing per second.
    s.feed.arrival = scenario::Arrival::Periodic { headway: 3.0 };
    let (b, noted) = busy(&s);
    assert!(b > 1.0, "busy {b}");
    assert!(noted, "no note for busy {b}");
}
