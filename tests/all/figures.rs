//! The figures zoom on the data, are to scale, and their labels never overlap (issue 32, item 7):
//! each SVG is read back ([`crate::xml`]) and checked for what a reader would see — the axis
//! range around the data, whole counts, labelled goal and stable states, a fence drawn at its
//! angle, titles that name the obstacles, obstacles named in their own colour, no two text boxes
//! (estimated from the font size) on top of one another.

use crate::support::{fresh_dir, pinfeed};
use crate::xml::{overlapping, parse_xml, text_boxes, Element, TextBox};
use pinfeed::engine::{run, RunOptions};
use pinfeed::maps::arcs::Arc;
use pinfeed::maps::ensemble::PredictedBands;
use pinfeed::report::animate::{self, AnimateOptions};
use std::path::Path;

fn read_svg(path: &Path) -> Element {
    let doc =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    parse_xml(&doc)
}

/// The numbers printed as tick labels with this `text-anchor` (middle: the x axis of a plotters
/// chart; end: its y axis), with their box.
fn ticks(boxes: &[TextBox], anchor: &str) -> Vec<(f64, TextBox)> {
    boxes
        .iter()
        .filter(|b| b.anchor.as_deref() == Some(anchor))
        .filter_map(|b| b.text.parse::<f64>().ok().map(|v| (v, b.clone())))
        .collect()
}

/// At least three y tick labels (a plotters chart's, anchored at their end), each in `range`.
fn y_ticks_within(boxes: &[TextBox], range: std::ops::RangeInclusive<f64>, what: &str) {
    let ys = ticks(boxes, "end");
    assert!(ys.len() >= 3, "{ys:?}");
    for (v, _) in &ys {
        assert!(range.contains(v), "y tick {v} far from {what}");
    }
}

fn no_overlaps(boxes: &[TextBox], what: &str) {
    let clash = overlapping(boxes);
    assert!(clash.is_empty(), "{what}: labels overlap: {clash:?}");
}

#[test]
fn the_orientation_histogram_zooms_on_the_data() {
    let dir = fresh_dir("figures-histogram");
    let scene = pinfeed::scenario::load(Path::new("scenarios/quickstart.toml")).unwrap();
    let mut opts = RunOptions::from_scene(&scene);
    opts.parts = 300;
    let result = run(&scene, &opts, &mut |_| {}).unwrap();
    let s = &result.summary;
    let path = dir.join("h.svg");
    pinfeed::report::plot_orientations::plot_orientation_histogram(&scene, s, &path).unwrap();
    let svg = read_svg(&path);
    let boxes = text_boxes(&svg);
    let h = &s.orientation_histogram;
    let occupied: Vec<f64> = (0..h.counts.len())
        .filter(|&i| h.counts[i] > 0)
        .map(|i| i as f64 * h.bin_deg)
        .collect();
    let (lo, hi) = (occupied[0], occupied[occupied.len() - 1] + h.bin_deg);
    assert!(
        hi - lo < 30.0,
        "quickstart ends in a narrow window: {lo}..{hi}"
    );
    let xs = ticks(&boxes, "middle");
    assert!(xs.len() >= 4, "{xs:?}");
    for (v, _) in &xs {
        assert!(
            (lo - 25.0..=hi + 25.0).contains(v),
            "x tick {v} far from the data {lo}..{hi}"
        );
    }
    let ys = ticks(&boxes, "end");
    assert!(ys.len() >= 3);
    for (v, b) in &ys {
        assert!(!b.text.contains('.'), "count printed as {}", b.text);
        assert_eq!(v.fract(), 0.0);
    }
    let texts: Vec<&str> = boxes.iter().map(|b| b.text.as_str()).collect();
    assert!(
        texts
            .iter()
            .any(|t| t.starts_with("goal ") && t.contains('±')),
        "{texts:?}"
    );
    // Every stable state is named: on its line, or below the axis when outside the view.
    let named = texts
        .iter()
        .filter(|t| t.starts_with("stable state"))
        .count();
    let outside = texts.iter().any(|t| t.contains("outside this view"));
    assert!(named > 0 || outside, "{texts:?}");
    no_overlaps(&boxes, "histogram");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn validation_plots_zoom_and_say_the_bands_are_offset() {
    let dir = fresh_dir("figures-validate");
    // Predictions around 100° (and one across 0°, drawn in one piece), measured bands beside.
    let spread: Vec<f64> = (0..200).map(|i| 95.0 + 0.05 * i as f64).collect();
    let w = vec![1.0; spread.len()];
    let p1 = PredictedBands::of(-0.2, "state:0".into(), &spread, &w);
    let p2 = PredictedBands::of(0.2, "state:0".into(), &spread, &w);
    let measured = vec![
        (-0.2, Arc::from_ends(96.0, 104.0)),
        (0.2, Arc::from_ends(97.0, 108.0)),
    ];
    let path = dir.join("v.svg");
    pinfeed::report::plot_validate::plot_band_distributions(&[&p1, &p2], &measured, "t", &path)
        .unwrap();
    let svg = read_svg(&path);
    let boxes = text_boxes(&svg);
    y_ticks_within(&boxes, 80.0..=125.0, "the data 95–108°");
    let texts: String = boxes.iter().map(|b| b.text.clone() + "\n").collect();
    assert!(
        texts.contains("left of d") && texts.contains("right of d"),
        "{texts}"
    );
    no_overlaps(&boxes, "validation plot");
    std::fs::remove_dir_all(&dir).ok();
}

/// A band of a configuration map from its ends and mean ± sd (degrees).
fn band(lo: f64, hi: f64, mean: f64, sd: f64) -> pinfeed::maps::Band {
    pinfeed::maps::Band {
        final_min_deg: lo,
        final_max_deg: hi,
        width_deg: hi - lo,
        mean_deg: mean,
        sd_deg: sd,
        adjusted_min_deg: mean - sd,
        adjusted_max_deg: mean + sd,
        initial_ranges_deg: vec![[0.0, 359.0]],
        com_y_min: 0.0,
        com_y_max: 0.0,
        samples: 10,
    }
}

/// Configuration maps of one band each, at the given d.
fn one_band_each(bands: Vec<(f64, pinfeed::maps::Band)>) -> Vec<pinfeed::maps::ConfigurationMap> {
    bands
        .into_iter()
        .map(|(d, b)| pinfeed::maps::ConfigurationMap {
            d,
            samples: vec![],
            bands: vec![b],
            no_contact_ranges_deg: vec![],
            fence: None,
        })
        .collect()
}

#[test]
fn band_interval_figures_zoom_on_the_bands() {
    let dir = fresh_dir("figures-bands");
    // Bands between 92° and 121° at three d: the θf axis should hold them, not 0–420°.
    let maps = one_band_each(vec![
        (-0.4, band(92.0, 104.0, 98.0, 3.0)),
        (0.0, band(100.0, 112.0, 106.0, 2.5)),
        (0.4, band(108.0, 121.0, 115.0, 4.0)),
    ]);
    for adjusted in [false, true] {
        let path = dir.join(format!("bands-{adjusted}.svg"));
        pinfeed::report::plot_map::plot_band_intervals(&maps, adjusted, "t", &path).unwrap();
        let boxes = text_boxes(&read_svg(&path));
        let what = format!("the bands 92–121° (adjusted: {adjusted})");
        y_ticks_within(&boxes, 70.0..=145.0, &what);
        let xs: Vec<String> = ticks(&boxes, "middle")
            .into_iter()
            .map(|t| t.1.text)
            .collect();
        assert!(
            !xs.iter()
                .any(|t| t.starts_with("-0") && t.parse() == Ok(0.0)),
            "{xs:?}"
        );
        let texts: String = boxes.iter().map(|b| b.text.clone() + "\n").collect();
        assert!(texts.contains("band mean"), "{texts}");
        no_overlaps(&boxes, "band intervals");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 57 item 16: a band-interval axis wider than 300° across 0°/360° read "…, 300, 350, 40,
/// 90" (plotters' 50° step, 400° wrapped). Its ticks are multiples of a step dividing 360, so the
/// labels advance evenly and read 0 where the axis crosses 360°.
#[test]
fn a_band_axis_across_360_is_ticked_on_a_step_dividing_360_with_a_zero() {
    let dir = fresh_dir("figures-bands-wrap");
    // Bands over 60°…375° (15° past 0): a gap of 45°, so the axis zooms to about 55°…380°.
    let maps = one_band_each(vec![
        (-0.4, band(60.0, 120.0, 90.0, 10.0)),
        (-0.2, band(130.0, 200.0, 165.0, 10.0)),
        (0.0, band(210.0, 280.0, 245.0, 10.0)),
        (0.2, band(290.0, 350.0, 320.0, 10.0)),
        (0.4, band(355.0, 375.0, 5.0, 3.0)),
    ]);
    for adjusted in [false, true] {
        let path = dir.join(format!("bands-{adjusted}.svg"));
        pinfeed::report::plot_map::plot_band_intervals(&maps, adjusted, "t", &path).unwrap();
        let boxes = text_boxes(&read_svg(&path));
        // The y tick labels from the bottom of the axis up.
        let mut ys = ticks(&boxes, "end");
        ys.sort_by(|a, b| b.1.y0.total_cmp(&a.1.y0));
        let labels: Vec<f64> = ys.iter().map(|t| t.0).collect();
        assert!(labels.len() >= 5, "{labels:?}");
        let step = (labels[1] - labels[0]).rem_euclid(360.0);
        assert_eq!(
            360.0 % step,
            0.0,
            "a step of {step}° does not divide 360: {labels:?}"
        );
        for w in labels.windows(2) {
            assert_eq!((w[0] + step) % 360.0, w[1], "{labels:?}");
        }
        assert!(
            labels.contains(&0.0),
            "the axis crosses 0° without a 0: {labels:?}"
        );
        no_overlaps(&boxes, "band intervals across 360°");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 57 item 16: every transitional sample of a map (a θ0 whose θf lands apart from both
/// neighbouring bands: a band of one sample) had a legend entry of its own. They share one:
/// `transitional (N samples …)`, and the real bands keep their numbers from the band table.
#[test]
fn a_map_figure_gives_its_transitional_samples_one_legend_entry() {
    let dir = fresh_dir("figures-map-transitional");
    // ngon:5 at d = -0.5: five bands of 71 samples, and five single samples between them.
    let out = crate::support::pinfeed_ok(&[
        "map",
        "--part",
        "ngon:5",
        "--d=-0.5",
        "--quiet",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("B10"), "ten bands expected:\n{table}");
    let boxes = text_boxes(&read_svg(&dir.join("map_d-0.5.svg")));
    let legend: Vec<&str> = boxes.iter().map(|b| b.text.as_str()).collect();
    let transitional: Vec<&&str> = legend
        .iter()
        .filter(|t| t.starts_with("transitional"))
        .collect();
    assert_eq!(
        transitional,
        [&"transitional (5 samples, each a band of its own)"],
        "{legend:?}"
    );
    let bands: Vec<&&str> = legend.iter().filter(|t| t.starts_with('B')).collect();
    assert_eq!(bands.len(), 5, "{legend:?}");
    for (b, n) in bands.iter().zip(["B1 ", "B3 ", "B5 ", "B7 ", "B9 "]) {
        assert!(b.starts_with(n), "{legend:?}");
    }
    // The θ0 axis is ticked every 30°, 0 to 360.
    let xs: Vec<f64> = ticks(&boxes, "middle").into_iter().map(|t| t.0).collect();
    let expected: Vec<f64> = (0..=12).map(|k| 30.0 * k as f64).collect();
    assert_eq!(xs, expected);
    no_overlaps(&boxes, "map figure");
    std::fs::remove_dir_all(&dir).ok();
}

/// The numbers of an element's `points`.
fn points(e: &Element) -> Vec<f64> {
    e.attr("points")
        .unwrap()
        .split([' ', ','])
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect()
}

/// The (x1, y1, x2, y2) of every `polyline` drawn with `stroke` at width 3.
fn thick_lines(svg: &Element, stroke: &str) -> Vec<[f64; 4]> {
    svg.all()
        .into_iter()
        .filter(|e| {
            e.name == "polyline"
                && e.attr("stroke") == Some(stroke)
                && e.attr("stroke-width") == Some("3")
        })
        .map(|e| {
            let p = points(e);
            [p[0], p[1], p[p.len() - 2], p[p.len() - 1]]
        })
        .collect()
}

/// The bounding box of every filled `polygon` (the part's silhouette).
fn polygons(svg: &Element) -> Vec<[f64; 4]> {
    svg.all()
        .into_iter()
        .filter(|e| e.name == "polygon")
        .map(|e| {
            let p = points(e);
            let xs = p.iter().step_by(2);
            let ys = p.iter().skip(1).step_by(2);
            [
                xs.clone().fold(f64::MAX, |a, &b| a.min(b)),
                xs.fold(f64::MIN, |a, &b| a.max(b)),
                ys.clone().fold(f64::MAX, |a, &b| a.min(b)),
                ys.fold(f64::MIN, |a, &b| a.max(b)),
            ]
        })
        .collect()
}

#[test]
fn a_fence_plan_is_drawn_to_scale_at_its_angles() {
    let dir = fresh_dir("figures-plan");
    let toml = dir.join("fences.toml");
    let args = [
        "plan",
        "--part",
        "vertices:0,0 36,0 8,22",
        "--scale",
        "0.001",
        "--fences",
        "--belt-width",
        "0.18",
        "--check-parts",
        "500",
        "--quiet",
        "--out",
        toml.to_str().unwrap(),
    ];
    let out = pinfeed(&args);
    // Confirmed (0) or written but not confirmed by the line (3): drawn either way.
    assert!(
        matches!(out.status.code(), Some(0 | 3)),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&toml).unwrap();
    let angles: Vec<f64> = text
        .lines()
        .filter_map(|l| l.strip_prefix("angle = "))
        .map(|v| v.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    assert!(!angles.is_empty(), "{text}");
    let svg = read_svg(&dir.join("fences.svg"));
    let boxes = text_boxes(&svg);
    let title = &boxes[0].text;
    assert!(
        title.contains("fence") && !title.contains("pin"),
        "title {title}"
    );
    // Each fence drawn at its true angle (SVG y grows downwards).
    let lines = thick_lines(&svg, "#283246");
    assert_eq!(lines.len(), angles.len(), "{lines:?}");
    for (l, a) in lines.iter().zip(&angles) {
        let drawn = (-(l[3] - l[1])).atan2(l[2] - l[0]).to_degrees();
        assert!(
            (drawn - a).abs() < 1.5,
            "fence at {a}° drawn at {drawn:.1}°"
        );
    }
    // One scale on both axes: px per mm from the belt view's x ticks (the first row of them
    // below its y ticks; the orientation sets' axes follow further down) equals that from its y
    // ticks.
    let ys = ticks(&boxes, "end");
    let bottom = ys.iter().map(|t| t.1.y1).fold(f64::MIN, f64::max);
    let below: Vec<(f64, TextBox)> = ticks(&boxes, "middle")
        .into_iter()
        .filter(|t| t.1.y0 > bottom - 12.0)
        .collect();
    let row = below.iter().map(|t| t.1.y0).fold(f64::MAX, f64::min);
    let xs: Vec<(f64, TextBox)> = below
        .into_iter()
        .filter(|t| (t.1.y0 - row).abs() < 1.0)
        .collect();
    assert!(xs.len() >= 3 && ys.len() >= 3, "{xs:?} {ys:?}");
    let per =
        |a: &(f64, TextBox), b: &(f64, TextBox), pa: f64, pb: f64| ((pb - pa) / (b.0 - a.0)).abs();
    let (xa, xb) = (&xs[0], &xs[xs.len() - 1]);
    let kx = per(xa, xb, (xa.1.x0 + xa.1.x1) / 2.0, (xb.1.x0 + xb.1.x1) / 2.0);
    let (ya, yb) = (&ys[0], &ys[ys.len() - 1]);
    let ky = per(ya, yb, (ya.1.y0 + ya.1.y1) / 2.0, (yb.1.y0 + yb.1.y1) / 2.0);
    assert!(
        (kx / ky - 1.0).abs() < 0.03,
        "px per mm: {kx} along, {ky} across"
    );
    no_overlaps(&boxes, "fence plan");
    let silhouettes = polygons(&svg);
    assert!(!silhouettes.is_empty());
    for p in silhouettes {
        for b in &boxes {
            let covered = b.x0 < p[1] && p[0] < b.x1 && b.y0 < p[3] && p[2] < b.y1;
            assert!(!covered, "label {:?} under the silhouette {p:?}", b.text);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn run_draw_names_the_pins_in_their_own_colour() {
    let dir = fresh_dir("figures-draw");
    let scene = pinfeed::scenario::load(Path::new("scenarios/tripoly1_sensing.toml")).unwrap();
    let mut opts = RunOptions::from_scene(&scene);
    opts.parts = 4;
    opts.sample_paths = 4;
    let result = run(&scene, &opts, &mut |_| {}).unwrap();
    let samples: Vec<_> = result.paths.iter().collect();
    let path = dir.join("draw.svg");
    pinfeed::report::plot_line::plot_line(&scene, &samples, &path).unwrap();
    let svg = read_svg(&path);
    let boxes = text_boxes(&svg);
    for ob in &scene.obstacles {
        assert!(
            boxes.iter().any(|b| b.text.starts_with(ob.name())),
            "{} unnamed",
            ob.name()
        );
    }
    let c = pinfeed::report::plot_line::outcome_colour(pinfeed::engine::PartOutcome::Collision);
    let collision = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    let fills: Vec<String> = svg
        .all()
        .into_iter()
        .filter(|e| e.name == "circle")
        .filter_map(|e| e.attr("fill").map(|f| f.to_uppercase()))
        .collect();
    assert!(
        fills.len() >= scene.obstacles.len() * samples.len(),
        "{fills:?}"
    );
    assert!(
        !fills.contains(&collision),
        "a pin drawn in the collision colour"
    );
    no_overlaps(&boxes, "--draw");
    std::fs::remove_dir_all(&dir).ok();
}

/// The animation's labels (obstacle names, marks, entry and exit): none over another while both
/// are shown, none across a belt edge.
fn check_animation_labels(doc: &str, what: &str) {
    let svg = parse_xml(doc);
    let boxes: Vec<TextBox> = text_boxes(&svg)
        .into_iter()
        .filter(|b| matches!(b.class.as_deref(), Some("belt" | "obstacle" | "mark")))
        .collect();
    assert!(boxes.iter().any(|b| b.class.as_deref() == Some("obstacle")));
    no_overlaps(&boxes, what);
    // The belt's edges: its two long dark lines.
    let edges: Vec<f64> = svg
        .all()
        .into_iter()
        .filter(|e| e.name == "line" && e.attr("stroke") == Some("#333"))
        .map(|e| e.attr("y1").unwrap().parse().unwrap())
        .collect();
    assert_eq!(edges.len(), 2);
    for b in &boxes {
        if b.class.as_deref() != Some("belt") {
            for &y in &edges {
                assert!(
                    !b.crosses(y),
                    "{what}: {:?} across the belt edge at {y}",
                    b.text
                );
            }
        }
    }
}

#[test]
fn animation_labels_never_overlap() {
    for (file, parts) in [
        ("scenarios/tripoly1_sensing.toml", 30),
        ("scenarios/tripoly1_online.toml", 30),
        ("scenarios/quickstart.toml", 20),
    ] {
        let scene = pinfeed::scenario::load(Path::new(file)).unwrap();
        let mut opts = RunOptions::from_scene(&scene);
        opts.parts = parts;
        opts.sample_paths = animate::DEFAULT_PARTS;
        opts.keep_records = true;
        let result = run(&scene, &opts, &mut |_| {}).unwrap();
        let anim = animate::from_run(&scene, &result, animate::DEFAULT_PARTS);
        let doc = animate::render(&anim, &AnimateOptions::default());
        check_animation_labels(&doc, file);
    }
}

#[test]
fn crowded_marks_take_separate_rows() {
    use pinfeed::geometry::Vec2;
    use pinfeed::report::animate::{AnimMark, AnimObstacle, AnimShape, Animation, MarkKind};
    // Three pins 1 cm apart, each with a long mark at the same instant, on both sides.
    let obstacles: Vec<AnimObstacle> = (0..3)
        .map(|i| AnimObstacle {
            name: format!("pin{i}"),
            shape: AnimShape::Pin {
                x: 0.2 + 0.01 * i as f64,
                radius: 0.003,
            },
            sensor: i == 0,
            track: vec![(0.0, if i == 1 { -0.01 } else { 0.01 }, true)],
        })
        .collect();
    let mut marks = Vec::new();
    for i in 0..3 {
        for kind in MarkKind::ALL {
            marks.push(AnimMark {
                t: 5.0,
                at: Vec2::new(0.2 + 0.01 * i as f64, if i == 1 { -0.01 } else { 0.01 }),
                kind,
                text: format!("{} of part {i} at pin{i}, a long label", kind.name()),
            });
        }
    }
    let anim = Animation {
        title: "crowded".into(),
        belt_length: 0.5,
        belt_width: 0.06,
        belt_speed: 0.05,
        outline: vec![
            Vec2::new(0.01, 0.0),
            Vec2::new(-0.01, 0.01),
            Vec2::new(-0.01, -0.01),
        ],
        obstacles,
        parts: vec![],
        marks,
        t_start: 0.0,
        t_end: 20.0,
    };
    let doc = animate::render(&anim, &AnimateOptions::default());
    check_animation_labels(&doc, "crowded");
}

/// Issue 57 item 16: the part figure's legend covered the part. No legend label's box meets the
/// bounding box of the drawn part (its filled polygon) or of the circle of radius a, for parts
/// of every shape.
#[test]
fn the_part_figures_legend_stays_off_the_part() {
    let dir = fresh_dir("figures-part-legend");
    for part in [
        "tripoly1",
        "tripoly2",
        "lshape",
        "vertices:0,0 40,0 40,10 10,10 10,30 0,30",
    ] {
        let svg = dir.join("part.svg");
        let o = pinfeed(&["part", "--part", part, "--plot", svg.to_str().unwrap()]);
        assert!(
            o.status.success(),
            "{part}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let doc = read_svg(&svg);
        // The outline's chart: the part's polygon (the first filled one) and its frame.
        let part_box = polygons(&doc)[0];
        let boxes = text_boxes(&doc);
        for label in ["radius a", "convex hull", "part", "centroid"] {
            let b = boxes
                .iter()
                .find(|b| b.text == label)
                .unwrap_or_else(|| panic!("{part}: no legend label {label}"));
            let meets = b.x0 < part_box[1]
                && b.x1 > part_box[0]
                && b.y0 < part_box[3]
                && b.y1 > part_box[2];
            assert!(
                !meets,
                "{part}: legend label {label} {b:?} meets the part {part_box:?}"
            );
            // Below the outline's square chart (460 px), not over the circle of radius a.
            assert!(
                b.y0 >= 460.0,
                "{part}: legend label {label} inside the outline: {b:?}"
            );
        }
        no_overlaps(&boxes, part);
    }
}

/// Issue 57 item 16: a study without a sweep drew its outcome bars with no axis label and no
/// word of what was perturbed; the x axis names the perturbations.
#[test]
fn an_unswept_study_figure_names_what_it_perturbs() {
    let dir = fresh_dir("figures-unswept");
    let study = dir.join("s.toml");
    std::fs::write(
        &study,
        format!(
            "scenario = \"{}/scenarios/quickstart.toml\"\nsamples = 20\n[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = 0.3\nmax = 0.7\n",
            env!("CARGO_MANIFEST_DIR")
        ),
    )
    .unwrap();
    let out = dir.join("o");
    crate::support::pinfeed_ok(&[
        "mc",
        study.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let svg = out.join("sensitivity.svg");
    let boxes = text_boxes(&read_svg(&svg));
    assert!(
        boxes
            .iter()
            .any(|b| b.text.starts_with("outcome of each sample under mu_c")),
        "{:?}",
        boxes.iter().map(|b| &b.text).collect::<Vec<_>>()
    );
}

/// Issue 57 item 16: the animation of a vertex-list part was titled "vertices", and its mover
/// targets were labelled in metres with every digit (`y=0.027487370837451`) where `plan` prints
/// mm. The title says what the part is; targets read `y=+12.00 mm`.
#[test]
fn an_animation_names_a_vertex_part_and_labels_targets_in_mm() {
    let text = std::fs::read_to_string("scenarios/tripoly1_sensing.toml").unwrap();
    let shape = "shape = \"tripoly1\"";
    assert!(text.contains(shape));
    // tripoly1 written out as its vertices (the same part, at the same scale).
    let poly = pinfeed::geometry::part_from_spec("tripoly1").unwrap();
    let vertices: Vec<String> = poly
        .vertices()
        .iter()
        .map(|v| format!("[{}, {}]", v.x, v.y))
        .collect();
    let text = text.replacen(shape, &format!("vertices = [{}]", vertices.join(", ")), 1);
    let scene = pinfeed::scenario::parse(Path::new("v.toml"), &text).unwrap();
    let mut opts = RunOptions::from_scene(&scene);
    opts.parts = 6;
    opts.sample_paths = animate::DEFAULT_PARTS;
    opts.keep_records = true;
    let result = run(&scene, &opts, &mut |_| {}).unwrap();
    let anim = animate::from_run(&scene, &result, animate::DEFAULT_PARTS);
    let n = poly.vertices().len();
    assert!(
        anim.title
            .contains(&format!("a part of {n} vertices on the line")),
        "{}",
        anim.title
    );
    let doc = animate::render(&anim, &AnimateOptions::default());
    // Labels `y=…` (not the attributes `y="…"`).
    let targets: Vec<&str> = doc
        .split("y=")
        .skip(1)
        .filter(|t| !t.starts_with('"'))
        .collect();
    assert!(!targets.is_empty(), "no mover target in the animation");
    for t in targets {
        let value = t.split(" mm").next().unwrap();
        assert!(
            value.starts_with(['+', '-'])
                && value.len() <= 7
                && t[value.len()..].starts_with(" mm"),
            "a target not in mm to 2 decimals: y={}",
            &t[..t.len().min(30)]
        );
    }
}
