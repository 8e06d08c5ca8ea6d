//! Measured-band CSV files and the arguments of `pinfeed validate` and `pinfeed calibrate`: 1–6
//! rows of the bundled data sets (tests/fixtures/validate/*.csv, with and without the part column,
//! with a quoted vertex list), 0–3 mutations of the text ([`CsvMutation`]: a field set to an
//! extreme number, an input state, a part or a trial count; a field dropped or added; a row
//! duplicated; the header dropped or its columns swapped; a UTF-8 byte-order mark; CRLF line ends;
//! an open quote; truncation) and a random set of the commands' flags (friction, pin radius,
//! `--uncertain`, `--part`, the score's settings, the members). Three cases in four validate with
//! at most 5 members, one in four calibrates with 10 members over the full grid. The file is read
//! from disk as the commands read it; every number of an accepted report must be finite.

use crate::cli::calibrate::CalibrateArgs;
use crate::cli::validate::ValidateArgs;
use crate::random::ChaCha8Rng;
use crate::study::robustness::{refused, shows_non_finite, CaseReport, Class, CommandCases};
use crate::validate::input::load_measured;
use clap::Parser;
use rand::RngExt;
use std::path::Path;

/// The seed files: header and data rows.
const SEEDS: [(&str, &[&str]); 3] = [
    (
        "part,d,input,min_deg,max_deg,trials",
        &[
            "tripoly1,-0.7,state:0,355.1,5.9,20",
            "tripoly1,-0.7,state:1,129.2,142.5,20",
            "tripoly1,0.4,state:2,219.4,229.7,20",
            "tripoly1,0.1,theta:60:80,167.6,179.6,",
            "tripoly1,-0.3,all,0.52,16.79,",
            "tripoly1,-0.3,all,140.65,167.30,",
            "\"vertices:0,0 36,0 8,22\",0.2,state:0,350.5,12.0,20",
        ],
    ),
    (
        "d,input,min_deg,max_deg,trials",
        &[
            "0.2,state:0,350.5,12.0,20",
            "-0.5,state:1,100,140,5",
            "0.3,all,163.21,179.48,",
            "0.9,theta:350:10,0,360,1",
        ],
    ),
    (
        "part,d,input,min_deg,max_deg",
        &[
            "tripoly2,0.3,all,12.70,39.35",
            "square,0.5,state:0,0,10",
            "rect:2:1,-0.2,theta:0:90,80,100",
        ],
    ),
];

const NUMBERS: [&str; 16] = [
    "",
    "nan",
    "inf",
    "-1",
    "0",
    "-0",
    "360",
    "360.0001",
    "1e308",
    "5e-324",
    "1.2",
    "-1.2",
    "1e-9",
    "12.5",
    "18446744073709551616",
    "x",
];
const INPUTS: [&str; 10] = [
    "state:0",
    "state:2",
    "state:9",
    "state:-1",
    "theta:0:360",
    "theta:10:5",
    "theta:a:b",
    "all",
    "bogus",
    "state:18446744073709551616",
];
const PARTS: [&str; 6] = [
    "tripoly1",
    "\"vertices:0,0 1,0 0,1\"",
    "bogus",
    "ngon:500",
    "\"rect:1e-9:1\"",
    "\"vertices:0,0 1,0\"",
];
const TRIALS: [&str; 7] = ["1", "0", "2", "1000000", "1000001", "-1", "1.5"];

/// One text mutation of a CSV file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsvMutation {
    /// Set field `col` of data row `row` to a value of the column's kind (`value` picks it).
    Field {
        row: usize,
        col: usize,
        value: usize,
    },
    DropField {
        row: usize,
        col: usize,
    },
    AddField {
        row: usize,
    },
    DuplicateRow {
        row: usize,
    },
    DropHeader,
    SwapHeader {
        a: usize,
        b: usize,
    },
    ByteOrderMark,
    Crlf,
    OpenQuote {
        row: usize,
    },
    Truncate {
        permille: u32,
    },
}

impl CsvMutation {
    fn random(rng: &mut ChaCha8Rng) -> CsvMutation {
        let row = rng.random_range(0..16usize);
        match rng.random_range(0..14u32) {
            0..=5 => CsvMutation::Field {
                row,
                col: rng.random_range(0..6),
                value: rng.random_range(0..64),
            },
            6 => CsvMutation::DropField {
                row,
                col: rng.random_range(0..6),
            },
            7 => CsvMutation::AddField { row },
            8 => CsvMutation::DuplicateRow { row },
            9 => CsvMutation::DropHeader,
            10 => CsvMutation::SwapHeader {
                a: rng.random_range(0..6),
                b: rng.random_range(0..6),
            },
            11 => [CsvMutation::ByteOrderMark, CsvMutation::Crlf][rng.random_range(0..2usize)],
            12 => CsvMutation::OpenQuote { row },
            _ => CsvMutation::Truncate {
                permille: rng.random_range(0..1000),
            },
        }
    }
}

/// Split a CSV line at commas outside double quotes (the fields keep their quotes).
fn fields(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    for c in line.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                out.last_mut().expect("one field").push(c);
            }
            ',' if !quoted => out.push(String::new()),
            _ => out.last_mut().expect("one field").push(c),
        }
    }
    out
}

/// Apply one mutation to the lines (header first).
fn apply(lines: &mut Vec<String>, m: CsvMutation) {
    // A file reduced to nothing (its header dropped) takes no more edits.
    if lines.is_empty() {
        return;
    }
    let data = lines.len().saturating_sub(1).max(1);
    let at = |row: usize| 1 + row % data;
    match m {
        CsvMutation::Field { row, col, value } => {
            let i = at(row).min(lines.len() - 1);
            let mut f = fields(&lines[i]);
            let header = fields(&lines[0]);
            let c = col % f.len();
            let name = header
                .get(c)
                .map(|h| h.trim().to_string())
                .unwrap_or_default();
            let v = match name.as_str() {
                "part" => PARTS[value % PARTS.len()],
                "input" => INPUTS[value % INPUTS.len()],
                "trials" => TRIALS[value % TRIALS.len()],
                _ => NUMBERS[value % NUMBERS.len()],
            };
            f[c] = v.to_string();
            lines[i] = f.join(",");
        }
        CsvMutation::DropField { row, col } => {
            let i = at(row).min(lines.len() - 1);
            let mut f = fields(&lines[i]);
            let c = col % f.len();
            f.remove(c);
            lines[i] = f.join(",");
        }
        CsvMutation::AddField { row } => {
            let i = at(row).min(lines.len() - 1);
            lines[i].push_str(",7");
        }
        CsvMutation::DuplicateRow { row } => {
            let i = at(row).min(lines.len() - 1);
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        CsvMutation::DropHeader => {
            if !lines.is_empty() {
                lines.remove(0);
            }
        }
        CsvMutation::SwapHeader { a, b } => {
            if let Some(h) = lines.first_mut() {
                let mut f = fields(h);
                let n = f.len();
                f.swap(a % n, b % n);
                *h = f.join(",");
            }
        }
        CsvMutation::ByteOrderMark => {
            if let Some(h) = lines.first_mut() {
                h.insert(0, '\u{feff}');
            }
        }
        CsvMutation::Crlf => {
            for l in lines.iter_mut() {
                l.push('\r');
            }
        }
        CsvMutation::OpenQuote { row } => {
            let i = at(row).min(lines.len() - 1);
            lines[i].insert(0, '"');
        }
        CsvMutation::Truncate { .. } => {}
    }
}

/// A case: the CSV text and the command's arguments (after the file name).
#[derive(Debug, Clone, PartialEq)]
pub struct CsvCase {
    pub calibrate: bool,
    pub text: String,
    pub args: Vec<String>,
}

fn pick<'a>(rng: &mut ChaCha8Rng, values: &[&'a str]) -> &'a str {
    values[rng.random_range(0..values.len())]
}

impl CsvCase {
    pub fn random(rng: &mut ChaCha8Rng) -> CsvCase {
        let (header, rows) = SEEDS[rng.random_range(0..SEEDS.len())];
        let n = rng.random_range(1..=rows.len().min(6));
        let mut lines = vec![header.to_string()];
        for _ in 0..n {
            lines.push(rows[rng.random_range(0..rows.len())].to_string());
        }
        let ms: Vec<CsvMutation> = (0..rng.random_range(0..=3usize))
            .map(|_| CsvMutation::random(rng))
            .collect();
        for &m in &ms {
            apply(&mut lines, m);
        }
        let mut text = lines.join("\n") + "\n";
        if let Some(CsvMutation::Truncate { permille }) = ms
            .iter()
            .find(|m| matches!(m, CsvMutation::Truncate { .. }))
        {
            let mut cut = text.len() * (*permille as usize) / 1000;
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            text.truncate(cut);
        }
        let calibrate = rng.random_range(0..4u32) == 0;
        let mut args: Vec<String> = Vec::new();
        let mut flag = |rng: &mut ChaCha8Rng, name: &str, values: &[&str], p: f64| {
            if rng.random::<f64>() < p {
                args.push(format!("{name}={}", pick(rng, values)));
            }
        };
        if calibrate {
            flag(rng, "--members", &["10"], 1.0);
            flag(rng, "--score-members", &["3", "5", "0"], 1.0);
            flag(rng, "--jitter", &["0", "3", "90", "91", "nan"], 0.5);
            flag(rng, "--support", &["tripod", "smooth", "uniform"], 0.3);
            flag(
                rng,
                "--mu-c-range",
                &["0.05:1", "0:10", "1:0.05", "0:0.01", "a"],
                0.3,
            );
            flag(
                rng,
                "--pin-radius-max",
                &["0.3", "1e-9", "1e3", "1e308", "0", "-1"],
                0.3,
            );
            flag(rng, "--pin-radius-sd", &["0.03", "1e-9", "0", "nan"], 0.3);
            flag(rng, "--mu-c", &["0.5", "0", "10", "11"], 0.2);
        } else {
            flag(rng, "--members", &["1", "2", "3", "5", "0", "1000001"], 1.0);
            flag(rng, "--mu-c", &["0.5", "0", "10", "11", "-1", "nan"], 0.3);
            flag(
                rng,
                "--pin-radius",
                &["0", "0.1", "10", "1e308", "-1", "inf"],
                0.3,
            );
            flag(
                rng,
                "--uncertain",
                &[
                    "mu_c=normal:0.5:0.1",
                    "pin_radius=uniform:0:0.1,jitter=2",
                    "support=tripod:0.5",
                    "support=smooth:1",
                    "mu_c=normal:0.5:-1",
                    "jitter=1e9",
                    "bogus=1",
                    "pin_radius=normal:0.12:0.03",
                    "pin_radius=normal:1e308:1",
                    "mu_c=triangular:0:0.5:1,jitter=90",
                ],
                0.5,
            );
        }
        flag(
            rng,
            "--part",
            &["tripoly1", "vertices:0,0 36,0 8,22", "bogus", "ngon:3"],
            0.2,
        );
        flag(rng, "--model", &["exact", "ellipsoid", "tip", "map"], 0.2);
        flag(rng, "--tol", &["1e-6", "1e-12", "1e-2", "0", "1"], 0.2);
        flag(rng, "--passes", &["1", "2", "0", "101"], 0.2);
        flag(rng, "--kernel", &["2", "0.01", "90", "0", "91"], 0.2);
        flag(rng, "--floor", &["0.01", "1e-9", "1", "0", "2"], 0.2);
        flag(rng, "--window", &["20", "0", "180", "181"], 0.2);
        flag(
            rng,
            "--contained-share",
            &["0.8", "0.01", "1", "0", "1.5", "nan"],
            0.2,
        );
        args.extend(["--threads=1", "--no-write"].map(String::from));
        CsvCase {
            calibrate,
            text,
            args,
        }
    }

    /// The command of a case with its file at `path`.
    pub fn command(&self, path: &Path) -> String {
        let words: Vec<String> = self
            .args
            .iter()
            .map(|a| crate::report::shell_word(a))
            .collect();
        format!(
            "pinfeed {} {} {}",
            if self.calibrate {
                "calibrate"
            } else {
                "validate"
            },
            path.display(),
            words.join(" ")
        )
    }
}

/// The cases of the csvs target, for the fuzzing driver: a case runs with its file written into
/// its folder; its input is the command line with the file's text.
pub const CASES: CommandCases = CommandCases {
    run: |rng, scratch| run(&CsvCase::random(rng), scratch),
    input: |rng| {
        let c = CsvCase::random(rng);
        format!(
            "{}\n# measured.csv:\n{}",
            c.command(Path::new("measured.csv")),
            c.text
        )
    },
};

#[derive(Parser)]
struct ValidateCommand {
    #[command(flatten)]
    args: ValidateArgs,
}

#[derive(Parser)]
struct CalibrateCommand {
    #[command(flatten)]
    args: CalibrateArgs,
}

/// Run a case with its file written into the folder `scratch`.
pub fn run(c: &CsvCase, scratch: &Path) -> CaseReport {
    let _ = std::fs::create_dir_all(scratch);
    let path = scratch.join("measured.csv");
    if let Err(e) = std::fs::write(&path, &c.text) {
        return CaseReport::with(Class::Named, format!("cannot write the file: {e}"));
    }
    let mut r = if c.calibrate {
        run_calibrate(c, &path)
    } else {
        run_validate(c, &path)
    };
    if r.class.is_problem() {
        r.detail = format!("{}: {}", c.command(&path), r.detail);
    }
    r.kind = Some(if c.calibrate { "calibrate" } else { "validate" }.into());
    r
}

fn argv(c: &CsvCase, command: &str, path: &Path) -> Vec<String> {
    let mut v = vec![command.to_string(), path.display().to_string()];
    v.extend(c.args.iter().cloned());
    v
}

fn run_validate(c: &CsvCase, path: &Path) -> CaseReport {
    let a = match ValidateCommand::try_parse_from(argv(c, "validate", path)) {
        Ok(a) => a.args,
        Err(e) => return refused(&e.to_string()),
    };
    let (score, spec, m) = match a.inputs() {
        Ok(x) => x,
        Err(e) => return refused(&format!("{e:#}")),
    };
    match crate::validate::validate(&m, &spec, a.common.seed, a.members, a.common.passes, &score) {
        Err(e) => refused(&e),
        Ok((rows, summary, _)) => {
            if shows_non_finite(&format!("{rows:?} {summary:?}")) {
                CaseReport::with(Class::NonFinite, "a row or the summary holds NaN or inf")
            } else {
                CaseReport::new(Class::Success)
            }
        }
    }
}

fn run_calibrate(c: &CsvCase, path: &Path) -> CaseReport {
    let a = match CalibrateCommand::try_parse_from(argv(c, "calibrate", path)) {
        Ok(a) => a.args,
        Err(e) => return refused(&e.to_string()),
    };
    let checked = (|| {
        let s = crate::cli::calibrate::settings(&a)?;
        let m = load_measured(&a.measured, &s.proposal(), a.common.part.as_deref())?;
        anyhow::Ok((s, m))
    })();
    let (s, m) = match checked {
        Ok(x) => x,
        Err(e) => return refused(&format!("{e:#}")),
    };
    let cal = match crate::validate::calibrate::calibrate(&m, &s) {
        Ok(cal) => cal,
        Err(e) => return refused(&e),
    };
    let fitted = s.spec_at(cal.estimate());
    let scored =
        crate::validate::validate(&m, &fitted, s.seed, a.score_members, s.passes, &s.score);
    match scored {
        Err(e) => refused(&e),
        Ok((rows, summary, _)) => {
            if shows_non_finite(&format!("{cal:?} {rows:?} {summary:?}")) {
                CaseReport::with(
                    Class::NonFinite,
                    "the calibration or the fitted score holds NaN or inf",
                )
            } else {
                CaseReport::new(Class::Success)
            }
        }
    }
}
