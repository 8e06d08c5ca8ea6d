//! Why a report could not be written: [`ReportError`], the error of the library's report writers
//! (files, figures, report folders).
//!
//! Each message reads as it did when the writers returned untyped errors: a wrapping variant
//! (`writing PATH`, `creating DIR`) names what failed and keeps the cause as its source, so a
//! chain printed in full (`{:#}`) reads `writing PATH: CAUSE`.

use std::path::{Path, PathBuf};

use plotters::drawing::DrawingAreaErrorKind;

/// A report writer's result.
pub type ReportResult<T> = Result<T, ReportError>;

/// Why a report, a figure or a report file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file system operation failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// The plotting backend failed (an SVG figure).
    #[error(transparent)]
    Plot(#[from] DrawingAreaErrorKind<std::io::Error>),
    /// A document could not be serialized to JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A CSV file could not be written.
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// Text could not be formatted.
    #[error(transparent)]
    Fmt(#[from] std::fmt::Error),
    /// A report file could not be written whole.
    #[error(transparent)]
    Write(#[from] crate::output::WriteError),
    /// A part named in a figure is not a part.
    #[error(transparent)]
    Part(#[from] crate::geometry::named::PartSpecError),
    /// The plan of a figure could not be compiled or followed.
    #[error(transparent)]
    Plan(#[from] crate::plan::PlanError),
    /// A sensing trial of a figure could not be simulated.
    #[error("{0}")]
    Trial(crate::sensing::evaluate::EvaluateError),
    /// An animation would last longer than allowed at the speed-up asked for (the setting
    /// `animate_speed`, by its field name here and by the caller's in [`ReportError::describe_setting`]).
    #[error("{}", too_long("animate_speed", *speedup, *duration_s, *max_s))]
    AnimationTooLong {
        /// The speed-up asked for.
        speedup: f64,
        /// How long the animation would last, in seconds.
        duration_s: f64,
        /// The longest animation allowed, in seconds.
        max_s: f64,
    },
    /// A folder could not be created.
    #[error("creating {}", dir.display())]
    Creating {
        /// The folder.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("writing {}", path.display())]
    Writing {
        /// The file.
        path: PathBuf,
        /// Why.
        source: Box<ReportError>,
    },
    /// A figure could not be drawn.
    #[error("drawing {}", path.display())]
    Drawing {
        /// The figure's file.
        path: PathBuf,
        /// Why.
        source: Box<ReportError>,
    },
    /// A set of files written together could not be put in place in a folder.
    #[error("writing the {what} into {}", dir.display())]
    WritingInto {
        /// What was written: "results", "report".
        what: &'static str,
        /// The folder.
        dir: PathBuf,
        /// Why.
        source: Box<ReportError>,
    },
    /// The files an earlier run left in a folder could not be removed.
    #[error("removing earlier {what} from {}", dir.display())]
    Removing {
        /// What was removed: "files", "figures".
        what: &'static str,
        /// The folder.
        dir: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// The message of [`ReportError::AnimationTooLong`], the speed-up setting named `name`.
fn too_long(name: &str, speedup: f64, duration_s: f64, max_s: f64) -> String {
    format!("{name} {speedup} would make the animation last {duration_s:.0} s; at most {max_s} s (choose a larger speed-up)")
}

impl ReportError {
    /// An animation's speed-up refused: the message with the setting named by `name(field)`
    /// (what the caller calls it, e.g. a flag); `None` for every other error.
    pub fn describe_setting(&self, name: &dyn Fn(&str) -> String) -> Option<String> {
        match self {
            ReportError::AnimationTooLong {
                speedup,
                duration_s,
                max_s,
            } => Some(too_long(
                &name("animate_speed"),
                *speedup,
                *duration_s,
                *max_s,
            )),
            _ => None,
        }
    }

    /// For `map_err`: the error of creating `dir`.
    pub fn creating(dir: &Path) -> impl FnOnce(std::io::Error) -> ReportError + '_ {
        move |source| ReportError::Creating {
            dir: dir.to_path_buf(),
            source,
        }
    }

    /// For `map_err`: the error of writing `path`, for any cause.
    pub fn writing<E: Into<ReportError>>(path: &Path) -> impl FnOnce(E) -> ReportError + '_ {
        move |e| ReportError::Writing {
            path: path.to_path_buf(),
            source: Box::new(e.into()),
        }
    }

    /// For `map_err`: the error of drawing the figure `path`, for any cause.
    pub fn drawing<E: Into<ReportError>>(path: &Path) -> impl FnOnce(E) -> ReportError + '_ {
        move |e| ReportError::Drawing {
            path: path.to_path_buf(),
            source: Box::new(e.into()),
        }
    }

    /// For `map_err`: the error of putting the `what` ("results", "report") in place in `dir`.
    pub fn writing_into<'a, E: Into<ReportError>>(
        what: &'static str,
        dir: &'a Path,
    ) -> impl FnOnce(E) -> ReportError + 'a {
        move |e| ReportError::WritingInto {
            what,
            dir: dir.to_path_buf(),
            source: Box::new(e.into()),
        }
    }

    /// For `map_err`: the error of removing the earlier `what` ("files", "figures") from `dir`.
    pub fn removing<'a>(
        what: &'static str,
        dir: &'a Path,
    ) -> impl FnOnce(std::io::Error) -> ReportError + 'a {
        move |source| ReportError::Removing {
            what,
            dir: dir.to_path_buf(),
            source,
        }
    }
}

/// Create the folder `dir` (and its parents), naming it on failure.
pub fn create_dir(dir: &Path) -> ReportResult<()> {
    std::fs::create_dir_all(dir).map_err(ReportError::creating(dir))
}

/// Write `bytes` to `path` whole (see [`crate::output`]), naming the file on failure.
pub fn write_whole(path: &Path, bytes: impl AsRef<[u8]>) -> ReportResult<()> {
    crate::output::write_atomic(path, bytes).map_err(ReportError::writing(path))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// A wrapper names what failed and keeps the cause as its only source (printed in full:
    /// `writing PATH: CAUSE`, the cause once).
    #[test]
    fn a_wrapper_names_the_file_and_keeps_the_cause_as_its_source() {
        let cause = std::io::Error::other("disk full");
        let e = ReportError::writing(Path::new("out/a.svg"))(cause);
        assert_eq!(e.to_string(), "writing out/a.svg");
        let source = e.source().expect("the cause");
        assert_eq!(source.to_string(), "disk full");
        assert!(source.source().is_none());
        let e = ReportError::removing("figures", Path::new("out"))(std::io::Error::other("busy"));
        assert_eq!(e.to_string(), "removing earlier figures from out");
    }
}
