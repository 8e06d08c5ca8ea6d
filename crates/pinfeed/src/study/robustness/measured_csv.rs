//! Measured-band CSV files for the robustness runs of `pinfeed validate` and `pinfeed calibrate`:
//! 1–6 rows of the bundled data sets (tests/fixtures/validate/*.csv, with and without the part
//! column, with a quoted vertex list) with 0–3 mutations of the text ([`CsvMutation`]: a field set
//! to an extreme number, an input state, a part or a trial count; a field dropped or added; a row
//! duplicated; the header dropped or its columns swapped; a UTF-8 byte-order mark; CRLF line ends;
//! an open quote; truncation).

use crate::random::ChaCha8Rng;
use rand::RngExt;

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
        /// Data row (modulo their number).
        row: usize,
        /// Column (modulo their number).
        col: usize,
        /// Picks the new value among the column's candidates.
        value: usize,
    },
    /// Remove field `col` of data row `row`.
    DropField {
        /// Data row (modulo their number).
        row: usize,
        /// Column (modulo the row's fields).
        col: usize,
    },
    /// Append a field to data row `row`.
    AddField {
        /// Data row (modulo their number).
        row: usize,
    },
    /// Insert a second copy of data row `row`.
    DuplicateRow {
        /// Data row (modulo their number).
        row: usize,
    },
    /// Remove the header line.
    DropHeader,
    /// Swap header fields `a` and `b`.
    SwapHeader {
        /// First header field (modulo their number).
        a: usize,
        /// Second header field (modulo their number).
        b: usize,
    },
    /// Start the file with a UTF-8 byte-order mark.
    ByteOrderMark,
    /// End lines with CRLF.
    Crlf,
    /// Start data row `row` with an unclosed quote.
    OpenQuote {
        /// Data row (modulo their number).
        row: usize,
    },
    /// Keep the first `permille`/1000 of the file.
    Truncate {
        /// Thousandths of the file kept, in [0, 1000).
        permille: u32,
    },
}

impl CsvMutation {
    /// A random mutation.
    pub fn random(rng: &mut ChaCha8Rng) -> CsvMutation {
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

/// A random measured-band CSV text: seed rows with random mutations applied.
pub fn random_text(rng: &mut ChaCha8Rng) -> String {
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
    text
}
