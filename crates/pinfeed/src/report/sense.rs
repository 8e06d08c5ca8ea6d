//! The reports of a sensing experiment (`pinfeed sense`, [`crate::sensing::experiment`]): the
//! terminal summary, `report.md` and the report directory with `sense.json` and the figures.

use crate::report::plot_sensing;
use crate::report::{ReportError, ReportResult};
use crate::sensing::evaluate::{trial_pass, Cell, Config, Problem, READING_STREAMS};
use crate::sensing::experiment::SenseReport;
use crate::sensing::read;
use crate::sensing::templates::TemplateSet;
use std::path::Path;

fn matrix_line(c: &Cell) -> String {
    let rows: Vec<String> = c
        .confusion
        .counts
        .iter()
        .zip(&c.confusion.labels)
        .map(|(r, l)| {
            let k = r.len() - 1;
            let v: Vec<String> = r[..k].iter().map(|x| x.to_string()).collect();
            format!("{l}→[{} | {}]", v.join(" "), r[k])
        })
        .collect();
    rows.join("  ")
}

/// The terminal summary: per classifier, accuracy and information against noise, and matrices.
pub fn text_summary(r: &SenseReport) -> String {
    let ev = &r.evaluation;
    let mut s = format!(
        "{} d {} sensor {}  hypotheses {}  {} trials ({} unscored), {} templates each  H(state) {:.3} bits, chance {:.1}%\n",
        r.part,
        r.d,
        r.sensor.kind.name(),
        ev.labels.join(", "),
        r.trials,
        ev.unscored,
        r.templates_per_hypothesis,
        ev.state_entropy_bits,
        100.0 * ev.chance_accuracy
    );
    for name in &r.classifiers {
        s += &format!("\n{name}\n  noise   accuracy  95% interval     unknown  I (bits)   confusion (rows true: decided… | unknown)\n");
        for c in ev.of(name) {
            s += &format!(
                "  ×{:<5} {:>7.1}%  [{:>5.1}, {:>5.1}]%  {:>7}  {:>8.3}   {}\n",
                c.noise_factor,
                100.0 * c.accuracy,
                100.0 * c.accuracy_ci95[0],
                100.0 * c.accuracy_ci95[1],
                c.unknown,
                c.mutual_information_bits,
                matrix_line(c)
            );
        }
    }
    for sk in &r.skipped {
        s += &format!("\nskipped {}: {}\n", sk.classifier, sk.reason);
    }
    for u in &r.untrained {
        s += &format!(
            "\n{} not trainable at ×{} (decided unknown): {}\n",
            u.classifier, u.noise_factor, u.reason
        );
    }
    if let Some(pl) = &r.placement {
        s += "\nplacement (nominal noise): d, sensor, best classifier, I (bits), accuracy\n";
        for row in &pl.rows {
            s += &format!(
                "  {:+.2}  {:>6}  {:<15} {:>6.3}  {:>5.1}%\n",
                row.d,
                row.sensor,
                row.classifier.as_deref().unwrap_or("-"),
                row.mutual_information_bits,
                100.0 * row.accuracy
            );
        }
        if let Some(b) = pl.best.and_then(|b| pl.rows.get(b)) {
            s += &format!(
                "  best: {} at d = {} ({}, {:.3} bits)\n",
                b.sensor,
                b.d,
                b.classifier.as_deref().unwrap_or("-"),
                b.mutual_information_bits
            );
        }
    }
    s
}

/// Write `sense.json`, the figures and `report.md` into `out` (figures of an earlier run that this
/// one does not draw are removed): `problem` and `config` redraw trial 0 over the templates.
pub fn write_report(
    r: &SenseReport,
    problem: &Problem,
    config: &Config,
    templates: &TemplateSet,
    out: &Path,
) -> ReportResult<()> {
    crate::report::error::create_dir(out)?;
    let json_path = out.join("sense.json");
    crate::output::write_atomic(&json_path, crate::report::versioned::pretty(r)?)
        .map_err(ReportError::writing(&json_path))?;
    let what = format!(
        "{} at d = {}, μc {}, {} sensor",
        r.part,
        r.d,
        r.uncertainty.mu_c,
        r.sensor.kind.name()
    );
    // (a) templates with trial 0's reading at noise factor 1.
    let (truth, pass) = trial_pass(problem, config, 0).map_err(ReportError::Trial)?;
    let mut rng = crate::random::stream(config.seed, READING_STREAMS);
    let reading = read(&pass.signal, &r.sensor, &mut rng);
    let overlay = match (&reading, pass.signal.span()) {
        (Some(rd), Some((b, _))) => Some(plot_sensing::Overlay {
            reading: rd,
            contact_begin: b,
            label: format!(
                "one reading at nominal noise (true: {})",
                truth.map_or("none".to_string(), |t| r.evaluation.labels[t].clone())
            ),
        }),
        _ => None,
    };
    let f_templates = out.join("templates.svg");
    plot_sensing::plot_templates(
        templates,
        overlay.as_ref(),
        &format!("Templates per hypothesis: {what}"),
        &f_templates,
    )
    .map_err(ReportError::writing(&f_templates))?;
    let f_acc = out.join("accuracy_noise.svg");
    plot_sensing::plot_accuracy_noise(
        &r.evaluation,
        &format!("Accuracy against noise: {what}, {} trials", r.trials),
        &f_acc,
    )
    .map_err(ReportError::writing(&f_acc))?;
    if let Some(pl) = &r.placement {
        let f = out.join("placement.svg");
        plot_sensing::plot_placement(
            pl,
            &format!(
                "Where to sense {} (nominal noise, {} trials per d)",
                r.part, r.trials
            ),
            &f,
        )
        .map_err(ReportError::writing(&f))?;
    }
    let readme = out.join("report.md");
    crate::report::error::write_whole(&readme, report_markdown(r))?;
    // A placement figure of an earlier run with --placement does not outlive this one.
    let written: Vec<String> = ["templates.svg", "accuracy_noise.svg"]
        .into_iter()
        .chain(r.placement.as_ref().map(|_| "placement.svg"))
        .map(String::from)
        .collect();
    crate::report::stale::remove_stale(out, &written, |n| n.ends_with(".svg"))
        .map_err(ReportError::removing("figures", out))?;
    Ok(())
}

/// `report.md`: the command, the settings, a table per classifier, the figures.
pub fn report_markdown(r: &SenseReport) -> String {
    let ev = &r.evaluation;
    let mut md = format!(
        "# What a sensor tells: {}\n\nRegenerate with\n\n    {}\n\n",
        r.part, r.command
    );
    md += &format!(
        "Part `{}` scaled to a = {:.4} m, mass {} kg, belt {} m/s; pin at d = {}, radius {} m, μs = {}, \
         model `{}`. Sensor `{}`: rate {} Hz, height {} m, noise σ {} N / {} N·mm, resolution {} N, \
         threshold {} N, jitter {} s at noise factor 1. Uncertainty: μc {}, tripod supports: {}, \
         θ jitter σ {}°, d jitter σ {}. Hypotheses: {}; {} templates each (built: {:?}); {} trials \
         (truth {:?}, {} unscored), seed {}. Module docs of `crates/pinfeed/src/sensing/evaluate.rs` give the streams \
         and the estimates; mutual information is the plug-in estimate (biased up by about \
         (k−1)(m−1)/(2n ln 2) bits on n trials).\n\n",
        r.part,
        r.a_m,
        r.mass_kg,
        r.belt_speed_m_s,
        r.d,
        r.pin_radius_m,
        r.mu_s,
        r.model,
        r.sensor.kind.name(),
        r.sensor.rate,
        r.sensor.height,
        r.sensor.noise_force,
        r.sensor.noise_torque,
        r.sensor.resolution_force,
        r.sensor.threshold,
        r.sensor.jitter,
        r.uncertainty.mu_c,
        r.uncertainty.tripod,
        r.uncertainty.theta_jitter_deg,
        r.uncertainty.d_jitter,
        ev.labels.join(", "),
        r.templates_per_hypothesis,
        ev.template_counts,
        r.trials,
        r.truth,
        ev.unscored,
        r.seed
    );
    md += &format!(
        "H(state) = {:.3} bits; chance accuracy {:.1}%.\n\n",
        ev.state_entropy_bits,
        100.0 * ev.chance_accuracy
    );
    for name in &r.classifiers {
        md += &format!("## {name}\n\n| noise | accuracy | 95% interval | unknown | I (bits) | confusion (rows true: decided … \\| unknown) |\n|---|---|---|---|---|---|\n");
        for c in ev.of(name) {
            md += &format!(
                "| ×{} | {:.1}% | [{:.1}, {:.1}]% | {} | {:.3} | {} |\n",
                c.noise_factor,
                100.0 * c.accuracy,
                100.0 * c.accuracy_ci95[0],
                100.0 * c.accuracy_ci95[1],
                c.unknown,
                c.mutual_information_bits,
                matrix_line(c).replace('|', "\\|")
            );
        }
        md += "\n";
    }
    for sk in &r.skipped {
        md += &format!("Skipped `{}`: {}\n\n", sk.classifier, sk.reason);
    }
    for u in &r.untrained {
        md += &format!(
            "`{}` could not be trained at noise ×{} (every reading counted unknown): {}\n\n",
            u.classifier, u.noise_factor, u.reason
        );
    }
    if let Some(pl) = &r.placement {
        md += "## Placement (nominal noise)\n\n| d | sensor | best classifier | I (bits) | accuracy | 95% interval |\n|---|---|---|---|---|---|\n";
        for row in &pl.rows {
            md += &format!(
                "| {:+.2} | {} | {} | {:.3} | {:.1}% | [{:.1}, {:.1}]% |\n",
                row.d,
                row.sensor,
                row.classifier.as_deref().unwrap_or("-"),
                row.mutual_information_bits,
                100.0 * row.accuracy,
                100.0 * row.accuracy_ci95[0],
                100.0 * row.accuracy_ci95[1]
            );
        }
        for &b in &pl.best_per_sensor {
            let row = &pl.rows[b];
            md += &format!(
                "\nBest {} placement: d = {} ({}, {:.3} bits, {:.1}%).",
                row.sensor,
                row.d,
                row.classifier.as_deref().unwrap_or("-"),
                row.mutual_information_bits,
                100.0 * row.accuracy
            );
        }
        md += "\n\n![placement](placement.svg)\n\n";
    }
    md += "## Figures\n\n![templates](templates.svg)\n\n![accuracy against noise](accuracy_noise.svg)\n";
    md
}
