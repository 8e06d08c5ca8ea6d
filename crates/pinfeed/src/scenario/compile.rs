//! Validation and compilation: [`RawScenario`] → [`SceneDraft`]. Every check names the key and the
//! allowed range (docs/physics.md#frames units: m, s, degrees in the file; radians inside).
//!
//! Geometry rules that keep a run well defined:
//! * a part enters with its centroid at x = 0 and must fit on the belt: the lateral offsets lie
//!   within [−width/2 + a, width/2 − a];
//! * obstacles (pins and fences) are checked in [`super::obstacles`], sensors in
//!   [`super::sensors`].
//!
//! [`compile`] composes one function per section (`compile_belt`, `compile_part`,
//! `compile_feed`, `compile_goal`, `compile_model`, `compile_effects`, `compile_output`), each
//! returning its piece of the [`Scene`] the draft builds.

use super::checker::Checker;
use super::draft::SceneDraft;
use super::error::{Locator, ScenarioError};
use super::limits;
use super::raw::*;
use super::scene::*;
use crate::geometry::{named, Polygon, StableState, Vec2};
use crate::maps::tier::TierSpec;
use crate::mechanics::{ContactSettings, PartModel, Support};

type R<T> = Result<T, ScenarioError>;

/// Compile a parsed scenario into a [`SceneDraft`]: everything checked, the sensor pins not yet
/// trained. `default_name` names the scene when the file does not.
///
/// The sections are checked in file order (name, belt, part, feed, obstacles, goal, model,
/// effects, output, the sensors' hypotheses, controller), so the first error reported is the same
/// whatever else is wrong.
pub fn compile(
    raw: &RawScenario,
    loc: &Locator,
    default_name: &str,
    policy: Option<&str>,
) -> R<SceneDraft> {
    let c = Checker::new(loc);
    let name = scene_name(&c, raw.name.as_deref(), default_name)?;
    let seed = raw.seed.unwrap_or(1);
    let belt = compile_belt(&c, raw.belt.as_ref())?;
    let mut part = compile_part(&c, raw.part.as_ref(), &belt)?;
    let feed = compile_feed(&c, raw.feed.as_ref(), &belt, &part)?;
    let (obstacles, neighbours, valid_sensors) =
        super::obstacles::compile_obstacles(&c, &raw.obstacles, &belt, part.radius, part.mu_c)?;
    part.model = part.model.with_slide_tables(&contact_mu_values(&obstacles));
    let goal = compile_goal(&c, raw.goal.as_ref())?;
    let contact = compile_model(&c, &raw.model, &part)?;
    let map_tier = compile_map_tier(&c, &raw.model)?;
    let effects = compile_effects(&raw.effects);
    let output = compile_output(&c, &raw.output)?;
    // Sensor pins: their hypotheses, resolved against the part and the feed.
    let mut sensors = Vec::new();
    for (i, valid) in &valid_sensors {
        if let Obstacle::Pin(pin) = &obstacles[*i] {
            sensors.push(super::sensors::draft(&c, *i, valid, pin, &part, &feed)?);
        }
    }
    // [controller] and [[rules]]: after the sensors, so that rules can name their labels.
    let controller = super::dynamic_check::controller(
        &c,
        loc,
        raw.controller.as_ref(),
        &raw.rules,
        &obstacles,
        &sensors,
        &part.label,
        policy,
    )?;
    let closed_loop = super::closed_loop::compile(
        &c,
        &raw.obstacles,
        raw.recirculation.as_ref(),
        &obstacles,
        &sensors,
        &belt,
        &part,
        &goal,
        matches!(
            controller.as_ref().map(|c| &c.mode),
            Some(super::dynamic::ControlMode::Online(_))
        ),
    )?;
    let mut scene = Scene {
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
        map_tier,
        closed_loop,
    };
    locate_belief(&c, raw, &mut scene);
    Ok(SceneDraft::new(scene, sensors))
}

/// `[controller] mode = "online"`: where the belief is declared (or the mode, when the belief is
/// not written), to locate an error in building the controller's model, which happens after
/// parsing (`engine::prepare`; docs/physics.md#belief-and-online-replanning).
fn locate_belief(c: &Checker, raw: &RawScenario, scene: &mut Scene) {
    let Some(ctl) = scene.controller.as_mut() else {
        return;
    };
    if !matches!(ctl.mode, super::dynamic::ControlMode::Online(_)) {
        return;
    }
    let at = match raw.controller.as_ref().and_then(|r| r.belief.as_ref()) {
        Some(_) => "controller.belief",
        None => "controller.mode",
    };
    ctl.belief_at = super::error::KeyLocation::of(c.err(at, ""));
}

/// The friction values the scene's pins (μc) and fences (μf) push with: the shared part model
/// tabulates its exact slides for these (built lazily, so a scene that never slides on an edge or
/// a vertex, or runs another fidelity, builds nothing; see `mechanics::slide_table`). A fence
/// sliding on a vertex of the part's hull uses that polygon vertex's tables; a hull edge flush
/// on a fence is solved in closed form and needs none.
fn contact_mu_values(obstacles: &[Obstacle]) -> Vec<f64> {
    obstacles
        .iter()
        .map(|o| match o {
            Obstacle::Pin(p) => p.mu_c,
            Obstacle::Fence(f) => f.mu_f,
        })
        .collect()
}

/// `name`: the scene's name (it names the results folder), else `default_name`.
fn scene_name(c: &Checker, name: Option<&str>, default_name: &str) -> R<String> {
    let Some(n) = name else {
        return Ok(default_name.to_string());
    };
    let ok = !n.is_empty()
        && n.chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_');
    if !ok {
        return Err(c.err(
            "name",
            format!("'{n}' must be non-empty and use only letters, digits, '-' and '_' (it names the results folder)"),
        ));
    }
    Ok(n.to_string())
}

/// `[belt]`: speed (m/s), width (m) and length (m).
fn compile_belt(c: &Checker, rb: Option<&RawBelt>) -> R<Belt> {
    let Some(rb) = rb else {
        return Err(c.missing(
            "belt",
            "missing section [belt]: give speed (m/s), width (m) and length (m)",
        ));
    };
    Ok(Belt {
        speed: c.range("belt.speed", rb.speed, limits::BELT_SPEED, "m/s")?,
        width: c.range("belt.width", rb.width, limits::BELT_WIDTH, "m")?,
        length: c.range("belt.length", rb.length, limits::BELT_LENGTH, "m")?,
    })
}

/// `[part]`: the shape (named or a vertex list) scaled to metres, its friction and mass, and its
/// contact model and stable states compiled once. A part wider than the `belt` that would fit
/// in millimetres is refused here, naming that likely cause (any other too-wide part is refused
/// at `belt.width` by the feed).
fn compile_part(c: &Checker, rp: Option<&RawPart>, belt: &Belt) -> R<PartSpec> {
    let Some(rp) = rp else {
        return Err(c.missing(
            "part",
            "missing section [part]: give shape = \"tripoly2\" (or vertices = [[x, y], ...]) and scale (m per unit)",
        ));
    };
    let (label, poly) = part_shape(c, rp)?;
    // A part file is in millimetres.
    let file_part = rp
        .shape
        .as_deref()
        .is_some_and(crate::geometry::cad::is_part_file);
    let scale = c.range(
        "part.scale",
        rp.scale.unwrap_or(if file_part { 0.001 } else { 1.0 }),
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
    if 2.0 * radius > belt.width {
        let mm = limits::mm_scale_fit(radius, scale, belt.width);
        let (key, given) = match rp.scale {
            Some(_) => ("part.scale", ""),
            None => ("part", ", the default: [part] gives no scale"),
        };
        let hint = match mm {
            Some(two_a) => format!(
                "vertices in mm? give scale = 0.001 (2a = {} m)",
                crate::mechanics::limits::short(two_a)
            ),
            None => "give scale, the metres per unit of the shape".to_string(),
        };
        if mm.is_some() || rp.scale.is_none() {
            return Err(c.err(
                key,
                format!(
                    "the part (2a = {} m at scale {}{given}) is wider than the belt ({} m): {hint}",
                    crate::mechanics::limits::short(2.0 * radius),
                    limits::num(scale),
                    limits::num(belt.width),
                ),
            ));
        }
    }
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
    Ok(PartSpec {
        label,
        polygon,
        radius,
        model,
        support: rp.support,
        mu_c,
        mu_s,
        mass,
        stable_states,
    })
}

/// The part's label and polygon in units: `shape` (a named part) or `vertices`, not both.
fn part_shape(c: &Checker, rp: &RawPart) -> R<(String, Polygon)> {
    match (&rp.shape, &rp.vertices) {
        (Some(_), Some(_)) => {
            Err(c.err("part.vertices", "give either shape or vertices, not both"))
        }
        (None, None) => Err(c.err(
            "part",
            format!(
                "the part needs shape = one of {} (e.g. \"tripoly2\"), or vertices = [[x, y], ...]",
                named::PART_NAMES.join(", ")
            ),
        )),
        (Some(shape), None) => {
            if shape.trim_start().starts_with("vertices") {
                return Err(c.err(
                    "part.shape",
                    "write a vertex list as vertices = [[x, y], ...], not as a shape",
                ));
            }
            if crate::geometry::cad::is_part_file(shape) {
                return Ok((shape.trim().to_string(), file_polygon(c, rp, shape)?));
            }
            if rp.units.is_some() || rp.flatten.is_some() {
                let key = if rp.units.is_some() {
                    "part.units"
                } else {
                    "part.flatten"
                };
                return Err(c.err(key, "units and flatten apply to a part file (shape = \"FILE.dxf\" or \"FILE.csv\") only"));
            }
            let p = named::part_from_spec(shape).map_err(|e| c.err("part.shape", e.to_string()))?;
            Ok((shape.trim().to_string(), p))
        }
        (None, Some(vs)) => Ok(("vertices".to_string(), vertex_polygon(c, vs)?)),
    }
}

/// `part.shape = "FILE.dxf"` (or `.csv`): the outline read from the file, a path relative to the
/// scenario's folder, with `part.units` and `part.flatten` (docs/cad.md).
fn file_polygon(c: &Checker, rp: &RawPart, shape: &str) -> R<Polygon> {
    use crate::geometry::cad::{read_part_file, PartFileOptions, Unit};
    let mut options = PartFileOptions::default();
    if let Some(u) = &rp.units {
        options.units = Some(Unit::parse(u).map_err(|e| c.err("part.units", e.to_string()))?);
    }
    if let Some(f) = rp.flatten {
        options.flatten_mm = c.within("part.flatten", f, 1e-6, 10.0, "mm")?;
    }
    let path = c.folder().join(shape.trim());
    let part = read_part_file(&path, &options).map_err(|e| c.err("part.shape", e.to_string()))?;
    part.polygon()
        .map_err(|e| c.err("part.shape", format!("{}: {e}", path.display())))
}

/// `part.vertices`: every coordinate finite and within the allowed magnitude, the polygon simple.
fn vertex_polygon(c: &Checker, vs: &[[f64; 2]]) -> R<Polygon> {
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
    Polygon::new(&pts).map_err(|e| {
        c.err(
            "part.vertices",
            format!("not a valid part: {e} (a part is a simple polygon with at least 3 vertices and non-zero area)"),
        )
    })
}

/// `[feed]`: number of parts, arrival process, orientation and lateral offset of each part.
fn compile_feed(c: &Checker, rf: Option<&RawFeed>, belt: &Belt, part: &PartSpec) -> R<Feed> {
    let Some(rf) = rf else {
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
    let arrival = feed_arrival(c, rf)?;
    let orientation = feed_orientation(c, rf, &part.stable_states)?;
    let lateral = feed_lateral(c, rf.lateral.as_ref(), belt, part.radius)?;
    Ok(Feed {
        parts: rf.parts,
        arrival,
        orientation,
        lateral,
    })
}

/// `feed.arrival` with `feed.headway` (s) or `feed.rate` (1/s).
fn feed_arrival(c: &Checker, rf: &RawFeed) -> R<Arrival> {
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
    Ok(match rf.arrival {
        ArrivalKind::Periodic => Arrival::Periodic { headway },
        ArrivalKind::Poisson => Arrival::Poisson { headway },
    })
}

/// `feed.orientation`: uniform, or the part's stable states with `weights` and `jitter`
/// (degrees).
fn feed_orientation(c: &Checker, rf: &RawFeed, stable_states: &[StableState]) -> R<Orientation> {
    let jitter = c
        .range(
            "feed.jitter",
            rf.jitter.unwrap_or(0.0),
            limits::JITTER_DEG,
            "degrees",
        )?
        .to_radians();
    match rf.orientation {
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
            Ok(Orientation::Uniform)
        }
        OrientationKind::Stable => {
            let thetas: Vec<f64> = stable_states.iter().map(|s| s.theta_rad).collect();
            if thetas.is_empty() {
                return Err(c.err(
                    "feed.orientation",
                    "this part has no stable state; use orientation = \"uniform\"",
                ));
            }
            let weights = stable_weights(c, rf.weights.as_deref(), &thetas)?;
            let total: f64 = weights.iter().sum();
            if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(c.err("feed.weights", "at least one weight must be positive"));
            }
            Ok(Orientation::Stable {
                thetas_rad: thetas,
                weights: weights.iter().map(|w| w / total).collect(),
                jitter_rad: jitter,
            })
        }
    }
}

/// `feed.weights`: one relative weight per stable state (at `thetas`, radians); all 1 if absent.
fn stable_weights(c: &Checker, weights: Option<&[f64]>, thetas: &[f64]) -> R<Vec<f64>> {
    let Some(w) = weights else {
        return Ok(vec![1.0; thetas.len()]);
    };
    if w.len() != thetas.len() {
        let list = thetas
            .iter()
            .map(|t| format!("{:.3}°", t.to_degrees()))
            .collect::<Vec<_>>()
            .join(", ");
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
    Ok(w.to_vec())
}

/// `feed.lateral`: the distribution of the lateral offset (m), every value keeping a part of size
/// `radius` on the belt.
fn feed_lateral(c: &Checker, lateral: Option<&RawLateral>, belt: &Belt, radius: f64) -> R<Lateral> {
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
    let Some(l) = lateral else {
        return Ok(Lateral::Fixed(0.0));
    };
    let range = format!("m; the belt half-width minus the part's a = {radius:.6} m");
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
            lateral_keys(c, l, &["value"])?;
            Ok(Lateral::Fixed(on_belt("value", l.value)?))
        }
        LateralKind::Uniform => {
            lateral_keys(c, l, &["min", "max"])?;
            let min = on_belt("min", l.min)?;
            let max = on_belt("max", l.max)?;
            if min > max {
                return Err(c.err(
                    "feed.lateral.max",
                    format!("must be at least min ({min}), got {max}"),
                ));
            }
            Ok(Lateral::Uniform { min, max })
        }
        LateralKind::Normal => {
            lateral_keys(c, l, &["mean", "sd"])?;
            let mean = on_belt("mean", l.mean)?;
            let sd = c.within(
                "feed.lateral.sd",
                l.sd.unwrap_or(0.0),
                0.0,
                belt.width,
                "m; at most the belt width",
            )?;
            Ok(Lateral::Normal {
                mean,
                sd,
                lo: -reach,
                hi: reach,
            })
        }
    }
}

/// The lateral distribution takes exactly the keys `keys`: none other given, none of them missing.
fn lateral_keys(c: &Checker, l: &RawLateral, keys: &[&str]) -> R<()> {
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
}

/// `[goal]`: any orientation, or named sets of orientations (degrees) with a tolerance.
fn compile_goal(c: &Checker, rg: Option<&RawGoal>) -> R<Goal> {
    let Some(rg) = rg else {
        return Err(c.missing(
            "goal",
            "missing section [goal]: give any = true, or one or more [[goal.sets]] with orientations (degrees)",
        ));
    };
    match (rg.any, rg.sets.is_empty()) {
        (true, false) => Err(c.err("goal.sets", "give either any = true or goal sets, not both")),
        (false, true) => Err(c.err(
            "goal",
            "give any = true, or one or more [[goal.sets]] with orientations = [degrees, ...]",
        )),
        (true, true) => Ok(Goal::Any),
        (false, false) => {
            let mut sets = Vec::new();
            for (i, s) in rg.sets.iter().enumerate() {
                let set = goal_set(c, i, s)?;
                if sets.iter().any(|g: &GoalSet| g.name == set.name) {
                    return Err(c.err(
                        &format!("goal.sets[{i}].name"),
                        format!("'{}' is used twice", set.name),
                    ));
                }
                sets.push(set);
            }
            Ok(Goal::Sets(sets))
        }
    }
}

/// `[[goal.sets]]` number `i`: its orientations (degrees → radians), tolerance and name.
fn goal_set(c: &Checker, i: usize, s: &RawGoalSet) -> R<GoalSet> {
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
    Ok(GoalSet {
        name,
        orientations_rad: os,
        tolerance_rad: tol.to_radians(),
    })
}

/// `[model]`: the contact model's fidelity, tolerance and travel limit, with the part's friction.
fn compile_model(c: &Checker, rm: &RawModel, part: &PartSpec) -> R<ContactSettings> {
    let defaults = ContactSettings::default();
    let tol = rm.tol.unwrap_or(defaults.tol);
    let tol = c.range("model.tol", tol, limits::TOL, "relative, in units of a")?;
    let max_travel = c.within(
        "model.max_travel",
        rm.max_travel.unwrap_or(defaults.max_travel),
        1.0,
        1e4,
        "units of a",
    )?;
    Ok(ContactSettings {
        fidelity: rm
            .fidelity
            .map_or(Default::default(), |f| f.contact_fidelity()),
        mu_c: part.mu_c,
        mu_s: part.mu_s,
        tol,
        max_travel,
        ..defaults
    })
}

/// `[model] fidelity = "map"` and `map_grid`: the map tier's grid (None without the tier; a grid
/// without the tier is an error, not silently ignored).
fn compile_map_tier(c: &Checker, rm: &RawModel) -> R<Option<TierSpec>> {
    if rm.fidelity != Some(RawFidelity::Map) {
        if rm.map_grid.is_some() {
            return Err(c.err("model.map_grid", "applies only with fidelity = \"map\""));
        }
        return Ok(None);
    }
    let mut spec = TierSpec::default();
    if let Some([t, d, depth]) = rm.map_grid {
        let ok = (4..=720).contains(&t) && (2..=200).contains(&d) && depth <= 8;
        if !ok {
            return Err(c.err(
                "model.map_grid",
                format!("[θ0 cells, d cells, depth] must lie in [4, 720] × [2, 200] × [0, 8], got [{t}, {d}, {depth}]"),
            ));
        }
        (spec.theta_cells, spec.d_cells, spec.max_depth) = (t, d, depth);
    }
    Ok(Some(spec))
}

/// `[effects]`: the optional work the engine does (collisions and obstacle sweeps on by default,
/// the event log off).
fn compile_effects(re: &RawEffects) -> Effects {
    Effects {
        collisions: re.collisions.unwrap_or(true),
        obstacle_sweeps: re.obstacle_sweeps.unwrap_or(true),
        event_log: re.event_log.unwrap_or(false),
    }
}

/// `[output]`: the results folder, which files a run writes, the histogram bin and how many parts
/// `--draw` shows.
fn compile_output(c: &Checker, ro: &RawOutput) -> R<OutputOptions> {
    Ok(OutputOptions {
        dir: ro
            .dir
            .clone()
            .unwrap_or_else(|| format!("{}/runs", crate::DEFAULT_OUT_ROOT)),
        parts_csv: ro.parts_csv.unwrap_or(false),
        histogram_svg: ro.histogram_svg.unwrap_or(true),
        histogram_bin_deg: histogram_bin(c, ro.histogram_bin.unwrap_or(5.0))?,
        draw_parts: {
            let n = ro.draw_parts.unwrap_or(4);
            if !(1..=20).contains(&n) {
                return Err(c.err("output.draw_parts", format!("must lie in [1, 20], got {n}")));
            }
            n
        },
    })
}

/// `output.histogram_bin` (degrees): within its range and a divisor of 360. At most
/// 360 / 0.01 = 36 000 bins: the histogram's memory is bounded.
fn histogram_bin(c: &Checker, b: f64) -> R<f64> {
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
    Ok(b)
}
