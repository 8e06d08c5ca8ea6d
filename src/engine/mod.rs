//! The feeder line: a discrete-event engine that streams randomly posed parts through a scene of
//! pins and fences, calls the contact model at each encounter and measures throughput and
//! orientation success (SPEC §6, §7; DESIGN.md "the shape of the program").
//!
//! * [`event_queue`]: events ordered by (time, sequence number);
//! * [`part_stream`]: part i drawn from its own random stream (seed, i);
//! * [`motion`]: a part riding the belt or held by a pin or fence, and its pose at any time;
//! * [`overlap`]: clearance between parts and obstacles, and the first touch over a time window;
//! * [`line`]: the event loop, detection of collisions, multi-contacts, off-belt parts and jams;
//! * [`outcome`]: the classes a part can end in;
//! * [`metrics`]: counts, rates, latency histogram, per-obstacle statistics, work counters and the
//!   deterministic [`Summary`].

pub mod event_queue;
pub mod line;
pub mod metrics;
pub mod motion;
pub mod outcome;
pub mod overlap;
pub mod part_stream;
pub mod sensing;

pub use line::{run, EngineError, PartRecord, RunOptions, RunResult, SamplePath};
pub use metrics::Summary;
pub use outcome::{OutcomeCounts, PartOutcome};
