//! Figures of `pinfeed sense` (SVG):
//! * [`plot_templates`]: the template ensembles per hypothesis — Fx and Fy against time since
//!   contact begin, one colour per hypothesis, every member a thin line — with one noisy reading
//!   over them (what the thesis's figures 5-5…5-9 show, from the simulator);
//! * [`plot_accuracy_noise`]: accuracy (95% interval) against the noise factor per classifier, with
//!   chance;
//! * [`plot_placement`]: mutual information against d per sensor kind, with the ceiling H(state).

use crate::output::Staged;
use crate::report::ReportResult;
use crate::sensing::evaluate::Evaluation;
use crate::sensing::placement::Placement;
use crate::sensing::reading::Reading;
use crate::sensing::templates::TemplateSet;
use plotters::prelude::*;
use std::path::Path;

/// The noisy reading drawn over the templates: the reading, the true push's contact begin (s since
/// the pass began) and its label.
pub struct Overlay<'a> {
    /// The noisy reading.
    pub reading: &'a Reading,
    /// The true push's contact begin (s since the pass began).
    pub contact_begin: f64,
    /// The true hypothesis's label.
    pub label: String,
}

/// Distinct, readable colours (then plotters' palette).
fn colour(i: usize) -> RGBAColor {
    const FIXED: [(u8, u8, u8); 6] = [
        (214, 39, 40),
        (31, 119, 180),
        (44, 160, 44),
        (255, 127, 14),
        (148, 103, 189),
        (140, 86, 75),
    ];
    match FIXED.get(i) {
        Some(&(r, g, b)) => RGBColor(r, g, b).to_rgba(),
        None => Palette99::pick(i).to_rgba(),
    }
}

/// Templates per hypothesis (Fx and Fy panels) with one reading over them.
pub fn plot_templates(
    templates: &TemplateSet,
    overlay: Option<&Overlay>,
    title: &str,
    path: &Path,
) -> ReportResult<()> {
    // Time axis (ms since contact begin): the longest template, padded.
    let mut tmax: f64 = 0.0;
    for m in templates.members.iter().flatten() {
        if let Some((b, e)) = m.span() {
            tmax = tmax.max(e - b);
        }
    }
    if tmax <= 0.0 {
        tmax = 1.0;
    }
    let pad = 0.08 * tmax;
    let (t0, t1) = (-pad, tmax + pad);
    let n = 400;
    // Curves: (hypothesis, member, [Fx, Fy] points in (ms, N)).
    type Curve = (usize, usize, [Vec<(f64, f64)>; 2]);
    let mut curves: Vec<Curve> = Vec::new();
    for (h, members) in templates.members.iter().enumerate() {
        for (m, s) in members.iter().enumerate() {
            let Some((b, _)) = s.span() else { continue };
            let mut fx = Vec::with_capacity(n + 1);
            let mut fy = Vec::with_capacity(n + 1);
            for j in 0..=n {
                let t = t0 + (t1 - t0) * j as f64 / n as f64;
                let v = s.at(b + t);
                fx.push((1e3 * t, v[0]));
                fy.push((1e3 * t, v[1]));
            }
            curves.push((h, m, [fx, fy]));
        }
    }
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (1000, 760)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(40);
    head.draw(&Text::new(
        title.to_string(),
        (15, 12),
        ("sans-serif", 17).into_font(),
    ))?;
    let panels = body.split_evenly((2, 1));
    for (c, panel) in panels.iter().enumerate() {
        let name = ["Fx", "Fy"][c];
        let mut lo = 0.0f64;
        let mut hi = 0.0f64;
        for (_, _, ch) in &curves {
            for p in &ch[c] {
                lo = lo.min(p.1);
                hi = hi.max(p.1);
            }
        }
        let mut points: Vec<(f64, f64)> = Vec::new();
        let mut marks: Vec<f64> = Vec::new();
        if let Some(o) = overlay {
            match o.reading {
                Reading::Ft(s) => {
                    for (k, v) in s.values.iter().enumerate() {
                        let t = s.time(k) - o.contact_begin;
                        if t >= t0 && t <= t1 {
                            points.push((1e3 * t, v[c]));
                            lo = lo.min(v[c]);
                            hi = hi.max(v[c]);
                        }
                    }
                }
                Reading::Timing(ct) => {
                    for &(b, e) in &ct.intervals {
                        marks.push(1e3 * (b - o.contact_begin));
                        marks.push(1e3 * (e - o.contact_begin));
                    }
                }
            }
        }
        let span = (hi - lo).max(1e-6);
        let (lo, hi) = (lo - 0.06 * span, hi + 0.06 * span);
        let mut ch = ChartBuilder::on(panel)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(65)
            .build_cartesian_2d((1e3 * t0)..(1e3 * t1), lo..hi)?;
        ch.configure_mesh()
            .x_desc("time since contact begin (ms)")
            .y_desc(format!("{name} on the pin (N)"))
            .draw()?;
        for (h, m, chs) in &curves {
            let col = colour(*h);
            let series = ch.draw_series(LineSeries::new(
                chs[c].iter().copied(),
                col.mix(0.55).stroke_width(1),
            ))?;
            if *m == 0 {
                let label = templates.labels[*h].clone();
                series
                    .label(format!(
                        "{label} ({} templates)",
                        templates.members[*h].len()
                    ))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                    });
            }
        }
        if !points.is_empty() {
            let s = ch.draw_series(points.iter().map(|&p| Circle::new(p, 2, BLACK.filled())))?;
            if let Some(o) = overlay {
                s.label(o.label.clone())
                    .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
            }
        }
        for (i, &x) in marks.iter().enumerate() {
            let s = ch.draw_series(DashedLineSeries::new(
                vec![(x, lo), (x, hi)],
                5,
                4,
                BLACK.stroke_width(1),
            ))?;
            if i == 0 {
                if let Some(o) = overlay {
                    s.label(o.label.clone()).legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1))
                    });
                }
            }
        }
        ch.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.85))
            .draw()?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}

/// Accuracy against noise factor per classifier (one point per factor, evenly spaced).
pub fn plot_accuracy_noise(ev: &Evaluation, title: &str, path: &Path) -> ReportResult<()> {
    let mut factors: Vec<f64> = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for c in &ev.cells {
        if !factors.contains(&c.noise_factor) {
            factors.push(c.noise_factor);
        }
        if !names.contains(&c.classifier) {
            names.push(c.classifier.clone());
        }
    }
    let n = factors.len().max(1);
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut ch = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 17))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.3f64..(n as f64 - 0.7), 0.0f64..101.0)?;
    let labels = factors.clone();
    ch.configure_mesh()
        .disable_x_mesh()
        .x_labels(n + 1)
        .x_label_formatter(&move |v| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
                format!("×{}", labels[i as usize])
            } else {
                String::new()
            }
        })
        .x_desc("noise (factor on the sensor's nominal white noise and timing jitter)")
        .y_desc("accuracy (%), 95% interval")
        .draw()?;
    let chance = 100.0 * ev.chance_accuracy;
    ch.draw_series(DashedLineSeries::new(
        vec![(-0.3, chance), (n as f64 - 0.7, chance)],
        6,
        4,
        BLACK.mix(0.6).stroke_width(1),
    ))?
    .label(format!("chance ({chance:.0}%)"))
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.6)));
    for (ci, name) in names.iter().enumerate() {
        let col = colour(ci);
        let off = (ci as f64 - (names.len() as f64 - 1.0) / 2.0) * 0.04;
        let pts: Vec<(f64, f64, f64, f64)> = ev
            .of(name)
            .filter_map(|c| {
                let i = factors.iter().position(|&f| f == c.noise_factor)?;
                Some((
                    i as f64 + off,
                    100.0 * c.accuracy,
                    100.0 * c.accuracy_ci95[0],
                    100.0 * c.accuracy_ci95[1],
                ))
            })
            .collect();
        for p in &pts {
            ch.draw_series(std::iter::once(PathElement::new(
                vec![(p.0, p.2), (p.0, p.3)],
                col.stroke_width(1),
            )))?;
        }
        ch.draw_series(LineSeries::new(
            pts.iter().map(|p| (p.0, p.1)),
            col.stroke_width(2),
        ))?
        .label(name.clone())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        ch.draw_series(pts.iter().map(|p| Circle::new((p.0, p.1), 4, col.filled())))?;
    }
    ch.configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()?;
    root.present()?;
    staged.commit()?;
    Ok(())
}

/// Mutual information of the best classifier against d, one line per sensor kind.
pub fn plot_placement(p: &Placement, title: &str, path: &Path) -> ReportResult<()> {
    let mut kinds: Vec<&str> = Vec::new();
    for r in &p.rows {
        if !kinds.contains(&r.sensor) {
            kinds.push(r.sensor);
        }
    }
    let (d0, d1) = p
        .grid
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| {
            (a.min(d), b.max(d))
        });
    let (d0, d1) = if d1 > d0 {
        (d0, d1)
    } else {
        (d0 - 0.1, d0 + 0.1)
    };
    let ceiling = p
        .rows
        .iter()
        .map(|r| r.state_entropy_bits)
        .fold(0.0, f64::max);
    let ymax = ceiling.max(0.1) * 1.08;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let pad = 0.03 * (d1 - d0);
    let mut ch = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 17))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d((d0 - pad)..(d1 + pad), 0.0..ymax)?;
    ch.configure_mesh()
        .x_desc("pin offset d = (y_pin − y_com)/a")
        .y_desc("mutual information I(state; decision) (bits)")
        .draw()?;
    ch.draw_series(DashedLineSeries::new(
        vec![(d0 - pad, ceiling), (d1 + pad, ceiling)],
        6,
        4,
        BLACK.mix(0.6).stroke_width(1),
    ))?
    .label(format!("H(state) = {ceiling:.2} bits"))
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.6)));
    for (ki, kind) in kinds.iter().enumerate() {
        let col = colour(ki);
        let pts: Vec<(f64, f64)> = p
            .rows
            .iter()
            .filter(|r| r.sensor == *kind)
            .map(|r| (r.d, r.mutual_information_bits))
            .collect();
        ch.draw_series(LineSeries::new(pts.iter().copied(), col.stroke_width(2)))?
            .label(format!("{kind} (best classifier per d)"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        ch.draw_series(pts.iter().map(|&q| Circle::new(q, 4, col.filled())))?;
    }
    if let Some(b) = p.best.and_then(|b| p.rows.get(b)) {
        ch.draw_series(std::iter::once(Circle::new(
            (b.d, b.mutual_information_bits),
            9,
            RED.stroke_width(2),
        )))?
        .label(format!("best: {} at d = {}", b.sensor, b.d))
        .legend(|(x, y)| Circle::new((x + 10, y), 6, RED.stroke_width(2)));
    }
    ch.configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .draw()?;
    root.present()?;
    staged.commit()?;
    Ok(())
}
