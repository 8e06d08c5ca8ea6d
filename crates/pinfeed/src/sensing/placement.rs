//! Where to put the sensor: over a grid of pin offsets d and sensor kinds, how much each placement
//! tells about the hypotheses — the mutual information I(state; decision) of its best classifier
//! (and that classifier's accuracy) at the sensor's nominal noise.
//!
//! Each d is an [`super::evaluate`] run of its own (templates and trials drawn anew for that push,
//! the same seed), and every sensor kind reads the same true pushes. The best classifier of a
//! placement is the one with the most information (ties: the higher accuracy, then the first
//! listed); the best placement likewise over the grid, per kind and overall.

use super::evaluate::{
    evaluate_with, Config, EvaluateError, Evaluation, Factory, Problem, SensorPoint,
};
use super::templates::PushSetup;
use serde::Serialize;

/// The default grid of d: −0.9 to 0.9 every 0.1.
pub fn default_grid() -> Vec<f64> {
    (-9..=9).map(|i| i as f64 / 10.0).collect()
}

/// One placement (d, sensor kind) and its best classifier.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// The pin's offset d (units of a).
    pub d: f64,
    /// The sensor kind's name (`ft`, `timing`).
    pub sensor: &'static str,
    /// The best classifier (None when no classifier was scored).
    pub classifier: Option<String>,
    /// The best classifier's mutual information between state and decision (bits).
    pub mutual_information_bits: f64,
    /// The best classifier's accuracy, in [0, 1].
    pub accuracy: f64,
    /// 95% Wilson interval of that accuracy, [low, high].
    pub accuracy_ci95: [f64; 2],
    /// H(state) of this placement's scored trials (bits).
    pub state_entropy_bits: f64,
    /// Every classifier's (name, information, accuracy) at this placement.
    pub scores: Vec<(String, f64, f64)>,
}

/// The placement search's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Placement {
    /// The offsets d tried (units of a).
    pub grid: Vec<f64>,
    /// One row per (offset, sensor kind).
    pub rows: Vec<Row>,
    /// The best row per sensor kind (indices into `rows`), in the order the kinds were given.
    pub best_per_sensor: Vec<usize>,
    /// The best row overall.
    pub best: Option<usize>,
}

fn better(a: &Row, b: &Row) -> bool {
    // Strictly more information, or as much (to 1e-12) and more accurate.
    a.mutual_information_bits > b.mutual_information_bits + 1e-12
        || ((a.mutual_information_bits - b.mutual_information_bits).abs() <= 1e-12
            && a.accuracy > b.accuracy)
}

fn rows_of(d: f64, points: &[SensorPoint], ev: &Evaluation) -> Vec<Row> {
    points
        .iter()
        .map(|p| {
            let cells: Vec<_> = ev
                .cells
                .iter()
                .filter(|c| c.sensor == p.sensor.kind.name() && c.noise_factor == p.noise_factor)
                .collect();
            let scores = cells
                .iter()
                .map(|c| (c.classifier.clone(), c.mutual_information_bits, c.accuracy))
                .collect();
            let mut row = Row {
                d,
                sensor: p.sensor.kind.name(),
                classifier: None,
                mutual_information_bits: 0.0,
                accuracy: 0.0,
                accuracy_ci95: [0.0, 1.0],
                state_entropy_bits: ev.state_entropy_bits,
                scores,
            };
            for c in cells {
                let cand = Row {
                    classifier: Some(c.classifier.clone()),
                    mutual_information_bits: c.mutual_information_bits,
                    accuracy: c.accuracy,
                    accuracy_ci95: c.accuracy_ci95,
                    ..row.clone()
                };
                if row.classifier.is_none() || better(&cand, &row) {
                    row = cand;
                }
            }
            row
        })
        .collect()
}

/// Scores every sensor point (one per kind, typically at nominal noise) at every d of `grid`.
/// `setup.d` is replaced by each grid value; `progress` is called after each d.
pub fn search_with(
    problem: &Problem,
    grid: &[f64],
    points: &[SensorPoint],
    config: &Config,
    factory: &Factory,
    progress: &mut dyn FnMut(f64, &[Row]),
) -> Result<Placement, EvaluateError> {
    let mut rows = Vec::new();
    for &d in grid {
        let setup = PushSetup {
            d,
            ..problem.setup.clone()
        };
        let p = Problem {
            setup: &setup,
            ..*problem
        };
        let (_, ev) = evaluate_with(&p, points, config, factory)?;
        let r = rows_of(d, points, &ev);
        progress(d, &r);
        rows.extend(r);
    }
    let mut best_per_sensor = Vec::new();
    for p in points {
        let kind = p.sensor.kind.name();
        let mut best: Option<usize> = None;
        for (i, r) in rows.iter().enumerate() {
            if r.sensor == kind && best.is_none_or(|b| better(r, &rows[b])) {
                best = Some(i);
            }
        }
        if let Some(b) = best {
            if !best_per_sensor.contains(&b) {
                best_per_sensor.push(b);
            }
        }
    }
    let mut best: Option<usize> = None;
    for (i, r) in rows.iter().enumerate() {
        if best.is_none_or(|b| better(r, &rows[b])) {
            best = Some(i);
        }
    }
    Ok(Placement {
        grid: grid.to_vec(),
        rows,
        best_per_sensor,
        best,
    })
}
