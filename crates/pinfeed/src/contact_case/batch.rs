//! A batch of contact cases from a CSV file (columns part,theta0,d,mu_c and optional
//! model,pin_radius,mu_s), one output row per case: `pinfeed contact --cases`.

use super::check::{check_flag_settings, check_geometry, check_inputs, check_stop_after_touch};
use super::{compile_part, parse_model, run_compiled, Case, CaseError};
use crate::geometry::{wrap_deg, Polygon};
use crate::mechanics::{ContactOutcome, PartModel};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A batch that cannot be run; a row's error names the file and line.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// The batch file could not be read.
    #[error("reading {}", path.display())]
    Read {
        /// The batch file.
        path: PathBuf,
        /// Why it could not be read.
        #[source]
        source: std::io::Error,
    },
    /// A row the CSV reader refuses (`at` is `file:line`).
    #[error("{at}: {error}")]
    Row {
        /// Where: `file:line`.
        at: String,
        /// What the reader refused.
        error: csv::Error,
    },
    /// A row's `model` field names no contact model (`at` is `file:line`).
    #[error("{at}: field 'model'")]
    RowModel {
        /// Where: `file:line`.
        at: String,
        /// Why the model is refused.
        #[source]
        source: CaseError,
    },
    /// A row's case is refused (`at` is `file:line`).
    #[error("{at}")]
    Case {
        /// Where: `file:line`.
        at: String,
        /// Why the case is refused.
        #[source]
        source: CaseError,
    },
    /// A setting of the flags is refused.
    #[error(transparent)]
    Flags(#[from] CaseError),
    /// The output CSV could not be written.
    #[error(transparent)]
    Write(#[from] csv::Error),
    /// The output could not be written.
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

/// Run every case of the CSV file `path` and write one CSV row per case to `out`. `defaults`
/// holds the settings every row takes unless the row gives its own (model, pin radius, μs) and
/// the ones only flags give (pin path, support, tolerance, fence); its part, θ0, d and μc are
/// not used. An error names a setting a row gives by its column (`column mu_c`), one of
/// `defaults` by `flag(field)` (the caller's name for that field of [`Case`]).
///
/// Every row is read and checked before any contact runs, so a refused row leaves `out` empty.
/// Rows that share a part and support share one compiled model, whose slide tables serve each μc
/// value that at least [`TABLED_ROWS`] of those rows use (`PartModel::with_slide_tables`: answers
/// agree with the untabled solve within the tolerance, docs/physics.md); the contacts then run in
/// parallel on rayon and are written in row order, so the output does not depend on the thread
/// count.
pub fn run_batch<W: std::io::Write>(
    defaults: &Case,
    path: &Path,
    out: W,
    flag: &dyn Fn(&str) -> String,
) -> Result<(), BatchError> {
    let (cases, models) = read_batch(defaults, path, flag)?;
    let outcomes: Vec<ContactOutcome> = cases
        .par_iter()
        .map(|(c, k)| {
            let (poly, model) = &models[*k];
            run_compiled(c, poly, model, false).0
        })
        .collect();
    let mut wtr = csv::Writer::from_writer(out);
    for ((c, _), out) in cases.iter().zip(&outcomes) {
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
            rotation_deg: out.rotation_rad.to_degrees(),
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

/// Rows of one part and μc that pay for that μc's slide tables: building a part's tables costs
/// about as much as 300–1 000 of its untabled contacts save (tripoly2, L-shape; `cargo bench
/// --features bench --bench contact`, `contact_batch`), so smaller groups solve untabled.
pub const TABLED_ROWS: usize = 500;

/// The μc values of one part's rows that have at least [`TABLED_ROWS`] rows.
fn tabled(mu: &[(f64, usize)]) -> Vec<f64> {
    mu.iter()
        .filter(|&&(_, n)| n >= TABLED_ROWS)
        .map(|&(m, _)| m)
        .collect()
}

/// Every case of the batch, checked, each with the index of its part's shared model.
type Batch = (Vec<(Case, usize)>, Vec<(Polygon, PartModel)>);

fn read_batch(
    defaults: &Case,
    path: &Path,
    flag: &dyn Fn(&str) -> String,
) -> Result<Batch, BatchError> {
    let text = crate::input::read_text(path).map_err(|source| BatchError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let mut index: std::collections::HashMap<String, usize> = Default::default();
    let mut models: Vec<(Polygon, PartModel)> = Vec::new();
    // Per part, each μc value with its number of rows.
    let mut mu_values: Vec<Vec<(f64, usize)>> = Vec::new();
    let mut cases = Vec::new();
    let args = defaults;
    // Flags that apply to every row are checked once, before any row (an error there is the
    // flag's, not a row's).
    check_flag_settings(args.pin_speed, args.pin_stop, args.tol, flag)?;
    check_stop_after_touch(args.pin_stop_after_touch, flag)?;
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
            _ => args.model,
        };
        let c = Case {
            part: row.part.clone(),
            theta0_deg: row.theta0,
            d: row.d,
            mu_c: row.mu_c,
            mu_s: row.mu_s.unwrap_or(args.mu_s),
            model,
            pin_radius: row.pin_radius.unwrap_or(args.pin_radius),
            ..args.clone()
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
        check_inputs(&c, &name).map_err(row_err)?;
        // Compile each distinct part once for the whole batch.
        let k = match index.get(&c.part) {
            Some(&k) => k,
            None => {
                let pm = compile_part(&c.part, &c.support).map_err(row_err)?;
                index.insert(c.part.clone(), models.len());
                models.push(pm);
                mu_values.push(Vec::new());
                models.len() - 1
            }
        };
        check_geometry(&c, &models[k].0, &name).map_err(row_err)?;
        match mu_values[k].iter_mut().find(|(m, _)| *m == c.mu_c) {
            Some((_, n)) => *n += 1,
            None => mu_values[k].push((c.mu_c, 1)),
        }
        cases.push((c, k));
    }
    let models = models
        .into_iter()
        .zip(&mu_values)
        .map(|((poly, model), mu)| (poly, model.with_slide_tables(&tabled(mu))))
        .collect();
    Ok((cases, models))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A setting named by its field.
    fn field(f: &str) -> String {
        f.to_string()
    }

    fn write_cases(name: &str, rows: &[String]) -> PathBuf {
        let p =
            std::env::temp_dir().join(format!("pinfeed-batch-{name}-{}.csv", std::process::id()));
        std::fs::write(&p, format!("part,theta0,d,mu_c\n{}\n", rows.join("\n"))).unwrap();
        p
    }

    fn run_in(threads: usize, path: &Path) -> Result<String, BatchError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut out = Vec::new();
        pool.install(|| run_batch(&Case::new("", 0.0, 0.0, 0.0), path, &mut out, &field))?;
        Ok(String::from_utf8(out).unwrap())
    }

    /// The shared, tabled models and the parallel run change neither the order nor the numbers
    /// beyond the tolerance: every row equals its own untabled single run within 1e-4°, and the
    /// output is byte-identical for one and two threads.
    #[test]
    fn a_batch_agrees_with_single_runs_for_any_thread_count() {
        let mut rows = Vec::new();
        // One group large enough for tables, two solved untabled.
        let groups = [
            ("tripoly1", 0.3, 12),
            ("tripoly2", 0.5, TABLED_ROWS),
            ("tripoly2", 0.7, 12),
        ];
        for (part, mu, n) in groups {
            for i in 0..n {
                let theta = (137.5 * i as f64 + 7.0) % 360.0;
                let d = -0.6 + 1.2 * ((i * 37 % n) as f64) / n as f64;
                rows.push(format!("{part},{theta},{d},{mu}"));
            }
        }
        let path = write_cases("agree", &rows);
        let one = run_in(1, &path).unwrap();
        let two = run_in(2, &path).unwrap();
        assert_eq!(one, two);
        let mut rdr = csv::Reader::from_reader(one.as_bytes());
        let mut n = 0;
        let (mut tabled_evals, mut untabled_evals) = (0u64, 0u64);
        for (rec, row) in rdr.records().zip(&rows) {
            let rec = rec.unwrap();
            let f: Vec<&str> = row.split(',').collect();
            let num = |k: usize| f[k].parse::<f64>().unwrap();
            let c = Case::new(f[0], num(1), num(2), num(3));
            let (poly, model) = compile_part(&c.part, &c.support).unwrap();
            let (single, _) = run_compiled(&c, &poly, &model, false);
            let batch: f64 = rec[8].parse().unwrap();
            let want = wrap_deg(single.pose_final.theta_rad.to_degrees());
            let diff = (batch - want + 180.0).rem_euclid(360.0) - 180.0;
            assert!(diff.abs() < 1e-4, "{row}: batch {batch}, single {want}");
            assert_eq!(&rec[15], single.status.name(), "{row}");
            if c.part == "tripoly2" && c.mu_c == 0.5 {
                tabled_evals += rec[14].parse::<u64>().unwrap();
                untabled_evals += single.evaluations;
            } else {
                assert_eq!(rec[14].parse::<u64>().unwrap(), single.evaluations, "{row}");
            }
            n += 1;
        }
        assert_eq!(n, rows.len());
        // The large group's slides came from tables: far fewer model evaluations.
        assert!(
            2 * tabled_evals < untabled_evals,
            "{tabled_evals} {untabled_evals}"
        );
        std::fs::remove_file(&path).unwrap();
    }

    /// A refused row anywhere refuses the whole batch before any contact is written.
    #[test]
    fn a_bad_last_row_leaves_the_output_empty() {
        let rows = vec![
            "tripoly2,90,0.3,0.5".to_string(),
            "tripoly2,90,0.3,-1".to_string(),
        ];
        let path = write_cases("bad", &rows);
        let mut out = Vec::new();
        let e = run_batch(&Case::new("", 0.0, 0.0, 0.0), &path, &mut out, &field)
            .unwrap_err()
            .to_string();
        assert!(e.contains(":3"), "{e}");
        assert!(out.is_empty());
        std::fs::remove_file(&path).unwrap();
    }
}
