//! The time-ordered event queue (docs/physics.md#the-line): events pop in increasing time; events at the same time
//! pop in the order they were scheduled (a sequence number), so a run is a pure function of
//! (scene, seed) with no dependence on heap internals.
//!
//! Event kinds cover the passive line: arrival, contact begin and end, exit, and part–part
//! collision. Sensors, a controller and moving pins will add their own kinds (a sensor reading, a
//! decision, an actuation) to [`EventKind`]; the queue and its ordering stay as they are.

use serde::Serialize;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// What happens at an event. Parts and obstacles are indices into the run's tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EventKind {
    /// Part `part` enters the belt at x = 0.
    Arrival {
        /// Index of the part in the stream.
        part: u64,
    },
    /// Part `part` first touches obstacle `obstacle`.
    ContactBegin {
        /// Index of the part in the stream.
        part: u64,
        /// Index of the obstacle in `Scene::obstacles`.
        obstacle: u32,
    },
    /// The contact of `part` with `obstacle` ends (the pin has passed, or the contact model stopped).
    ContactEnd {
        /// Index of the part in the stream.
        part: u64,
        /// Index of the obstacle in `Scene::obstacles`.
        obstacle: u32,
    },
    /// Part `part`'s centroid reaches the end of the belt.
    Exit {
        /// Index of the part in the stream.
        part: u64,
    },
    /// Parts `first` < `second` overlap.
    Collision {
        /// The lower part index.
        first: u64,
        /// The higher part index.
        second: u64,
    },
    /// Sensor pin `obstacle`'s decision on `part` reaches the controller (after its latency):
    /// hypothesis index, or `u32::MAX` for no decision.
    Decision {
        /// Index of the part in the stream.
        part: u64,
        /// Index of the sensor pin in `Scene::obstacles`.
        obstacle: u32,
        /// Index into the sensor's hypotheses, or `u32::MAX` for no decision.
        hypothesis: u32,
    },
    /// A closed loop: part `part` (its number in the feed) reaches the merge's buffer off the
    /// return conveyor.
    Return {
        /// Number of the part in the feed.
        part: u64,
    },
    /// A closed loop: the merge is free to let the next waiting part onto the belt.
    MergeFree,
    /// The online controller asks whether part `part` has gone past sensor pin `obstacle`
    /// without touching it (evidence for the part's belief).
    Unread {
        /// Index of the part in the stream.
        part: u64,
        /// Index of the sensor pin in `Scene::obstacles`.
        obstacle: u32,
    },
}

/// A scheduled event.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Event {
    /// Seconds since the first arrival.
    pub time: f64,
    /// Order of scheduling; breaks ties in time.
    pub seq: u64,
    /// What happens.
    pub kind: EventKind,
}

impl Eq for Event {}

impl Ord for Event {
    /// Reversed so that `BinaryHeap` (a max-heap) pops the earliest event, then the lowest seq.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .time
            .total_cmp(&self.time)
            .then_with(|| other.seq.cmp(&self.seq))
    }
}

impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// A min-queue of events by (time, sequence number).
///
/// Defence in depth: an event at a non-finite time (which validated scenarios never produce) is
/// not queued; it is counted and the first one kept, and the engine stops the run with
/// [`super::EngineError::NonFiniteTime`] instead of panicking or looping.
#[derive(Debug, Default)]
pub struct EventQueue {
    heap: BinaryHeap<Event>,
    next_seq: u64,
    scheduled: u64,
    refused: u64,
    first_refused: Option<(f64, EventKind)>,
}

impl EventQueue {
    /// An empty queue.
    pub fn new() -> EventQueue {
        EventQueue::default()
    }

    /// Schedule `kind` at `time` (seconds). Returns the event's sequence number, or None when
    /// `time` is not finite: the event is then refused and counted ([`EventQueue::refused`]).
    pub fn schedule(&mut self, time: f64, kind: EventKind) -> Option<u64> {
        if !time.is_finite() {
            self.refused += 1;
            self.first_refused.get_or_insert((time, kind));
            return None;
        }
        let seq = self.next_seq;
        self.next_seq += 1;
        self.scheduled += 1;
        self.heap.push(Event { time, seq, kind });
        Some(seq)
    }

    /// Events refused because their time was not finite.
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// The first refused event: its time and kind.
    pub fn first_refused(&self) -> Option<(f64, EventKind)> {
        self.first_refused
    }

    /// The sequence number the next scheduled event will get.
    pub fn next_seq(&self) -> u64 {
        self.next_seq
    }

    /// The earliest event (lowest sequence number among equal times).
    pub fn pop(&mut self) -> Option<Event> {
        self.heap.pop()
    }

    /// Events waiting in the queue.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Is no event waiting?
    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }

    /// Events scheduled so far.
    pub fn scheduled(&self) -> u64 {
        self.scheduled
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_time_order_with_ties_in_scheduling_order() {
        let mut q = EventQueue::new();
        q.schedule(2.0, EventKind::Exit { part: 0 });
        q.schedule(1.0, EventKind::Exit { part: 1 });
        q.schedule(2.0, EventKind::Exit { part: 2 });
        q.schedule(0.5, EventKind::Exit { part: 3 });
        q.schedule(2.0, EventKind::Arrival { part: 4 });
        q.schedule(1.0, EventKind::Exit { part: 5 });
        let order: Vec<u64> = std::iter::from_fn(|| q.pop())
            .map(|e| match e.kind {
                EventKind::Exit { part } | EventKind::Arrival { part } => part,
                _ => unreachable!(),
            })
            .collect();
        assert_eq!(order, vec![3, 1, 5, 0, 2, 4]);
    }

    #[test]
    fn negative_zero_and_zero_are_ordered_deterministically() {
        let mut q = EventQueue::new();
        q.schedule(0.0, EventKind::Exit { part: 0 });
        q.schedule(-0.0, EventKind::Exit { part: 1 });
        let a = q.pop().unwrap();
        let b = q.pop().unwrap();
        // total_cmp puts −0 before +0: the order depends only on the values, never on the heap.
        assert_eq!(a.kind, EventKind::Exit { part: 1 });
        assert_eq!(b.kind, EventKind::Exit { part: 0 });
    }

    #[test]
    fn a_non_finite_time_is_refused_and_counted() {
        let mut q = EventQueue::new();
        assert_eq!(q.schedule(1.0, EventKind::Exit { part: 0 }), Some(0));
        assert_eq!(q.schedule(f64::INFINITY, EventKind::Exit { part: 1 }), None);
        assert_eq!(q.schedule(f64::NAN, EventKind::Arrival { part: 2 }), None);
        assert_eq!((q.len(), q.refused(), q.scheduled()), (1, 2, 1));
        let (t, kind) = q.first_refused().unwrap();
        assert_eq!((t, kind), (f64::INFINITY, EventKind::Exit { part: 1 }));
    }
}
