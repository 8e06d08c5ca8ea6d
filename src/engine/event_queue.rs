//! The time-ordered event queue (SPEC §7): events pop in increasing time; events at the same time
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
    Arrival { part: u64 },
    /// Part `part` first touches obstacle `obstacle`.
    ContactBegin { part: u64, obstacle: u32 },
    /// The contact of `part` with `obstacle` ends (the pin has passed, or the contact model stopped).
    ContactEnd { part: u64, obstacle: u32 },
    /// Part `part`'s centroid reaches the end of the belt.
    Exit { part: u64 },
    /// Parts `first` < `second` overlap.
    Collision { first: u64, second: u64 },
}

/// A scheduled event.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Event {
    /// Seconds since the first arrival.
    pub time: f64,
    /// Order of scheduling; breaks ties in time.
    pub seq: u64,
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
#[derive(Debug, Default)]
pub struct EventQueue {
    heap: BinaryHeap<Event>,
    next_seq: u64,
    scheduled: u64,
}

impl EventQueue {
    pub fn new() -> EventQueue {
        EventQueue::default()
    }

    /// Schedule `kind` at `time` (seconds; finite). Returns the event's sequence number.
    pub fn schedule(&mut self, time: f64, kind: EventKind) -> u64 {
        assert!(
            time.is_finite(),
            "event time must be finite: {kind:?} at {time}"
        );
        let seq = self.next_seq;
        self.next_seq += 1;
        self.scheduled += 1;
        self.heap.push(Event { time, seq, kind });
        seq
    }

    /// The earliest event (lowest sequence number among equal times).
    pub fn pop(&mut self) -> Option<Event> {
        self.heap.pop()
    }

    pub fn len(&self) -> usize {
        self.heap.len()
    }

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
}
