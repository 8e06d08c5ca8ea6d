//! Parts from CAD files and lines back to CAD (docs/cad.md): DXF drawings written here with the
//! `dxf` crate (LWPOLYLINE with bulges, POLYLINE, LINE/ARC loops, CIRCLE; mm, cm, inch and
//! unitless) read into parts whose area and centroid match the exact figures (1e-6 relative for
//! polygons; within the flattening bound for arcs); every malformed outline is an error naming
//! the entity's handle and layer; a design planned from a DXF part equals the one planned from
//! its vertices; the layout drawing of `run --dxf` and `plan --dxf` re-read with the `dxf` crate
//! gives every obstacle of the scenario to 1 µm.

use crate::support::{fresh_dir, pinfeed, pinfeed_ok};
use dxf::entities::{Arc, Circle, Entity, EntityType, Line, LwPolyline, Polyline, Text, Vertex};
use dxf::enums::{AcadVersion, Units};
use dxf::{Drawing, LwPolylineVertex, Point};
use pinfeed::geometry::cad::{read_part_file, PartFile, PartFileOptions, Unit};
use pinfeed::geometry::Vec2;
use pinfeed::report::layout_dxf::layout_drawing;
use pinfeed::scenario::{Actuator, Obstacle, Scene, SceneDraft};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

const LAYER: &str = "OUTLINE";

fn drawing(units: Units) -> Drawing {
    let mut d = Drawing::new();
    d.header.version = AcadVersion::R2000;
    d.header.default_drawing_units = units;
    d
}

/// Add an entity on the outline layer; its handle as CAD tools show it.
fn add(d: &mut Drawing, specific: EntityType) -> String {
    let mut e = Entity::new(specific);
    e.common.layer = LAYER.into();
    format!("{:X}", d.add_entity(e).common.handle.0)
}

fn lw(pts: &[(f64, f64, f64)], closed: bool) -> EntityType {
    let mut pl = LwPolyline {
        vertices: pts
            .iter()
            .map(|&(x, y, bulge)| LwPolylineVertex {
                x,
                y,
                bulge,
                ..Default::default()
            })
            .collect(),
        ..Default::default()
    };
    pl.set_is_closed(closed);
    EntityType::LwPolyline(pl)
}

/// A closed LWPOLYLINE of straight edges.
fn closed(pts: &[(f64, f64)]) -> EntityType {
    let with_bulges: Vec<(f64, f64, f64)> = pts.iter().map(|&(x, y)| (x, y, 0.0)).collect();
    lw(&with_bulges, true)
}

fn line(a: (f64, f64), b: (f64, f64)) -> EntityType {
    EntityType::Line(Line::new(
        Point::new(a.0, a.1, 0.0),
        Point::new(b.0, b.1, 0.0),
    ))
}

fn arc(c: (f64, f64), r: f64, start_deg: f64, end_deg: f64) -> EntityType {
    EntityType::Arc(Arc::new(Point::new(c.0, c.1, 0.0), r, start_deg, end_deg))
}

fn save(d: &Drawing, dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    d.save_file(&p).expect("writing the test drawing");
    p
}

fn read(path: &Path) -> PartFile {
    read_part_file(path, &PartFileOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn read_err(path: &Path, options: &PartFileOptions) -> String {
    match read_part_file(path, options).and_then(|p| p.polygon().map_err(|e| panic!("{e}"))) {
        Ok(_) => panic!("{} read without error", path.display()),
        Err(e) => e.to_string(),
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Area and centroid (mm², mm) of a part file's polygon.
fn mass(p: &PartFile) -> (f64, Vec2) {
    let poly = p.polygon().expect("a valid part");
    (poly.area(), poly.offset())
}

#[test]
fn polygons_in_inch_and_mm_give_exact_area_and_centroid() {
    let dir = fresh_dir("cad-polygons");
    // A triangle in inches: area 1.5 in², centroid (1, 1/3) in.
    let mut d = drawing(Units::Inches);
    add(&mut d, closed(&[(0.0, 0.0), (3.0, 0.0), (0.0, 1.0)]));
    let p = read(&save(&d, &dir, "tri_inch.dxf"));
    assert_eq!(p.unit.name, "inch");
    let (area, c) = mass(&p);
    let inch = 25.4;
    assert!(rel(area, 1.5 * inch * inch) < 1e-6, "area {area}");
    assert!(
        rel(c.x, inch) < 1e-6 && rel(c.y, inch / 3.0) < 1e-6,
        "centroid {c:?}"
    );
    // An L in millimetres as an old-style POLYLINE: area 3 × 100², centroid (500/6·…).
    let mut d = drawing(Units::Millimeters);
    let mut pl = Polyline::default();
    pl.set_is_closed(true);
    let l = [
        (0.0, 0.0),
        (200.0, 0.0),
        (200.0, 100.0),
        (100.0, 100.0),
        (100.0, 200.0),
        (0.0, 200.0),
    ];
    for (x, y) in l {
        pl.add_vertex(&mut d, Vertex::new(Point::new(x, y, 0.0)));
    }
    add(&mut d, EntityType::Polyline(pl));
    let p = read(&save(&d, &dir, "l_mm.dxf"));
    let (area, c) = mass(&p);
    assert!(rel(area, 30_000.0) < 1e-6, "area {area}");
    // Three unit squares at (50, 50), (150, 50), (50, 150): centroid (250/3, 250/3).
    assert!(
        rel(c.x, 250.0 / 3.0) < 1e-6 && rel(c.y, 250.0 / 3.0) < 1e-6,
        "{c:?}"
    );
    // Drawn from below (extrusion −Z): the object coordinates are mirrored in x.
    let mut d = drawing(Units::Millimeters);
    let mut below = closed(&[(0.0, 0.0), (3.0, 0.0), (0.0, 1.0)]);
    if let EntityType::LwPolyline(pl) = &mut below {
        pl.extrusion_direction = dxf::Vector::new(0.0, 0.0, -1.0);
    }
    add(&mut d, below);
    let (_, c) = mass(&read(&save(&d, &dir, "below.dxf")));
    assert!(rel(c.x, -1.0) < 1e-6 && rel(c.y, 1.0 / 3.0) < 1e-6, "{c:?}");
    // The same triangle as a CSV of x,y rows (mm, a header row and a comment).
    let csv = dir.join("tri.csv");
    std::fs::write(&csv, "x,y\n# a triangle\n0,0\n76.2,0\n0,25.4\n").unwrap();
    let (area, _) = mass(&read(&csv));
    assert!(rel(area, 1.5 * inch * inch) < 1e-6, "csv area {area}");
}

#[test]
fn bulges_are_arcs_within_the_flattening_bound() {
    let dir = fresh_dir("cad-bulges");
    // A 40 × 20 mm rectangle whose right side is an outward semicircle (bulge 1), r = 10.
    let mut d = drawing(Units::Millimeters);
    add(
        &mut d,
        lw(
            &[
                (0.0, 0.0, 0.0),
                (40.0, 0.0, 1.0),
                (40.0, 20.0, 0.0),
                (0.0, 20.0, 0.0),
            ],
            true,
        ),
    );
    let path = save(&d, &dir, "bulge.dxf");
    let r = 10.0;
    let exact_area = 800.0 + PI * r * r / 2.0;
    let exact_cx = (800.0 * 20.0 + PI * r * r / 2.0 * (40.0 + 4.0 * r / (3.0 * PI))) / exact_area;
    for flatten in [0.05, 0.001] {
        let o = PartFileOptions {
            flatten_mm: flatten,
            ..Default::default()
        };
        let p = read_part_file(&path, &o).unwrap();
        let (area, c) = mass(&p);
        // Chords inside the arc: the area lost is at most the tolerance times the arc's length.
        let lost = exact_area - area;
        let bound = flatten * PI * r;
        assert!(
            lost >= 0.0 && lost <= bound,
            "flatten {flatten}: lost {lost}, bound {bound}"
        );
        // The centroid moves by at most the part's diameter times the lost share of the area.
        let c_bound = 50.0 * bound / area;
        assert!(
            (c.x - exact_cx).abs() <= c_bound,
            "cx {} vs {exact_cx}",
            c.x
        );
        assert!((c.y - 10.0).abs() <= 1e-9, "cy {}", c.y);
        // No flattened vertex lies off the arc or outside it.
        let far = p.vertices.iter().map(|v| v.x).fold(0.0, f64::max);
        assert!(far <= 50.0 + 1e-9 && far >= 50.0 - flatten, "reach {far}");
    }
}

#[test]
fn a_loop_of_lines_and_arcs_in_cm_chains_in_any_order_and_direction() {
    let dir = fresh_dir("cad-loop");
    // A stadium 30 cm long and 10 cm wide, its entities out of order, one line drawn backwards.
    let mut d = drawing(Units::Centimeters);
    add(&mut d, arc((30.0, 5.0), 5.0, 270.0, 90.0));
    add(&mut d, line((0.0, 10.0), (30.0, 10.0)));
    add(&mut d, line((0.0, 0.0), (30.0, 0.0)));
    add(&mut d, arc((0.0, 5.0), 5.0, 90.0, 270.0));
    let path = save(&d, &dir, "stadium.dxf");
    let o = PartFileOptions {
        flatten_mm: 0.01,
        ..Default::default()
    };
    let p = read_part_file(&path, &o).unwrap();
    assert_eq!(p.unit.name, "cm");
    let (area, c) = mass(&p);
    let exact = (300.0 * 100.0) + PI * 50.0 * 50.0;
    let lost = exact - area;
    assert!(
        (0.0..=0.01 * 2.0 * PI * 50.0).contains(&lost),
        "lost {lost}"
    );
    assert!(
        (c.x - 150.0).abs() < 1e-6 && (c.y - 50.0).abs() < 1e-6,
        "{c:?}"
    );
    // A CIRCLE alone is a round part.
    let mut d = drawing(Units::Millimeters);
    add(
        &mut d,
        EntityType::Circle(Circle::new(Point::new(5.0, 5.0, 0.0), 8.0)),
    );
    let (area, c) = mass(&read(&save(&d, &dir, "disc.dxf")));
    assert!(
        area <= PI * 64.0 && PI * 64.0 - area <= 0.05 * 2.0 * PI * 8.0,
        "{area}"
    );
    assert!((c.x - 5.0).abs() < 1e-9 && (c.y - 5.0).abs() < 1e-9);
}

#[test]
fn units_come_from_the_header_or_the_option_and_none_is_refused() {
    let dir = fresh_dir("cad-units");
    let mut d = drawing(Units::Unitless);
    add(&mut d, closed(&[(0.0, 0.0), (2.0, 0.0), (0.0, 1.0)]));
    let path = save(&d, &dir, "unitless.dxf");
    let e = read_err(&path, &PartFileOptions::default());
    assert!(e.contains("unitless.dxf") && e.contains("--units"), "{e}");
    let o = PartFileOptions {
        units: Some(Unit::parse("inch").unwrap()),
        ..Default::default()
    };
    let (area, _) = mass(&read_part_file(&path, &o).unwrap());
    assert!(rel(area, 25.4 * 25.4) < 1e-6, "{area}");
    // A drawing that states mm, read as inches: refused, naming both.
    let mut d = drawing(Units::Millimeters);
    add(&mut d, closed(&[(0.0, 0.0), (2.0, 0.0), (0.0, 1.0)]));
    let e = read_err(&save(&d, &dir, "mm.dxf"), &o);
    assert!(e.contains("mm") && e.contains("inch"), "{e}");
}

#[test]
fn malformed_outlines_are_errors_naming_the_entity() {
    let dir = fresh_dir("cad-errors");
    let o = PartFileOptions::default();
    let check = |name: &str, d: &Drawing, words: &[&str], handles: &[&String]| {
        let e = read_err(&save(d, &dir, name), &o);
        assert!(e.contains(name), "names the file: {e}");
        for w in words {
            assert!(e.contains(w), "'{w}' in: {e}");
        }
        for h in handles {
            assert!(e.contains(&format!("handle {h},")), "handle {h} in: {e}");
        }
        assert!(
            handles.is_empty() || e.contains(&format!("layer '{LAYER}'")),
            "{e}"
        );
    };
    // An open loop: a triangle with a gap of 1 mm.
    let mut d = drawing(Units::Millimeters);
    let a = add(&mut d, line((0.0, 0.0), (30.0, 0.0)));
    let b = add(&mut d, line((30.0, 0.0), (0.0, 20.0)));
    add(&mut d, line((0.0, 20.0), (0.0, 1.0)));
    let e = read_err(&save(&d, &dir, "open.dxf"), &o);
    assert!(
        e.contains("open outline") && e.contains("layer 'OUTLINE'"),
        "{e}"
    );
    assert!(
        e.contains(&format!("handle {a},")) || e.contains(&format!("handle {b},")),
        "{e}"
    );
    // Two closed loops side by side.
    let mut d = drawing(Units::Millimeters);
    let a = add(&mut d, closed(&[(0.0, 0.0), (10.0, 0.0), (0.0, 10.0)]));
    let b = add(&mut d, closed(&[(20.0, 0.0), (30.0, 0.0), (20.0, 10.0)]));
    check("two.dxf", &d, &["not nested"], &[&a, &b]);
    // A bow tie crosses itself.
    let mut d = drawing(Units::Millimeters);
    let a = add(
        &mut d,
        closed(&[(0.0, 0.0), (10.0, 10.0), (10.0, 0.0), (0.0, 10.0)]),
    );
    check("bowtie.dxf", &d, &["crosses itself"], &[&a]);
    // A loop with zero area (collinear).
    let mut d = drawing(Units::Millimeters);
    let a = add(&mut d, closed(&[(0.0, 0.0), (10.0, 0.0), (20.0, 0.0)]));
    check("flat.dxf", &d, &["zero area"], &[&a]);
    // Three lines meeting at one point.
    let mut d = drawing(Units::Millimeters);
    let a = add(&mut d, line((0.0, 0.0), (10.0, 0.0)));
    add(&mut d, line((10.0, 0.0), (0.0, 10.0)));
    add(&mut d, line((10.0, 0.0), (10.0, 10.0)));
    add(&mut d, line((0.0, 10.0), (0.0, 0.0)));
    check("branch.dxf", &d, &["branches"], &[&a]);
    // A NaN coordinate.
    let mut d = drawing(Units::Millimeters);
    add(&mut d, line((0.0, 0.0), (10.0, 0.0)));
    let a = add(&mut d, line((10.0, 0.0), (f64::NAN, 10.0)));
    check("nan.dxf", &d, &["not a finite number"], &[&a]);
    // An arc flattened so finely that the outline would have too many vertices.
    let mut d = drawing(Units::Millimeters);
    let a = add(
        &mut d,
        EntityType::Circle(Circle::new(Point::new(0.0, 0.0, 0.0), 1000.0)),
    );
    let fine = PartFileOptions {
        flatten_mm: 1e-6,
        ..Default::default()
    };
    let e = read_err(&save(&d, &dir, "fine.dxf"), &fine);
    assert!(
        e.contains("more than 10000 vertices") && e.contains(&format!("handle {a},")),
        "{e}"
    );
    // No outline at all: a text only.
    let mut d = drawing(Units::Millimeters);
    add(&mut d, EntityType::Text(Text::default()));
    check("empty.dxf", &d, &["no outline"], &[]);
    // Not a drawing, and a file over the size cap: errors, not panics.
    let junk = dir.join("junk.dxf");
    std::fs::write(&junk, b"0\nSECTION\n2\nENTITIES\n0\nLINE\n10\nx\n\xff\xfe").unwrap();
    assert!(read_part_file(&junk, &o).is_err());
    let huge = dir.join("huge.dxf");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(65 << 20)
        .unwrap();
    let e = read_part_file(&huge, &o).unwrap_err().to_string();
    assert!(e.contains("huge.dxf") && e.contains("MiB"), "{e}");
    // The command: exit status 1 with the located message.
    let out = pinfeed(&[
        "part",
        "--part",
        save(&d, &dir, "empty2.dxf").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no outline"));
}

#[test]
fn holes_are_ignored_with_a_warning() {
    let dir = fresh_dir("cad-holes");
    let mut d = drawing(Units::Millimeters);
    add(
        &mut d,
        closed(&[(0.0, 0.0), (40.0, 0.0), (40.0, 40.0), (0.0, 40.0)]),
    );
    let hole = add(
        &mut d,
        EntityType::Circle(Circle::new(Point::new(20.0, 20.0, 0.0), 5.0)),
    );
    let path = save(&d, &dir, "holed.dxf");
    let p = read(&path);
    assert!(rel(mass(&p).0, 1600.0) < 1e-6);
    assert_eq!(p.notes.len(), 1, "{:?}", p.notes);
    assert!(
        p.notes[0].contains("1 hole ignored") && p.notes[0].contains(&hole),
        "{:?}",
        p.notes
    );
    let out = pinfeed_ok(&["part", "--part", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning:") && err.contains("hole ignored"),
        "{err}"
    );
}

/// tripoly2 at 30 mm per unit: (−20, −10), (40, −10), (−20, 20) mm, exact in decimal.
const TRI: [(f64, f64); 3] = [(-20.0, -10.0), (40.0, -10.0), (-20.0, 20.0)];

fn plan_json(part: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "plan",
        "--nominal",
        "--part",
        part,
        "--pins",
        "--check-parts",
        "300",
        "--screen-parts",
        "100",
        "--no-margins",
        "--time-limit",
        "60",
        "--json",
        "--quiet",
    ];
    args.extend_from_slice(extra);
    let out = pinfeed(&args);
    assert!(
        matches!(out.status.code(), Some(0 | 3)),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_design_from_a_dxf_part_is_the_design_from_its_vertices_and_draws_to_dxf() {
    let dir = fresh_dir("cad-plan");
    let mut d = drawing(Units::Millimeters);
    add(&mut d, closed(&TRI));
    let part = save(&d, &dir, "tri.dxf");
    let layout = dir.join("tri_layout.dxf");
    let out = dir.join("tri.toml");
    let from_file = plan_json(
        part.to_str().unwrap(),
        &[
            "--out",
            out.to_str().unwrap(),
            "--dxf",
            layout.to_str().unwrap(),
        ],
    );
    let verts = format!(
        "vertices:{}",
        TRI.map(|(x, y)| format!("{x},{y}")).join(" ")
    );
    let from_vertices = plan_json(&verts, &["--scale", "0.001", "--no-write"]);
    assert_eq!(
        from_file["chosen"]["layout"],
        from_vertices["chosen"]["layout"]
    );
    assert_eq!(from_file["obstacles"], from_vertices["obstacles"]);
    let check = |v: &serde_json::Value| {
        let mut c = v["line_check"].clone();
        c.as_object_mut().unwrap().remove("elapsed_s");
        c
    };
    assert_eq!(check(&from_file), check(&from_vertices));
    // The written scenario names the file and runs from another folder.
    let toml = std::fs::read_to_string(&out).unwrap();
    assert!(toml.contains("tri.dxf"), "{toml}");
    pinfeed_ok(&[
        "run",
        out.to_str().unwrap(),
        "--parts",
        "20",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
    ]);
    // The layout drawing has the design's pins.
    let scene = pinfeed::scenario::load(&out).unwrap();
    check_layout(&scene, &dxf::Drawing::load_file(&layout).unwrap());
}

#[test]
fn a_scenario_reads_its_part_file_beside_it() {
    let dir = fresh_dir("cad-scenario");
    let mut d = drawing(Units::Millimeters);
    add(&mut d, closed(&TRI));
    save(&d, &dir, "part.dxf");
    let quick = std::fs::read_to_string("scenarios/quickstart.toml").unwrap();
    let verts = "vertices = [[-20, -10], [40, -10], [-20, 20]]\nscale = 0.001";
    let with = |part: &str| {
        quick
            .replacen("shape = \"tripoly2\"", part, 1)
            .replacen("scale = 0.02", "", 1)
    };
    std::fs::write(dir.join("file.toml"), with("shape = \"part.dxf\"")).unwrap();
    std::fs::write(dir.join("verts.toml"), with(verts)).unwrap();
    let run = |name: &str| {
        let p = dir.join(name);
        let out = pinfeed_ok(&[
            "run",
            p.to_str().unwrap(),
            "--parts",
            "50",
            "--json",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (v["success_rate"].clone(), v["outcomes"].clone())
    };
    assert_eq!(run("file.toml"), run("verts.toml"));
    // A missing part file is an error located at part.shape.
    std::fs::write(dir.join("missing.toml"), with("shape = \"nothere.dxf\"")).unwrap();
    let out = pinfeed(&["run", dir.join("missing.toml").to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("part.shape") && err.contains("nothere.dxf"),
        "{err}"
    );
}

/// Every obstacle of `scene` is in the drawing to 1 µm (the drawing in mm).
fn check_layout(scene: &Scene, d: &Drawing) {
    assert_eq!(d.header.default_drawing_units, Units::Millimeters);
    let um = 1e-3;
    let near = |a: &Point, x: f64, y: f64| (a.x - x * 1e3).abs() < um && (a.y - y * 1e3).abs() < um;
    let on = |layer: &str| {
        d.entities()
            .filter(move |e| e.common.layer == layer)
            .collect::<Vec<_>>()
    };
    let (w, len) = (scene.belt.width, scene.belt.length);
    let belt: Vec<_> = on("BELT");
    for y in [-w / 2.0, w / 2.0] {
        assert!(belt.iter().any(|e| matches!(&e.specific, EntityType::Line(l) if near(&l.p1, 0.0, y) && near(&l.p2, len, y))), "belt edge {y}");
    }
    for ob in &scene.obstacles {
        match ob {
            Obstacle::Pin(p) => {
                let layer = match (&p.actuator, p.sensor.is_some()) {
                    (_, true) => "SENSORS",
                    (Some(_), false) => "MOVING",
                    (None, false) => "PINS",
                };
                let found = on(layer).iter().any(|e| matches!(&e.specific, EntityType::Circle(c)
                    if near(&c.center, p.centre.x, p.centre.y) && (c.radius - p.radius * 1e3).abs() < um));
                assert!(found, "pin {} on {layer}", p.name);
                if let Some(Actuator::Moving(m)) = &p.actuator {
                    let travel = on("MOVING").iter().any(|e| matches!(&e.specific, EntityType::Line(l)
                        if near(&l.p1, p.centre.x, m.travel[0]) && near(&l.p2, p.centre.x, m.travel[1])));
                    assert!(travel, "travel of {}", p.name);
                }
                let named = on("TEXT").iter().any(
                    |e| matches!(&e.specific, EntityType::Text(t) if t.value.starts_with(&p.name)),
                );
                assert!(named, "name of {}", p.name);
            }
            Obstacle::Fence(f) => {
                let spec = f.spec();
                let end = spec.straight_end();
                let straight = on("FENCES").iter().any(|e| {
                    matches!(&e.specific, EntityType::Line(l)
                    if near(&l.p1, f.start.x, f.start.y) && near(&l.p2, end.x, end.y))
                });
                assert!(straight, "fence {}", f.name);
                if let Some((c, r, _, _)) = spec.tail_arc() {
                    let far = spec.far_end();
                    let tail = on("FENCES").iter().any(|e| match &e.specific {
                        EntityType::Arc(a) => {
                            let at = |deg: f64| {
                                let t = deg.to_radians();
                                (
                                    a.center.x + a.radius * t.cos(),
                                    a.center.y + a.radius * t.sin(),
                                )
                            };
                            let (s, t) = (at(a.start_angle), at(a.end_angle));
                            let is = |p: (f64, f64), v: Vec2| {
                                (p.0 - v.x * 1e3).abs() < um && (p.1 - v.y * 1e3).abs() < um
                            };
                            near(&a.center, c.x, c.y)
                                && (a.radius - r * 1e3).abs() < um
                                && ((is(s, end) && is(t, far)) || (is(s, far) && is(t, end)))
                        }
                        _ => false,
                    });
                    assert!(tail, "tail of {}", f.name);
                }
            }
        }
    }
}

#[test]
fn layout_drawings_give_every_obstacle_to_a_micrometre() {
    let dir = fresh_dir("cad-layout");
    // Sensor, moving and fixed pins (the online line, drafted: its sensors untrained).
    let draft = SceneDraft::read(Path::new("scenarios/tripoly1_online.toml")).unwrap();
    let sensors: Vec<usize> = draft.sensors().iter().map(|s| s.obstacle).collect();
    assert!(!sensors.is_empty());
    let scene = draft.untrained();
    let d = layout_drawing(scene, &sensors);
    let mut bytes = Vec::new();
    d.save(&mut bytes).unwrap();
    let back = Drawing::load(&mut bytes.as_slice()).unwrap();
    check_layout_sensors(scene, &back, &sensors);
    // Fences with curved tails, through `run --dxf`.
    let fences = std::fs::read_to_string("scenarios/tripoly2_fences.toml").unwrap();
    let tailed = fences.replace("mu_f = 0.5", "mu_f = 0.5\ntail_radius = 0.03");
    assert!(
        tailed.contains("tail_radius"),
        "the fences scenario has no mu_f line to extend"
    );
    let scen = dir.join("tailed.toml");
    std::fs::write(&scen, tailed).unwrap();
    let out = dir.join("tailed.dxf");
    pinfeed_ok(&[
        "run",
        scen.to_str().unwrap(),
        "--parts",
        "5",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--dxf",
        out.to_str().unwrap(),
    ]);
    let scene = pinfeed::scenario::load(&scen).unwrap();
    assert!(scene
        .obstacles
        .iter()
        .any(|o| matches!(o, Obstacle::Fence(f) if f.tail_radius.is_some())));
    check_layout(&scene, &Drawing::load_file(&out).unwrap());
    // The quickstart's pins, through `run --dxf`.
    let out = dir.join("quick.dxf");
    pinfeed_ok(&[
        "run",
        "scenarios/quickstart.toml",
        "--parts",
        "5",
        "--quiet",
        "--out",
        dir.to_str().unwrap(),
        "--dxf",
        out.to_str().unwrap(),
    ]);
    let scene = pinfeed::scenario::load(Path::new("scenarios/quickstart.toml")).unwrap();
    check_layout(&scene, &Drawing::load_file(&out).unwrap());
}

/// [`check_layout`] for a drafted scene: the pins in `sensors` on the SENSORS layer.
fn check_layout_sensors(scene: &Scene, d: &Drawing, sensors: &[usize]) {
    for &i in sensors {
        let Obstacle::Pin(p) = &scene.obstacles[i] else {
            panic!("a sensor is a pin")
        };
        let found = d.entities().any(|e| e.common.layer == "SENSORS" && matches!(&e.specific, EntityType::Circle(c)
            if (c.center.x - p.centre.x * 1e3).abs() < 1e-3 && (c.center.y - p.centre.y * 1e3).abs() < 1e-3 && (c.radius - p.radius * 1e3).abs() < 1e-3));
        assert!(found, "sensor pin {}", p.name);
    }
    let mut others = scene.clone();
    others.obstacles = scene
        .obstacles
        .iter()
        .enumerate()
        .filter(|(i, _)| !sensors.contains(i))
        .map(|(_, o)| o.clone())
        .collect();
    check_layout(&others, d);
}

#[test]
fn the_readme_from_cad_example_prints_what_it_shows() {
    // README's "From CAD" block: the command, then its output block.
    let readme = std::fs::read_to_string("README.md").unwrap();
    let section = readme.split("## From CAD").nth(1).unwrap();
    let section = section.split("\n## ").next().unwrap();
    let blocks: Vec<&str> = section.split("```").skip(1).step_by(2).collect();
    let cmd = blocks[0]
        .trim()
        .strip_prefix("cargo run --release -- ")
        .unwrap();
    let words: Vec<&str> = cmd.split_whitespace().collect();
    let out = pinfeed_ok(&words);
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        blocks[1].trim()
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("1 hole ignored"), "{err}");
    // The example is an exporter-style file: a header with $INSUNITS and no tables.
    let p = read(Path::new("examples/cad/bracket.dxf"));
    assert_eq!((p.unit.name, p.unit_source), ("mm", "$INSUNITS"));
    let exact = 1800.0 + PI * 15.0 * 15.0 / 2.0;
    let lost = exact - mass(&p).0;
    assert!((0.0..=0.05 * PI * 15.0).contains(&lost), "{lost}");
}
