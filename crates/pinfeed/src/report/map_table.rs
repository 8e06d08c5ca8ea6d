//! Tables of configuration-map bands for people: one row per band B_j (final-angle interval, width,
//! mean, sd, adjusted interval mean ± sd, the θ0 runs K_j that feed it, the COM_j range and the sample
//! count) and one row per map (per d, or the fence of a fence map) for its no-contact runs NC_j. Rendered as aligned plain text for the
//! terminal or as a Markdown table for results files. Intervals [a, b] with b < a straddle 0°/360°.

use crate::maps::ConfigurationMap;

const HEADER: [&str; 10] = [
    "d",
    "band",
    "final [min, max] °",
    "width °",
    "mean °",
    "sd °",
    "adjusted [min, max] °",
    "θ0 runs (K / NC) °",
    "COM y [min, max]",
    "n",
];

fn interval(lo: f64, hi: f64, digits: usize) -> String {
    format!("[{lo:.digits$}, {hi:.digits$}]")
}

fn ranges(r: &[[f64; 2]]) -> String {
    if r.is_empty() {
        return "—".into();
    }
    r.iter()
        .map(|x| interval(x[0], x[1], 1))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The table's cells: a row per band and a row per map with no-contact runs.
fn rows(maps: &[ConfigurationMap]) -> Vec<[String; 10]> {
    let mut out = Vec::new();
    for m in maps {
        for (j, b) in m.bands.iter().enumerate() {
            out.push([
                m.label(),
                format!("B{}", j + 1),
                interval(b.final_min_deg, b.final_max_deg, 2),
                format!("{:.2}", b.width_deg),
                format!("{:.2}", b.mean_deg),
                format!("{:.2}", b.sd_deg),
                interval(b.adjusted_min_deg, b.adjusted_max_deg, 2),
                ranges(&b.initial_ranges_deg),
                interval(b.com_y_min, b.com_y_max, 3),
                b.samples.to_string(),
            ]);
        }
        let nc = m.samples.iter().filter(|s| !s.contact).count();
        if nc > 0 {
            let dash = || "—".to_string();
            out.push([
                m.label(),
                "NC".into(),
                dash(),
                dash(),
                dash(),
                dash(),
                dash(),
                ranges(&m.no_contact_ranges_deg),
                dash(),
                nc.to_string(),
            ]);
        }
    }
    out
}

/// The header: the first column names the pin maps' d, or the fence of fence maps.
fn header(maps: &[ConfigurationMap]) -> [&'static str; 10] {
    let mut h = HEADER;
    if maps.iter().any(|m| m.fence.is_some()) {
        h[0] = "map";
    }
    h
}

/// Aligned plain-text table for the terminal, a blank line between maps.
pub fn bands_text(maps: &[ConfigurationMap]) -> String {
    let rows = rows(maps);
    let lines = super::aligned::aligned_lines(&header(maps), &rows);
    let mut s = lines[0].clone();
    for (i, (r, l)) in rows.iter().zip(&lines[1..]).enumerate() {
        if i > 0 && rows[i - 1][0] != r[0] {
            s.push('\n');
        }
        s += l;
    }
    s
}

/// Markdown table for results files.
pub fn bands_markdown(maps: &[ConfigurationMap]) -> String {
    let head = header(maps);
    let mut s = format!("| {} |\n", head.join(" | "));
    s += &format!("|{}\n", "---|".repeat(head.len()));
    for r in rows(maps) {
        s += &format!("| {} |\n", r.join(" | "));
    }
    s
}

/// The text of predicted bands: `[lo, hi] mass%` per band.
pub fn predicted_bands_text(p: &crate::maps::ensemble::PredictedBands) -> String {
    p.bands
        .iter()
        .map(|b| {
            format!(
                "[{:.1}, {:.1}] {:.0}%",
                b.arc.lo,
                b.arc.hi(),
                100.0 * b.mass
            )
        })
        .collect::<Vec<_>>()
        .join("  ")
}
