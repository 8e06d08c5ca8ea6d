//! The feeder line: a discrete-event engine that streams randomly posed parts through a scene of
//! pins and fences, calls the contact model at each encounter and measures throughput and
//! orientation success (docs/physics.md#fences, #the-line; the data flow of the crate docs in `src/lib.rs`).
//!
//! The run's state and its inputs:
//!
//! * [`event_queue`]: events ordered by (time, sequence number);
//! * `state`: the run state by concern: the belt (event queue, parts on it, finished count) and
//!   the sinks (metrics, records, event log, sample paths, captured pushes, last end);
//! * [`part_stream`]: part i drawn from its own random stream (seed, i);
//! * [`motion`]: a part riding the belt or held by a pin or fence, and its pose at any time;
//! * [`overlap`]: clearance between parts and obstacles, and the first touch over a time window;
//! * [`results`]: what a run takes ([`RunOptions`]) and gives ([`RunResult`]);
//! * [`prepare`]: what a scene needs built before it runs (the online controller's model);
//! * [`outcome`]: the classes a part can end in;
//! * [`metrics`]: counts, rates, latency histogram, per-obstacle statistics, work counters and the
//!   deterministic [`Summary`];
//! * [`controller`]: the controller's state (the dynamic pins' timelines and command queues) and
//!   what it reports; `actuator`: a dynamic pin's timeline; [`online`]: the online controller's
//!   model;
//! * [`sensing`]: a sensor pin's reading and classification of one pass;
//! * [`sequential`]: `run --precision`, the rule that stops the feed once the rate is known;
//! * [`trace`]: the event trace (`run --trace`), noted as the stages go.
//!
//! The event loop ([`mod@line`]) dispatches each event to its stage; each stage is a function
//! whose signature names the pieces of the run state it reads and writes. In the order a part
//! meets them:
//!
//! * `arrival`: a part enters (drawn from the feed, or a forced entry) and the next arrival is
//!   scheduled;
//! * `plan`: the next event of a free part (first touch of an obstacle, else the exit), and a
//!   part put (back) on the belt;
//! * [`pairs`]: part–part overlap checks (broad and narrow phase) after each change of motion;
//! * [`contact`]: contact begin: the push, its stop, grazes, neighbouring obstacles and the belt's
//!   edges, and the decision a sensor pin's reading schedules;
//! * [`contact_map`]: the map tier's lookup of a push (else the exact contact model);
//! * `reading`: a sensor pin reads and classifies the push;
//! * `contact_end`: the push is over: the part is taken off or rides on;
//! * `exit`: a part leaves at the belt's end and is classified; any stage takes a part off the
//!   line through its `finish`;
//! * `decision`: a sensor's decision reaches the rule-table controller, which queues commands;
//! * `online_decide`: the online controller's belief (prior at arrival, readings, passes without
//!   contact) and its decision;
//! * `serve`: the dynamic pins carry out queued commands in the parts' order, and the parts
//!   near a pin that moved are planned again.

pub(crate) mod actuator;
mod arrival;
pub mod closed_loop;
pub mod contact;
mod contact_end;
pub mod contact_map;
pub mod controller;
mod decision;
pub mod event_queue;
mod exit;
pub mod line;
pub mod metrics;
pub mod motion;
pub mod online;
mod online_decide;
pub mod outcome;
pub mod overlap;
pub mod pairs;
pub mod part_stream;
mod plan;
pub mod prepare;
mod reading;
pub mod results;
pub mod sensing;
pub mod sequential;
mod serve;
mod state;
pub mod trace;

pub use line::{run, run_capturing, run_entry, run_single, Entry, SingleRun};
pub use metrics::Summary;
pub use outcome::{Cause, OutcomeCounts, PartOutcome};
pub use results::{CapturedPush, EngineError, PartRecord, RunOptions, RunResult, SamplePath};
