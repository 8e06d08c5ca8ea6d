//! `pinfeed run --trace FILE.jsonl` (docs/outputs.md#event-trace): what happened on the line, one
//! JSON object a line, in the order the engine processed it (so in time order).
//!
//! The engine notes a [`TraceEvent`] (plain numbers, no text, nothing allocated) into a buffer
//! that exists only when a trace is asked for, and hands each to the caller's sink after every
//! queue event ([`run_traced`]); without a trace the buffer is absent and noting is one branch.
//! [`TraceFile`] writes the events as JSON lines, naming obstacles and labels, to a temporary file
//! beside the target, renamed over it only when the run and the writing have both succeeded
//! ([`crate::output`]): the trace is written whole or not at all.
//!
//! On the belt a part is known by its entry number (on an open line, its number in the feed; on a
//! closed loop with a return path, the order it entered the belt in, a returning part entering
//! again as a new entry). Every entry has exactly one beginning (`arrival`, or `reentry` for a
//! returning part) and one end: `exit` (delivered, with its outcome), `reject` (taken off by the
//! closed loop's gate) or `loss` (taken off on the belt: collision, off the belt, multi-contact,
//! jam, solver).

use super::outcome::{Cause, PartOutcome};
use super::results::{EngineError, RunOptions, RunResult};
use crate::geometry::{wrap_deg, Pose};
use crate::output::{create_parent, Staged, WriteError};
use crate::scenario::{Obstacle, Scene};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One thing that happened on the line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceEvent {
    /// Simulated time (s).
    pub t: f64,
    /// The entry it concerns (None for the return path, the merge's buffer and the feed).
    pub entry: Option<u64>,
    /// What happened.
    pub kind: TraceKind,
}

/// What happened (obstacles and hypotheses as indices into the scene).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TraceKind {
    /// New part `part` enters the belt at `pose`.
    Arrival {
        /// Its number in the feed.
        part: u64,
        /// Its world pose on entering.
        pose: Pose,
    },
    /// Part `part`, sent round by the closed loop, enters the belt again for pass `pass` (1 is
    /// its second).
    Reentry {
        /// Its number in the feed.
        part: u64,
        /// Passes made before this one.
        pass: u32,
        /// Its world pose on entering.
        pose: Pose,
    },
    /// The entry touches an obstacle and is pushed.
    ContactBegin {
        /// The obstacle's index in the scene.
        obstacle: u32,
    },
    /// The entry touches an obstacle that pushes nothing and rides on.
    Graze {
        /// The obstacle's index in the scene.
        obstacle: u32,
    },
    /// The push ends.
    ContactEnd {
        /// The obstacle's index in the scene.
        obstacle: u32,
    },
    /// A sensor pin reads the push (at its beginning; the reading is over at the contact end).
    Reading {
        /// The sensor pin's index in the scene.
        obstacle: u32,
        /// The decided hypothesis (index into the sensor's labels); None: `unknown`.
        hypothesis: Option<u32>,
    },
    /// A sensor pin's decision reaches the controller.
    Decision {
        /// The sensor pin's index in the scene.
        obstacle: u32,
        /// The hypothesis the controller acts on; None: no decision.
        hypothesis: Option<u32>,
    },
    /// Two parts touch: this entry and `other` (both are then lost).
    Collision {
        /// The other entry.
        other: u64,
    },
    /// The entry leaves at the belt's end, delivered.
    Exit {
        /// Success or wrong orientation.
        outcome: PartOutcome,
        /// Its world pose there.
        pose: Pose,
    },
    /// The closed loop's gate takes the entry off at the belt's end.
    Reject {
        /// Its world pose there.
        pose: Pose,
    },
    /// The entry is taken off the line on the belt.
    Loss {
        /// How it ended.
        outcome: PartOutcome,
        /// Why (multi-contact, jam and solver), else [`Cause::None`].
        cause: Cause,
        /// Its world pose then.
        pose: Pose,
    },
    /// Part `part` reaches the merge's buffer off the return conveyor.
    Return {
        /// Its number in the feed.
        part: u64,
    },
    /// `run --precision`: the rule held after `trials` finished parts (or deliveries); the feed
    /// sends no more.
    FeedStop {
        /// Trials (parts finished, or delivered) when it held.
        trials: u64,
    },
}

/// Run the line as [`super::run`] does, handing every [`TraceEvent`] to `trace` in order. The
/// result is the same as without the trace.
pub fn run_traced(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    trace: &mut dyn FnMut(&TraceEvent),
) -> Result<RunResult, EngineError> {
    super::line::run_with_trace(scene, opts, progress, trace)
}

/// Why a traced run failed: the run itself, or writing its trace (located at the file).
#[derive(Debug, thiserror::Error)]
pub enum TracedRunError {
    /// The run failed; no trace was written.
    #[error(transparent)]
    Run(#[from] EngineError),
    /// The trace could not be written.
    #[error("--trace: {0}")]
    Write(#[from] WriteError),
}

/// Run the line, writing its trace to `path` as JSON lines (see the module documentation):
/// whole or not at all. The file is opened before the run, so an unwritable path is refused
/// before any simulation.
pub fn run_to_file(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    path: &Path,
) -> Result<RunResult, TracedRunError> {
    let mut file = TraceFile::create(scene, path)?;
    let result = run_traced(scene, opts, progress, &mut |e| file.write(e))?;
    file.commit()?;
    Ok(result)
}

/// A trace being written: JSON lines into a temporary file beside the target.
pub struct TraceFile<'a> {
    scene: &'a Scene,
    staged: Staged,
    out: std::io::BufWriter<std::fs::File>,
    /// The first write error, reported at [`TraceFile::commit`].
    error: Option<std::io::Error>,
}

impl<'a> TraceFile<'a> {
    /// Start the trace of a run of `scene` at `path` (its folder created if need be).
    pub fn create(scene: &'a Scene, path: &Path) -> Result<TraceFile<'a>, WriteError> {
        create_parent(path)?;
        let staged = Staged::new(path);
        let located = |error| WriteError::Writing {
            path: path.to_path_buf(),
            error,
        };
        let file = std::fs::File::create(staged.tmp()).map_err(located)?;
        Ok(TraceFile {
            scene,
            staged,
            out: std::io::BufWriter::with_capacity(1 << 16, file),
            error: None,
        })
    }

    /// Write one event as a line (after a write error, nothing more is written).
    pub fn write(&mut self, e: &TraceEvent) {
        if self.error.is_some() {
            return;
        }
        let line = TraceLine::of(self.scene, e);
        let written = serde_json::to_writer(&mut self.out, &line)
            .map_err(std::io::Error::from)
            .and_then(|()| self.out.write_all(b"\n"));
        if let Err(error) = written {
            self.error = Some(error);
        }
    }

    /// Flush the trace and rename it over its target.
    pub fn commit(self) -> Result<(), WriteError> {
        let path: PathBuf = self.staged.path().to_path_buf();
        let located = |error| WriteError::Writing {
            path: path.clone(),
            error,
        };
        if let Some(error) = self.error {
            return Err(located(error));
        }
        let file = self.out.into_inner().map_err(|e| located(e.into_error()))?;
        drop(file);
        self.staged.commit().map_err(located)
    }
}

/// One line of the trace as written.
#[derive(Serialize)]
struct TraceLine<'a> {
    t: f64,
    kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    entry: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    part: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pass: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    obstacle: Option<&'a str>,
    /// Of a reading or a decision: the label, or `unknown` (a reading) / null (no decision).
    #[serde(skip_serializing_if = "Option::is_none")]
    label: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    other: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    outcome: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cause: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    trials: Option<u64>,
    /// World pose: x, y (m), θ (degrees in [0, 360)).
    #[serde(skip_serializing_if = "Option::is_none")]
    pose: Option<[f64; 3]>,
}

impl<'a> TraceLine<'a> {
    fn of(scene: &'a Scene, e: &TraceEvent) -> TraceLine<'a> {
        let mut l = TraceLine {
            t: e.t,
            kind: "",
            entry: e.entry,
            part: None,
            pass: None,
            obstacle: None,
            label: None,
            other: None,
            outcome: None,
            cause: None,
            trials: None,
            pose: None,
        };
        let name = |j: u32| Some(scene.obstacles[j as usize].name());
        let label = |j: u32, h: Option<u32>| -> Option<&'a str> {
            let Obstacle::Pin(pin) = &scene.obstacles[j as usize] else {
                return None;
            };
            let labels = &pin.sensor.as_ref()?.labels;
            Some(
                h.and_then(|h| labels.get(h as usize))
                    .map_or("unknown", |s| s.as_str()),
            )
        };
        let pose = |p: Pose| Some([p.x, p.y, wrap_deg(p.theta_rad.to_degrees())]);
        match e.kind {
            TraceKind::Arrival { part, pose: p } => {
                (l.kind, l.part, l.pass, l.pose) = ("arrival", Some(part), Some(0), pose(p));
            }
            TraceKind::Reentry {
                part,
                pass,
                pose: p,
            } => {
                (l.kind, l.part, l.pass, l.pose) = ("reentry", Some(part), Some(pass), pose(p));
            }
            TraceKind::ContactBegin { obstacle } => {
                (l.kind, l.obstacle) = ("contact_begin", name(obstacle));
            }
            TraceKind::Graze { obstacle } => (l.kind, l.obstacle) = ("graze", name(obstacle)),
            TraceKind::ContactEnd { obstacle } => {
                (l.kind, l.obstacle) = ("contact_end", name(obstacle));
            }
            TraceKind::Reading {
                obstacle,
                hypothesis,
            } => {
                l.kind = "reading";
                (l.obstacle, l.label) = (name(obstacle), label(obstacle, hypothesis));
            }
            TraceKind::Decision {
                obstacle,
                hypothesis,
            } => {
                l.kind = "decision";
                l.obstacle = name(obstacle);
                l.label = hypothesis.and_then(|h| label(obstacle, Some(h)));
            }
            TraceKind::Collision { other } => (l.kind, l.other) = ("collision", Some(other)),
            TraceKind::Exit { outcome, pose: p } => {
                (l.kind, l.outcome, l.pose) = ("exit", Some(outcome.name()), pose(p));
            }
            TraceKind::Reject { pose: p } => (l.kind, l.pose) = ("reject", pose(p)),
            TraceKind::Loss {
                outcome,
                cause,
                pose: p,
            } => {
                (l.kind, l.outcome, l.pose) = ("loss", Some(outcome.name()), pose(p));
                l.cause = (cause != Cause::None).then(|| cause.name());
            }
            TraceKind::Return { part } => (l.kind, l.part) = ("return", Some(part)),
            TraceKind::FeedStop { trials } => (l.kind, l.trials) = ("feed_stop", Some(trials)),
        }
        l
    }
}
