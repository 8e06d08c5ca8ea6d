//! The drawing of a survey of planned parts: each surveyed polygon to scale in its first stable state
//! (flat side down), its name, and three badges — **P** (sensorless pins orient it), **S** (pins
//! orient it only with a sensor), **F** (fences orient it) — filled when true, hollow when not.

use crate::geometry::named::part_from_spec;
use crate::report::ReportResult;
use std::fmt::Write as _;
use std::path::Path;

const CELL: f64 = 150.0;
const COLS: usize = 5;

/// Draw `rows` (part spec, [pins, sensing only, fences]) to `path`.
pub fn plot_survey(rows: &[(String, [bool; 3])], path: &Path) -> ReportResult<()> {
    let n_rows = rows.len().div_ceil(COLS).max(1);
    let (w, h) = (CELL * COLS as f64, CELL * n_rows as f64 + 40.0);
    let mut s = String::new();
    writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif">"#
    )?;
    writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#)?;
    writeln!(
        s,
        r#"<text x="10" y="24" font-size="14">P: sensorless pins orient it · S: only with a sensor · F: fences orient it (filled = yes)</text>"#
    )?;
    for (k, (spec, marks)) in rows.iter().enumerate() {
        let (cx, cy) = (
            CELL * (k % COLS) as f64 + CELL / 2.0,
            40.0 + CELL * (k / COLS) as f64 + CELL / 2.0 - 10.0,
        );
        let poly = part_from_spec(spec)?;
        let theta = poly.stable_states().first().map_or(0.0, |st| st.theta_rad);
        let pts: Vec<_> = poly.vertices().iter().map(|v| v.rotate(theta)).collect();
        let r = pts.iter().map(|p| p.norm()).fold(0.0, f64::max).max(1e-9);
        let scale = 0.36 * CELL / r;
        let d: Vec<String> = pts
            .iter()
            .map(|p| format!("{:.1},{:.1}", cx + scale * p.x, cy - scale * p.y))
            .collect();
        let fill = if marks.iter().any(|&m| m) {
            "#cfe3f7"
        } else {
            "#f3d0d0"
        };
        writeln!(
            s,
            r##"<polygon points="{}" fill="{fill}" stroke="#333" stroke-width="1.2"/>"##,
            d.join(" ")
        )?;
        writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle">{spec}</text>"#,
            cx,
            cy + CELL / 2.0 - 4.0
        )?;
        for (j, (label, on)) in ["P", "S", "F"].iter().zip(marks).enumerate() {
            let bx = cx - CELL / 2.0 + 12.0 + 20.0 * j as f64;
            let by = cy - CELL / 2.0 + 14.0;
            let (bg, fg) = if *on {
                ("#2a6fb0", "white")
            } else {
                ("white", "#999")
            };
            writeln!(
                s,
                r##"<circle cx="{bx:.1}" cy="{by:.1}" r="8" fill="{bg}" stroke="#2a6fb0"/><text x="{bx:.1}" y="{:.1}" font-size="10" text-anchor="middle" fill="{fg}">{label}</text>"##,
                by + 3.5
            )?;
        }
    }
    writeln!(s, "</svg>")?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::report::error::create_dir(dir)?;
    }
    crate::report::error::write_whole(path, s)
}
