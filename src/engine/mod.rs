//! The feeder line: a discrete-event engine that streams randomly posed parts through a scene of
//! pins and fences, calls the contact model at each encounter and measures throughput and
//! orientation success (docs/physics.md#fences, #the-line; the data flow of the crate docs in `src/lib.rs`).
//!
//! * [`event_queue`]: events ordered by (time, sequence number);
//! * [`part_stream`]: part i drawn from its own random stream (seed, i);
//! * [`motion`]: a part riding the belt or held by a pin or fence, and its pose at any time;
//! * [`overlap`]: clearance between parts and obstacles, and the first touch over a time window;
//! * [`mod@line`]: the event loop: arrivals, the next event of a free part, contact end, exit;
//! * [`contact`]: contact begin: the push, its stop, neighbouring obstacles and the belt's edges;
//! * [`pairs`]: part–part overlap checks (broad and narrow phase);
//! * [`results`]: what a run takes ([`RunOptions`]) and gives ([`RunResult`]);
//! * [`prepare`]: what a scene needs built before it runs (the online controller's model);
//! * [`outcome`]: the classes a part can end in;
//! * [`metrics`]: counts, rates, latency histogram, per-obstacle statistics, work counters and the
//!   deterministic [`Summary`].

pub(crate) mod actuator;
pub mod contact;
pub mod contact_map;
pub mod controller;
pub mod event_queue;
pub mod line;
pub mod metrics;
pub mod motion;
pub mod online;
pub mod outcome;
pub mod overlap;
pub mod pairs;
pub mod part_stream;
pub mod prepare;
pub mod results;
pub mod sensing;

pub use line::{run, run_capturing, run_entry, run_single, Entry, SingleRun};
pub use metrics::Summary;
pub use outcome::{Cause, OutcomeCounts, PartOutcome};
pub use results::{CapturedPush, EngineError, PartRecord, RunOptions, RunResult, SamplePath};
