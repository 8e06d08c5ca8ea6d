//! A closed loop on the line (docs/physics.md#closed-loop; docs/scenario-format.md#closed-loop):
//! the reject gate at the belt's end, the return conveyor, its buffer and the merge where parts
//! re-enter the belt, as stages of the discrete-event line.
//!
//! * **Gate.** A part reaching the belt's end is taken off when the gate wants it (its sensor
//!   pin decided a hypothesis outside `accept`, or `unknown` with `unknown = "reject"`; a gate
//!   without a sensor wants every part), the decision was ready in time (end of the reading +
//!   `actuation` ≤ the part's arrival at the gate), the part's centroid lies within `reach` of
//!   the gate's `y`, and the gate is not busy from its last action (it cannot act again for a
//!   `busy` time drawn per action). Otherwise the part is delivered: success or wrong
//!   orientation, as on an open line. A gate that loses the parts arriving while it is busy is
//!   the M/G/1/1 loss system: with Poisson arrivals at rate λ it acts on λ/(1 + λ·E(S)) parts per
//!   second whatever the distribution of S (Erlang's loss formula and its insensitivity;
//!   Gudmundsson & Goldberg 1999 treat a feeder's stations as such queues).
//! * **Return path.** Without `[recirculation]` a rejected part leaves the line (`rejected`).
//!   With it, a part rejected on pass k < `max_passes` rides the return conveyor for a `transit`
//!   time, waits in the buffer before the merge (a full buffer blocks it on the conveyor or drops
//!   it, by `when_full`), and re-enters the belt as pass k + 1 with a new pose drawn as the feed
//!   draws one (its support kept); a part rejected on its last pass is scrapped.
//! * **Merge.** Every entry (new or returning) passes the merge, a single server whose service is
//!   the least gap between entries (`merge_gap`); returning parts go first, new parts wait in
//!   the order they came. With Poisson arrivals and no returns it is an M/G/1 queue whose mean
//!   wait is Pollaczek–Khinchine's λ·E(G²) / (2(1 − λ·E(G))).
//!
//! Identity: a part on the belt is known by its entry number (the order it entered in, which the
//! dynamic pins serve by); the loop maps each entry to (part, pass). Pass 0 of part i is drawn
//! from the part's own stream exactly as on an open line, so a loop whose gate passes every part
//! and whose merge never holds one runs the open line's parts. Every draw of the loop comes from
//! a stream of its own keyed by the entry number ([`crate::random::substream`]): the run stays a
//! pure function of (scene, seed).
//!
//! Conservation (asserted at the end of every run): every new part is delivered (in the goal or
//! not), lost on the line (collision, off the belt, jam, …), rejected out of an open loop,
//! scrapped (its last pass, or dropped at a full buffer), or still in the system.

use super::event_queue::{EventKind, EventQueue};
use crate::mechanics::PartModel;
use crate::random::substream;
use crate::scenario::{Arrival, ClosedLoop, Feed, RejectGate, RejectOn, WhenFull};
use crate::statistics::wilson_interval;
use serde::Serialize;
use std::collections::{BTreeMap, VecDeque};

/// Purposes of the loop's random streams ([`substream`]), keyed by entry number.
const GATE_PURPOSE: u64 = 0x4741_5445;
const TRANSIT_PURPOSE: u64 = 0x5452_414E;
const MERGE_PURPOSE: u64 = 0x4D45_5247;

/// What the gate decided about one part, set when its sensor pin read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct GateCall {
    /// Does the decision reject the part?
    pub(super) reject: bool,
    /// When the gate is ready to act on it (s): the end of the reading plus the actuation.
    pub(super) ready_at: f64,
}

impl RejectGate {
    /// The gate's call on a part that touched its contact pin, the touch over at `t_end`.
    pub(super) fn call_touched(&self, t_end: f64) -> GateCall {
        GateCall {
            reject: true,
            ready_at: t_end + self.actuation,
        }
    }

    /// The gate's call on a part whose sensor decided `label` (None: unknown), the reading over
    /// at `t_end`.
    pub(super) fn call(&self, label: Option<&str>, t_end: f64) -> GateCall {
        let reject = match label {
            Some(l) => !self.accept.iter().any(|a| a == l),
            None => self.unknown_rejects,
        };
        GateCall {
            reject,
            ready_at: t_end + self.actuation,
        }
    }
}

/// Counts of what the gate did with the parts reaching it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct GateCounts {
    /// Parts it took off the belt.
    pub acted: u64,
    /// Parts it let pass because their decision passed them.
    pub accepted: u64,
    /// Parts it wanted but let pass: still busy from its last action.
    pub busy: u64,
    /// … the decision came too late (reading end + actuation after the part's arrival).
    pub late: u64,
    /// … the part's centroid lay outside its reach.
    pub out_of_reach: u64,
    /// Parts its sensor pin never read (counted as `unknown`).
    pub unread: u64,
}

/// Where the new parts ended.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Fates {
    /// Delivered in the goal.
    pub delivered_ok: u64,
    /// Delivered outside the goal.
    pub delivered_wrong: u64,
    /// Lost on the line on some pass (collision, off the belt, multi-contact, jam, solver).
    pub lost: u64,
    /// Rejected by a gate with no return path.
    pub rejected: u64,
    /// Scrapped: rejected on their last allowed pass.
    pub scrapped_max_passes: u64,
    /// Scrapped: dropped at a full buffer.
    pub scrapped_full: u64,
}

impl Fates {
    /// Parts with a fate.
    pub fn total(&self) -> u64 {
        self.delivered_ok
            + self.delivered_wrong
            + self.lost
            + self.rejected
            + self.scrapped_max_passes
            + self.scrapped_full
    }
    /// Parts delivered.
    pub fn delivered(&self) -> u64 {
        self.delivered_ok + self.delivered_wrong
    }
}

/// A level over time: its time integral and its largest value.
#[derive(Debug, Clone, Copy, Default)]
struct Level {
    now: u64,
    area: f64,
    max: u64,
}

impl Level {
    fn add(&mut self, dt: f64, delta: i64) {
        self.area += self.now as f64 * dt;
        self.now = (self.now as i64 + delta) as u64;
        self.max = self.max.max(self.now);
    }
}

/// Add the area of `level` over [a, b) to the bins of width `bin` it covers.
fn spread(bins: &mut Vec<f64>, bin: f64, a: f64, b: f64, level: u64) {
    if level == 0 || b <= a {
        return;
    }
    let last = (b / bin).floor() as usize;
    if bins.len() <= last {
        bins.resize(last + 1, 0.0);
    }
    let mut k = (a / bin).floor() as usize;
    while k <= last {
        let (lo, hi) = (k as f64 * bin, (k + 1) as f64 * bin);
        bins[k] += level as f64 * (hi.min(b) - lo.max(a)).max(0.0);
        k += 1;
    }
}

/// A part off the belt between passes: the passes it has made and its own support.
struct Returning {
    passes: u32,
    model: Option<PartModel>,
    /// When it joined the queue it waits in (s).
    since: f64,
}

/// The loop's state in a run.
pub(super) struct LoopState {
    gate: RejectGate,
    recirculation: Option<crate::scenario::Recirculation>,
    seed: u64,
    busy_until: f64,
    /// Entry number → (part, passes before this one); only with a return path (else the entry
    /// number is the part and every pass the first).
    entries: BTreeMap<u64, (u64, u32)>,
    /// When each part still in the system first arrived (s), by part.
    born: BTreeMap<u64, f64>,
    next_entry: u64,
    /// Parts off the belt between passes, by part.
    off_belt: BTreeMap<u64, Returning>,
    buffer: VecDeque<u64>,
    blocked: VecDeque<u64>,
    new_waiting: VecDeque<(u64, f64)>,
    merge_free_at: f64,
    merge_pending: bool,
    last_t: f64,
    return_load: Level,
    buffer_level: Level,
    stats: LoopStats,
}

/// What the loop counts as the run goes.
#[derive(Debug, Clone, Default)]
struct LoopStats {
    new_parts: u64,
    passes: u64,
    gate: GateCounts,
    fates: Fates,
    recirculated: u64,
    blocked: u64,
    /// Delivered parts by passes made (index 0: one pass).
    passes_of_delivered: Vec<u64>,
    merge_wait_new_s: f64,
    merge_wait_return_s: f64,
    merge_new: u64,
    merge_returns: u64,
    bin_s: f64,
    delivered_bins: Vec<u64>,
    ok_bins: Vec<u64>,
    first_delivery: Option<f64>,
    last_delivery: f64,
    last_new_arrival: f64,
    /// Deliveries (all, in the goal) before the latest new arrival: the steady window's counts.
    delivered_at_last_arrival: (u64, u64),
    /// Every delivery: its time and the part's time in the system (first arrival to delivery).
    deliveries: Vec<(f64, f64)>,
    /// Area (part·s) of the return load and of the buffer per bin.
    load_bins: Vec<f64>,
    buffer_bins: Vec<f64>,
}

impl LoopStats {
    /// A new part arrives at `t`.
    fn arrival(&mut self, t: f64) {
        self.new_parts += 1;
        self.last_new_arrival = t;
        let f = &self.fates;
        self.delivered_at_last_arrival = (f.delivered(), f.delivered_ok);
    }
}

/// A part the merge lets onto the belt: its part number, the passes it has made, and its own
/// support when it has been round before.
pub(super) struct Entering {
    pub(super) entry: u64,
    pub(super) part: u64,
    pub(super) pass: u32,
    pub(super) model: Option<Option<PartModel>>,
}

impl LoopState {
    /// The loop of `cl` in a run seeded `seed` of `parts` new parts fed as `feed` says.
    pub(super) fn new(cl: &ClosedLoop, feed: &Feed, seed: u64, parts: u64) -> LoopState {
        let headway = match feed.arrival {
            Arrival::Periodic { headway } | Arrival::Poisson { headway } => headway,
        };
        // About 1000 bins over the feed's span: MSER-5's batches of five bins then place a
        // warm-up to within 0.5% of the span.
        let bin_s = headway * (parts as f64 / 1000.0).ceil().max(1.0);
        LoopState {
            gate: cl.gate.clone(),
            recirculation: cl.recirculation.clone(),
            seed,
            busy_until: f64::NEG_INFINITY,
            entries: BTreeMap::new(),
            born: BTreeMap::new(),
            next_entry: 0,
            off_belt: BTreeMap::new(),
            buffer: VecDeque::new(),
            blocked: VecDeque::new(),
            new_waiting: VecDeque::new(),
            merge_free_at: f64::NEG_INFINITY,
            merge_pending: false,
            last_t: 0.0,
            return_load: Level::default(),
            buffer_level: Level::default(),
            stats: LoopStats {
                bin_s,
                ..LoopStats::default()
            },
        }
    }

    /// Does every entry pass the merge (a return path exists)?
    pub(super) fn merges(&self) -> bool {
        self.recirculation.is_some()
    }

    /// Move the levels' clocks to `t`, changing the return load and the buffer by the deltas.
    fn levels(&mut self, t: f64, load: i64, buffer: i64) {
        let dt = (t - self.last_t).max(0.0);
        let s = &mut self.stats;
        spread(
            &mut s.load_bins,
            s.bin_s,
            self.last_t,
            t,
            self.return_load.now,
        );
        spread(
            &mut s.buffer_bins,
            s.bin_s,
            self.last_t,
            t,
            self.buffer_level.now,
        );
        self.return_load.add(dt, load);
        self.buffer_level.add(dt, buffer);
        self.last_t = self.last_t.max(t);
    }

    /// Part `part` and the passes it made before the one on the belt as entry `entry`.
    fn identity(&self, entry: u64) -> (u64, u32) {
        self.entries.get(&entry).copied().unwrap_or((entry, 0))
    }

    /// A new part `part` arrives at the merge at `t`.
    pub(super) fn new_part(&mut self, part: u64, t: f64) {
        self.stats.arrival(t);
        self.born.insert(part, t);
        self.new_waiting.push_back((part, t));
    }

    /// An open line's entry (no return path): part `part` enters as itself.
    pub(super) fn open_entry(&mut self, part: u64, t: f64) {
        self.stats.arrival(t);
        self.born.insert(part, t);
        self.stats.passes += 1;
    }

    /// The merge at `t`: the next part it lets onto the belt, if it is free and one waits (a
    /// returning part first); otherwise, if one waits, the merge's next free time is scheduled.
    pub(super) fn merge(&mut self, t: f64, queue: &mut EventQueue) -> Option<Entering> {
        let waiting = !(self.buffer.is_empty() && self.new_waiting.is_empty());
        if !waiting {
            return None;
        }
        if t < self.merge_free_at {
            if !self.merge_pending {
                self.merge_pending = true;
                queue.schedule(self.merge_free_at, EventKind::MergeFree);
            }
            return None;
        }
        let entry = self.next_entry;
        self.next_entry += 1;
        let (part, pass, model) = if let Some(part) = self.buffer.pop_front() {
            let r = self
                .off_belt
                .remove(&part)
                .expect("a buffered part is off the belt");
            self.stats.merge_returns += 1;
            self.stats.merge_wait_return_s += t - r.since;
            self.levels(t, -1, -1);
            if let Some(next) = self.blocked.pop_front() {
                if let Some(b) = self.off_belt.get_mut(&next) {
                    b.since = b.since.min(t);
                }
                self.buffer.push_back(next);
            }
            (part, r.passes, Some(r.model))
        } else {
            let (part, since) = self.new_waiting.pop_front().expect("a part waits");
            self.stats.merge_new += 1;
            self.stats.merge_wait_new_s += t - since;
            (part, 0, None)
        };
        self.stats.passes += 1;
        self.entries.insert(entry, (part, pass));
        let gap = self.recirculation.as_ref().expect("a merge").merge_gap;
        self.merge_free_at = t + gap.draw(&mut substream(self.seed, MERGE_PURPOSE, entry));
        if !(self.buffer.is_empty() && self.new_waiting.is_empty()) {
            self.merge_pending = true;
            queue.schedule(self.merge_free_at, EventKind::MergeFree);
        }
        Some(Entering {
            entry,
            part,
            pass,
            model,
        })
    }

    /// The merge's scheduled free time has come.
    pub(super) fn merge_freed(&mut self) {
        self.merge_pending = false;
    }

    /// Entry `entry` reaches the gate at `t` at lateral offset `y` with the gate's call on it
    /// (None: its sensor never read it) and the online controller's predicted success for it (if
    /// it decided one): does the gate take it off?
    pub(super) fn gate_takes(
        &mut self,
        entry: u64,
        t: f64,
        y: f64,
        call: Option<GateCall>,
        predicted: Option<f64>,
    ) -> bool {
        let g = &self.gate;
        let counts = &mut self.stats.gate;
        let belief = predicted
            .filter(|_| g.reject_on == RejectOn::Belief)
            .map(|p| GateCall {
                reject: p < g.min_success,
                ready_at: t,
            });
        let call = match (g.decided_by, belief.or(call)) {
            (None, Some(c)) => c,
            (None, None) if g.reject_on == RejectOn::Belief => {
                counts.unread += 1;
                GateCall {
                    reject: g.unknown_rejects,
                    ready_at: t,
                }
            }
            (None, _) => GateCall {
                reject: true,
                ready_at: t,
            },
            (Some(_), Some(c)) => c,
            // A contact switch the part did not touch: it passes.
            (Some(_), None) if g.reject_on == RejectOn::Contact => GateCall {
                reject: false,
                ready_at: t,
            },
            (Some(_), None) => {
                counts.unread += 1;
                GateCall {
                    reject: g.unknown_rejects,
                    ready_at: t,
                }
            }
        };
        if !call.reject {
            counts.accepted += 1;
            return false;
        }
        if call.ready_at > t {
            counts.late += 1;
            return false;
        }
        if (y - g.y).abs() > g.reach {
            counts.out_of_reach += 1;
            return false;
        }
        if t < self.busy_until {
            counts.busy += 1;
            return false;
        }
        counts.acted += 1;
        let busy = g.busy.draw(&mut substream(self.seed, GATE_PURPOSE, entry));
        self.busy_until = t + busy;
        true
    }

    /// The gate took entry `entry` off at `t` (its support `model`): it leaves the line, is
    /// scrapped, or rides the return conveyor (its arrival at the buffer scheduled).
    pub(super) fn rejected(
        &mut self,
        entry: u64,
        t: f64,
        model: Option<PartModel>,
        queue: &mut EventQueue,
    ) {
        let (part, pass) = self.identity(entry);
        self.entries.remove(&entry);
        let Some(r) = &self.recirculation else {
            self.stats.fates.rejected += 1;
            self.born.remove(&part);
            return;
        };
        if pass + 1 >= r.max_passes {
            self.stats.fates.scrapped_max_passes += 1;
            self.born.remove(&part);
            return;
        }
        let transit = r
            .transit
            .draw(&mut substream(self.seed, TRANSIT_PURPOSE, entry));
        self.stats.recirculated += 1;
        self.levels(t, 1, 0);
        self.off_belt.insert(
            part,
            Returning {
                passes: pass + 1,
                model,
                since: t,
            },
        );
        queue.schedule(t + transit, EventKind::Return { part });
    }

    /// Part `part` reaches the buffer at `t` off the return conveyor.
    pub(super) fn returned(&mut self, part: u64, t: f64) {
        let r = self.recirculation.as_ref().expect("a return path");
        let full = r.buffer.is_some_and(|cap| self.buffer.len() as u64 >= cap);
        let returning = self.off_belt.get_mut(&part).expect("a returning part");
        returning.since = t;
        if !full {
            self.buffer.push_back(part);
            self.levels(t, 0, 1);
            return;
        }
        match r.when_full {
            WhenFull::Block => {
                self.stats.blocked += 1;
                self.blocked.push_back(part);
                self.levels(t, 0, 1);
            }
            WhenFull::Drop => {
                self.off_belt.remove(&part);
                self.born.remove(&part);
                self.stats.fates.scrapped_full += 1;
                self.levels(t, -1, 0);
            }
        }
    }

    /// Entry `entry` left the line at `t` with `outcome` (not through the gate).
    pub(super) fn finished(&mut self, entry: u64, t: f64, outcome: super::PartOutcome) {
        let (part, pass) = self.identity(entry);
        self.entries.remove(&entry);
        let born = self.born.remove(&part).unwrap_or(t);
        let s = &mut self.stats;
        if !outcome.exited() {
            s.fates.lost += 1;
            return;
        }
        let ok = outcome == super::PartOutcome::Success;
        if ok {
            s.fates.delivered_ok += 1;
        } else {
            s.fates.delivered_wrong += 1;
        }
        let k = pass as usize;
        if s.passes_of_delivered.len() <= k {
            s.passes_of_delivered.resize(k + 1, 0);
        }
        s.passes_of_delivered[k] += 1;
        s.deliveries.push((t, t - born));
        s.first_delivery.get_or_insert(t);
        s.last_delivery = t;
        let bin = (t / s.bin_s).floor().max(0.0) as usize;
        if s.delivered_bins.len() <= bin {
            s.delivered_bins.resize(bin + 1, 0);
            s.ok_bins.resize(bin + 1, 0);
        }
        s.delivered_bins[bin] += 1;
        s.ok_bins[bin] += u64::from(ok);
    }

    /// The purity's counts: (delivered in the goal, delivered).
    pub(super) fn purity_counts(&self) -> (u64, u64) {
        let f = &self.stats.fates;
        (f.delivered_ok, f.delivered())
    }

    /// Passes the gate took off the belt (entries that did not end in an outcome class).
    pub(super) fn diverted(&self) -> u64 {
        self.stats.gate.acted
    }

    /// MSER-5 on the deliveries per bin, then batch means (see [`OutputAnalysis`]).
    fn output_analysis(&self) -> OutputAnalysis {
        use crate::statistics::MserVerdict;
        let s = &self.stats;
        let steady_bins =
            ((s.last_new_arrival / s.bin_s).floor() as usize).min(s.delivered_bins.len());
        let series = |bins: &[u64]| -> Vec<f64> {
            bins[..steady_bins.min(bins.len())]
                .iter()
                .map(|&n| n as f64)
                .collect()
        };
        let delivered = series(&s.delivered_bins);
        let m = crate::statistics::mser5(&delivered);
        let cut = m.truncation.min(delivered.len());
        let warm_up_s = cut as f64 * s.bin_s;
        let per_min = 60.0 / s.bin_s;
        let oriented = series(&s.ok_bins);
        let times: Vec<f64> = (s.deliveries.iter())
            .filter(|&&(t, _)| t >= warm_up_s && t < s.last_new_arrival)
            .map(|&(_, st)| st)
            .collect();
        OutputAnalysis {
            warm_up_s,
            warm_up_verdict: match m.verdict {
                MserVerdict::Reliable => "reliable",
                MserVerdict::TooShort => "too_short",
                MserVerdict::AtSearchEdge => "at_search_edge",
            },
            delivered_per_min: SteadyMean::of(&delivered[cut..], per_min),
            oriented_per_min: SteadyMean::of(&oriented[cut.min(oriented.len())..], per_min),
            system_time_s: SteadyMean::of(&times, 1.0),
        }
    }

    /// Check conservation at the end of a run of `parts` new parts: every part has a fate and
    /// nothing waits.
    pub(super) fn assert_conserved(&self, parts: u64) {
        let s = &self.stats;
        assert_eq!(s.new_parts, parts, "every new part reached the line");
        assert!(
            self.buffer.is_empty() && self.blocked.is_empty() && self.new_waiting.is_empty(),
            "parts left waiting at the merge after the last event"
        );
        assert!(self.off_belt.is_empty(), "parts left on the return path");
        assert!(self.born.is_empty(), "parts left without a fate");
        assert_eq!(
            s.fates.total(),
            parts,
            "conservation: every part is delivered, lost, rejected or scrapped ({:?})",
            s.fates
        );
    }

    /// The loop's summary at the end of a run whose simulated time ran to `end` (s).
    pub(super) fn summary(&self, end: f64) -> LoopSummary {
        let s = &self.stats;
        let delivered = s.fates.delivered();
        let span = (end - 0.0).max(0.0);
        let level = |l: &Level| {
            let mean = if span > 0.0 { l.area / span } else { 0.0 };
            LevelSummary { mean, max: l.max }
        };
        let mean_passes = if delivered > 0 {
            s.passes_of_delivered
                .iter()
                .enumerate()
                .map(|(k, &n)| (k as f64 + 1.0) * n as f64)
                .sum::<f64>()
                / delivered as f64
        } else {
            0.0
        };
        // The steady window: from the first delivery to the last new part's arrival (after it
        // only the parts still in the loop drain out).
        let window = s
            .first_delivery
            .filter(|&a| s.last_new_arrival > a)
            .map(|a| [a, s.last_new_arrival]);
        let (delivered_rate, ok_rate) = match window {
            Some([a, b]) => {
                let (d, k) = s.delivered_at_last_arrival;
                let per_min = |n: u64| n as f64 / (b - a) * 60.0;
                (Some(per_min(d)), Some(per_min(k)))
            }
            None => (None, None),
        };
        let merge_mean = |sum: f64, n: u64| if n > 0 { sum / n as f64 } else { 0.0 };
        LoopSummary {
            gate: self.gate.name.clone(),
            new_parts: s.new_parts,
            passes: s.passes,
            fates: s.fates,
            purity: if delivered > 0 {
                s.fates.delivered_ok as f64 / delivered as f64
            } else {
                0.0
            },
            purity_ci95: wilson_interval(s.fates.delivered_ok, delivered),
            yield_per_pass: if s.passes > 0 {
                delivered as f64 / s.passes as f64
            } else {
                0.0
            },
            passes_per_delivered: PassesSummary {
                mean: mean_passes,
                counts: s.passes_of_delivered.clone(),
            },
            gate_counts: s.gate,
            recirculated: s.recirculated,
            blocked: s.blocked,
            steady_window_s: window,
            delivered_per_min: delivered_rate,
            oriented_per_min: ok_rate,
            return_load: level(&self.return_load),
            buffer: level(&self.buffer_level),
            merge_wait_s: MergeWait {
                new: merge_mean(s.merge_wait_new_s, s.merge_new),
                returning: merge_mean(s.merge_wait_return_s, s.merge_returns),
            },
            output_analysis: self.output_analysis(),
            series: Series {
                bin_s: s.bin_s,
                delivered: s.delivered_bins.clone(),
                oriented: s.ok_bins.clone(),
                return_load: s.load_bins.iter().map(|a| a / s.bin_s).collect(),
                buffer: s.buffer_bins.iter().map(|a| a / s.bin_s).collect(),
            },
        }
    }
}

/// A level over the run: its time average and largest value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LevelSummary {
    /// Time average over the run.
    pub mean: f64,
    /// Largest value.
    pub max: u64,
}

/// Passes per delivered part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassesSummary {
    /// Mean passes of the delivered parts.
    pub mean: f64,
    /// `counts[k]`: delivered parts that made k + 1 passes.
    pub counts: Vec<u64>,
}

/// Mean wait at the merge (s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MergeWait {
    /// Of the new parts.
    pub new: f64,
    /// Of the returning parts, from their arrival at the buffer.
    pub returning: f64,
}

/// Deliveries over time, in bins.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Series {
    /// Bin width (s).
    pub bin_s: f64,
    /// Parts delivered per bin.
    pub delivered: Vec<u64>,
    /// Parts delivered in the goal per bin.
    pub oriented: Vec<u64>,
    /// Time-average parts on the return path per bin.
    pub return_load: Vec<f64>,
    /// Time-average parts waiting at the merge per bin.
    pub buffer: Vec<f64>,
}

/// The closed loop's block of a run's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoopSummary {
    /// The gate's name.
    pub gate: String,
    /// New parts fed.
    pub new_parts: u64,
    /// Passes (entries onto the belt).
    pub passes: u64,
    /// Where the new parts ended.
    pub fates: Fates,
    /// Delivered parts in the goal / delivered parts.
    pub purity: f64,
    /// 95% Wilson interval of the purity.
    pub purity_ci95: [f64; 2],
    /// Passes that ended delivered / passes.
    pub yield_per_pass: f64,
    /// Passes per delivered part.
    pub passes_per_delivered: PassesSummary,
    /// What the gate did.
    pub gate_counts: GateCounts,
    /// Parts sent round again.
    pub recirculated: u64,
    /// Returning parts that found the buffer full and waited on the conveyor.
    pub blocked: u64,
    /// [first delivery, last new arrival] (s): the window of the rates below.
    pub steady_window_s: Option<[f64; 2]>,
    /// Parts delivered per minute over the steady window.
    pub delivered_per_min: Option<f64>,
    /// Parts delivered in the goal per minute over the steady window.
    pub oriented_per_min: Option<f64>,
    /// Parts on the return path (conveyor, buffer and blocked).
    pub return_load: LevelSummary,
    /// Parts waiting at the merge's buffer (and blocked behind it).
    pub buffer: LevelSummary,
    /// Mean waits at the merge.
    pub merge_wait_s: MergeWait,
    /// Warm-up and the steady rates' and system time's intervals (MSER-5, batch means).
    pub output_analysis: OutputAnalysis,
    /// Deliveries over time.
    pub series: Series,
}

/// A steady-state mean and its 95% batch-means interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SteadyMean {
    /// The mean over the kept observations.
    pub mean: f64,
    /// Its 95% interval (Student t over the batch means).
    pub ci95: [f64; 2],
    /// Batches the interval was formed from.
    pub batches: usize,
}

impl SteadyMean {
    fn of(series: &[f64], scale: f64) -> Option<SteadyMean> {
        let b = crate::statistics::batch_means(series, OUTPUT_BATCHES);
        (b.batches >= 2).then(|| SteadyMean {
            mean: b.mean * scale,
            ci95: [b.ci95[0] * scale, b.ci95[1] * scale],
            batches: b.batches,
        })
    }
}

/// Batches of the batch-means intervals (Law & Kelton recommend 10 to 30).
const OUTPUT_BATCHES: usize = 20;

/// The loop's output analysis: the warm-up MSER-5 finds in the deliveries per bin (up to the
/// last new arrival: the drain after it is not steady), and over the bins after it the delivered
/// and oriented rates with batch-means intervals; the system time (first arrival to delivery) of
/// the parts delivered after the warm-up, likewise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OutputAnalysis {
    /// The warm-up MSER-5 truncates (s from the first arrival).
    pub warm_up_s: f64,
    /// `reliable`, `too_short` (fewer than 10 batches of five bins) or `at_search_edge` (the
    /// minimum is at half the series: run longer).
    pub warm_up_verdict: &'static str,
    /// Delivered parts per minute after the warm-up.
    pub delivered_per_min: Option<SteadyMean>,
    /// Delivered parts in the goal per minute after the warm-up.
    pub oriented_per_min: Option<SteadyMean>,
    /// Time in the system of the parts delivered after the warm-up (s).
    pub system_time_s: Option<SteadyMean>,
}
