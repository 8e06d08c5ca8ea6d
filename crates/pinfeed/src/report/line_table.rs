//! The terminal summary of a line run: outcomes, success rate with its 95% interval, throughput,
//! latency, contacts and per-obstacle statistics (definitions in [`crate::engine::metrics`]).

use crate::engine::{PartOutcome, Summary};
use std::fmt::Write;

fn opt(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) => format!("{x:.digits$}"),
        None => "n/a".into(),
    }
}

/// What a `busy` above 100% means, printed under the obstacles when one is.
pub const BUSY_ABOVE_100: &str = "busy: an obstacle's push time per second of the run, summed over the parts it pushes; above 100% it pushes several parts at once (parts sliding along a fence together)";

/// A readable multi-line summary.
pub fn table(s: &Summary) -> String {
    let mut o = String::new();
    let pct = |k: u64| {
        if s.parts_in > 0 {
            100.0 * k as f64 / s.parts_in as f64
        } else {
            0.0
        }
    };
    let _ = writeln!(
        o,
        "scenario {}  seed {}  fidelity {}",
        s.scenario, s.seed, s.fidelity
    );
    match &s.closed_loop {
        None => {
            let _ = writeln!(o, "parts in                  {}", s.parts_in);
        }
        Some(l) => {
            let _ = writeln!(
                o,
                "parts in                  {}  (passes onto the belt; {} taken off by the gate)",
                s.parts_in, l.gate_counts.acted
            );
        }
    }
    for outcome in PartOutcome::ALL {
        let k = s.outcomes.get(outcome);
        let _ = writeln!(o, "  {:<22}  {:>8}  {:5.1}%", outcome.name(), k, pct(k));
    }
    let _ = writeln!(
        o,
        "success rate              {:.4}  (95% CI {:.4}–{:.4})",
        s.success_rate, s.success_ci95[0], s.success_ci95[1]
    );
    let _ = writeln!(
        o,
        "throughput in             {} parts/min",
        opt(s.throughput_in_per_min, 2)
    );
    let window = match s.steady_window_s {
        Some([a, b]) => format!("  (steady window {a:.1}–{b:.1} s)"),
        None => String::new(),
    };
    let _ = writeln!(
        o,
        "throughput out / ok       {} / {} parts/min{window}",
        opt(s.throughput_out_per_min, 2),
        opt(s.throughput_ok_per_min, 2)
    );
    match &s.latency_s {
        Some(l) => {
            let _ = writeln!(
                o,
                "latency p50/p90/p99/max   {:.2} / {:.2} / {:.2} / {:.2} s",
                l.p50, l.p90, l.p99, l.max
            );
        }
        None => {
            let _ = writeln!(o, "latency                   n/a (no part exited)");
        }
    }
    let _ = writeln!(o, "contacts per part         {:.3}", s.contacts_per_part);
    if !s.obstacles.is_empty() {
        let _ = writeln!(o, "obstacles                 contacts    busy");
        for ob in &s.obstacles {
            let _ = writeln!(
                o,
                "  {:<22}  {:>8}  {:5.1}%",
                ob.name,
                ob.contacts,
                100.0 * ob.busy_fraction
            );
        }
        if s.obstacles.iter().any(|ob| ob.busy_fraction > 1.0) {
            let _ = writeln!(o, "  {BUSY_ABOVE_100}");
        }
    }
    for (label, map) in [
        ("multi_contact causes", &s.causes.multi_contact),
        ("jam causes", &s.causes.jam),
        ("solver causes", &s.causes.solver),
    ] {
        if !map.is_empty() {
            let list: Vec<String> = map.iter().map(|(k, v)| format!("{k} {v}")).collect();
            let _ = writeln!(o, "{label:<26}{}", list.join(", "));
        }
    }
    for sensor in &s.sensors {
        sensor_table(&mut o, sensor);
    }
    if let Some(c) = &s.controller {
        controller_table(&mut o, c);
    }
    if let Some(l) = &s.closed_loop {
        loop_table(&mut o, l);
    }
    // The most populated orientation bins.
    let h = &s.orientation_histogram;
    let mut bins: Vec<(usize, u64)> = h
        .counts
        .iter()
        .copied()
        .enumerate()
        .filter(|&(_, c)| c > 0)
        .collect();
    bins.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    if !bins.is_empty() {
        let top: Vec<String> = bins
            .iter()
            .take(4)
            .map(|&(i, c)| {
                format!(
                    "[{:.0}°, {:.0}°) {c}",
                    i as f64 * h.bin_deg,
                    (i + 1) as f64 * h.bin_deg
                )
            })
            .collect();
        let _ = writeln!(o, "final orientations        {}", top.join(", "));
    }
    let _ = writeln!(
        o,
        "simulated time            {:.1} s ({} events, {} contact solves)",
        s.simulated_time_s, s.work.events, s.work.contact_solves
    );
    map_tier_line(&mut o, &s.work.map_tier);
    o
}

/// The closed loop's block: where the new parts ended, purity, passes, the gate, the return path
/// and the merge, and the delivered rates.
pub fn loop_table(o: &mut String, l: &crate::engine::closed_loop::LoopSummary) {
    let f = &l.fates;
    let _ = writeln!(
        o,
        "closed loop               gate {}: {} new parts, {} passes; yield per pass {:.4}",
        l.gate, l.new_parts, l.passes, l.yield_per_pass
    );
    let _ = writeln!(
        o,
        "  delivered               {} (in the goal {}, not {}): purity {:.4} (95% CI {:.4}–{:.4})",
        f.delivered(),
        f.delivered_ok,
        f.delivered_wrong,
        l.purity,
        l.purity_ci95[0],
        l.purity_ci95[1]
    );
    let counts: Vec<String> = (l.passes_per_delivered.counts.iter().enumerate())
        .filter(|(_, &n)| n > 0)
        .map(|(k, n)| format!("{}: {n}", k + 1))
        .collect();
    let _ = writeln!(
        o,
        "  passes per delivered    mean {:.3}  ({})",
        l.passes_per_delivered.mean,
        if counts.is_empty() {
            "none".to_string()
        } else {
            counts.join(", ")
        }
    );
    let _ = writeln!(
        o,
        "  lost / rejected / scrapped  {} / {} / {} (last pass {}, buffer full {})",
        f.lost,
        f.rejected,
        f.scrapped_max_passes + f.scrapped_full,
        f.scrapped_max_passes,
        f.scrapped_full
    );
    let g = &l.gate_counts;
    let _ = writeln!(
        o,
        "  gate                    acted {}, accepted {}, busy {}, late {}, out of reach {}, unread {}",
        g.acted, g.accepted, g.busy, g.late, g.out_of_reach, g.unread
    );
    let _ = writeln!(
        o,
        "  return path             recirculated {}, blocked {}; load mean {:.2} max {}; buffer mean {:.2} max {}",
        l.recirculated, l.blocked, l.return_load.mean, l.return_load.max, l.buffer.mean, l.buffer.max
    );
    let _ = writeln!(
        o,
        "  merge wait              new {:.3} s, returning {:.3} s",
        l.merge_wait_s.new, l.merge_wait_s.returning
    );
    let oa = &l.output_analysis;
    let steady = |m: &Option<crate::engine::closed_loop::SteadyMean>, d: usize| match m {
        Some(m) => format!("{:.d$} ({:.d$}–{:.d$})", m.mean, m.ci95[0], m.ci95[1]),
        None => "n/a".into(),
    };
    let _ = writeln!(
        o,
        "  steady state            warm-up {:.1} s (MSER-5, {}); delivered {} / in goal {} parts/min; time in system {} s (95% batch means)",
        oa.warm_up_s,
        oa.warm_up_verdict.replace('_', " "),
        steady(&oa.delivered_per_min, 2),
        steady(&oa.oriented_per_min, 2),
        steady(&oa.system_time_s, 1)
    );
    let window = match l.steady_window_s {
        Some([a, b]) => format!("  (window {a:.1}–{b:.1} s)"),
        None => String::new(),
    };
    let _ = writeln!(
        o,
        "  delivered / in goal     {} / {} parts/min{window}",
        opt(l.delivered_per_min, 2),
        opt(l.oriented_per_min, 2)
    );
}

/// With the map tier: how many pushes the map served and why the others were computed exactly.
fn map_tier_line(o: &mut String, m: &crate::engine::metrics::MapTierCounters) {
    if m.is_unused() {
        return;
    }
    let total = (m.served + m.fallbacks()).max(1) as f64;
    let _ = writeln!(
        o,
        "map tier                  {} served ({:.1}%), {} exact ({})",
        m.served,
        100.0 * m.served as f64 / total,
        m.fallbacks(),
        m.fallback_reasons()
    );
}

/// The controller's block: decisions and how their parts ended, misclassifications and the
/// failures they caused, and per dynamic pin its commands, moves, late ones, travel and use.
fn controller_table(o: &mut String, c: &crate::engine::controller::ControllerSummary) {
    match &c.online {
        None => {
            let _ = writeln!(
                o,
                "controller                rules from {}, latency {} s, late commands: {}",
                c.rules_from,
                c.latency_s,
                c.on_late.name()
            );
        }
        Some(on) => online_block(o, c, on),
    }
    for (decision, d) in &c.decisions {
        let _ = writeln!(
            o,
            "  {decision:<24}{:>6} parts, {:>6} ok ({:.1}%), {} wrong decisions ({} failed)",
            d.parts,
            d.success,
            100.0 * d.success as f64 / d.parts.max(1) as f64,
            d.wrong,
            d.wrong_failed
        );
    }
    let _ = writeln!(
        o,
        "  misclassified             {} parts, {} of them failed; late actuations {}",
        c.misclassified, c.misclassified_failed, c.late_actuations
    );
    for a in &c.actuators {
        let _ = writeln!(
            o,
            "  pin {:<22}{} commands, {} moves, {} late, {} dropped, travel {:.3} m, busy {:.1} s ({:.1}%)",
            a.name,
            a.commands,
            a.moves,
            a.late,
            a.dropped,
            a.travel_m,
            a.busy_s,
            100.0 * a.utilisation
        );
    }
}

/// The online controller: its model, the belief's entropy, the prediction beside what the line
/// did with the same parts, and the calibration bins.
fn online_block(
    o: &mut String,
    c: &crate::engine::controller::ControllerSummary,
    on: &crate::engine::controller::OnlineSummary,
) {
    let _ = writeln!(
        o,
        "controller                online: {} hypotheses, {} joint commands ({} line runs, {} contact-model evaluations to build), latency {} s, late commands: {}",
        on.hypotheses, on.actions, on.model_runs, on.model_evaluations, c.latency_s, c.on_late.name()
    );
    let temper: Vec<String> = on
        .temper
        .iter()
        .map(|(k, &v)| {
            let sigma = on.classifier_power.get(k).copied().unwrap_or(0.0);
            let power = |p: f64| {
                if p > 0.0 {
                    format!("{p:.0e}")
                } else {
                    "off".to_string()
                }
            };
            format!("{k} filter {}, classifier {}", power(v), power(sigma))
        })
        .collect();
    let _ = writeln!(
        o,
        "  belief                  {} decisions; entropy {:.2} → {:.2} bits; true state most probable in {} of {}; likelihood power {}; {} passes without contact; {} observations unexplained",
        on.decisions,
        on.entropy_prior_bits,
        on.entropy_posterior_bits,
        on.state_correct,
        on.state_known,
        temper.join(", "),
        on.no_contact_passes,
        on.inconsistent
    );
    let _ = writeln!(
        o,
        "  predicted vs line       predicted {:.3}, the line {:.3} on the same parts",
        on.predicted_mean, on.observed
    );
    for b in &on.bounds {
        let _ = writeln!(
            o,
            "  model, {:<17}P(goal) {:.3} with no information, {:.3} with a belief certain of the hypothesis",
            format!("{} support", b.support),
            b.no_information,
            b.certain_hypothesis
        );
    }
    for b in &on.calibration {
        let _ = writeln!(
            o,
            "    P in [{:.1}, {:.1})      {:>6} parts: predicted {:.3}, observed {:.3}",
            b.lo, b.hi, b.parts, b.predicted_mean, b.observed
        );
    }
}

/// A sensor pin's block: readings, accuracy, untouched parts and the confusion matrix (rows: the
/// true hypothesis, columns: the decision).
fn sensor_table(o: &mut String, s: &crate::engine::sensing::SensorStats) {
    let c = &s.confusion;
    let _ = writeln!(
        o,
        "sensor {:<19}{} readings ({}), {} correct ({:.1}%), {} parts passed untouched",
        s.name,
        s.readings,
        s.classifier,
        c.correct(),
        100.0 * c.accuracy(),
        s.untouched
    );
    if s.unmatched > 0 {
        let _ = writeln!(o, "  {} readings matched no hypothesis", s.unmatched);
    }
    let width = c.labels.iter().map(|l| l.len()).max().unwrap_or(0).max(7);
    let mut head = format!("  {:>width$} →", "true");
    for l in c.labels.iter().map(String::as_str).chain(["unknown"]) {
        head += &format!(" {l:>width$}");
    }
    let _ = writeln!(o, "{head}");
    for (label, row) in c.labels.iter().zip(&c.counts) {
        let mut line = format!("  {label:>width$}  ");
        for n in row {
            line += &format!(" {n:>width$}");
        }
        let _ = writeln!(o, "{line}");
    }
}

/// What the exact model's slide tables built during a run, as a line of the run table (they are
/// built on first use and serve every later contact; the line's own work counters leave them
/// out): empty for a model without tables (tip or ellipsoid fidelity, a part with its own
/// tripod). A scene's model has no stick tables (a map tier's build makes them).
pub fn tables_line(model: &crate::mechanics::PartModel) -> String {
    match model.slide_table_stats() {
        Some(slide) if slide.tables > 0 => format!(
            "exact model's tables      {} slide tables ({} nodes); {} evaluations to build\n",
            slide.tables, slide.nodes, slide.evaluations
        ),
        _ => String::new(),
    }
}
