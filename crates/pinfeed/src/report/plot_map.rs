//! SVG figures of configuration maps (thesis chapter 3):
//!
//! * [`plot_map`]: one map as θ0 against θf (the thesis's Figure 3-3): samples coloured by band,
//!   each band B_j shaded over the θ0 runs K_j that feed it, its adjusted interval (mean ± sd) as
//!   dashed lines, no-contact samples as red crosses on the diagonal with their runs NC_j drawn along
//!   it, and samples whose contact did not end `ok` ringed in black. Transitional bands (at most
//!   [`TRANSITIONAL_SAMPLES`] samples) are grey, under one legend entry; both axes are ticked
//!   every 30°.
//! * [`plot_band_intervals`]: band intervals against d for every map given (Figure 3-6), with "+"
//!   at the ends and a dot at the mean; with `adjusted` the intervals are mean ± sd (Figure 3-8),
//!   drawn over the raw ones in grey. Its orientation axis zooms on the bands
//!   (`plot_zoom`; an interval across 0°/360° is then one piece), ticked on multiples of a step
//!   that divides 360 (labels wrapped into [0, 360) read evenly, 0 where the axis crosses 360°),
//!   and its legend stands in a row above the chart, where it hides no interval.
//!
//! In the map figure, intervals straddling 0°/360° are drawn as two pieces.

use super::plot_labels::text_width;
use super::plot_zoom::{degree_axis, degree_view, DegreeAxis, DegreeView};
use crate::geometry::wrap_deg;
use crate::maps::{Band, ConfigurationMap};
use crate::output::Staged;
use crate::report::ReportResult;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::ComposedElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(188, 189, 34),
    RGBColor(227, 119, 194),
];

/// The arc that starts at `start` (degrees) and runs `width` degrees counter-clockwise, as pieces
/// inside [0, 360].
pub(crate) fn arc_pieces(start: f64, width: f64) -> Vec<(f64, f64)> {
    if width >= 360.0 {
        return vec![(0.0, 360.0)];
    }
    let lo = wrap_deg(start);
    let hi = lo + width;
    if hi <= 360.0 {
        vec![(lo, hi)]
    } else {
        vec![(lo, 360.0), (0.0, hi - 360.0)]
    }
}

/// A θ0 run [first, last] on a grid of spacing `step`, widened by half a step each side.
fn run_pieces(run: [f64; 2], step: f64) -> Vec<(f64, f64)> {
    arc_pieces(run[0] - step / 2.0, wrap_deg(run[1] - run[0]) + step)
}

fn raw_arc(b: &Band) -> Vec<(f64, f64)> {
    arc_pieces(b.final_min_deg, b.width_deg)
}

/// A chart of orientations against orientations (a configuration map).
pub(crate) type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<DegreeAxis, DegreeAxis>>;

/// A chart of orientations up against contact parameter d across ([`d_chart`]).
pub(crate) type DChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, DegreeAxis>>;

/// A white chart with a title and orientations 0°…360° on both axes, ticked every 30°.
pub(crate) fn degree_chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
    title: &str,
) -> ReportResult<Chart<'a, 'b>> {
    root.fill(&WHITE)?;
    Ok(ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(degree_axis(0.0..360.0, 13), degree_axis(0.0..360.0, 13))?)
}

/// How a legend entry in a header row ([`header_with_legend`]) is marked.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Swatch {
    /// A filled box (a shaded area).
    Filled(RGBColor),
    /// A thick line (an interval).
    Line(RGBColor),
    /// A "+" (an interval's end).
    Plus(RGBColor),
    /// A dot (a mean).
    Dot(RGBColor),
}

/// Fill `root` white and split off a header of `height` px (at least 62): `title` centred at its
/// top and, in one row below it, the legend `entries`; returns the body below the header.
pub(crate) fn header_with_legend<'a>(
    root: &DrawingArea<SVGBackend<'a>, Shift>,
    title: &str,
    entries: &[(&str, Swatch)],
    height: u32,
) -> ReportResult<DrawingArea<SVGBackend<'a>, Shift>> {
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(height.max(62));
    let centre = root.dim_in_pixel().0 as i32 / 2;
    head.draw(&Text::new(
        title.to_string(),
        (centre, 8),
        ("sans-serif", 18)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top)),
    ))?;
    let font = ("sans-serif", 12).into_font();
    let mut x = 40;
    for &(label, swatch) in entries {
        match swatch {
            Swatch::Filled(c) => head.draw(&Rectangle::new(
                [(x, 38), (x + 14, 46)],
                c.mix(0.55).filled(),
            ))?,
            Swatch::Line(c) => head.draw(&PathElement::new(
                vec![(x, 42), (x + 14, 42)],
                c.stroke_width(3),
            ))?,
            Swatch::Plus(c) => head.draw(&plus((x + 7, 42), 5, c.into()))?,
            Swatch::Dot(c) => head.draw(&Circle::new((x + 7, 42), 3, c.filled()))?,
        }
        head.draw(&Text::new(
            label.to_string(),
            (x + 20, 42),
            font.color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        // plotters draws a 12 px font about 9.7 px high: estimate at that size.
        x += 20 + text_width(label, 10.0, false) as i32 + 16;
    }
    Ok(body)
}

pub(crate) fn draw_legend<'a, 'b: 'a>(
    ch: &mut Chart<'a, 'b>,
    position: SeriesLabelPosition,
) -> ReportResult<()> {
    ch.configure_series_labels()
        .position(position)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .label_font(("sans-serif", 12))
        .draw()?;
    Ok(())
}

/// Bands of at most this many samples are *transitional*: the few θ0 where θf turns fast between
/// two real bands land apart from both (and from each other), each a band of its own. The map
/// figure draws them grey under one legend entry instead of one entry each.
pub const TRANSITIONAL_SAMPLES: usize = 2;

/// The colour of transitional samples ([`TRANSITIONAL_SAMPLES`]).
const TRANSITIONAL: RGBColor = RGBColor(128, 128, 128);

fn is_transitional(b: &Band) -> bool {
    b.samples <= TRANSITIONAL_SAMPLES
}

/// A real band's legend entry: its number (as in the band table), interval, mean ± sd.
fn band_label(j: usize, band: &Band) -> String {
    format!(
        "B{} [{:.1}°, {:.1}°], mean ± sd {:.1}° ± {:.1}°",
        j + 1,
        band.final_min_deg,
        band.final_max_deg,
        band.mean_deg,
        band.sd_deg
    )
}

/// The one legend entry of `samples` transitional samples in `bands` bands.
fn transitional_label(samples: usize, bands: usize) -> String {
    let s = if samples == 1 { "" } else { "s" };
    if samples == bands {
        format!("transitional ({samples} sample{s}, each a band of its own)")
    } else {
        format!("transitional ({samples} sample{s} in {bands} bands of ≤ {TRANSITIONAL_SAMPLES})")
    }
}

/// Draw one configuration map (θ0 against θf) into an SVG file; `step_deg` is the θ0 grid spacing.
pub fn plot_map(
    map: &ConfigurationMap,
    title: &str,
    step_deg: f64,
    path: &Path,
) -> ReportResult<()> {
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (760, 680)).into_drawing_area();
    let mut ch = degree_chart(&root, title)?;
    ch.configure_mesh()
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .light_line_style(WHITE)
        .x_desc("initial orientation θ0 (deg)")
        .y_desc("final orientation θf (deg)")
        .draw()?;
    // Colours go to the real bands in order; transitional ones are grey and share one entry.
    let mut colours = Vec::with_capacity(map.bands.len());
    let mut next = 0;
    for band in &map.bands {
        if is_transitional(band) {
            colours.push(TRANSITIONAL);
        } else {
            colours.push(PALETTE[next % PALETTE.len()]);
            next += 1;
        }
    }
    for (j, band) in map.bands.iter().enumerate() {
        let colour = colours[j];
        let runs: Vec<(f64, f64)> = band
            .initial_ranges_deg
            .iter()
            .flat_map(|&r| run_pieces(r, step_deg))
            .collect();
        let mut shades = Vec::new();
        for &(x0, x1) in &runs {
            for (y0, y1) in raw_arc(band) {
                shades.push(Rectangle::new(
                    [(x0, y0), (x1, y1)],
                    colour.mix(0.18).filled(),
                ));
            }
        }
        ch.draw_series(shades)?;
        if is_transitional(band) {
            continue;
        }
        for &(x0, x1) in &runs {
            for y in [band.adjusted_min_deg, band.adjusted_max_deg] {
                ch.draw_series(DashedLineSeries::new(
                    vec![(x0, y), (x1, y)],
                    4,
                    3,
                    colour.stroke_width(1),
                ))?;
            }
        }
        let points = map
            .samples
            .iter()
            .filter(|s| s.band == Some(j))
            .map(|s| Circle::new((s.theta0_deg, s.theta_final_deg), 2, colour.filled()));
        ch.draw_series(points)?
            .label(band_label(j, band))
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
    }
    let transitional: Vec<usize> = (0..map.bands.len())
        .filter(|&j| is_transitional(&map.bands[j]))
        .collect();
    if !transitional.is_empty() {
        let points = map
            .samples
            .iter()
            .filter(|s| s.band.is_some_and(|j| transitional.contains(&j)));
        let n = points.clone().count();
        ch.draw_series(
            points
                .map(|s| Circle::new((s.theta0_deg, s.theta_final_deg), 2, TRANSITIONAL.filled())),
        )?
        .label(transitional_label(n, transitional.len()))
        .legend(|(x, y)| Circle::new((x + 8, y), 4, TRANSITIONAL.filled()));
    }
    for r in &map.no_contact_ranges_deg {
        for (x0, x1) in run_pieces(*r, step_deg) {
            ch.draw_series(LineSeries::new(
                vec![(x0, x0), (x1, x1)],
                RED.mix(0.35).stroke_width(6),
            ))?;
        }
    }
    if map.samples.iter().any(|s| !s.contact) {
        let crosses = map
            .samples
            .iter()
            .filter(|s| !s.contact)
            .map(|s| Cross::new((s.theta0_deg, s.theta_final_deg), 3, RED));
        ch.draw_series(crosses)?
            .label("no contact (θf = θ0), runs NC_j shaded")
            .legend(|(x, y)| Cross::new((x + 8, y), 4, RED));
    }
    if map.non_ok_samples() > 0 {
        let rings = map
            .samples
            .iter()
            .filter(|s| !s.status.is_ok())
            .map(|s| Circle::new((s.theta0_deg, s.theta_final_deg), 5, BLACK));
        ch.draw_series(rings)?
            .label("contact status not ok")
            .legend(|(x, y)| Circle::new((x + 8, y), 5, BLACK));
    }
    ch.draw_series(std::iter::once(PathElement::new(
        vec![(0.0, 0.0), (0.0, 0.0)],
        WHITE,
    )))?
    .label("dashed: adjusted band mean ± sd (eq. 3-2)")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
    draw_legend(&mut ch, SeriesLabelPosition::UpperLeft)?;
    root.present()?;
    staged.commit()?;
    Ok(())
}

/// A "+" marker of half-size `r` pixels at `at` (any coordinate system).
type Plus<C, DB> = ComposedElement<C, DB, PathElement<(i32, i32)>, PathElement<(i32, i32)>>;

fn plus<C, DB: DrawingBackend>(at: C, r: i32, style: ShapeStyle) -> Plus<C, DB> {
    EmptyElement::at(at)
        + PathElement::new(vec![(-r, 0), (r, 0)], style)
        + PathElement::new(vec![(0, -r), (0, r)], style)
}

/// The orientation axis of a band figure: every band's interval and, with `adjusted`, its
/// mean ± sd, with a margin of 5° (at least 30° in all; the whole circle when the bands leave no
/// gap of 40°).
fn band_view(maps: &[ConfigurationMap], adjusted: bool) -> DegreeView {
    let arcs: Vec<(f64, f64)> = maps
        .iter()
        .flat_map(|m| &m.bands)
        .flat_map(|b| {
            let raw = (b.final_min_deg, b.width_deg.max(0.5));
            let adj = (b.mean_deg - b.sd_deg, (2.0 * b.sd_deg).max(0.5));
            std::iter::once(raw).chain(adjusted.then_some(adj))
        })
        .collect();
    degree_view(&arcs, 5.0, 30.0, 40.0)
}

/// A tick label of d: at most three decimals, trailing zeros dropped, never "-0".
fn d_label(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// A chart of orientations on `view` (up, ticked on multiples of a step dividing 360, labels
/// wrapped into [0, 360)) against contact
/// parameter d over `x`, on the body below a [`header_with_legend`].
pub(crate) fn d_chart<'a, 'b>(
    body: &'a DrawingArea<SVGBackend<'b>, Shift>,
    x: std::ops::Range<f64>,
    view: DegreeView,
    x_desc: &str,
    y_desc: &str,
) -> ReportResult<DChart<'a, 'b>> {
    let mut ch = ChartBuilder::on(body)
        .margin(14)
        .margin_top(4)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(x, degree_axis(view.lo..view.hi, 15))?;
    ch.configure_mesh()
        .y_label_formatter(&|v| DegreeView::label(*v))
        .x_label_formatter(&|v| d_label(*v))
        .light_line_style(WHITE)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()?;
    Ok(ch)
}

/// Draw the band intervals of all maps against d (Figure 3-6; with `adjusted`, Figure 3-8).
pub fn plot_band_intervals(
    maps: &[ConfigurationMap],
    adjusted: bool,
    title: &str,
    path: &Path,
) -> ReportResult<()> {
    let (mut dmin, mut dmax) = maps
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), m| {
            (lo.min(m.d), hi.max(m.d))
        });
    if !(dmin.is_finite() && dmax.is_finite()) {
        (dmin, dmax) = (-1.0, 1.0);
    }
    let pad = ((dmax - dmin) * 0.06).max(0.1);
    let view = band_view(maps, adjusted);
    let blue = PALETTE[0];
    let grey = RGBColor(185, 185, 185);
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 640)).into_drawing_area();
    let legend: Vec<(&str, Swatch)> = if adjusted {
        vec![
            ("adjusted band (mean ± sd)", Swatch::Line(blue)),
            ("raw band [min, max]", Swatch::Line(grey)),
            ("adjusted band ends", Swatch::Plus(BLACK)),
            ("band mean", Swatch::Dot(RED)),
        ]
    } else {
        vec![
            ("band [min, max]", Swatch::Line(blue)),
            ("band ends", Swatch::Plus(BLACK)),
            ("band mean", Swatch::Dot(RED)),
        ]
    };
    let body = header_with_legend(&root, title, &legend, 62)?;
    let y_desc = if adjusted {
        "adjusted band mean ± sd (deg)"
    } else {
        "final orientation band (deg)"
    };
    let mut ch = d_chart(
        &body,
        (dmin - pad)..(dmax + pad),
        view,
        "contact parameter d",
        y_desc,
    )?;
    for m in maps {
        for b in &m.bands {
            let style = if adjusted {
                grey.stroke_width(5)
            } else {
                blue.stroke_width(2)
            };
            for (y0, y1) in view.pieces(b.final_min_deg, b.width_deg) {
                ch.draw_series(LineSeries::new(vec![(m.d, y0), (m.d, y1)], style))?;
            }
            if adjusted {
                for (y0, y1) in view.pieces(b.mean_deg - b.sd_deg, 2.0 * b.sd_deg) {
                    ch.draw_series(LineSeries::new(
                        vec![(m.d, y0), (m.d, y1)],
                        blue.stroke_width(2),
                    ))?;
                }
            }
        }
    }
    let shown = |d: f64, deg: f64| view.shows(deg).then(|| (d, view.place(deg)));
    let ends = maps.iter().flat_map(|m| {
        m.bands.iter().flat_map(move |b| {
            let (lo, hi) = if adjusted {
                (b.adjusted_min_deg, b.adjusted_max_deg)
            } else {
                (b.final_min_deg, b.final_max_deg)
            };
            [shown(m.d, lo), shown(m.d, hi)]
        })
    });
    ch.draw_series(ends.flatten().map(|at| plus(at, 5, BLACK.into())))?;
    let means = maps
        .iter()
        .flat_map(|m| m.bands.iter().filter_map(move |b| shown(m.d, b.mean_deg)));
    ch.draw_series(means.map(|at| Circle::new(at, 3, RED.filled())))?;
    root.present()?;
    staged.commit()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arcs_through_zero_are_split_in_two() {
        assert_eq!(arc_pieces(350.0, 20.0), vec![(350.0, 360.0), (0.0, 10.0)]);
        assert_eq!(arc_pieces(-5.0, 3.0), vec![(355.0, 358.0)]);
        assert_eq!(arc_pieces(10.0, 400.0), vec![(0.0, 360.0)]);
        assert_eq!(
            run_pieces([359.0, 1.0], 1.0),
            vec![(358.5, 360.0), (0.0, 1.5)]
        );
    }
}
