//! A batch of contact cases from a CSV file (columns part,theta0,d,mu_c and optional
//! model,pin_radius,mu_s), one output row per case: `pinfeed contact --cases`.

use super::check::{
    check_flag_settings, check_geometry_named, check_inputs_named, check_stop_after_touch, flag,
};
use super::{compile_part, parse_fence, parse_model, run_compiled, Case, CaseError};
use crate::geometry::{wrap_deg, Polygon};
use crate::mechanics::PartModel;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The settings every row takes unless the row gives its own (model, pin radius, μs), and the
/// ones only flags give (pin path, support, tolerance, fence).
#[derive(Debug, Clone)]
pub struct BatchDefaults {
    pub model: String,
    pub mu_s: f64,
    pub pin_radius: f64,
    pub pin_speed: f64,
    pub pin_stop: Option<f64>,
    pub pin_stop_after_touch: Option<f64>,
    pub support: String,
    pub tol: f64,
    /// `ANGLE_DEG[:LENGTH]`.
    pub fence: Option<String>,
}

/// A batch that cannot be run; a row's error names the file and line.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    #[error("reading {}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A row the CSV reader refuses (`at` is `file:line`).
    #[error("{at}: {error}")]
    Row { at: String, error: csv::Error },
    #[error("{at}: field 'model'")]
    RowModel {
        at: String,
        #[source]
        source: CaseError,
    },
    /// A row's case is refused (`at` is `file:line`).
    #[error("{at}")]
    Case {
        at: String,
        #[source]
        source: CaseError,
    },
    /// A setting of the flags is refused.
    #[error(transparent)]
    Flags(#[from] CaseError),
    #[error(transparent)]
    Write(#[from] csv::Error),
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseRow {
    part: String,
    theta0: f64,
    d: f64,
    mu_c: f64,
    model: Option<String>,
    pin_radius: Option<f64>,
    mu_s: Option<f64>,
}

#[derive(Debug, Serialize)]
struct CaseOut<'a> {
    part: &'a str,
    theta0: f64,
    d: f64,
    mu_c: f64,
    model: &'a str,
    pin_radius: f64,
    mu_s: f64,
    contact: bool,
    theta_final_deg: f64,
    rotation_deg: f64,
    com_final_x: f64,
    com_final_y: f64,
    contact_length: f64,
    segments: usize,
    evaluations: u64,
    status: &'a str,
}

/// Run every case of the CSV file `path` and write one CSV row per case to `out`.
pub fn run_batch<W: std::io::Write>(
    defaults: &BatchDefaults,
    path: &Path,
    out: W,
) -> Result<(), BatchError> {
    let text = crate::input::read_text(path).map_err(|source| BatchError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let mut wtr = csv::Writer::from_writer(out);
    let mut compiled: std::collections::HashMap<String, (Polygon, PartModel)> = Default::default();
    let args = defaults;
    let fence = args.fence.as_deref().map(parse_fence).transpose()?;
    // Flags that apply to every row are checked once, before any row (an error there is the
    // flag's, not a row's).
    check_flag_settings(args.pin_speed, args.pin_stop, args.tol, &flag)?;
    check_stop_after_touch(args.pin_stop_after_touch)?;
    for (i, row) in rdr.deserialize::<CaseRow>().enumerate() {
        let row = row.map_err(|error| {
            let line = error.position().map(|p| p.line()).unwrap_or(i as u64 + 2);
            BatchError::Row {
                at: format!("{}:{}", path.display(), line),
                error,
            }
        })?;
        let line = i + 2;
        let at = || format!("{}:{line}", path.display());
        let model = match &row.model {
            Some(m) if !m.is_empty() => {
                parse_model(m).map_err(|source| BatchError::RowModel { at: at(), source })?
            }
            _ => parse_model(&args.model)?,
        };
        let c = Case {
            part: row.part.clone(),
            theta0_deg: row.theta0,
            d: row.d,
            mu_c: row.mu_c,
            mu_s: row.mu_s.unwrap_or(args.mu_s),
            model,
            pin_radius: row.pin_radius.unwrap_or(args.pin_radius),
            pin_speed: args.pin_speed,
            pin_stop: args.pin_stop,
            pin_stop_after_touch: args.pin_stop_after_touch,
            support: args.support.clone(),
            tol: args.tol,
            fence,
        };
        // A setting given in the row is named by its column, one taken from a flag by the flag.
        let in_row = |field: &str| match field {
            "theta0" | "d" | "mu_c" => true,
            "pin_radius" => row.pin_radius.is_some(),
            "mu_s" => row.mu_s.is_some(),
            _ => false,
        };
        let name = |field: &str| {
            if in_row(field) {
                format!("column {field}")
            } else {
                flag(field)
            }
        };
        let row_err = |source| BatchError::Case { at: at(), source };
        check_inputs_named(&c, &name).map_err(row_err)?;
        // Compile each distinct part once for the whole batch.
        if !compiled.contains_key(&c.part) {
            let pm = compile_part(&c.part, &c.support).map_err(row_err)?;
            compiled.insert(c.part.clone(), pm);
        }
        let (poly, model) = &compiled[&c.part];
        check_geometry_named(&c, poly, &name).map_err(row_err)?;
        let (out, _) = run_compiled(&c, poly, model, false);
        wtr.serialize(CaseOut {
            part: &c.part,
            theta0: c.theta0_deg,
            d: c.d,
            mu_c: c.mu_c,
            model: c.model.name(),
            pin_radius: c.pin_radius,
            mu_s: c.mu_s,
            contact: out.contact,
            theta_final_deg: wrap_deg(out.pose_final.theta_rad.to_degrees()),
            rotation_deg: out.rotation.to_degrees(),
            com_final_x: out.pose_final.x,
            com_final_y: out.pose_final.y,
            contact_length: out.contact_length,
            segments: out.segments.len(),
            evaluations: out.evaluations,
            status: out.status.name(),
        })?;
    }
    wtr.flush()?;
    Ok(())
}
