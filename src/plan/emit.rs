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

/// The scenario of a plan. `parts` is the feed's part count (the line check's), `command` the
/// command line that wrote it, `symmetry` the order of the part's rotational symmetry, `file` the scenario's file name, `stable_count` the part's number of stable states.
pub fn scenario_toml(
    problem: &Problem,
    plan: &Plan,
    stable_count: usize,
    symmetry: u32,
    parts: u64,
    command: &str,
    file: &str,
) -> String {
    if plan
        .steps
        .iter()
        .any(|s| matches!(s.action, Action::Fence(_)))
    {
        return fence_scenario_toml(problem, plan, stable_count, symmetry, parts, command, file);
    }
    let n = plan.steps.len();
    let sp = problem.spacing_m;
    let mut t = String::new();
    let name = format!("plan_{}", crate::cli::part_folder(&problem.part));
    t += &plan_header(
        problem,
        plan,
        ("", "sensorless pin", "pin"),
        &format!(
            "pin intervals with margin ≥ {} mm",
            problem.min_margin_m * 1e3
        ),
        command,
        file,
    );
    let length = sp * (n as f64 + 1.0);
    t += &line_sections(&name, problem, (length, "pin"), stable_count, parts, None);
    for (k, step) in plan.steps.iter().enumerate() {
        let Action::Pin(pin) = step.action else {
            continue;
        };
        t += &format!(
            "\n[[obstacles]]   # margin {:.2} mm; after it: {} set(s), best window {:.3}\nkind = \"pin\"\nname = \"pin{}\"\nx = {}\ny = {}\nradius = {}\n",
            pin.margin_m * 1e3,
            step.sets,
            step.window.share,
            k + 1,
            num(sp * (k as f64 + 1.0), 6),
            num(pin.y_m, 6),
            num(problem.pin_radius_m, 6),
        );
    }
    t += &goal_and_model(problem, plan.window.centre_deg, symmetry);
    t
}

/// The header of an emitted sensorless plan: the command that wrote it, what the plan claims (a
/// shortest plan or a best effort) over which abstraction (`rule`: how its actions are placed),
/// its prediction, the uncertainty it was planned against, and how to run it. `words`: the
/// command's flag, the planner's name and the action's name.
fn plan_header(
    problem: &Problem,
    plan: &Plan,
    (flag, planner, what): (&str, &str, &str),
    rule: &str,
    command: &str,
    file: &str,
) -> String {
    let mut t = format!(
        "# Written by `pinfeed plan{flag}` ({planner} planner, issue 14):\n#\n#   {command}\n#\n"
    );
    t += &best_effort_note(problem, plan, what);
    t += &format!(
        "# {} {what}(s), {} (BFS over {} particle(s), θ rounded to {}°,\n",
        plan.steps.len(),
        kind_of(problem, plan),
        plan.initial.total(),
        problem.theta_quantum_deg
    );
    t += &format!(
        "# y to {} mm; {rule}). Predicted success {:.4} ({} of {}\n",
        problem.y_quantum_m * 1e3,
        plan.predicted_success,
        plan.window.inside,
        plan.initial.total(),
    );
    t += &format!(
        "# particles within {}° ± {}°).",
        num(plan.window.centre_deg, 2),
        problem.tolerance_deg
    );
    if let Some((lo, hi)) = problem.mu_c_range {
        t += &format!(
            " Planned against μc ∈ [{lo}, {hi}] per part (the line uses μc = {}).",
            problem.mu_c
        );
    }
    if problem.tripod {
        t += " Planned against random tripod supports.";
    }
    t += &format!("\n#\n#   pinfeed run {file}\n\n");
    t
}

/// Does the plan reach the problem's goal (or is it the best effort of a search that found none)?
fn reaches_goal(problem: &Problem, plan: &Plan) -> bool {
    problem.fewest_sets || plan.predicted_success >= problem.target - 1e-12
}

fn kind_of(problem: &Problem, plan: &Plan) -> &'static str {
    if reaches_goal(problem, plan) {
        "a shortest plan for its action set"
    } else {
        "the shortest of those bringing the most particles into one window"
    }
}

/// The header line that marks a best-effort plan (none reaches the goal).
fn best_effort_note(problem: &Problem, plan: &Plan, what: &str) -> String {
    if reaches_goal(problem, plan) {
        return String::new();
    }
    format!(
        "# BEST EFFORT: no plan in the search reaches the goal ({} of the parts in one window); these\n# {what}s come closest.\n#\n",
        problem.target
    )
}

/// The scenario of a fence plan (the fence planner, [`super::fences`]): fences one after another
/// along the belt (the first upstream end one spacing in, then the gap of
/// [`super::fences::layout`]), each a `kind = "fence"` obstacle from its upstream end, parts every
/// [`super::fences::headway_s`] apart (a part sliding along a fence lags the belt).
#[allow(clippy::too_many_arguments)]
pub fn fence_scenario_toml(
    problem: &Problem,
    plan: &Plan,
    stable_count: usize,
    symmetry: u32,
    parts: u64,
    command: &str,
    file: &str,
) -> String {
    let fences: Vec<super::FenceAction> = plan
        .steps
        .iter()
        .filter_map(|s| match s.action {
            Action::Fence(f) => Some(f),
            Action::Pin(_) => None,
        })
        .collect();
    let radius = problem.compile().map(|c| c.radius).unwrap_or(0.0);
    let (xs, end) = super::fences::layout(&fences, radius, problem.spacing_m);
    let mut t = String::new();
    let name = format!("plan_{}_fences", crate::cli::part_folder(&problem.part));
    t += &plan_header(
        problem,
        plan,
        (" --fences", "sensorless fence", "fence"),
        "each fence's upstream end clear of every part's reach",
        command,
        file,
    );
    // Parts lag the belt along the fences: they are fed further apart.
    let headway = super::fences::headway_s(&fences, radius, BELT_SPEED);
    let length = end + problem.spacing_m;
    t += &line_sections(
        &name,
        problem,
        (length, "fence"),
        stable_count,
        parts,
        Some(headway),
    );
    for (k, (f, x)) in fences.iter().zip(&xs).enumerate() {
        let step = &plan.steps[k];
        t += &format!(
            "\n[[obstacles]]   # margin {:.2} mm; after it: {} set(s), best window {:.3}\nkind = \"fence\"\nname = \"fence{}\"\nx = {}             # m: the upstream end\ny = {}\nangle = {}          # degrees\nlength = {}\nmu_f = {}\n",
            f.margin_m * 1e3,
            step.sets,
            step.window.share,
            k + 1,
            num(*x, 6),
            num(f.y0_m, 6),
            num(f.angle_deg, 6),
            num(f.length_m, 6),
            num(f.mu_f, 6),
        );
    }
    t += &goal_and_model(problem, plan.window.centre_deg, symmetry);
    t
}

/// The `[part]`, `[feed]` and `[feed.lateral]` sections of a planned scenario.
/// The belt speed of every planned line (m/s).
const BELT_SPEED: f64 = 0.05;
/// Seconds between parts on a planned pin line.
const HEADWAY_S: f64 = 4.0;

/// The name, `[belt]` (`length` m: one spacing after the last `obstacle`), `[part]`, `[feed]` and
/// `[feed.lateral]` sections of a planned scenario; `headway` (s) replaces the default spacing of
/// parts where the obstacles make them lag.
fn line_sections(
    name: &str,
    problem: &Problem,
    (length, obstacle): (f64, &str),
    stable_count: usize,
    parts: u64,
    headway: Option<f64>,
) -> String {
    let mut t = format!("name = \"{name}\"\nseed = {}\n\n", problem.seed);
    t += &format!("[belt]\nspeed = {BELT_SPEED}        # m/s\n");
    t += &format!("width = {}\n", num(problem.belt_width_m, 6));
    t += &format!(
        "length = {}        # m: one spacing after the last {obstacle}\n\n",
        num(length, 6)
    );
    t += "[part]\n";
    if let Some(v) = problem.part.trim().strip_prefix("vertices:") {
        let pts = crate::geometry::named::parse_vertex_list(v).unwrap_or_default();
        let list: Vec<String> = pts
            .iter()
            .map(|p| format!("[{}, {}]", num(p.x, 9), num(p.y, 9)))
            .collect();
        t += &format!("vertices = [{}]\n", list.join(", "));
    } else {
        t += &format!("shape = \"{}\"\n", problem.part.trim());
    }
    t += &format!("scale = {}\n", num(problem.scale, 9));
    t += &format!("mu_c = {}\n", num(problem.mu_c, 6));
    t += &format!(
        "support = \"{}\"\n\n",
        if problem.tripod { "tripod" } else { "uniform" }
    );
    t += &match headway {
        None => format!("[feed]\nparts = {parts}\narrival = \"periodic\"\nheadway = {HEADWAY_S:.1}\n"),
        Some(h) => format!(
            "[feed]\nparts = {parts}\narrival = \"periodic\"\nheadway = {}        # s: parts lag the belt along the fences\n",
            num(h, 3)
        ),
    };
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
    t += "\n[model]\nfidelity = \"exact\"\ntol = 1e-6\n\n[output]\ndir = \"results\"\nhistogram_svg = false\nhistogram_bin = 1\n";
    t
}

/// The scenario and policy file of a contingent plan: (scenario TOML, policy TOML). `policy_file`
/// is the policy's file name as the scenario refers to it (relative to the scenario).
#[allow(clippy::too_many_arguments)]
pub fn contingent_toml(
    problem: &Problem,
    plan: &super::contingent::ContingentPlan,
    stable_count: usize,
    symmetry: u32,
    parts: u64,
    command: &str,
    file: &str,
    policy_file: &str,
) -> (String, String) {
    let sp = problem.spacing_m;
    let k = plan.k;
    let half = problem.belt_width_m / 2.0;
    let mut t = String::new();
    let name = format!("plan_{}_sensing", crate::cli::part_folder(&problem.part));
    t += &format!(
        "# Written by `pinfeed plan --sensor` (contingent planner with sensing, issue 14):\n#\n#   {command}\n#\n"
    );
    t += &format!(
        "# A force/torque sensor pin reads the stable state; {k} moving pin(s) then take, per part, the\n# lateral position the policy ({policy_file}) gives for the decision. The fewest moving pins for\n"
    );
    t += &format!(
        "# its action set (BFS per branch over {} particle(s), θ rounded to {}°, y to {} mm, margins ≥ {} mm).\n",
        plan.branches.iter().map(|b| b.total).sum::<u32>(),
        problem.theta_quantum_deg,
        problem.y_quantum_m * 1e3,
        problem.min_margin_m * 1e3
    );
    t += &format!(
        "# Predicted success {:.4} with a perfect classifier, within {}° ± {}°.\n#\n#   pinfeed run {file}\n\n",
        plan.predicted_success,
        num(plan.centre_deg, 2),
        problem.tolerance_deg
    );
    let length = sp * (k as f64 + 2.0);
    t += &line_sections(&name, problem, (length, "pin"), stable_count, parts, None);
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
        "# Policy of {file} (written by `pinfeed plan --sensor`): per decision of the sensor pin\n# `probe`, the lateral position of each moving pin.\n\npart = \"{}\"\n",
        problem.part.trim()
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
