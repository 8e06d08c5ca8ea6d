//! What a run measures, accumulated as events happen (docs/physics.md#the-line), and the
//! deterministic [`Summary`] built from it.
//!
//! Definitions:
//! * **throughput** (parts/min): a rate over a window [t_a, t_b] counts the events in [t_a, t_b)
//!   and divides by t_b − t_a, so N periodic events h apart give exactly 1/h. `throughput_in`
//!   uses the arrivals (first to last arrival). The **steady window** for the output side runs from
//!   the first to the last exit (success or wrong orientation): it leaves out the time the belt
//!   takes to fill and to empty. `throughput_out` counts all exits in it, `throughput_ok` the
//!   successes.
//! * **success rate**: successes / parts in, with the 95% Wilson score interval.
//! * **latency**: exit time − arrival time of the parts that exit, in an HDR histogram of
//!   microseconds (3 significant digits), reported in seconds.
//! * **contacts per part**: obstacle encounters (pushes by pins and fences) / parts in.
//! * **busy fraction** of an obstacle (pin or fence): total time it is pushing a part / simulated
//!   time (first arrival to last event).
//! * **work**: counters of the work each optional effect did, so a test can show that an effect a
//!   scene does not use costs nothing. Wall-clock speed is not part of the summary (it would make
//!   runs differ); the CLI prints it beside the table.

use super::outcome::{OutcomeCounts, PartOutcome};
use hdrhistogram::Histogram;
use serde::Serialize;
use std::collections::BTreeMap;

/// Work done, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct WorkCounters {
    /// Events taken off the queue.
    pub events: u64,
    /// Calls of the contact model (pushes), excluding re-runs for traces.
    pub contact_solves: u64,
    /// Limit-surface evaluations reported by those calls.
    pub model_evaluations: u64,
    /// First-contact ray casts to find a part's next obstacle.
    pub ray_casts: u64,
    /// Pushes recorded as they were computed because something was going to look at their path
    /// (a neighbouring obstacle, a fence's edge crossing, a drawn path, another part on the belt).
    pub traces_recorded: u64,
    /// Pushes computed a second time, with a recorder, because a path was needed that was not
    /// foreseen when the push was computed (a part arriving during it); rare.
    pub pushes_rerun: u64,
    /// Pairs of parts considered for overlap (only while two or more parts share the belt).
    pub part_part_checks: u64,
    /// Of those, pairs close enough to need a time-resolved check.
    pub part_part_narrow_checks: u64,
    /// Neighbouring obstacles checked against a push.
    pub obstacle_sweep_checks: u64,
    /// Clearance evaluations in time-resolved checks.
    pub clearance_evaluations: u64,
    /// Random tripods drawn (support = "tripod").
    pub tripods_drawn: u64,
    /// Sensor readings taken (passes against sensor pins).
    pub sensor_readings: u64,
    /// Integrator knots recorded for sensor signals (the push itself, never a second one).
    pub signal_knots: u64,
    /// Readings classified.
    pub classifications: u64,
    /// Decisions that reached the controller (this and the next four counters stay 0 without
    /// dynamic pins).
    pub decisions: u64,
    /// Commands given to dynamic pins.
    pub actuator_commands: u64,
    /// Commands that could not finish before their part arrived.
    pub late_actuations: u64,
    /// Free parts planned again after a pin's timeline changed.
    pub replans: u64,
    /// Events dropped as stale.
    pub stale_events: u64,
    /// Pushes answered by the map tier and pushes it handed to the exact model, by reason (only
    /// with `[model] fidelity = "map"`; absent from the summary otherwise).
    #[serde(skip_serializing_if = "MapTierCounters::is_unused")]
    pub map_tier: MapTierCounters,
}

/// How the map tier answered the line's pushes (see [`crate::maps::tier`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct MapTierCounters {
    /// Answered from the map: interpolated in a certified cell, or a miss found by the exact ray
    /// cast.
    pub served: u64,
    /// Computed exactly because the query fell in an uncertified cell (near a jump).
    pub fallback_uncertified: u64,
    /// … because the pin started inside or against the part.
    pub fallback_pin_inside: u64,
    /// … because the push's path was recorded as it was computed (sensor pin, neighbouring
    /// obstacle, drawn part).
    pub fallback_trace: u64,
    /// … because the pin moves.
    pub fallback_moving_pin: u64,
    /// … because a fence pushed.
    pub fallback_fence: u64,
    /// … because the part has its own support (a random tripod per part).
    pub fallback_part_support: u64,
    /// … because the query fell in a base cell the map has not built (never for a line, whose
    /// maps are built whole; absent from the summary when 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub fallback_unbuilt: u64,
}

fn is_zero(k: &u64) -> bool {
    *k == 0
}

impl MapTierCounters {
    /// No push went through the tier (a scene without the map tier).
    pub fn is_unused(&self) -> bool {
        *self == MapTierCounters::default()
    }
    /// Pushes handed to the exact model.
    pub fn fallbacks(&self) -> u64 {
        self.fallback_uncertified
            + self.fallback_pin_inside
            + self.fallback_trace
            + self.fallback_moving_pin
            + self.fallback_fence
            + self.fallback_part_support
            + self.fallback_unbuilt
    }
    /// The fallbacks by reason, `name count` joined by commas (`none` without any).
    pub fn fallback_reasons(&self) -> String {
        let reasons: Vec<String> = [
            ("uncertified", self.fallback_uncertified),
            ("trace", self.fallback_trace),
            ("pin_inside", self.fallback_pin_inside),
            ("moving_pin", self.fallback_moving_pin),
            ("fence", self.fallback_fence),
            ("part_support", self.fallback_part_support),
            ("unbuilt", self.fallback_unbuilt),
        ]
        .iter()
        .filter(|(_, k)| *k > 0)
        .map(|(name, k)| format!("{name} {k}"))
        .collect();
        if reasons.is_empty() {
            "none".into()
        } else {
            reasons.join(", ")
        }
    }
    /// Count a fallback by its reason.
    pub fn count(&mut self, why: crate::maps::tier::Fallback) {
        use crate::maps::tier::Fallback as F;
        *match why {
            F::Uncertified => &mut self.fallback_uncertified,
            F::PinInside => &mut self.fallback_pin_inside,
            F::Trace => &mut self.fallback_trace,
            F::MovingPin => &mut self.fallback_moving_pin,
            F::Fence => &mut self.fallback_fence,
            F::PartSupport => &mut self.fallback_part_support,
            F::Unbuilt => &mut self.fallback_unbuilt,
        } += 1;
    }
}

/// Per-obstacle statistics.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ObstacleStats {
    /// The obstacle's name in the scene.
    pub name: String,
    /// Pushes by this obstacle (each encounter counts once).
    pub contacts: u64,
    /// Seconds spent pushing parts.
    pub busy_s: f64,
}

/// Accumulators of a run.
#[derive(Debug, Clone)]
pub struct Metrics {
    /// Parts that arrived.
    pub parts_in: u64,
    /// Parts per final outcome.
    pub outcomes: OutcomeCounts,
    /// Multi-contact failures by cause (e.g. `second_obstacle`, `pin_inside_part`).
    pub multi_contact_causes: BTreeMap<String, u64>,
    /// Jams by cause (`travel_limit`, `fence_angle`).
    pub jam_causes: BTreeMap<String, u64>,
    /// Solver failures by cause (e.g. `grazing_loop`).
    pub solver_causes: BTreeMap<String, u64>,
    /// Time of the first arrival (s), None before any.
    pub first_arrival: Option<f64>,
    /// Time of the latest arrival (s).
    pub last_arrival: f64,
    /// Time of the first exit (s), None before any.
    pub first_exit: Option<f64>,
    /// Time of the latest exit (s).
    pub last_exit: f64,
    /// Exits at exactly `last_exit` (left out of the steady window's count, which is half-open).
    pub exits_at_last: u64,
    /// Successes at exactly `last_exit`.
    pub successes_at_last: u64,
    /// Parts that exited (success or wrong orientation).
    pub exits: u64,
    /// Time of the latest event handled (s).
    pub last_event: f64,
    /// Entry → exit, microseconds.
    pub latency_us: Histogram<u64>,
    /// Whether finished parts' latencies go into [`Metrics::latency_us`]: not in a line of one
    /// entered part (every pass of an online model's build), whose latency nothing reads.
    pub(crate) record_latency: bool,
    /// Largest latency (s), exact.
    pub latency_max: f64,
    /// Smallest latency (s), exact (+∞ before the first exit).
    pub latency_min: f64,
    /// Obstacle encounters (pushes) over all obstacles.
    pub contacts: u64,
    /// Per obstacle, in scene order.
    pub obstacles: Vec<ObstacleStats>,
    /// Final orientations of exiting parts, counts per bin of `bin_deg`.
    pub orientation_bins: Vec<u64>,
    /// Width of an orientation bin (degrees; divides 360).
    pub bin_deg: f64,
    /// Work done by the engine, by kind.
    pub work: WorkCounters,
    /// Per sensor pin, in obstacle order.
    pub sensors: Vec<super::sensing::SensorStats>,
}

/// The largest latency the histogram records (10⁶ s in µs); longer ones count at this value
/// (their exact value is kept in `latency_max`).
const LATENCY_MAX_US: u64 = 1_000_000_000_000;

impl Metrics {
    /// Empty accumulators for the scene's obstacles (in order) and an orientation bin of `bin_deg` degrees (must divide 360).
    pub fn new(obstacle_names: Vec<String>, bin_deg: f64) -> Metrics {
        let bins = (360.0 / bin_deg).round() as usize;
        Metrics {
            parts_in: 0,
            outcomes: OutcomeCounts::default(),
            multi_contact_causes: BTreeMap::new(),
            jam_causes: BTreeMap::new(),
            solver_causes: BTreeMap::new(),
            first_arrival: None,
            last_arrival: 0.0,
            first_exit: None,
            last_exit: 0.0,
            exits_at_last: 0,
            successes_at_last: 0,
            exits: 0,
            last_event: 0.0,
            // Grows as latencies arrive (same buckets as fixed bounds of 1 µs to 10⁶ s at three
            // significant digits, so the same percentiles): a line of one part — every pass of
            // an online model's build — does not clear 0.6 MB of counts it never uses.
            latency_us: Histogram::new(3).expect("three significant digits are valid"),
            record_latency: true,
            latency_max: 0.0,
            latency_min: f64::INFINITY,
            contacts: 0,
            obstacles: obstacle_names
                .into_iter()
                .map(|name| ObstacleStats {
                    name,
                    ..ObstacleStats::default()
                })
                .collect(),
            orientation_bins: vec![0; bins],
            bin_deg,
            work: WorkCounters::default(),
            sensors: Vec::new(),
        }
    }

    /// A part arrived at time `t` (s).
    pub fn arrival(&mut self, t: f64) {
        self.parts_in += 1;
        if self.first_arrival.is_none() {
            self.first_arrival = Some(t);
        }
        self.last_arrival = t;
    }

    /// A part has finished with `outcome` at time `t`; `theta_deg` is its final orientation in
    /// [0, 360) and `latency` its time on the belt.
    pub fn finish(&mut self, outcome: PartOutcome, t: f64, theta_deg: f64, latency: f64) {
        self.outcomes.add(outcome);
        if !outcome.exited() {
            return;
        }
        if self.first_exit.is_none() {
            self.first_exit = Some(t);
        }
        if t > self.last_exit || self.exits == 0 {
            self.last_exit = t;
            self.exits_at_last = 0;
            self.successes_at_last = 0;
        }
        self.exits += 1;
        self.exits_at_last += 1;
        if outcome == PartOutcome::Success {
            self.successes_at_last += 1;
        }
        let us = ((latency * 1e6).round().max(1.0) as u64).min(LATENCY_MAX_US);
        // `record`, not `saturating_record`: the latter clamps to the current top instead of
        // growing the histogram.
        if self.record_latency {
            self.latency_us
                .record(us)
                .expect("an auto-resizing histogram records any latency up to 10⁶ s");
        }
        self.latency_max = self.latency_max.max(latency);
        self.latency_min = self.latency_min.min(latency);
        let n = self.orientation_bins.len();
        let bin = ((theta_deg / self.bin_deg).floor() as usize).min(n - 1);
        self.orientation_bins[bin] += 1;
    }

    /// Record the cause of a failed part; ignored for outcomes other than multi-contact, jam and solver.
    pub fn cause(&mut self, outcome: PartOutcome, cause: super::Cause) {
        let map = match outcome {
            PartOutcome::MultiContact => &mut self.multi_contact_causes,
            PartOutcome::Jam => &mut self.jam_causes,
            PartOutcome::Solver => &mut self.solver_causes,
            _ => return,
        };
        *map.entry(cause.name().to_string()).or_insert(0) += 1;
    }
}

/// Latency quantiles (seconds; the quantiles to the histogram's 3 significant digits, the
/// maximum exact).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LatencySummary {
    /// Median (s).
    pub p50: f64,
    /// 90th percentile (s).
    pub p90: f64,
    /// 99th percentile (s).
    pub p99: f64,
    /// Largest latency (s, exact).
    pub max: f64,
}

/// Per-obstacle line of the summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObstacleSummary {
    /// The obstacle's name.
    pub name: String,
    /// Pushes by this obstacle.
    pub contacts: u64,
    /// Time it spent pushing parts / simulated time, in [0, 1] unless pushes overlap.
    pub busy_fraction: f64,
}

/// Final-orientation histogram of the exiting parts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationHistogram {
    /// Bin width (degrees; divides 360).
    pub bin_deg: f64,
    /// `counts[k]` = parts with final θ in [k·bin, (k+1)·bin) degrees.
    pub counts: Vec<u64>,
}

/// Causes behind the multi_contact, jam and solver classes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Causes {
    /// Multi-contact failures by cause (e.g. `second_obstacle`, `pin_inside_part`).
    pub multi_contact: BTreeMap<String, u64>,
    /// `travel_limit` (a pin still pushing after `model.max_travel`) or `fence_angle` (stopped
    /// against a fence at α + atan μf ≥ 90°).
    pub jam: BTreeMap<String, u64>,
    /// Solver failures by cause (e.g. `grazing_loop`).
    pub solver: BTreeMap<String, u64>,
}

/// The deterministic result of a run: a pure function of (scene, seed, parts).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The scene's name.
    pub scenario: String,
    /// The run's seed.
    pub seed: u64,
    /// Contact-model fidelity used (`exact`, `ellipsoid`, `tip`, or `map`).
    pub fidelity: String,
    /// Parts that arrived.
    pub parts_in: u64,
    /// Parts per final outcome.
    pub outcomes: OutcomeCounts,
    /// Successes / parts in (0 without parts).
    pub success_rate: f64,
    /// 95% Wilson score interval of the success rate, [low, high].
    pub success_ci95: [f64; 2],
    /// Arrival rate over first to last arrival (parts/min; None with fewer than two distinct arrival times).
    pub throughput_in_per_min: Option<f64>,
    /// Exit rate over the steady window (parts/min; None without a window of positive length).
    pub throughput_out_per_min: Option<f64>,
    /// Success rate over the steady window (parts/min; None without a window of positive length).
    pub throughput_ok_per_min: Option<f64>,
    /// [first exit, last exit] (s).
    pub steady_window_s: Option<[f64; 2]>,
    /// Time on the belt of the exiting parts (None when no part exited).
    pub latency_s: Option<LatencySummary>,
    /// Obstacle encounters per part in.
    pub contacts_per_part: f64,
    /// Per obstacle, in scene order.
    pub obstacles: Vec<ObstacleSummary>,
    /// Final orientations of the exiting parts.
    pub orientation_histogram: OrientationHistogram,
    /// Why parts failed, by outcome class.
    pub causes: Causes,
    /// First arrival to last event (s).
    pub simulated_time_s: f64,
    /// Work done by the engine, by kind (not wall-clock time).
    pub work: WorkCounters,
    /// Sensor pins: readings, confusion against the truth, parts that passed untouched (absent
    /// from the JSON when the scene has no sensor).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sensors: Vec<super::sensing::SensorStats>,
    /// The controller of dynamic pins (absent from the JSON without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller: Option<super::controller::ControllerSummary>,
    /// The closed loop: gate, return path and merge (absent from the JSON on an open line).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<super::closed_loop::LoopSummary>,
    /// `run --precision`: the rule, where the feed stopped and the rate's confidence sequence
    /// (absent from the JSON without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequential: Option<super::sequential::SequentialSummary>,
}

pub use crate::statistics::wilson_interval;

impl Metrics {
    /// Build the summary.
    pub fn summary(&self, scenario: &str, seed: u64, fidelity: &str) -> Summary {
        let n = self.parts_in;
        let per_min = |count: u64, a: f64, b: f64| -> Option<f64> {
            (b > a).then(|| count as f64 / (b - a) * 60.0)
        };
        let first_arrival = self.first_arrival.unwrap_or(0.0);
        let throughput_in = per_min(n.saturating_sub(1), first_arrival, self.last_arrival);
        let (throughput_out, throughput_ok, window) = match self.first_exit {
            Some(a) => (
                per_min(self.exits - self.exits_at_last, a, self.last_exit),
                per_min(
                    self.outcomes.success - self.successes_at_last,
                    a,
                    self.last_exit,
                ),
                Some([a, self.last_exit]),
            ),
            None => (None, None, None),
        };
        let latency = (!self.latency_us.is_empty()).then(|| {
            let [p50, p90, p99] = crate::statistics::latency_percentiles(
                &self.latency_us,
                self.latency_min,
                self.latency_max,
            );
            LatencySummary {
                p50,
                p90,
                p99,
                max: self.latency_max,
            }
        });
        let span = self.last_event - first_arrival;
        Summary {
            scenario: scenario.to_string(),
            seed,
            fidelity: fidelity.to_string(),
            parts_in: n,
            outcomes: self.outcomes,
            success_rate: if n > 0 {
                self.outcomes.success as f64 / n as f64
            } else {
                0.0
            },
            success_ci95: wilson_interval(self.outcomes.success, n),
            throughput_in_per_min: throughput_in,
            throughput_out_per_min: throughput_out,
            throughput_ok_per_min: throughput_ok,
            steady_window_s: window,
            latency_s: latency,
            contacts_per_part: if n > 0 {
                self.contacts as f64 / n as f64
            } else {
                0.0
            },
            obstacles: self
                .obstacles
                .iter()
                .map(|o| ObstacleSummary {
                    name: o.name.clone(),
                    contacts: o.contacts,
                    busy_fraction: if span > 0.0 { o.busy_s / span } else { 0.0 },
                })
                .collect(),
            orientation_histogram: OrientationHistogram {
                bin_deg: self.bin_deg,
                counts: self.orientation_bins.clone(),
            },
            causes: Causes {
                multi_contact: self.multi_contact_causes.clone(),
                jam: self.jam_causes.clone(),
                solver: self.solver_causes.clone(),
            },
            simulated_time_s: span,
            work: self.work,
            sensors: self.sensors.clone(),
            controller: None,
            closed_loop: None,
            sequential: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periodic_rate_is_exact() {
        let mut m = Metrics::new(vec![], 5.0);
        for i in 0..11 {
            m.arrival(2.0 * i as f64);
            m.finish(PartOutcome::Success, 10.0 + 2.0 * i as f64, 0.0, 10.0);
        }
        m.last_event = 30.0;
        let s = m.summary("t", 1, "exact");
        assert_eq!(s.throughput_in_per_min, Some(30.0));
        assert_eq!(s.throughput_ok_per_min, Some(30.0));
        let lat = s.latency_s.unwrap();
        assert!((lat.p50 - 10.0).abs() < 0.01 && lat.max == 10.0, "{lat:?}");
    }

    /// The growing histogram buckets latencies exactly as one with fixed bounds of 1 µs to 10⁶ s:
    /// the same percentiles for latencies from microseconds to days.
    #[test]
    fn growing_latency_histogram_matches_fixed_bounds() {
        let lat = [3e-6, 0.5, 12.1958, 13.3613, 14.7, 900.0, 86_400.0];
        let mut m = Metrics::new(vec![], 5.0);
        let mut fixed = Histogram::<u64>::new_with_bounds(1, LATENCY_MAX_US, 3).unwrap();
        for (i, &l) in lat.iter().enumerate() {
            m.arrival(i as f64);
            m.finish(PartOutcome::Success, i as f64 + l, 0.0, l);
            fixed.record((l * 1e6).round() as u64).unwrap();
        }
        for q in [0.1, 0.5, 0.9, 0.99, 1.0] {
            assert_eq!(
                m.latency_us.value_at_quantile(q),
                fixed.value_at_quantile(q),
                "q {q}"
            );
        }
        assert_eq!(m.latency_us.len(), lat.len() as u64);
    }
}
