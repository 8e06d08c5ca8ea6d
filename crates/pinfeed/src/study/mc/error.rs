//! Why a Monte Carlo study could not be loaded, run, sharded or merged.

use super::sample::SampleError;
use super::shard::ShardPointError;
use super::tally::TallyMergeError;
use crate::engine::EngineError;
use crate::scenario::{InvalidScenario, ScenarioError};
use std::path::PathBuf;
use thiserror::Error;

/// Errors of the Monte Carlo study.
#[derive(Debug, Error)]
pub enum StudyError {
    /// The study file could not be read.
    /// (The cause is in the message, not a `source`, so that it is printed once.)
    #[error("{}: cannot read the study: {error}{hint}", path.display())]
    Io {
        /// The study file.
        path: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
        /// What the user may have meant (`; did you mean …`), or empty.
        hint: String,
    },
    /// A located problem in the study file (file:line:column, key, what is allowed).
    #[error("{0}")]
    Invalid(Box<InvalidScenario>),
    /// The scenario the study points at is invalid.
    #[error("{0}")]
    Scenario(ScenarioError),
    /// A sample could not be drawn (e.g. a shape tolerance so large that no valid polygon comes out).
    #[error("sample {sample} of sweep point {point}: {reason}")]
    Sample {
        /// Index of the sweep point (0-based).
        point: usize,
        /// Index of the sample within its sweep point (0-based).
        sample: u64,
        /// Why no valid sample came out.
        reason: Box<SampleError>,
    },
    /// The line engine refused a sample.
    #[error("sample {sample} of sweep point {point}: {source}")]
    Engine {
        /// Index of the sweep point (0-based).
        point: usize,
        /// Index of the sample within its sweep point (0-based).
        sample: u64,
        /// What the engine refused.
        #[source]
        source: EngineError,
    },
    /// The worker threads could not be started.
    #[error("cannot start {threads} worker threads: {reason}")]
    Threads {
        /// The number of threads asked for.
        threads: usize,
        /// Why the thread pool could not be built.
        reason: String,
    },
    /// A shard file or a set of shard files that cannot be used.
    #[error("{0}")]
    Shard(String),
    /// A point of a shard file whose counts do not hang together.
    /// (The cause is in the message, not a `source`, so that it is printed once.)
    #[error("{}: {error}", path.display())]
    ShardPoint {
        /// The shard file.
        path: PathBuf,
        /// What is wrong with the point.
        error: ShardPointError,
    },
    /// A shard file whose tally of a point cannot be added to the other shards'.
    /// (The cause is in the message, not a `source`, so that it is printed once.)
    #[error("{}: {error}", path.display())]
    ShardMerge {
        /// The shard file.
        path: PathBuf,
        /// Why the tallies do not add.
        error: TallyMergeError,
    },
}

impl StudyError {
    /// The located details of an invalid study file.
    pub fn invalid(&self) -> Option<&InvalidScenario> {
        match self {
            StudyError::Invalid(i) => Some(i),
            _ => None,
        }
    }
}

impl From<ScenarioError> for StudyError {
    /// A located error built with the scenario machinery on the *study* file.
    fn from(e: ScenarioError) -> StudyError {
        match e {
            ScenarioError::Invalid(i) => StudyError::Invalid(i),
            other => StudyError::Scenario(other),
        }
    }
}
