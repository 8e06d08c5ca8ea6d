//! The study's report: per sweep point the outcome counts, the success rate and every class's share
//! with its 95% Wilson score interval, contacts per part and latency quantiles; as JSON, as a
//! Markdown table (the terminal output) and as a Markdown document headed by the command that
//! regenerates it. The report is a pure function of the [`StudyHeader`] and the integer tallies —
//! no wall-clock time, no floating sums over samples — so one run and merged shards give the same
//! bytes.

use super::tally::PointTally;
use super::Study;
use crate::engine::{OutcomeCounts, PartOutcome};
use crate::mechanics::limits::short;
use crate::statistics::wilson_interval;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Everything about a study a report needs besides the counts; stored in every shard.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyHeader {
    /// The study's name (its report folder).
    pub study: String,
    /// The study file, as given.
    pub study_file: String,
    /// The scenario file, resolved against the study file's folder.
    pub scenario_file: String,
    /// The scenario's name.
    pub scenario: String,
    /// The contact model the samples run (`exact`, `map`, … with the reason when the map tier is
    /// off).
    pub fidelity: String,
    /// Content hash of the study (hex).
    pub study_hash: String,
    /// Content hash of the scenario (hex).
    pub scenario_hash: String,
    /// Version of pinfeed that ran the study.
    pub pinfeed_version: String,
    /// Seed of the study's random streams.
    pub seed: u64,
    /// Samples per sweep point.
    pub samples_per_point: u64,
    /// The swept parameters and their values.
    pub sweep: Vec<SweepOut>,
    /// Parameter values of each point (one per swept parameter).
    pub points: Vec<Vec<f64>>,
    /// The uncertain parameters as declared (before sweeps).
    pub uncertain: Vec<String>,
    /// The command that regenerates the report.
    pub command: String,
    /// The line's sensor pins, `name (classifier, kind)`; absent without sensors (the report is
    /// then what it was before sensors existed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<String>,
}

/// The model the samples run: the scene's fidelity, or the map tier — unless a parameter gives
/// samples different maps at some sweep point, in which case the samples run the exact model and
/// the report says why.
fn fidelity(study: &Study) -> String {
    if study.scene.map_tier.is_none() {
        return study.scene.contact.fidelity.name().to_string();
    }
    let varying: Vec<&str> = study
        .points
        .iter()
        .filter_map(|p| p.varies_map_inputs())
        .collect();
    let Some(why) = varying.first() else {
        return "map".to_string();
    };
    let reason =
        format!("`{why}` varies per sample, and a map is per part, support, pin radius and μc");
    if varying.len() == study.points.len() {
        format!("exact (map tier off: {reason})")
    } else {
        format!("map, exact at the sweep points where {reason}")
    }
}

/// A swept parameter in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepOut {
    /// `NAME` or `NAME.FIELD` of the swept parameter.
    pub parameter: String,
    /// Its values, in order.
    pub values: Vec<f64>,
}

impl StudyHeader {
    /// The header of a loaded study.
    pub fn of(study: &Study) -> StudyHeader {
        let file = study.file.display().to_string();
        StudyHeader {
            study: study.name.clone(),
            study_file: file.clone(),
            scenario_file: study.scenario_file.display().to_string(),
            scenario: study.scene.name.clone(),
            fidelity: fidelity(study),
            study_hash: super::hash::hex(study.study_hash),
            scenario_hash: super::hash::hex(study.scenario_hash),
            pinfeed_version: env!("CARGO_PKG_VERSION").to_string(),
            seed: study.seed,
            samples_per_point: study.samples,
            sweep: study
                .axes
                .iter()
                .map(|a| SweepOut {
                    parameter: a.parameter.clone(),
                    values: a.values.clone(),
                })
                .collect(),
            points: study.point_values.clone(),
            uncertain: study.declared.describe(),
            command: format!("pinfeed mc {file} --samples {}", study.samples),
            sensors: study
                .scene
                .obstacles
                .iter()
                .filter_map(|o| match o {
                    crate::scenario::Obstacle::Pin(p) => p.sensor.as_ref().map(|s| {
                        format!(
                            "{} ({}, {})",
                            p.name,
                            s.classifier_name,
                            s.settings.kind.name()
                        )
                    }),
                    crate::scenario::Obstacle::Fence(_) => None,
                })
                .collect(),
        }
    }

    /// Total samples of the study.
    pub fn total_samples(&self) -> u64 {
        self.points.len() as u64 * self.samples_per_point
    }
}

/// A share with its 95% Wilson interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Share {
    /// Samples of this class.
    pub count: u64,
    /// `count` / samples, in [0, 1].
    pub rate: f64,
    /// 95% Wilson interval of the rate, [low, high].
    pub ci95: [f64; 2],
}

/// Latency quantiles (s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Latency {
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Largest latency.
    pub max: f64,
}

/// What the sensor pins told, over every reading of a sweep point (all sensor pins together).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SensorShare {
    /// Passes read by sensor pins.
    pub readings: u64,
    /// Readings decided correctly (against the truth the simulator knows).
    pub correct: u64,
    /// correct / readings (0 without readings), with its 95% Wilson interval.
    pub accuracy: f64,
    /// 95% Wilson interval of the accuracy, [low, high].
    pub ci95: [f64; 2],
}

/// One sweep point of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointReport {
    /// Swept parameter → value.
    pub values: BTreeMap<String, f64>,
    /// Samples drawn at this point.
    pub samples: u64,
    /// Count per outcome class.
    pub outcomes: OutcomeCounts,
    /// Share of samples that ended in success, in [0, 1].
    pub success_rate: f64,
    /// 95% Wilson interval of the success rate, [low, high].
    pub success_ci95: [f64; 2],
    /// Every class's share with its interval.
    pub shares: BTreeMap<String, Share>,
    /// Mean pin encounters per sample.
    pub contacts_per_part: f64,
    /// Of the parts that reached the end of the belt.
    pub latency_s: Option<Latency>,
    /// Perturbed polygons redrawn because they were invalid.
    pub shape_redraws: u64,
    /// Other values redrawn because they left their domain.
    pub other_redraws: u64,
    /// Sensor accuracy; only when the line has sensor pins.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor: Option<SensorShare>,
    /// What an online controller decided and predicted; only when the line has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub online: Option<super::online::OnlineShare>,
    /// How the point's sequential run stopped; only under `--precision`
    /// ([`super::sequential`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequential: Option<super::sequential::Sequential>,
    /// A closed loop's purity and passes; only when the line has a reject gate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<LoopShare>,
}

/// What a closed loop did with a point's samples (one part each, sent round until delivered or
/// taken off for good).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopShare {
    /// Parts delivered in the goal / parts delivered (success / (success + wrong orientation)).
    pub purity: f64,
    /// Its 95% Wilson interval.
    pub purity_ci95: [f64; 2],
    /// Passes per part, over the samples.
    pub passes_per_part: f64,
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct McReport {
    /// [`crate::SCHEMA_VERSION`] (the header carries `pinfeed_version`).
    pub schema_version: u32,
    /// The study's description, flattened into the report.
    #[serde(flatten)]
    pub header: StudyHeader,
    /// What one sample is.
    pub sample: String,
    /// Samples over every sweep point.
    pub total_samples: u64,
    /// One entry per sweep point, in point order.
    pub results: Vec<PointReport>,
}

/// What a sample is, in one sentence (docs/physics.md#monte-carlo and the `sample` module docs).
pub const SAMPLE_MEANING: &str =
    "one part through a freshly perturbed copy of the line (independent samples; no part-part collisions)";

fn point_report(header: &StudyHeader, j: usize, t: &PointTally) -> PointReport {
    let n = t.samples;
    let mut shares = BTreeMap::new();
    for c in PartOutcome::EVERY {
        let k = t.outcomes.get(c);
        // `rejected` only on a closed loop (whose samples count passes).
        if c == PartOutcome::Rejected && t.passes == 0 {
            continue;
        }
        shares.insert(
            c.name().to_string(),
            Share {
                count: k,
                rate: if n > 0 { k as f64 / n as f64 } else { 0.0 },
                ci95: wilson_interval(k, n),
            },
        );
    }
    let h = &t.latency_us;
    let latency = (!h.is_empty()).then(|| {
        let max = h.max() as f64 * 1e-6;
        let [p50, p90, p99] = crate::statistics::latency_percentiles(h, h.min() as f64 * 1e-6, max);
        Latency { p50, p90, p99, max }
    });
    let success = shares["success"];
    PointReport {
        values: header
            .sweep
            .iter()
            .zip(&header.points[j])
            .map(|(a, &v)| (a.parameter.clone(), v))
            .collect(),
        samples: n,
        outcomes: t.outcomes,
        success_rate: success.rate,
        success_ci95: success.ci95,
        shares,
        contacts_per_part: if n > 0 {
            t.contacts as f64 / n as f64
        } else {
            0.0
        },
        latency_s: latency,
        shape_redraws: t.shape_redraws,
        other_redraws: t.other_redraws,
        sensor: (!header.sensors.is_empty()).then(|| SensorShare {
            readings: t.sensor_readings,
            correct: t.sensor_correct,
            accuracy: if t.sensor_readings > 0 {
                t.sensor_correct as f64 / t.sensor_readings as f64
            } else {
                0.0
            },
            ci95: wilson_interval(t.sensor_correct, t.sensor_readings),
        }),
        online: t.online.report(),
        sequential: None,
        closed_loop: (t.passes > 0).then(|| {
            let (ok, wrong) = (t.outcomes.success, t.outcomes.wrong_orientation);
            LoopShare {
                purity: ok as f64 / (ok + wrong).max(1) as f64,
                purity_ci95: wilson_interval(ok, ok + wrong),
                passes_per_part: t.passes as f64 / n.max(1) as f64,
            }
        }),
    }
}

/// Build the report from the header and the tally of every point (index order).
pub fn build(header: &StudyHeader, tallies: &[PointTally]) -> McReport {
    McReport {
        schema_version: crate::SCHEMA_VERSION,
        header: header.clone(),
        sample: SAMPLE_MEANING.to_string(),
        total_samples: tallies.iter().map(|t| t.samples).sum(),
        results: tallies
            .iter()
            .enumerate()
            .map(|(j, t)| point_report(header, j, t))
            .collect(),
    }
}

/// The report of a sequential run (`--precision`): each point's result with how it stopped
/// (`stops`, in point order).
pub fn with_sequential(mut r: McReport, stops: &[super::sequential::Sequential]) -> McReport {
    for (p, s) in r.results.iter_mut().zip(stops) {
        p.sequential = Some(*s);
    }
    r
}

/// The header of a sequential run: its regenerating command asks for the same `precision`.
pub fn with_precision(mut header: StudyHeader, precision: f64) -> StudyHeader {
    header
        .command
        .push_str(&format!(" --precision {precision}"));
    header
}

/// The report as pretty JSON with a final newline.
pub fn json(r: &McReport) -> String {
    serde_json::to_string_pretty(r).expect("a report serialises") + "\n"
}

fn pct(s: &Share) -> String {
    pct_in(s.rate, s.ci95, 1)
}

/// A rate and its interval in per cent with `d` decimals: `97.5% [96.1, 98.4]`.
fn pct_in(rate: f64, ci: [f64; 2], d: usize) -> String {
    format!(
        "{:.d$}% [{:.d$}, {:.d$}]",
        100.0 * rate,
        100.0 * ci[0],
        100.0 * ci[1]
    )
}

/// The per-point table (Markdown; also what the terminal shows).
pub fn table(r: &McReport) -> String {
    // Classes shown: success always, the others where any point has one.
    let shown: Vec<PartOutcome> = PartOutcome::EVERY
        .into_iter()
        .filter(|&c| c == PartOutcome::Success || r.results.iter().any(|p| p.outcomes.get(c) > 0))
        .collect();
    let mut head: Vec<String> = r.header.sweep.iter().map(|a| a.parameter.clone()).collect();
    head.push("samples".into());
    for c in &shown {
        head.push(format!("{} % [95% CI]", c.name()));
    }
    head.extend(
        [
            "contacts/part",
            "latency p50 s",
            "p99 s",
            "redrawn shapes",
            "other redraws",
        ]
        .map(String::from),
    );
    let sensing = !r.header.sensors.is_empty();
    if sensing {
        head.push("sensor readings".into());
        head.push("sensor accuracy % [95% CI]".into());
    }
    let sequential = r.results.iter().any(|p| p.sequential.is_some());
    if sequential {
        head.push("success % [95% CS]".into());
        head.push("stopped on".into());
    }
    let looped = r.results.iter().any(|p| p.closed_loop.is_some());
    if looped {
        head.push("purity % [95% CI]".into());
        head.push("passes/part".into());
    }
    let mut s = format!("| {} |\n|{}\n", head.join(" | "), "---|".repeat(head.len()));
    for p in &r.results {
        let mut row: Vec<String> = r
            .header
            .sweep
            .iter()
            .map(|a| short(p.values[&a.parameter]))
            .collect();
        row.push(p.samples.to_string());
        for c in &shown {
            row.push(pct(&p.shares[c.name()]));
        }
        row.push(format!("{:.2}", p.contacts_per_part));
        match p.latency_s {
            Some(l) => {
                row.push(format!("{:.2}", l.p50));
                row.push(format!("{:.2}", l.p99));
            }
            None => row.extend(["–".to_string(), "–".to_string()]),
        }
        row.push(p.shape_redraws.to_string());
        row.push(p.other_redraws.to_string());
        if let Some(sn) = p.sensor.filter(|_| sensing) {
            row.push(sn.readings.to_string());
            row.push(if sn.readings > 0 {
                pct_in(sn.accuracy, sn.ci95, 1)
            } else {
                "–".to_string()
            });
        }
        if let Some(q) = p.sequential.filter(|_| sequential) {
            row.push(pct_in(p.success_rate, q.confidence_sequence, 1));
            row.push(q.stopped.name().to_string());
        }
        if let Some(l) = p.closed_loop.filter(|_| looped) {
            row.push(pct_in(l.purity, l.purity_ci95, 2));
            row.push(format!("{:.3}", l.passes_per_part));
        }
        s.push_str(&format!("| {} |\n", row.join(" | ")));
    }
    s
}

/// The Markdown document: the regenerating command, what was studied, the figure and the table.
pub fn markdown(r: &McReport, figure: &str) -> String {
    let h = &r.header;
    let mut s = format!(
        "# Monte Carlo study: {}\n\nRegenerate (writes this file, report.json and {figure}):\n\n```\n{}\n```\n\n",
        h.study, h.command
    );
    s.push_str(&format!(
        "Scenario `{}` (`{}`, {} model), seed {}, {} samples per sweep point, {} point{}, {} samples in all. \
         A sample is {}. Intervals are 95% Wilson score intervals. Study hash {} (pinfeed {}).\n\n",
        h.scenario_file,
        h.scenario,
        h.fidelity,
        h.seed,
        h.samples_per_point,
        h.points.len(),
        if h.points.len() == 1 { "" } else { "s" },
        r.total_samples,
        r.sample,
        h.study_hash,
        h.pinfeed_version
    ));
    if let Some(q) = r.results.iter().find_map(|p| p.sequential) {
        s.push_str(&format!(
            "Sampling was sequential (`--precision {}`): each point ran blocks of {} samples until the \
             half-width of the 95% confidence sequence of its success rate (CS; Robbins' beta-binomial \
             mixture, valid however the stop is chosen) was at most {}, or its {} samples were spent \
             (`stopped on`: precision or cap).\n\n",
            q.precision,
            q.block,
            q.precision,
            h.samples_per_point
        ));
    }
    s.push_str("Uncertain parameters:\n\n");
    for u in &h.uncertain {
        s.push_str(&format!("- {u}\n"));
    }
    for a in &h.sweep {
        s.push_str(&format!(
            "- swept: `{}` over {}\n",
            a.parameter,
            a.values
                .iter()
                .map(|&v| short(v))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    if !h.sensors.is_empty() {
        s.push_str(&format!(
            "\nSensor pins: {}. Sensor accuracy is the share of their readings decided correctly \
             (against the truth the simulator knows), all sensor pins together; each classifier is \
             the one trained on the scenario's nominal sensor.\n",
            h.sensors.join(", ")
        ));
    }
    s.push_str(&format!("\n![sensitivity]({figure})\n\n"));
    s.push_str(&table(r));
    let online: Vec<(String, &super::online::OnlineShare)> = r
        .results
        .iter()
        .filter_map(|p| {
            let name = if p.values.is_empty() {
                "all".to_string()
            } else {
                p.values
                    .iter()
                    .map(|(k, v)| format!("{k} = {}", short(*v)))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            p.online.as_ref().map(|o| (name, o))
        })
        .collect();
    s.push_str(&super::online::markdown(&online));
    s
}

/// The header with `--out DIR` on its regenerating command: the report names the folder it was
/// written to, so its command rewrites exactly that report (and never the default folder in
/// place of a committed one).
pub fn with_out(mut header: StudyHeader, dir: &std::path::Path) -> StudyHeader {
    header.command.push_str(" --out ");
    header
        .command
        .push_str(&crate::output::shell_word(&dir.display().to_string()));
    header
}
