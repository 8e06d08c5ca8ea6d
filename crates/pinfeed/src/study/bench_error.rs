//! Why a benchmark study could not run or write its report: [`BenchError`], the error of the
//! studies behind `pinfeed bench` (`contact_cost`, `map_cost`, `line_cost`, `accuracy`,
//! `map_tier`).

use crate::geometry::PartSpecError;

/// Why a benchmark study failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A setting is out of its range (`contacts`, `repeats`, `tol`); named by its field here,
    /// by the caller's name in [`BenchError::describe`].
    #[error("{setting} must be {range}, got {got}")]
    Argument {
        /// The setting, by its field name.
        setting: &'static str,
        /// Its range, as the message says it ("between 1 and 1000", "in (0, 0.01]").
        range: &'static str,
        /// The value given.
        got: String,
    },
    /// A part of the study is not a part.
    #[error(transparent)]
    PartSpec(#[from] PartSpecError),
    /// A part the user named is not a part.
    #[error("part '{part}'")]
    Part {
        /// The name given.
        part: String,
        /// Why it is not a part.
        source: PartSpecError,
    },
    /// A part's contact model could not be built.
    #[error("{0}")]
    Model(crate::mechanics::PartModelError),
    /// The thread pool of a timing could not be built.
    #[error(transparent)]
    Threads(#[from] rayon::ThreadPoolBuildError),
    /// A configuration map could not be computed.
    #[error(transparent)]
    Maps(#[from] crate::maps::MapError),
    /// A scenario could not be loaded.
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
    /// A line could not be run.
    #[error(transparent)]
    Engine(#[from] crate::engine::EngineError),
    /// The scenario runs on the map tier, which a bare batch of its pushes would not use.
    #[error(
        "scenario '{0}' runs on the map tier: its pushes are answered by a map that a bare batch would not use (see `pinfeed bench map-tier`)"
    )]
    MapTier(String),
    /// The captured pushes, run as a batch, did not make the line's evaluations.
    #[error(
        "the batch of captured pushes made {batch} evaluations where the line made {line}: the capture is incomplete"
    )]
    IncompleteCapture {
        /// The batch's model evaluations.
        batch: u64,
        /// The line's model evaluations.
        line: u64,
    },
    /// The report could not be written.
    #[error(transparent)]
    Write(#[from] crate::output::WriteError),
}

impl BenchError {
    /// Setting `setting` (a field name) is not `range` ("between 1 and 1000"): it is `got`.
    pub fn argument(setting: &'static str, range: &'static str, got: impl ToString) -> BenchError {
        BenchError::Argument {
            setting,
            range,
            got: got.to_string(),
        }
    }

    /// The message with a setting named by `name(field)` (what the caller calls it, e.g. a flag).
    pub fn describe(&self, name: &dyn Fn(&str) -> String) -> String {
        match self {
            BenchError::Argument {
                setting,
                range,
                got,
            } => format!("{} must be {range}, got {got}", name(setting)),
            other => other.to_string(),
        }
    }
}

/// The contact model of `poly` (uniform support), its error as a [`BenchError`].
pub(crate) fn uniform_model(
    poly: &crate::geometry::Polygon,
) -> Result<crate::mechanics::PartModel, BenchError> {
    crate::mechanics::PartModel::new(poly, &crate::mechanics::Support::Uniform)
        .map_err(BenchError::Model)
}
