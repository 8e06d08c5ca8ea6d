//! Validation and compilation: [`RawScenario`] → [`Scene`]. Every check names the key and the
//! allowed range (SPEC §1 units: m, s, degrees in the file; radians inside).
//!
//! Geometry rules that keep a run well defined:
//! * a part enters with its centroid at x = 0 and must fit on the belt: the lateral offsets lie
//!   within [−width/2 + a, width/2 − a];
//! * obstacles (pins and fences) are checked in [`super::obstacles`].

use super::checker::Checker;
use super::error::{Locator, ScenarioError};
use super::limits;
use super::raw::*;
use super::scene::*;
use crate::geometry::{named, Polygon, Vec2};
use crate::mechanics::{ContactSettings, PartModel, Support};

type R<T> = Result<T, ScenarioError>;

/// Compile a parsed scenario. `default_name` names the scene when the file does not.
pub fn compile(raw: &RawScenario, loc: &Locator, default_name: &str) -> R<Scene> {
    let c = Checker::new(loc);
    let name = match &raw.name {
        Some(n) => {
            let ok = !n.is_empty()
                && n.chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_');
            if !ok {
                return Err(c.err(
                    "name",
                    format!("'{n}' must be non-empty and use only letters, digits, '-' and '_' (it names the results folder)"),
                ));
            }
            n.clone()
        }
        None => default_name.to_string(),
    };
    let seed = raw.seed.unwrap_or(1);

    // [belt]
    let Some(rb) = &raw.belt else {
        return Err(c.missing(
            "belt",
            "missing section [belt]: give speed (m/s), width (m) and length (m)",
        ));
    };
    let belt = Belt {
        speed: c.range("belt.speed", rb.speed, limits::BELT_SPEED, "m/s")?,
        width: c.range("belt.width", rb.width, limits::BELT_WIDTH, "m")?,
        length: c.range("belt.length", rb.length, limits::BELT_LENGTH, "m")?,
    };

    // [part]
    let Some(rp) = &raw.part else {
        return Err(c.missing(
            "part",
            "missing section [part]: give shape = \"tripoly2\" (or vertices = [[x, y], ...]) and scale (m per unit)",
        ));
    };
    let (label, poly) = match (&rp.shape, &rp.vertices) {
        (Some(_), Some(_)) => {
            return Err(c.err("part.vertices", "give either shape or vertices, not both"))
        }
        (None, None) => {
            return Err(c.err(
                "part",
                format!(
                "the part needs shape = one of {} (e.g. \"tripoly2\"), or vertices = [[x, y], ...]",
                named::PART_NAMES.join(", ")
            ),
            ))
        }
        (Some(shape), None) => {
            if shape.trim_start().starts_with("vertices") {
                return Err(c.err(
                    "part.shape",
                    "write a vertex list as vertices = [[x, y], ...], not as a shape",
                ));
            }
            let p = named::part_from_spec(shape).map_err(|e| c.err("part.shape", e.to_string()))?;
            (shape.trim().to_string(), p)
        }
        (None, Some(vs)) => {
            let (lo, hi) = limits::VERTEX_MAGNITUDE;
            let mut largest = 0.0f64;
            for (i, v) in vs.iter().enumerate() {
                for (k, &x) in v.iter().enumerate() {
                    let path = format!("part.vertices[{i}][{k}]");
                    c.finite(&path, x)?;
                    if x.abs() > hi {
                        return Err(c.err(
                            &path,
                            format!("a vertex coordinate must lie within ±{} units (use part.scale for large parts), got {}", limits::num(hi), limits::num(x)),
                        ));
                    }
                    largest = largest.max(x.abs());
                }
            }
            if largest < lo {
                return Err(c.err(
                    "part.vertices",
                    format!("the largest vertex coordinate must be at least {} units in magnitude (use part.scale for small parts), got {}", limits::num(lo), limits::num(largest)),
                ));
            }
            let pts: Vec<Vec2> = vs.iter().map(|v| Vec2::new(v[0], v[1])).collect();
            let p = Polygon::new(&pts).map_err(|e| {
                c.err(
                    "part.vertices",
                    format!("not a valid part: {e} (a part is a simple polygon with at least 3 vertices and non-zero area)"),
                )
            })?;
            ("vertices".to_string(), p)
        }
    };
    let scale = c.range(
        "part.scale",
        rp.scale.unwrap_or(1.0),
        limits::PART_SCALE,
        "m per unit",
    )?;
    let scaled_radius = poly.radius() * scale;
    if !limits::contains(limits::PART_RADIUS, scaled_radius) {
        let key = if rp.scale.is_some() {
            "part.scale"
        } else {
            "part"
        };
        return Err(c.err(
            key,
            format!(
                "the scaled part's size a (centroid to farthest vertex) must lie in {} m, got {} m ({} units × scale {})",
                limits::show(limits::PART_RADIUS),
                limits::num(scaled_radius),
                limits::num(poly.radius()),
                limits::num(scale)
            ),
        ));
    }
    let polygon = poly.scaled(scale);
    let radius = polygon.radius();
    let mu_c = c.range(
        "part.mu_c",
        rp.mu_c.unwrap_or(0.5),
        limits::FRICTION,
        "friction coefficient",
    )?;
    let mu_s = c.range(
        "part.mu_s",
        rp.mu_s.unwrap_or(0.3),
        limits::FRICTION,
        "friction coefficient",
    )?;
    if mu_s == 0.0 {
        return Err(c.err(
            "part.mu_s",
            "must be greater than 0 (friction coefficient; it scales forces)",
        ));
    }
    let mass = c.range("part.mass", rp.mass.unwrap_or(0.05), limits::MASS_KG, "kg")?;
    let model = PartModel::new(&polygon, &Support::Uniform).map_err(|e| {
        c.err(
            "part",
            format!("cannot compile the part's contact model: {e}"),
        )
    })?;
    let stable_states = polygon.stable_states();

    // [feed]
    let Some(rf) = &raw.feed else {
        return Err(c.missing(
            "feed",
            "missing section [feed]: give parts, arrival (periodic | poisson), headway (s) or rate (1/s), orientation (uniform | stable)",
        ));
    };
    if rf.parts == 0 || rf.parts > 1_000_000_000 {
        return Err(c.err(
            "feed.parts",
            format!("must lie in [1, 1000000000], got {}", rf.parts),
        ));
    }
    let headway = match (rf.headway, rf.rate) {
        (Some(_), Some(_)) => {
            return Err(c.err(
                "feed.rate",
                "give either headway (s) or rate (1/s), not both",
            ))
        }
        (None, None) => {
            return Err(c.err(
                "feed",
                "give headway (seconds between arrivals) or rate (arrivals per second)",
            ))
        }
        (Some(h), None) => c.range("feed.headway", h, limits::HEADWAY, "s")?,
        (None, Some(r)) => 1.0 / c.range("feed.rate", r, limits::RATE, "arrivals per second")?,
    };
    let arrival = match rf.arrival {
        ArrivalKind::Periodic => Arrival::Periodic { headway },
        ArrivalKind::Poisson => Arrival::Poisson { headway },
    };
    let jitter = c
        .range(
            "feed.jitter",
            rf.jitter.unwrap_or(0.0),
            limits::JITTER_DEG,
            "degrees",
        )?
        .to_radians();
    let orientation = match rf.orientation {
        OrientationKind::Uniform => {
            if rf.weights.is_some() {
                return Err(c.err(
                    "feed.weights",
                    "weights apply only to orientation = \"stable\"",
                ));
            }
            if rf.jitter.is_some() {
                return Err(c.err(
                    "feed.jitter",
                    "jitter applies only to orientation = \"stable\"",
                ));
            }
            Orientation::Uniform
        }
        OrientationKind::Stable => {
            let thetas: Vec<f64> = stable_states.iter().map(|s| s.theta).collect();
            if thetas.is_empty() {
                return Err(c.err(
                    "feed.orientation",
                    "this part has no stable state; use orientation = \"uniform\"",
                ));
            }
            let list = thetas
                .iter()
                .map(|t| format!("{:.3}°", t.to_degrees()))
                .collect::<Vec<_>>()
                .join(", ");
            let weights = match &rf.weights {
                None => vec![1.0; thetas.len()],
                Some(w) => {
                    if w.len() != thetas.len() {
                        return Err(c.err(
                            "feed.weights",
                            format!(
                                "needs one weight per stable state: {} ({list}), got {}",
                                thetas.len(),
                                w.len()
                            ),
                        ));
                    }
                    for (i, &x) in w.iter().enumerate() {
                        c.range(
                            &format!("feed.weights[{i}]"),
                            x,
                            limits::WEIGHT,
                            "relative weight",
                        )?;
                    }
                    w.clone()
                }
            };
            let total: f64 = weights.iter().sum();
            if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(c.err("feed.weights", "at least one weight must be positive"));
            }
            Orientation::Stable {
                thetas,
                weights: weights.iter().map(|w| w / total).collect(),
                jitter,
            }
        }
    };
    let reach = belt.width / 2.0 - radius;
    if reach < 0.0 {
        return Err(c.err(
            "belt.width",
            format!(
                "the belt ({} m) is narrower than the part (2a = {:.6} m)",
                belt.width,
                2.0 * radius
            ),
        ));
    }
    let range = format!("m; the belt half-width minus the part's a = {radius:.6} m");
    let lateral = match &rf.lateral {
        None => Lateral::Fixed(0.0),
        Some(l) => {
            let allowed = |keys: &[&str]| -> R<()> {
                let given = [
                    ("value", l.value.is_some()),
                    ("min", l.min.is_some()),
                    ("max", l.max.is_some()),
                    ("mean", l.mean.is_some()),
                    ("sd", l.sd.is_some()),
                ];
                for (k, present) in given {
                    if present && !keys.contains(&k) {
                        return Err(c.err(
                            &format!("feed.lateral.{k}"),
                            format!(
                                "does not apply to this distribution, which takes {}",
                                keys.join(", ")
                            ),
                        ));
                    }
                }
                for k in keys {
                    let present = given.iter().any(|(g, p)| g == k && *p);
                    if !present {
                        return Err(c.err(
                            "feed.lateral",
                            format!("this distribution needs {}", keys.join(", ")),
                        ));
                    }
                }
                Ok(())
            };
            let on_belt = |key: &str, v: Option<f64>| {
                c.within(
                    &format!("feed.lateral.{key}"),
                    v.unwrap_or(0.0),
                    -reach,
                    reach,
                    &range,
                )
            };
            match l.distribution {
                LateralKind::Fixed => {
                    allowed(&["value"])?;
                    Lateral::Fixed(on_belt("value", l.value)?)
                }
                LateralKind::Uniform => {
                    allowed(&["min", "max"])?;
                    let min = on_belt("min", l.min)?;
                    let max = on_belt("max", l.max)?;
                    if min > max {
                        return Err(c.err(
                            "feed.lateral.max",
                            format!("must be at least min ({min}), got {max}"),
                        ));
                    }
                    Lateral::Uniform { min, max }
                }
                LateralKind::Normal => {
                    allowed(&["mean", "sd"])?;
                    let mean = on_belt("mean", l.mean)?;
                    let sd = c.within(
                        "feed.lateral.sd",
                        l.sd.unwrap_or(0.0),
                        0.0,
                        belt.width,
                        "m; at most the belt width",
                    )?;
                    Lateral::Normal {
                        mean,
                        sd,
                        lo: -reach,
                        hi: reach,
                    }
                }
            }
        }
    };
    let feed = Feed {
        parts: rf.parts,
        arrival,
        orientation,
        lateral,
    };

    // [[obstacles]]
    let (mut obstacles, neighbours, sensor_drafts) =
        super::obstacles::compile_obstacles(&c, &raw.obstacles, &belt, radius, mu_c)?;

    // [goal]
    let Some(rg) = &raw.goal else {
        return Err(c.missing(
            "goal",
            "missing section [goal]: give any = true, or one or more [[goal.sets]] with orientations (degrees)",
        ));
    };
    let goal =
        match (rg.any, rg.sets.is_empty()) {
            (true, false) => {
                return Err(c.err("goal.sets", "give either any = true or goal sets, not both"))
            }
            (false, true) => return Err(c.err(
                "goal",
                "give any = true, or one or more [[goal.sets]] with orientations = [degrees, ...]",
            )),
            (true, true) => Goal::Any,
            (false, false) => {
                let mut sets = Vec::new();
                for (i, s) in rg.sets.iter().enumerate() {
                    if s.orientations.is_empty() {
                        return Err(c.err(
                            &format!("goal.sets[{i}].orientations"),
                            "needs at least one orientation (degrees)",
                        ));
                    }
                    let mut os = Vec::new();
                    for (j, &o) in s.orientations.iter().enumerate() {
                        os.push(
                            c.range(
                                &format!("goal.sets[{i}].orientations[{j}]"),
                                o,
                                limits::ORIENTATION_DEG,
                                "degrees",
                            )?
                            .to_radians(),
                        );
                    }
                    let tol = s.tolerance.unwrap_or(5.0);
                    let tol = c.within(
                        &format!("goal.sets[{i}].tolerance"),
                        tol,
                        0.0,
                        180.0,
                        "degrees",
                    )?;
                    let name = s.name.clone().unwrap_or_else(|| format!("set{}", i + 1));
                    if sets.iter().any(|g: &GoalSet| g.name == name) {
                        return Err(c.err(
                            &format!("goal.sets[{i}].name"),
                            format!("'{name}' is used twice"),
                        ));
                    }
                    sets.push(GoalSet {
                        name,
                        orientations: os,
                        tolerance: tol.to_radians(),
                    });
                }
                Goal::Sets(sets)
            }
        };

    // [model]
    let defaults = ContactSettings::default();
    let tol = raw.model.tol.unwrap_or(defaults.tol);
    let tol = c.range("model.tol", tol, limits::TOL, "relative, in units of a")?;
    let max_travel = c.within(
        "model.max_travel",
        raw.model.max_travel.unwrap_or(defaults.max_travel),
        1.0,
        1e4,
        "units of a",
    )?;
    let contact = ContactSettings {
        fidelity: raw.model.fidelity.unwrap_or_default(),
        mu_c,
        mu_s,
        tol,
        max_travel,
        ..defaults
    };

    let effects = Effects {
        collisions: raw.effects.collisions.unwrap_or(true),
        obstacle_sweeps: raw.effects.obstacle_sweeps.unwrap_or(true),
        event_log: raw.effects.event_log.unwrap_or(false),
    };
    let ro = &raw.output;
    let output = OutputOptions {
        dir: ro.dir.clone().unwrap_or_else(|| "results".into()),
        parts_csv: ro.parts_csv.unwrap_or(false),
        histogram_svg: ro.histogram_svg.unwrap_or(true),
        histogram_bin_deg: {
            let b = ro.histogram_bin.unwrap_or(5.0);
            // At most 360 / 0.01 = 36 000 bins: the histogram's memory is bounded.
            c.range(
                "output.histogram_bin",
                b,
                limits::HISTOGRAM_BIN_DEG,
                "degrees; it must divide 360",
            )?;
            if (360.0 / b - (360.0 / b).round()).abs() >= 1e-9 {
                return Err(c.err(
                    "output.histogram_bin",
                    format!(
                        "must divide 360 (degrees, in {}), got {b}",
                        limits::show(limits::HISTOGRAM_BIN_DEG)
                    ),
                ));
            }
            b
        },
        draw_parts: {
            let n = ro.draw_parts.unwrap_or(4);
            if !(1..=20).contains(&n) {
                return Err(c.err("output.draw_parts", format!("must lie in [1, 20], got {n}")));
            }
            n
        },
    };

    let part = PartSpec {
        label,
        polygon,
        radius,
        model,
        support: rp.support,
        mu_c,
        mu_s,
        mass,
        stable_states,
    };
    // Sensor pins: train each sensor's classifier on templates of this scene.
    for (i, draft) in &sensor_drafts {
        if let Obstacle::Pin(pin) = &obstacles[*i] {
            let trained = super::sensors::train(
                &c, *i, draft, pin, &part, &feed, belt.speed, &contact, seed,
            )?;
            if let Obstacle::Pin(pin) = &mut obstacles[*i] {
                pin.sensor = Some(std::sync::Arc::new(trained));
            }
        }
    }

    // [controller] and [[rules]]: after training, so that rules can name the sensors' labels.
    let controller = super::dynamic_check::controller(
        &c,
        loc,
        raw.controller.as_ref(),
        &raw.rules,
        &obstacles,
        &part.label,
    )?;

    Ok(Scene {
        name,
        seed,
        belt,
        part,
        feed,
        obstacles,
        neighbours,
        goal,
        contact,
        effects,
        output,
        controller,
    })
}
