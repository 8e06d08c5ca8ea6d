//! The feeder line as a discrete-event simulation (docs/physics.md#the-line; the data flow in `src/lib.rs`).
//!
//! Parts arrive (periodic or Poisson, at x = 0 with a random orientation and lateral offset), ride
//! the belt, are pushed by pins and fences and leave at x = belt length. Each part is, at any time,
//! either free (riding the belt) or held (being pushed); see [`super::motion`]. Its next event is
//! always known: from a free state the first touch (belt frame) over every obstacle gives the next
//! contact begin, else the exit — for a pin the first-contact ray cast the contact model uses, for
//! a fence [`crate::mechanics::fence_first_touch`]; the earliest obstacle wins. At contact begin the
//! contact model ([`crate::mechanics::push`], [`crate::mechanics::push_fence`]) gives the whole
//! push and so the contact end. Events are processed in time order, ties by sequence number
//! ([`super::event_queue`]).
//!
//! Detection (never silent mis-simulation):
//! * **two obstacles at once**: when a push starts, each obstacle close enough to the pushing one
//!   to be reached (distance between pin discs and fence segments ≤ 2a, precomputed per scene) is
//!   checked against the part's recorded path during the push; a touch ends the push there as
//!   `multi_contact`. The contact model itself reports a pin in a concave notch (also
//!   `multi_contact`). See [`super::contact`].
//! * **part–part overlap**: whenever a part's motion changes (arrival, contact begin, contact end),
//!   its new motion is checked against every other part on the belt over the time both motions are
//!   known (until the earlier of their next events). Every interval of time in which two parts
//!   coexist starts at such a change of one of them, so every overlap is found. A broad phase
//!   (bounding capsules in the belt frame) skips distant pairs; close pairs are resolved in time
//!   with [`super::overlap::first_touch`]. The first overlap schedules a collision event; both
//!   parts are taken off the line then, unless one of them has already gone.
//!   Only while two or more parts share the belt does this run (`work.part_part_checks`). See
//!   [`super::pairs`].
//! * **off the belt**: after a push, a centroid outside |y| ≤ width/2 means the part falls off. A
//!   fence carries parts across the belt, so during a fence push whose reach (the fence's lateral
//!   extent plus a: the centroid stays within a of the contact on the fence) crosses an edge the
//!   recorded path is checked too, and the part falls off where its centroid crosses the edge
//!   ([`super::contact`]).
//! * **jam**: an obstacle that holds the part for good: a pin still pushing it after the contact
//!   model's travel limit (cause `travel_limit`), or a fence at α + atan μf ≥ 90° against which the
//!   part stops in the world while the belt slips under it (cause `fence_angle`, docs/physics.md#fences). A real
//!   line would stop there; the simulator counts the part and takes it off at that instant, so the
//!   parts behind it are still measured.
//! * **solver**: any other failure of the contact model, with its cause.
//!
//! Every part that enters ends in exactly one class ([`super::outcome`]); the run asserts it. What a
//! run takes and gives is in [`super::results`].

use super::arrival::{arrival, merge};
use super::closed_loop::LoopState;
use super::contact::contact_begin;
use super::contact_end::contact_end;
use super::contact_map::LineMaps;
use super::controller::Control;
use super::decision::decide;
use super::event_queue::{Event, EventKind};
use super::exit::{exit, finish};
use super::online_decide::{decide_online, unread};
use super::outcome::{Cause, PartOutcome};
use super::results::{CapturedPush, EngineError, PartRecord, RunOptions, RunResult};
use super::sequential::SequentialStop;
use super::serve::serve;
use super::state::{Belt, Sinks, Touch};
use super::trace::{TraceEvent, TraceKind};
use crate::geometry::Pose;
use crate::mechanics::PartModel;
use crate::scenario::Scene;

/// The run state: the scene and options it runs, the belt, what the run has produced, the
/// controller and the map tier. [`Line::handle`] dispatches each event to its stage, which takes
/// only the pieces it reads and writes.
struct Line<'a> {
    scene: &'a Scene,
    opts: &'a RunOptions,
    /// The pending events and the parts on the belt.
    belt: Belt,
    /// Metrics, records, events, paths and captured pushes.
    sinks: Sinks,
    /// The controller and the dynamic pins' timelines (None without dynamic pins).
    control: Option<Control>,
    /// The pins' maps (None unless `[model] fidelity = "map"`).
    maps: Option<LineMaps>,
    /// A forced first part ([`run_entry`]): its pose and support instead of the feed's draw.
    entry: Option<Entry>,
}

/// One part with a given entry pose and support, for [`run_entry`].
#[derive(Debug, Clone)]
pub struct Entry {
    /// Orientation at entry (radians).
    pub theta_rad: f64,
    /// Lateral offset of the centroid at entry (m).
    pub y: f64,
    /// Position of the centroid along the belt at entry (m; 0 is the line's start). The part
    /// arrives at time 0 wherever it enters, so a start past 0 suits a line whose pins stand
    /// still (the online model's stages), not one whose pins keep time.
    pub x: f64,
    /// The part's own contact model (a tripod), else the scene's.
    pub model: Option<PartModel>,
}

/// The options of a line of one part at the scene's seed.
fn one_part(scene: &Scene, keep_records: bool) -> RunOptions {
    RunOptions {
        parts: 1,
        seed: scene.seed,
        sample_paths: 0,
        keep_records,
        online: None,
        stop: None,
    }
}

/// Run the line with one part entering as `entry` says (instead of a draw from the feed), keeping
/// its record and, with `capture`, every push it met: what the online controller's model
/// predicts a hypothesis does on the line ([`super::online`]). Same engine, same detection.
pub fn run_entry(
    scene: &Scene,
    entry: Entry,
    capture: bool,
) -> Result<(PartRecord, Vec<CapturedPush>), EngineError> {
    let opts = one_part(scene, true);
    let (mut r, captured) = run_inner(
        scene,
        &opts,
        &mut |_| {},
        capture.then(Vec::new),
        Some(entry),
        None,
    )?;
    let record = r.records.pop().expect("one part, one record");
    Ok((record, captured))
}

/// How a part entering as [`Entry`] says left a line, with no summary or record assembled: the
/// online model runs the line this way hundreds of thousands of times.
#[derive(Debug, Clone)]
pub struct SingleRun {
    /// How the part left the line.
    pub outcome: PartOutcome,
    /// The part's world pose when it left (at the belt's end when it exited).
    pub pose: Pose,
    /// Contact-model evaluations the run took (the work counter of the same name).
    pub model_evaluations: u64,
}

/// Run one part entering as `entry` says through `scene`, and return only how and where it
/// left (see [`SingleRun`]).
pub fn run_single(scene: &Scene, entry: Entry) -> Result<SingleRun, EngineError> {
    let opts = one_part(scene, false);
    let line = simulate(scene, &opts, &mut |_| {}, None, Some(entry), None)?;
    let (outcome, pose) = line.sinks.last_end.expect("one part, one end");
    Ok(SingleRun {
        outcome,
        pose,
        model_evaluations: line.sinks.metrics.work.model_evaluations,
    })
}

/// Run the line: a pure function of (scene, options). `progress` is called with the number of
/// finished parts from time to time.
///
/// ```
/// use pinfeed::engine::{run, PartOutcome, RunOptions};
/// use std::path::Path;
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/quickstart.toml");
/// let scene = pinfeed::scenario::load(&path).unwrap();
/// let opts = RunOptions { parts: 100, ..RunOptions::from_scene(&scene) };
/// let result = run(&scene, &opts, &mut |_| {}).unwrap();
/// assert_eq!(result.summary.parts_in, 100);
/// // The quickstart line orients every part.
/// assert_eq!(result.summary.outcomes.get(PartOutcome::Success), 100);
/// ```
pub fn run(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
) -> Result<RunResult, EngineError> {
    run_with(scene, opts, progress, None).map(|(r, _)| r)
}

/// As [`run`], also returning every push the line asked of the contact model (or the map tier),
/// in order: what `pinfeed bench line` runs again as a bare batch to see what the line adds.
pub fn run_capturing(
    scene: &Scene,
    opts: &RunOptions,
) -> Result<(RunResult, Vec<CapturedPush>), EngineError> {
    run_with(scene, opts, &mut |_| {}, Some(Vec::new()))
}

fn run_with(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    captured: Option<Vec<CapturedPush>>,
) -> Result<(RunResult, Vec<CapturedPush>), EngineError> {
    run_inner(scene, opts, progress, captured, None, None)
}

/// [`run`], handing every trace event to `trace` ([`super::trace::run_traced`]).
pub(super) fn run_with_trace(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    trace: &mut dyn FnMut(&TraceEvent),
) -> Result<RunResult, EngineError> {
    run_inner(scene, opts, progress, None, None, Some(trace)).map(|(r, _)| r)
}

fn run_inner(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    captured: Option<Vec<CapturedPush>>,
    entry: Option<Entry>,
    trace: Option<&mut dyn FnMut(&TraceEvent)>,
) -> Result<(RunResult, Vec<CapturedPush>), EngineError> {
    let line = simulate(scene, opts, progress, captured, entry, trace)?;
    let closed_loop =
        (line.belt.closed_loop.as_ref()).map(|l| l.summary(line.sinks.metrics.last_event));
    let sequential = line.belt.stop.as_ref().map(|s| {
        let (k, n) = line.rate_counts();
        let rate = match line.belt.closed_loop {
            Some(_) => "purity",
            None => "success_rate",
        };
        s.summary(rate, line.belt.fed, k, n)
    });
    let (sinks, mut control) = (line.sinks, line.control);
    let fidelity = match scene.map_tier {
        Some(_) => "map",
        None => scene.contact.fidelity.name(),
    };
    let mut summary = sinks.metrics.summary(&scene.name, opts.seed, fidelity);
    summary.closed_loop = closed_loop;
    summary.sequential = sequential;
    let mut control_log = Vec::new();
    if let Some(c) = control.as_mut() {
        summary.controller = Some(c.finish(summary.simulated_time_s));
        control_log = c.log.take().unwrap_or_default();
    }
    let result = RunResult {
        summary,
        metrics: sinks.metrics,
        records: sinks.records.unwrap_or_default(),
        events: sinks.events,
        paths: sinks.paths,
        control: control_log,
    };
    Ok((result, sinks.captured.unwrap_or_default()))
}

/// Process every event of the run and return the line as it ends.
fn simulate<'a>(
    scene: &'a Scene,
    opts: &'a RunOptions,
    progress: &mut dyn FnMut(u64),
    captured: Option<Vec<CapturedPush>>,
    entry: Option<Entry>,
    mut trace: Option<&mut dyn FnMut(&TraceEvent)>,
) -> Result<Line<'a>, EngineError> {
    let online = match &opts.online {
        Some(m) => Some(m.clone()),
        None => super::prepare::online_model(scene).map_err(EngineError::OnlineModel)?,
    };
    let mut line = Line {
        scene,
        opts,
        belt: Belt::new(),
        sinks: Sinks::for_scene(scene, opts.keep_records, captured),
        control: Control::new(
            scene,
            scene.effects.event_log || opts.sample_paths > 0,
            online,
        ),
        maps: LineMaps::for_scene(scene),
        entry,
    };
    // A line of one entered part returns its end, record and pushes, never a latency summary;
    // nor does it pass a closed loop's gate (the online model's passes run the line up to it).
    line.sinks.metrics.record_latency = line.entry.is_none();
    if line.entry.is_none() {
        line.belt.closed_loop = (scene.closed_loop.as_ref())
            .map(|cl| LoopState::new(cl, &scene.feed, opts.seed, opts.parts));
        line.belt.stop = opts.stop.map(SequentialStop::new);
    }
    if trace.is_some() {
        line.sinks.trace = Some(Vec::new());
    }
    if opts.parts > 0 {
        line.belt
            .queue
            .schedule(0.0, EventKind::Arrival { part: 0 });
    }
    loop {
        if let Some((time, kind)) = line.belt.queue.first_refused() {
            return Err(EngineError::NonFiniteTime {
                time,
                kind,
                refused: line.belt.queue.refused(),
            });
        }
        let Some(ev) = line.belt.queue.pop() else {
            break;
        };
        let t = ev.time;
        line.handle(ev)?;
        line.check_precision(t);
        if let (Some(buffer), Some(sink)) = (line.sinks.trace.as_mut(), trace.as_mut()) {
            buffer.drain(..).for_each(|e| sink(&e));
        }
        if line.belt.finished % 256 == 0 {
            progress(line.belt.finished);
        }
    }
    progress(line.belt.finished);
    assert!(
        line.belt.active.is_empty(),
        "parts left on the belt after the last event"
    );
    let metrics = &line.sinks.metrics;
    let diverted = line.belt.closed_loop.as_ref().map_or(0, |l| l.diverted());
    assert_eq!(
        metrics.outcomes.total() + diverted,
        metrics.parts_in,
        "conservation: every part that enters ends in exactly one class or at the gate"
    );
    let fed = line.belt.fed;
    assert!(
        fed == opts.parts || line.belt.feed_stopped(),
        "the feed sends its parts unless the precision rule stopped it"
    );
    match &line.belt.closed_loop {
        Some(l) => l.assert_conserved(fed),
        None => assert_eq!(metrics.parts_in, fed),
    }
    Ok(line)
}

impl Line<'_> {
    /// The watched rate's (successes, trials): on an open line successes / parts finished, on a
    /// closed loop delivered in the goal / delivered.
    fn rate_counts(&self) -> (u64, u64) {
        match &self.belt.closed_loop {
            Some(l) => l.purity_counts(),
            None => {
                let o = &self.sinks.metrics.outcomes;
                (o.get(PartOutcome::Success), o.total())
            }
        }
    }

    /// `run --precision`: after an event at `t`, check the rule if the trials changed; when it
    /// holds the feed stops (noted in the trace).
    fn check_precision(&mut self, t: f64) {
        if self.belt.stop.is_none() {
            return;
        }
        let (k, n) = self.rate_counts();
        if self.belt.stop.as_mut().is_some_and(|s| s.check(k, n)) {
            self.sinks.note(t, None, TraceKind::FeedStop { trials: n });
        }
    }

    /// Dispatch event `ev` to its stage; then, with a controller, serve the dynamic pins (a part
    /// that moved on may have freed one for the next command).
    fn handle(&mut self, ev: Event) -> Result<(), EngineError> {
        let Line {
            scene,
            opts,
            belt,
            sinks,
            control,
            maps,
            entry,
        } = self;
        let scene: &Scene = scene;
        if control.is_some() && belt.stale(ev.seq, &ev.kind) {
            sinks.metrics.work.stale_events += 1;
            return Ok(());
        }
        if matches!(ev.kind, EventKind::Arrival { .. }) {
            if belt.feed_stopped() {
                // `run --precision` met: the arrival scheduled before is dropped unprocessed.
                return Ok(());
            }
            belt.fed += 1;
        }
        sinks.metrics.work.events += 1;
        sinks.metrics.last_event = sinks.metrics.last_event.max(ev.time);
        if scene.effects.event_log {
            sinks.events.push(ev);
        }
        let t = ev.time;
        let touch = |part, obstacle: u32| Touch {
            t,
            part,
            obstacle: obstacle as usize,
        };
        match ev.kind {
            EventKind::Arrival { part } => {
                let control = control.as_ref();
                arrival(scene, opts, entry.take(), control, belt, sinks, t, part)?
            }
            EventKind::ContactBegin { part, obstacle } => {
                let (maps, control) = (maps.as_ref(), control.as_mut());
                let touch = touch(part, obstacle);
                contact_begin(scene, opts.seed, maps, control, belt, sinks, touch)
            }
            EventKind::ContactEnd { part, obstacle } => {
                contact_end(scene, control.as_mut(), belt, sinks, touch(part, obstacle))
            }
            EventKind::Exit { part } => exit(scene, control.as_mut(), belt, sinks, t, part),
            EventKind::Collision { first, second } => {
                if belt.active.contains_key(&first) && belt.active.contains_key(&second) {
                    let other = TraceKind::Collision { other: second };
                    sinks.note(t, Some(first), other);
                    let end = (PartOutcome::Collision, Cause::None);
                    finish(scene, control.as_mut(), belt, sinks, first, t, end);
                    finish(scene, control.as_mut(), belt, sinks, second, t, end);
                }
            }
            EventKind::Decision {
                part,
                obstacle,
                hypothesis,
            } => {
                let h = (hypothesis != u32::MAX).then_some(hypothesis);
                sinks.note(
                    t,
                    Some(part),
                    TraceKind::Decision {
                        obstacle,
                        hypothesis: h,
                    },
                );
                let work = &mut sinks.metrics.work;
                if let Some(c) = control.as_mut() {
                    let taken = if c.online_model().is_some() {
                        decide_online(scene, c, &mut belt.active, work, t, part)
                    } else {
                        let h = (hypothesis != u32::MAX).then_some(hypothesis as usize);
                        decide(scene, c, work, t, part, obstacle as usize, h);
                        true
                    };
                    // A decision taken is served at once, before the serving after every event.
                    if taken {
                        serve(scene, c, belt, work, t);
                    }
                }
            }
            EventKind::Return { part } => {
                if let Some(lp) = belt.closed_loop.as_mut() {
                    lp.returned(part, t);
                }
                sinks.note(t, None, TraceKind::Return { part });
                merge(scene, opts, control.as_ref(), belt, sinks, t)?
            }
            EventKind::MergeFree => {
                if let Some(lp) = belt.closed_loop.as_mut() {
                    lp.merge_freed();
                }
                merge(scene, opts, control.as_ref(), belt, sinks, t)?
            }
            EventKind::Unread { part, obstacle } => {
                unread(scene, control.as_mut(), belt, t, part, obstacle as usize)
            }
        }
        if let Some(c) = control.as_mut() {
            serve(scene, c, belt, &mut sinks.metrics.work, t);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quickstart() -> Scene {
        crate::scenario::load(&crate::project_path("scenarios/quickstart.toml")).unwrap()
    }

    fn entry(theta_rad: f64) -> Entry {
        Entry {
            theta_rad,
            y: 0.0,
            x: 0.0,
            model: None,
        }
    }

    /// A line without obstacles only carries the part: it leaves at the belt's end with the
    /// orientation and offset it entered with, and the contact model is never called.
    #[test]
    fn an_empty_line_carries_the_part_unchanged_and_calls_no_model() {
        let mut scene = quickstart();
        scene.obstacles.clear();
        for theta in [0.0, 1.0, 4.0] {
            let r = run_single(&scene, entry(theta)).unwrap();
            assert!(r.outcome.exited(), "{:?}", r.outcome);
            assert_eq!(r.pose.theta_rad.rem_euclid(std::f64::consts::TAU), theta);
            assert_eq!(r.pose.y, 0.0);
            assert_eq!(r.model_evaluations, 0);
        }
    }

    /// The same entry through the same line ends the same way to the bit, and a part that meets
    /// the quickstart's pins is pushed: the model is called and the orientation changes.
    #[test]
    fn a_pushed_part_ends_the_same_way_every_time() {
        let scene = quickstart();
        let a = run_single(&scene, entry(1.0)).unwrap();
        let b = run_single(&scene, entry(1.0)).unwrap();
        assert_eq!(
            (a.outcome, a.pose, a.model_evaluations),
            (b.outcome, b.pose, b.model_evaluations)
        );
        assert!(a.model_evaluations > 0);
        assert_ne!(a.pose.theta_rad.rem_euclid(std::f64::consts::TAU), 1.0);
    }

    /// A line of one entered part (an online model's pass) leaves the latency histogram empty;
    /// the same line fed from its stream records the part's latency.
    #[test]
    fn only_a_fed_line_records_latencies() {
        let scene = quickstart();
        let opts = one_part(&scene, false);
        let entered = simulate(&scene, &opts, &mut |_| {}, None, Some(entry(1.0)), None).unwrap();
        assert_eq!(entered.sinks.metrics.exits, 1);
        assert!(entered.sinks.metrics.latency_us.is_empty());
        let fed = simulate(&scene, &opts, &mut |_| {}, None, None, None).unwrap();
        assert_eq!(fed.sinks.metrics.exits, 1);
        assert_eq!(fed.sinks.metrics.latency_us.len(), 1);
    }

    /// Untraced, the run keeps no trace buffer (noting an event is one branch, nothing
    /// allocated); traced, every event reaches the sink and the buffer is left empty.
    #[test]
    fn only_a_traced_run_notes_events() {
        let scene = quickstart();
        let opts = RunOptions {
            parts: 20,
            ..RunOptions::from_scene(&scene)
        };
        let plain = simulate(&scene, &opts, &mut |_| {}, None, None, None).unwrap();
        assert!(plain.sinks.trace.is_none());
        let mut seen = Vec::new();
        let sink: &mut dyn FnMut(&TraceEvent) = &mut |e| seen.push(*e);
        let traced = simulate(&scene, &opts, &mut |_| {}, None, None, Some(sink)).unwrap();
        assert_eq!(traced.sinks.trace.as_deref(), Some(&[][..]));
        let arrivals = seen
            .iter()
            .filter(|e| matches!(e.kind, TraceKind::Arrival { .. }));
        assert_eq!(arrivals.count(), 20);
        assert_eq!(plain.sinks.metrics.work, traced.sinks.metrics.work);
    }
}
