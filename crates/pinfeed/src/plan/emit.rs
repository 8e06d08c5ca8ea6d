//! A plan as a runnable scenario TOML (README "Scenario format"): the quickstart line's belt
//! (5 cm/s, one part every 4 s) with the planned width, pins at x = spacing·k (k = 1 … n) and the
//! belt ending one spacing after the last pin, the feed the plan was made for, and the goal = the
//! final window's centre ± tol. The header names the command that wrote it and the prediction.

use super::problem::{FeedKind, Problem};
use super::search::Plan;
use super::Action;

/// Shortest decimal text of a number rounded to `digits` decimals.
fn num(x: f64, digits: usize) -> String {
    let s = format!("{:.*}", digits, x);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    let s = if s == "-0" { "0".to_string() } else { s };
    if s.contains('.') || s.contains('e') {
        s
    } else {
        format!("{s}.0")
    }
}

/// How an emitted line is laid out and fed: its name (the scenario's `name`, which names its
/// output folder), the seconds between parts, the belt width (m) and the feed's part count.
#[derive(Debug, Clone, PartialEq)]
pub struct LineSpec {
    /// The scenario's `name` (names its output folder).
    pub name: String,
    /// Seconds between parts.
    pub headway_s: f64,
    /// Belt width (m).
    pub belt_width_m: f64,
    /// Parts in the feed.
    pub parts: u64,
}

/// Where the obstacles of a sequence plan stand along the belt: each step's x (m; a fence's
/// upstream end) and the belt length. The first obstacle stands one spacing in; after a pin the
/// next one follows one spacing on, after a fence [`super::fences::fence_gap_m`] past its
/// downstream end (so a part touches one obstacle at a time); the belt ends one spacing after
/// the last pin, or a gap and a spacing after the last fence.
pub fn layout(problem: &Problem, plan: &Plan, radius_m: f64) -> (Vec<f64>, f64) {
    let gap = super::fences::fence_gap_m(radius_m);
    let sp = problem.spacing_m;
    let mut xs = Vec::with_capacity(plan.steps.len());
    let mut cursor = sp;
    let mut last_fence = false;
    for step in &plan.steps {
        xs.push(cursor);
        match step.action {
            Action::Pin(_) => {
                cursor += sp;
                last_fence = false;
            }
            Action::Fence(f) => {
                cursor += f.x_extent_m() + gap;
                last_fence = true;
            }
        }
    }
    let length = if last_fence { cursor + sp } else { cursor };
    (xs, length)
}

/// A count of orientation sets for people: `usize::MAX` (the particles lost alone miss the
/// target, [`super::particles::orientation_sets`]) is no count, and reads "unbounded".
pub fn sets_text(sets: usize) -> String {
    if sets == usize::MAX {
        "sets unbounded (the lost parts alone miss the target)".to_string()
    } else {
        format!("{sets} set(s)")
    }
}

/// The body of a sequence plan's scenario (pins, fences, or both in belt order), without the
/// header ([`header`]): the line of `line`, the feed the plan was made for and the goal.
pub fn sequence_toml(
    problem: &Problem,
    plan: &Plan,
    stable_count: usize,
    symmetry: u32,
    line: &LineSpec,
) -> String {
    let radius = problem.compile().map(|c| c.radius).unwrap_or(0.0);
    let (xs, length) = layout(problem, plan, radius);
    let mut t = line_sections(problem, line, length, stable_count);
    let (mut pins, mut fences) = (0, 0);
    for (step, x) in plan.steps.iter().zip(&xs) {
        match step.action {
            Action::Pin(pin) => {
                pins += 1;
                t += &format!(
                    "\n[[obstacles]]   # margin {:.2} mm; after it: {}, best window {:.3}\nkind = \"pin\"\nname = \"pin{pins}\"\nx = {}\ny = {}\nradius = {}\n",
                    pin.margin_m * 1e3,
                    sets_text(step.sets),
                    step.window.share,
                    num(*x, 6),
                    num(pin.y_m, 6),
                    num(problem.pin_radius_m, 6),
                );
            }
            Action::Fence(f) => {
                fences += 1;
                t += &format!(
                    "\n[[obstacles]]   # margin {:.2} mm; after it: {}, best window {:.3}\nkind = \"fence\"\nname = \"fence{fences}\"\nx = {}             # m: the upstream end\ny = {}\nangle = {}          # degrees\nlength = {}\nmu_f = {}\n",
                    f.margin_m * 1e3,
                    sets_text(step.sets),
                    step.window.share,
                    num(*x, 6),
                    num(f.y0_m, 6),
                    num(f.angle_deg, 6),
                    num(f.length_m, 6),
                    num(f.mu_f, 6),
                );
                if let Some(r) = f.tail_radius_m {
                    t += &format!(
                        "tail_radius = {}   # m: a curved tail turning it parallel to the belt\n",
                        num(r, 6)
                    );
                }
            }
        }
    }
    t += &goal_and_model(problem, plan.window.centre_deg, symmetry);
    t
}

/// A scenario file's header: `lines` as comments (each already a sentence), then how to run it.
pub fn header(lines: &[String], file: &str) -> String {
    let mut t = String::new();
    for l in lines {
        if l.is_empty() {
            t += "#\n";
        } else {
            for w in l.lines() {
                t += &format!("# {w}\n");
            }
        }
    }
    t += &format!("#\n#   pinfeed run {file}\n\n");
    t
}

/// What a sequence plan claims over which abstraction: its kind (a shortest plan or a best
/// effort), the particles, quanta and action rule, and its prediction (header lines).
pub fn prediction_lines(problem: &Problem, plan: &Plan) -> Vec<String> {
    let pins = plan
        .steps
        .iter()
        .filter(|s| matches!(s.action, Action::Pin(_)))
        .count();
    let fences = plan.steps.len() - pins;
    let what = match (pins, fences) {
        (_, 0) => format!("{pins} pin(s)"),
        (0, _) => format!("{fences} fence(s)"),
        _ => format!("{pins} pin(s) and {fences} fence(s)"),
    };
    let kind = if reaches_goal(problem, plan) {
        "a shortest plan for its action set"
    } else {
        "BEST EFFORT: no plan in the search reached the goal; the shortest of those bringing the most particles into one window"
    };
    let mut l = vec![format!(
        "Prediction: {what}, {kind} (BFS over {} particle(s), θ rounded to {}°, y to {} mm, margins ≥ {} mm): {:.4} ({} of {} particles within {}° ± {}°).",
        plan.initial.total(),
        problem.theta_quantum_deg,
        problem.y_quantum_m * 1e3,
        problem.min_margin_m * 1e3,
        plan.predicted_success,
        plan.window.inside,
        plan.initial.total(),
        num(plan.window.centre_deg, 2),
        problem.tolerance_deg
    )];
    if let Some((lo, hi)) = problem.mu_c_range {
        l.push(format!(
            "Planned against μc ∈ [{lo}, {hi}] per part (the line uses μc = {}).",
            problem.mu_c
        ));
    }
    if problem.tripod {
        l.push("Planned against random tripod supports.".into());
    }
    l
}

/// Does the plan reach the problem's goal (or is it the best effort of a search that found none)?
fn reaches_goal(problem: &Problem, plan: &Plan) -> bool {
    problem.fewest_sets || plan.predicted_success >= problem.target - 1e-12
}

/// The part's label as a scenario names it (what a policy file's `part` must match): the shape
/// name, or `vertices` for a vertex list.
pub fn scenario_part_label(part: &str) -> String {
    let p = part.trim();
    if p.to_lowercase().starts_with("vertices:") {
        "vertices".into()
    } else {
        p.to_string()
    }
}

/// The belt speed of every planned line (m/s).
pub const BELT_SPEED: f64 = 0.05;

/// The name, `[belt]` (`length` m), `[part]`, `[feed]` and `[feed.lateral]` sections of a
/// planned scenario.
fn line_sections(problem: &Problem, line: &LineSpec, length: f64, stable_count: usize) -> String {
    let mut t = format!("name = \"{}\"\nseed = {}\n\n", line.name, problem.seed);
    t += &format!("[belt]\nspeed = {BELT_SPEED}        # m/s\n");
    t += &format!("width = {}\n", num(line.belt_width_m, 6));
    t += &format!("length = {}        # m\n\n", num(length, 6));
    t += "[part]\n";
    if let Some(v) = problem.part.trim().strip_prefix("vertices:") {
        let pts = crate::geometry::named::parse_vertex_list(v).unwrap_or_default();
        let list: Vec<String> = pts
            .iter()
            .map(|p| format!("[{}, {}]", num(p.x, 9), num(p.y, 9)))
            .collect();
        t += &format!("vertices = [{}]\n", list.join(", "));
    } else if crate::geometry::cad::is_part_file(&problem.part) {
        let path = problem
            .part
            .trim()
            .replace('\\', "\\\\")
            .replace('"', "\\\"");
        t += &format!("shape = \"{path}\"        # a part file, in mm\n");
        if let Some(u) = problem.part_file.units {
            t += &format!("units = \"{}\"\n", u.name);
        }
        let flatten = problem.part_file.flatten_mm;
        if flatten != crate::geometry::cad::DEFAULT_FLATTEN_MM {
            t += &format!("flatten = {}        # mm\n", num(flatten, 9));
        }
    } else {
        t += &format!("shape = \"{}\"\n", problem.part.trim());
    }
    t += &format!("scale = {}\n", num(problem.scale, 9));
    t += &format!("mu_c = {}\n", num(problem.mu_c, 6));
    t += &format!(
        "support = \"{}\"\n\n",
        if problem.tripod { "tripod" } else { "uniform" }
    );
    t += &format!(
        "[feed]\nparts = {}\narrival = \"periodic\"\nheadway = {}        # s: chosen on the line (see the header)\n",
        line.parts,
        num(line.headway_s, 3)
    );
    match problem.feed {
        FeedKind::Stable => {
            let w = vec!["1"; stable_count].join(", ");
            t += &format!(
                "orientation = \"stable\"\nweights = [{w}]\njitter = {}\n",
                num(problem.jitter_deg, 6)
            );
        }
        FeedKind::Uniform => t += "orientation = \"uniform\"\n",
    }
    if problem.lateral_m > 0.0 {
        t += &format!(
            "\n[feed.lateral]\ndistribution = \"uniform\"\nmin = {}\nmax = {}\n",
            num(-problem.lateral_m, 9),
            num(problem.lateral_m, 9)
        );
    } else {
        t += "\n[feed.lateral]\ndistribution = \"fixed\"\nvalue = 0.0\n";
    }
    t
}

/// The `[goal]` (the window centred at `centre_deg` ± tol, repeated over the part's symmetry),
/// `[model]` and `[output]` sections.
fn goal_and_model(problem: &Problem, centre_deg: f64, symmetry: u32) -> String {
    let mut t = String::new();
    // A symmetric part: the orientations one symmetry period apart are the same pose.
    let goals: Vec<String> = (0..symmetry.max(1))
        .map(|j| num(centre_deg + j as f64 * 360.0 / symmetry.max(1) as f64, 3))
        .collect();
    t += &format!(
        "\n[goal]\n[[goal.sets]]\nname = \"planned\"\norientations = [{}]\ntolerance = {}\n",
        goals.join(", "),
        num(problem.tolerance_deg, 6)
    );
    t += "\n[model]\nfidelity = \"exact\"\ntol = 1e-6\n\n[output]\nhistogram_svg = false\nhistogram_bin = 1\n";
    t
}

/// The body (no header: [`header`]) and policy file of a contingent plan: (scenario TOML,
/// policy TOML). `policy_file` is the policy's file name as the scenario refers to it (relative to
/// the scenario).
pub fn contingent_toml(
    problem: &Problem,
    plan: &super::contingent::ContingentPlan,
    stable_count: usize,
    symmetry: u32,
    line: &LineSpec,
    policy_file: &str,
) -> (String, String) {
    let sp = problem.spacing_m;
    let k = plan.k;
    let half = line.belt_width_m / 2.0;
    let length = sp * (k as f64 + 2.0);
    let mut t = line_sections(problem, line, length, stable_count);
    t += &format!(
        "\n[[obstacles]]   # the sensor (margin {:.2} mm)\nkind = \"sensor_pin\"\nname = \"probe\"\nx = {}\ny = {}\nradius = {}\n",
        plan.sensor.margin_m * 1e3,
        num(sp, 6),
        num(plan.sensor.y_m, 6),
        num(problem.pin_radius_m, 6)
    );
    t += "\n[obstacles.sensor]\ntype = \"ft\"\nrate = 1000          # Hz\nheight = 0.02        # m\nclassifier = \"likelihood\"\ntemplates = 32       # per stable state\n";
    let mut rules = String::new();
    rules += &format!(
        "# Policy of {} (written by `pinfeed plan`): per decision of the sensor pin `probe`, the\n# lateral position of each moving pin.\n\npart = \"{}\"\n",
        line.name,
        scenario_part_label(&problem.part)
    );
    for j in 0..k {
        let ys: Vec<f64> = plan.branches.iter().map(|b| b.targets_m[j]).collect();
        let x = num(sp * (j as f64 + 2.0), 6);
        let pname = format!("mover{}", j + 1);
        if ys.iter().all(|&y| (y - ys[0]).abs() < 1e-12) {
            // Every branch wants the same position: a fixed pin.
            t += &format!(
                "\n[[obstacles]]   # the same position for every decision\nkind = \"pin\"\nname = \"pin{}\"\nx = {x}\ny = {}\nradius = {}\n",
                j + 2,
                num(ys[0], 6),
                num(problem.pin_radius_m, 6)
            );
            continue;
        }
        let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let lo = (lo - 0.001).max(-half);
        let hi = (hi + 0.001).min(half);
        t += &format!(
            "\n[[obstacles]]\nkind = \"moving_pin\"\nname = \"{pname}\"\nx = {x}\ny = {}            # home (m)\nradius = {}\ntravel = [{}, {}]   # m\nspeed = 0.1          # m/s\naccel = 1.0          # m/s²\nsettle = 0.05        # s\n",
            num(ys[0], 6),
            num(problem.pin_radius_m, 6),
            num(lo, 6),
            num(hi, 6)
        );
        for b in &plan.branches {
            let used = j < b.pins.len();
            rules +=
                &format!(
                "\n[[rules]]{}\nsensor = \"probe\"\ndecides = \"{}\"\npin = \"{pname}\"\ny = {}\n",
                if used { "" } else { "   # parked: touches none of this branch's parts" },
                b.label,
                num(b.targets_m[j], 6)
            );
        }
    }
    if rules.contains("[[rules]]") {
        t += &format!(
            "\n[controller]\nlatency = 0.02       # s, from the end of a reading to the command\non_late = \"skip\"\npolicy = \"{policy_file}\"\n"
        );
    }
    t += &goal_and_model(problem, plan.centre_deg, symmetry);
    (t, rules)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::fences::FenceAction;
    use crate::plan::particles::{State, Window};
    use crate::plan::search::PlanStep;

    /// A best-effort fence plan whose lost particles alone miss the target: its sets are
    /// `usize::MAX`, which the scenario's comments and the JSON must not print as a number.
    #[test]
    fn unbounded_sets_read_as_a_word_in_the_scenario_and_null_in_json() {
        let problem = Problem::new("tripoly2");
        let window = Window {
            centre_deg: 10.0,
            inside: 1,
            share: 0.5,
        };
        let fence = FenceAction {
            angle_deg: 25.0,
            y0_m: -0.02,
            y1_m: 0.02,
            length_m: 0.1,
            mu_f: 0.5,
            lo_m: -0.03,
            hi_m: -0.01,
            margin_m: 0.01,
            max_lag_m: 0.0,
            tail_radius_m: None,
        };
        let state = State::canonical(vec![], 1);
        let plan = Plan {
            initial: state.clone(),
            initial_window: window,
            initial_sets: usize::MAX,
            steps: vec![
                PlanStep {
                    action: Action::Fence(fence),
                    state: state.clone(),
                    window,
                    sets: 2,
                },
                PlanStep {
                    action: Action::Fence(FenceAction {
                        angle_deg: -25.0,
                        ..fence
                    }),
                    state,
                    window,
                    sets: usize::MAX,
                },
            ],
            window,
            predicted_success: 0.5,
            sets: usize::MAX,
        };
        let line = LineSpec {
            name: "t".into(),
            headway_s: 4.0,
            belt_width_m: 0.12,
            parts: 10,
        };
        let toml = sequence_toml(&problem, &plan, 3, 1, &line);
        assert!(!toml.contains(&usize::MAX.to_string()), "{toml}");
        let comments: Vec<&str> = toml.lines().filter(|l| l.contains("after it:")).collect();
        assert_eq!(comments.len(), 2, "{toml}");
        assert!(
            comments[0].contains("after it: 2 set(s)"),
            "{}",
            comments[0]
        );
        assert!(
            comments[1].contains("after it: sets unbounded"),
            "{}",
            comments[1]
        );
        let json = serde_json::to_value(&plan).unwrap();
        assert!(
            json["sets"].is_null() && json["initial_sets"].is_null(),
            "{json}"
        );
        assert_eq!(json["steps"][0]["sets"], 2);
        assert!(json["steps"][1]["sets"].is_null(), "{json}");
    }

    /// A fence with a curved tail is written with its `tail_radius`, and the scenario parses back
    /// to a fence whose tail is that radius, placed along the belt with the tail's extent.
    #[test]
    fn a_tailed_fence_is_emitted_with_its_tail_and_parses_back() {
        let problem = Problem::new("tripoly2");
        let window = Window {
            centre_deg: 10.0,
            inside: 1,
            share: 1.0,
        };
        let tailed = FenceAction {
            angle_deg: 25.0,
            y0_m: -0.03,
            y1_m: 0.02,
            length_m: 0.05 / 25f64.to_radians().sin(),
            mu_f: 0.5,
            lo_m: -0.06,
            hi_m: -0.02,
            margin_m: 0.01,
            max_lag_m: 0.0,
            tail_radius_m: Some(0.3),
        };
        let state = State::canonical(vec![], 0);
        let step = |action| PlanStep {
            action,
            state: state.clone(),
            window,
            sets: 1,
        };
        let plan = Plan {
            initial: state.clone(),
            initial_window: window,
            initial_sets: 1,
            steps: vec![
                step(Action::Fence(tailed)),
                step(Action::Fence(FenceAction {
                    angle_deg: -25.0,
                    y0_m: 0.05,
                    y1_m: 0.0,
                    tail_radius_m: None,
                    ..tailed
                })),
            ],
            window,
            predicted_success: 1.0,
            sets: 1,
        };
        let line = LineSpec {
            name: "t".into(),
            headway_s: 6.0,
            belt_width_m: 0.16,
            parts: 10,
        };
        let toml = sequence_toml(&problem, &plan, 3, 1, &line);
        assert_eq!(toml.matches("tail_radius = 0.3").count(), 1, "{toml}");
        let scene = crate::scenario::parse(std::path::Path::new("t.toml"), &toml).unwrap();
        let fences: Vec<_> = scene
            .obstacles
            .iter()
            .filter_map(|o| match o {
                crate::scenario::Obstacle::Fence(f) => Some(f),
                _ => None,
            })
            .collect();
        assert_eq!(fences.len(), 2);
        assert_eq!(fences[0].tail_radius, Some(0.3));
        assert_eq!(fences[1].tail_radius, None);
        // The second fence starts a part diameter and 2 cm past the first one's tail.
        let radius = problem.compile().unwrap().radius;
        let gap = super::super::fences::fence_gap_m(radius);
        let want = fences[0].start.x + tailed.x_extent_m() + gap;
        assert!(
            (fences[1].start.x - want).abs() < 1e-6,
            "{} vs {want}",
            fences[1].start.x
        );
    }
}
