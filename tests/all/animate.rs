//! `pinfeed run --animate`: the animated SVG's structure, read back with a small XML reader
//! (well-formed, one group per part and per obstacle, every animation's keyTimes in [0, 1] and
//! nondecreasing with as many values, outcome colours, a moving pin's `cy`, a withdrawn pin's
//! opacity, timed marks) on a hand-built animation and on runs of the bundled scenes.
//!
//! Set `PINFEED_ANIMATE_DEMO=DIR` to keep the SVGs for a look in a browser.

use crate::xml::{parse_xml, Element};
use pinfeed::engine::{run, PartOutcome, RunOptions};
use pinfeed::geometry::{Pose, Vec2};
use pinfeed::report::animate::{
    self, AnimMark, AnimObstacle, AnimPart, AnimShape, AnimateOptions, Animation, MarkKind,
};
use pinfeed::report::plot_line::outcome_colour;
use std::path::Path;

// ---------- checks every animation must pass ----------

fn numbers(list: &str) -> Vec<f64> {
    list.split(';')
        .map(|v| v.trim().parse::<f64>().expect("a number"))
        .collect()
}

/// Every SMIL element: loops with the document's `dur`; keyTimes in [0, 1], nondecreasing,
/// starting at 0 (and ending at 1 unless discrete), as many as the values. Returns the `dur`.
fn check_animations(svg: &Element) -> f64 {
    let mut dur = None;
    let mut n = 0;
    for e in svg.all() {
        if !matches!(e.name.as_str(), "animate" | "animateTransform" | "set") {
            continue;
        }
        n += 1;
        if e.name == "set" {
            assert!(e.attr("to").is_some());
            continue;
        }
        let d = e.attr("dur").expect("dur");
        let secs: f64 = d.strip_suffix('s').expect("dur in s").parse().unwrap();
        assert!(secs > 0.0);
        assert_eq!(e.attr("repeatCount"), Some("indefinite"));
        let Some(kt) = e.attr("keyTimes") else {
            // The belt's stripes: a short from/to loop of their own.
            assert!(e.attr("from").is_some() && e.attr("to").is_some(), "{e:?}");
            continue;
        };
        match dur {
            None => dur = Some(secs),
            Some(d0) => assert_eq!(d0, secs, "all timed animations share one loop"),
        }
        let times = numbers(kt);
        let values: Vec<&str> = e.attr("values").expect("values").split(';').collect();
        assert_eq!(times.len(), values.len(), "{e:?}");
        assert!(times.len() >= 2);
        assert_eq!(times[0], 0.0);
        assert!(times.iter().all(|t| (0.0..=1.0).contains(t)), "{kt}");
        assert!(times.windows(2).all(|w| w[0] <= w[1]), "{kt}");
        if e.attr("calcMode") != Some("discrete") {
            assert_eq!(*times.last().unwrap(), 1.0, "{kt}");
        }
    }
    assert!(n > 0, "no animation at all");
    dur.expect("a timed animation")
}

/// The key time at which a discrete `attr` animation of `e` first takes `value`.
fn first_switch(e: &Element, attr: &str, value: &str) -> Option<f64> {
    let a = e
        .all()
        .into_iter()
        .find(|a| a.name == "animate" && a.attr("attributeName") == Some(attr))?;
    let values: Vec<&str> = a.attr("values")?.split(';').collect();
    let times = numbers(a.attr("keyTimes")?);
    values.iter().position(|v| *v == value).map(|i| times[i])
}

fn hex(o: PartOutcome) -> String {
    let c = outcome_colour(o);
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

fn keep(name: &str, svg: &str) {
    if let Ok(dir) = std::env::var("PINFEED_ANIMATE_DEMO") {
        std::fs::write(Path::new(&dir).join(name), svg).unwrap();
    }
}

// ---------- a hand-built animation ----------

fn tripoly2_outline() -> Vec<Vec2> {
    [
        (-2.0 / 3.0, -1.0 / 3.0),
        (4.0 / 3.0, -1.0 / 3.0),
        (-2.0 / 3.0, 2.0 / 3.0),
    ]
    .iter()
    .map(|&(x, y)| Vec2::new(x * 0.02, y * 0.02))
    .collect()
}

/// Parts every 4 s along y = 0, each turning 90° near x = 0.3 m; a pin moving across the belt,
/// a pin that withdraws and rises, a fence, and one mark of each kind.
fn demo(n_parts: usize, steps_per_part: usize) -> Animation {
    let speed = 0.05;
    let outcomes = [
        PartOutcome::Success,
        PartOutcome::WrongOrientation,
        PartOutcome::Collision,
        PartOutcome::OffBelt,
    ];
    let parts = (0..n_parts)
        .map(|i| {
            let t0 = 4.0 * i as f64;
            let t1 = t0 + 0.6 / speed;
            let poses = (0..=steps_per_part)
                .map(|k| {
                    let t = t0 + (t1 - t0) * k as f64 / steps_per_part as f64;
                    let x = speed * (t - t0);
                    let turn = ((x - 0.28) / 0.04).clamp(0.0, 1.0) * std::f64::consts::FRAC_PI_2;
                    let y = if outcomes[i % 4] == PartOutcome::OffBelt {
                        0.08 * (x / 0.6)
                    } else {
                        0.004 * (i % 3) as f64
                    };
                    (t, Pose::new(x, y, 0.3 * i as f64 + turn))
                })
                .collect();
            AnimPart {
                part: i as u64,
                outcome: outcomes[i % 4],
                poses,
            }
        })
        .collect();
    Animation {
        title: "hand-built: moving & retractable pins <demo>".into(),
        belt_length: 0.6,
        belt_width: 0.1,
        belt_speed: speed,
        outline: tripoly2_outline(),
        obstacles: vec![
            AnimObstacle {
                name: "still".into(),
                shape: AnimShape::Pin {
                    x: 0.15,
                    radius: 0.002,
                },
                sensor: true,
                track: vec![(0.0, 0.004, true)],
            },
            AnimObstacle {
                name: "mover".into(),
                shape: AnimShape::Pin {
                    x: 0.3,
                    radius: 0.002,
                },
                sensor: false,
                track: vec![
                    (0.0, -0.02, true),
                    (5.0, -0.02, true),
                    (7.0, 0.02, true),
                    (13.0, 0.02, true),
                    (15.0, -0.02, true),
                ],
            },
            AnimObstacle {
                name: "gate".into(),
                shape: AnimShape::Pin {
                    x: 0.45,
                    radius: 0.003,
                },
                sensor: false,
                track: vec![(0.0, 0.0, true), (10.0, 0.0, false), (18.0, 0.0, true)],
            },
            AnimObstacle {
                name: "fence".into(),
                shape: AnimShape::Fence {
                    p0: Vec2::new(0.5, -0.05),
                    p1: Vec2::new(0.58, -0.03),
                    tail: None,
                },
                sensor: false,
                track: vec![],
            },
        ],
        parts,
        marks: vec![
            AnimMark {
                t: 3.0,
                at: Vec2::new(0.15, 0.004),
                kind: MarkKind::Reading,
                text: "still: F/T reading".into(),
            },
            AnimMark {
                t: 4.0,
                at: Vec2::new(0.15, 0.004),
                kind: MarkKind::Decision,
                text: "part 0 → 90° (0.97) & go".into(),
            },
            AnimMark {
                t: 5.0,
                at: Vec2::new(0.3, -0.02),
                kind: MarkKind::Actuation,
                text: "mover → +20 mm".into(),
            },
            AnimMark {
                t: 10.0,
                at: Vec2::new(0.45, 0.0),
                kind: MarkKind::Late,
                text: "gate: late".into(),
            },
        ],
        t_start: 0.0,
        t_end: 4.0 * n_parts as f64 + 12.0,
    }
}

fn obstacle<'a>(svg: &'a Element, name: &str) -> &'a Element {
    svg.with_class("obstacle")
        .into_iter()
        .find(|e| e.attr("data-name") == Some(name))
        .unwrap_or_else(|| panic!("no obstacle {name}"))
}

#[test]
fn hand_built_animation_has_the_expected_structure() {
    let anim = demo(8, 200);
    let doc = animate::render(&anim, &AnimateOptions::default());
    keep("demo.svg", &doc);
    let svg = parse_xml(&doc);
    assert_eq!(svg.name, "svg");
    assert!(svg
        .all()
        .iter()
        .any(|e| e.name == "title"
            && e.inner_text() == "hand-built: moving & retractable pins <demo>"));
    let dur = check_animations(&svg);
    // Default speed-up: the loop lasts 20–40 s.
    assert!((20.0..=40.0).contains(&dur), "dur {dur}");
    assert_eq!(svg.with_class("part").len(), anim.parts.len());
    assert_eq!(svg.with_class("obstacle").len(), anim.obstacles.len());
    // Each part: translate and rotate keyframes, and its outcome colour when it ends.
    for (p, g) in anim.parts.iter().zip(svg.with_class("part")) {
        assert_eq!(g.attr("data-part"), Some(p.part.to_string().as_str()));
        let kinds: Vec<&str> = g
            .all()
            .iter()
            .filter(|e| e.name == "animateTransform")
            .filter_map(|e| e.attr("type"))
            .collect();
        assert_eq!(kinds, ["translate", "rotate"]);
        let colour = hex(p.outcome);
        let t_end = p.poses.last().unwrap().0;
        let u = first_switch(g, "fill", &colour).expect("turns its outcome colour");
        assert!((u - t_end / anim.t_end).abs() < 1e-4, "{u}");
        // Appears when it arrives.
        let u_in = first_switch(g, "visibility", "visible").unwrap();
        assert!((u_in - p.poses[0].0 / anim.t_end).abs() < 1e-4);
    }
    for o in [
        PartOutcome::Success,
        PartOutcome::WrongOrientation,
        PartOutcome::Collision,
        PartOutcome::OffBelt,
    ] {
        assert!(doc.contains(&hex(o)), "{o:?} colour");
    }
    // The moving pin animates its centre across the belt; the still pins do not.
    let mover = obstacle(&svg, "mover");
    let cy = mover
        .all()
        .into_iter()
        .find(|e| e.name == "animate" && e.attr("attributeName") == Some("cy"))
        .expect("moving pin animates cy");
    let ys = numbers(cy.attr("values").unwrap());
    let (lo, hi) = ys
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &y| (a.min(y), b.max(y)));
    assert!(hi - lo > 10.0, "travels {} px", hi - lo);
    for still in ["still", "gate"] {
        assert!(!obstacle(&svg, still)
            .all()
            .iter()
            .any(|e| e.attr("attributeName") == Some("cy")));
    }
    // The retractable pin fades when withdrawn (from t = 10 s to 18 s).
    let gate = obstacle(&svg, "gate");
    let faded = first_switch(gate, "opacity", "0.2").expect("withdrawn pin fades");
    assert!((faded - 10.0 / anim.t_end).abs() < 1e-4);
    let back = first_switch(gate, "opacity", "1").unwrap();
    assert_eq!(back, 0.0);
    // Marks: one timed group each, with its text, shown from its time.
    let marks = svg.with_class("mark");
    assert_eq!(marks.len(), anim.marks.len());
    for (m, g) in anim.marks.iter().zip(&marks) {
        assert_eq!(g.attr("data-kind"), Some(m.kind.name()));
        assert!(g.inner_text().contains(&m.text), "{}", g.inner_text());
        let a = g
            .children
            .iter()
            .find(|e| e.name == "animate" && e.attr("attributeName") == Some("opacity"))
            .expect("timed opacity");
        let times = numbers(a.attr("keyTimes").unwrap());
        let values = numbers(a.attr("values").unwrap());
        let shown = times
            .iter()
            .zip(&values)
            .find(|(_, v)| **v == 1.0)
            .map(|(t, _)| *t)
            .unwrap();
        assert!((shown - m.t / anim.t_end).abs() < 1e-4);
    }
    // A clock: a progress bar over the loop.
    let bar = svg.with_class("progress");
    assert_eq!(bar.len(), 1);
}

#[test]
fn the_speed_up_sets_the_loop() {
    let anim = demo(4, 50);
    let doc = animate::render(&anim, &AnimateOptions { speedup: Some(2.0) });
    let dur = check_animations(&parse_xml(&doc));
    assert!((dur - anim.t_end / 2.0).abs() < 1e-3, "dur {dur}");
    assert_eq!(
        animate::duration(
            &anim,
            &AnimateOptions {
                speedup: Some(1e-9)
            }
        ),
        animate::MAX_DURATION_S
    );
}

#[test]
fn twelve_long_paths_stay_small() {
    // 12 parts of 20 000 recorded poses each: thinned to bounded keyframes.
    let anim = demo(12, 20_000);
    let doc = animate::render(&anim, &AnimateOptions::default());
    assert!(doc.len() < 1_000_000, "{} bytes", doc.len());
    let svg = parse_xml(&doc);
    check_animations(&svg);
    for e in svg.all() {
        if let Some(v) = e.attr("values") {
            assert!(v.split(';').count() <= animate::MAX_KEYS + 2);
        }
    }
}

#[test]
fn bad_data_does_not_break_the_document() {
    let mut anim = demo(3, 20);
    anim.parts[0]
        .poses
        .push((f64::NAN, Pose::new(f64::NAN, 0.0, 0.0)));
    anim.parts[1].poses.clear();
    anim.parts.extend((0..60).map(|i| AnimPart {
        part: 100 + i,
        outcome: PartOutcome::Jam,
        poses: vec![(1.0, Pose::new(0.1, 0.0, 0.0))],
    }));
    anim.marks.push(AnimMark {
        t: f64::INFINITY,
        at: Vec2::new(0.1, 0.0),
        kind: MarkKind::Late,
        text: "never".into(),
    });
    anim.t_end = anim.t_start; // an empty span
    let doc = animate::render(
        &anim,
        &AnimateOptions {
            speedup: Some(-3.0),
        },
    );
    let svg = parse_xml(&doc);
    check_animations(&svg);
    assert_eq!(svg.with_class("part").len(), animate::MAX_PARTS);
    assert_eq!(svg.with_class("mark").len(), anim.marks.len() - 1);
}

// ---------- from a run ----------

fn run_scene(path: &str, parts: u64, keep_records: bool) -> (pinfeed::scenario::Scene, String) {
    let scene = pinfeed::scenario::load(Path::new(path)).unwrap();
    let mut opts = RunOptions::from_scene(&scene);
    opts.parts = parts;
    opts.sample_paths = animate::DEFAULT_PARTS;
    opts.keep_records = keep_records;
    let result = run(&scene, &opts, &mut |_| {}).unwrap();
    let anim = animate::from_run(&scene, &result, animate::DEFAULT_PARTS);
    assert_eq!(anim.parts.len(), animate::DEFAULT_PARTS);
    assert!(anim.parts.windows(2).all(|w| w[0].part + 1 == w[1].part));
    assert_eq!(anim.obstacles.len(), scene.obstacles.len());
    let doc = animate::render(&anim, &AnimateOptions::default());
    assert_eq!(doc, animate::render(&anim, &AnimateOptions::default()));
    (scene, doc)
}

#[test]
fn quickstart_run_animates() {
    let (scene, doc) = run_scene("scenarios/quickstart.toml", 20, false);
    keep("quickstart.svg", &doc);
    let svg = parse_xml(&doc);
    let dur = check_animations(&svg);
    assert!((20.0..=40.0).contains(&dur));
    assert_eq!(svg.with_class("part").len(), animate::DEFAULT_PARTS);
    assert_eq!(svg.with_class("obstacle").len(), scene.obstacles.len());
    assert!(svg.with_class("mark").is_empty());
    assert!(doc.contains(&hex(PartOutcome::Success)));
    assert!(doc.len() < 500_000);
}

#[test]
fn sensor_run_marks_readings_and_decisions() {
    let (_, doc) = run_scene("scenarios/tripoly1_sensor.toml", 12, true);
    keep("tripoly1_sensor.svg", &doc);
    let svg = parse_xml(&doc);
    check_animations(&svg);
    let probe = obstacle(&svg, "probe");
    assert!(probe.inner_text().contains("sensor"));
    let marks = svg.with_class("mark");
    let readings = marks
        .iter()
        .filter(|m| m.attr("data-kind") == Some("reading"))
        .count();
    let decisions: Vec<String> = marks
        .iter()
        .filter(|m| m.attr("data-kind") == Some("decision"))
        .map(|m| m.inner_text())
        .collect();
    assert!(readings > 0);
    assert_eq!(readings, decisions.len());
    assert!(decisions
        .iter()
        .all(|d| d.contains('°') || d.contains("unknown")));
}

#[test]
fn cli_writes_the_animation() {
    let dir = std::env::temp_dir().join(format!("pinfeed-animate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("line.svg");
    let pinfeed = |extra: &[&str]| {
        let mut args = vec![
            "run",
            "scenarios/quickstart.toml",
            "--parts",
            "15",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
            "--animate",
            svg.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_pinfeed"))
            .args(&args)
            .output()
            .unwrap()
    };
    let o = pinfeed(&["--animate-speed", "4"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let doc = std::fs::read_to_string(&svg).unwrap();
    let svg_el = parse_xml(&doc);
    let dur = check_animations(&svg_el);
    assert_eq!(svg_el.with_class("part").len(), animate::DEFAULT_PARTS);
    // Ten parts every 4 s, 12 s on the belt and a tenth more: about 56 s at ×4.
    assert!((10.0..20.0).contains(&dur), "dur {dur}");
    for bad in ["0", "-1", "nan", "1e-6"] {
        let o = pinfeed(&[&format!("--animate-speed={bad}")]);
        assert!(!o.status.success(), "--animate-speed {bad} accepted");
        assert!(String::from_utf8_lossy(&o.stderr).contains("--animate-speed"));
    }
    std::fs::remove_dir_all(&dir).ok();
}
