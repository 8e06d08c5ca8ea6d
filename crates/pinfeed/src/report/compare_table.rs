//! The table of `pinfeed compare`: one row per line design run on the same part stream (definitions
//! in [`crate::study::compare`]), as aligned plain text for the terminal or as Markdown.

use crate::scenario::{FeedSource, Lateral, Orientation};
use crate::study::compare::{ComparisonRow, GoalWindow};

const HEADER: [&str; 11] = [
    "scenario",
    "obstacles",
    "parts",
    "goal",
    "success (95% CI)",
    "footprint m",
    "across / belt m",
    "oriented/min",
    "latency mean / p99 s",
    "contacts/part",
    "jams",
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

fn cells(r: &ComparisonRow) -> [String; 11] {
    let obstacles = match (r.pins, r.fences) {
        (0, 0) => "none".to_string(),
        (p, 0) => format!("{p} pin{}", if p == 1 { "" } else { "s" }),
        (0, f) => format!("{f} fence{}", if f == 1 { "" } else { "s" }),
        (p, f) => format!("{p} pins + {f} fences"),
    };
    [
        r.scenario.clone(),
        obstacles,
        r.parts_in.to_string(),
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
        r.jams.to_string(),
    ]
}

/// Aligned plain text.
pub fn text(rows: &[ComparisonRow]) -> String {
    let body: Vec<[String; 11]> = rows.iter().map(cells).collect();
    super::aligned::aligned_lines(&HEADER, &body).concat()
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

/// One line saying which part stream every design ran on.
pub fn feed_line(file: &str, source: &FeedSource, parts: u64) -> String {
    let feed = &source.feed;
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
        "part stream of {file}: seed {}, {parts} parts, {arrival}, orientation {orientation}, {lateral}",
        source.seed
    )
}
