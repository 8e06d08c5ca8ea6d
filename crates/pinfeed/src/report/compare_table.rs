//! The table of `pinfeed compare`: one row per line design run on the same part stream (definitions
//! in [`crate::study::compare`]), as aligned plain text for the terminal or as Markdown.

use crate::engine::PartOutcome;
use crate::scenario::{FeedOverrides, Lateral, Orientation, Scene};
use crate::study::compare::{ComparisonRow, GoalWindow};

const HEADER: [&str; 12] = [
    "scenario",
    "obstacles",
    "parts",
    "headway s",
    "goal",
    "success (95% CI)",
    "footprint m",
    "across / belt m",
    "oriented/min",
    "latency mean / p99 s",
    "contacts/part",
    "other outcomes",
];

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "n/a".into(), |x| format!("{x:.digits$}"))
}

/// A goal as the table shows it: `name 6.6° ± 3°` per set (orientations joined by `/`), `any exit`
/// without sets.
pub fn goal_text(goal: &[GoalWindow]) -> String {
    if goal.is_empty() {
        return "any exit".into();
    }
    let sets: Vec<String> = goal
        .iter()
        .map(|g| {
            let o: Vec<String> = g.orientations_deg.iter().map(|d| format!("{d}°")).collect();
            format!("{} {} ± {}°", g.name, o.join("/"), g.tolerance_deg)
        })
        .collect();
    sets.join("; ")
}

/// Every outcome class besides success that happened, with its count (`2294 collision, 3 jam`),
/// `none` when every part succeeded.
pub fn other_outcomes(r: &ComparisonRow) -> String {
    let named: Vec<String> = PartOutcome::ALL
        .iter()
        .filter(|&&o| o != PartOutcome::Success && r.outcomes.get(o) > 0)
        .map(|&o| format!("{} {}", r.outcomes.get(o), o.name()))
        .collect();
    if named.is_empty() {
        "none".into()
    } else {
        named.join(", ")
    }
}

fn cells(r: &ComparisonRow) -> [String; 12] {
    [
        r.scenario.clone(),
        r.obstacle_kinds.to_string(),
        r.parts_in.to_string(),
        r.headway_s.to_string(),
        goal_text(&r.goal),
        format!(
            "{:.4} ({:.4}–{:.4})",
            r.success_rate, r.success_ci95[0], r.success_ci95[1]
        ),
        opt(r.footprint_m, 3),
        format!("{} / {}", opt(r.across_m, 3), r.belt_width_m),
        opt(r.throughput_ok_per_min, 2),
        format!("{} / {}", opt(r.latency_mean_s, 2), opt(r.latency_p99_s, 2)),
        format!("{:.3}", r.contacts_per_part),
        other_outcomes(r),
    ]
}

/// Aligned plain text.
pub fn text(rows: &[ComparisonRow]) -> String {
    let body: Vec<[String; 12]> = rows.iter().map(cells).collect();
    super::aligned::aligned_lines(&HEADER, &body).concat()
}

/// A line per closed loop among the rows (empty without one): its purity, passes and scrap, and
/// what its success column counts.
pub fn loop_lines(rows: &[ComparisonRow]) -> String {
    let mut s = String::new();
    for r in rows {
        if let Some(l) = &r.closed_loop {
            s += &format!(
                "closed loop {}: purity {:.4} ({:.4}–{:.4}), {:.3} passes per delivered part, {} scrapped, {} delivered/min; its success is the parts delivered in the goal per new part\n",
                r.scenario,
                l.purity,
                l.purity_ci95[0],
                l.purity_ci95[1],
                l.passes_per_delivered,
                l.scrapped,
                opt(l.delivered_per_min, 2)
            );
        }
    }
    s
}

/// A Markdown table.
pub fn markdown(rows: &[ComparisonRow]) -> String {
    let mut s = format!(
        "| {} |\n|{}\n",
        HEADER.join(" | "),
        "---|".repeat(HEADER.len())
    );
    for r in rows {
        s += &format!("| {} |\n", cells(r).join(" | "));
    }
    s
}

/// What the designs ran on: one line when their feeds (and seeds) agree, otherwise a line per
/// design; what the user imposed is marked `(--headway)`, `(--seed)`, ….
pub fn feed_lines(files: &[String], scenes: &[Scene], overrides: &FeedOverrides) -> String {
    let lines: Vec<String> = scenes.iter().map(|s| feed_text(s, overrides)).collect();
    if lines.windows(2).all(|w| w[0] == w[1]) {
        format!("every design's part stream: {}", lines[0])
    } else {
        let mut s = "each design runs its own feed (as its file says):".to_string();
        for (file, line) in files.iter().zip(&lines) {
            s += &format!("\n  {file}: {line}");
        }
        s
    }
}

fn feed_text(scene: &Scene, overrides: &FeedOverrides) -> String {
    let mark = |imposed: bool, flag: &str| {
        if imposed {
            format!(" ({flag})")
        } else {
            String::new()
        }
    };
    let feed = &scene.feed;
    let orientation = match &feed.orientation {
        Orientation::Uniform => "uniform on [0°, 360°)".to_string(),
        Orientation::Stable {
            thetas_rad: thetas,
            weights,
            jitter_rad: jitter,
        } => {
            let states: Vec<String> = thetas
                .iter()
                .zip(weights)
                .map(|(t, w)| format!("{:.3}° ×{w:.3}", t.to_degrees()))
                .collect();
            format!(
                "stable states {} ± {:.3}° (sd)",
                states.join(", "),
                jitter.to_degrees()
            )
        }
    };
    let lateral = match feed.lateral {
        Lateral::Fixed(y) => format!("at y = {y} m"),
        Lateral::Uniform { min, max } => format!("y uniform on [{min}, {max}] m"),
        Lateral::Normal { mean, sd, .. } => format!("y normal, mean {mean} m, sd {sd} m"),
    };
    let arrival = match feed.arrival {
        crate::scenario::Arrival::Periodic { headway } => format!("one every {headway} s"),
        crate::scenario::Arrival::Poisson { headway } => {
            format!("Poisson, mean headway {headway} s")
        }
    };
    format!(
        "seed {}{}, {} parts{}, {arrival}{}, orientation {orientation}{}, {lateral}",
        scene.seed,
        mark(overrides.seed.is_some(), "--seed"),
        feed.parts,
        mark(overrides.parts.is_some(), "--parts"),
        mark(overrides.headway.is_some(), "--headway"),
        mark(overrides.uniform_orientation, "--uniform-orientation"),
    )
}
