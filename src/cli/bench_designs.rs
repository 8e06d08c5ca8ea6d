//! `pinfeed bench designs`: maps its arguments to [`crate::plan::design::survey`] and writes the
//! Markdown report (rewritten after every part, so a long survey shows its progress).

use crate::plan::design::survey::{markdown, survey_part, SurveyPart, SurveySettings};
use crate::report::atomic::write_atomic;
use crate::report::shell_word;
use anyhow::{anyhow, bail, Context, Result};
use std::path::PathBuf;

/// The arguments of `bench designs`.
#[derive(Debug, Clone)]
pub struct DesignsArgs {
    pub random: u64,
    pub first: u64,
    pub parts: Vec<String>,
    pub time_limit: f64,
    pub check_parts: u64,
    pub mu_c_range: Option<String>,
    pub tripod: bool,
    pub threads: usize,
    pub out: PathBuf,
}

/// Run the survey.
pub fn run(a: &DesignsArgs, spin: &indicatif::ProgressBar) -> Result<()> {
    if a.random > 10_000 {
        bail!("--random {}: must lie in 0..=10000", a.random);
    }
    let mu_c_range = match &a.mu_c_range {
        None => None,
        Some(r) => {
            let (lo, hi) = r
                .split_once(':')
                .ok_or_else(|| anyhow!("--mu-c-range '{r}': expected LO:HI"))?;
            Some((
                lo.trim()
                    .parse::<f64>()
                    .map_err(|_| anyhow!("--mu-c-range '{r}': '{lo}' is not a number"))?,
                hi.trim()
                    .parse::<f64>()
                    .map_err(|_| anyhow!("--mu-c-range '{r}': '{hi}' is not a number"))?,
            ))
        }
    };
    let mut parts: Vec<SurveyPart> = a.parts.iter().map(|s| SurveyPart::parse(s)).collect();
    parts.extend(
        (a.first..a.first.saturating_add(a.random))
            .map(|s| SurveyPart::parse(&format!("random:{s}"))),
    );
    if parts.is_empty() {
        bail!("no part to survey: give --random N or --parts");
    }
    let s = SurveySettings {
        parts: parts.clone(),
        time_limit_s: a.time_limit,
        check_parts: a.check_parts,
        mu_c_range,
        tripod: a.tripod,
        seed: 1,
    };
    let mut command = format!(
        "cargo run --release -- bench designs --random {} --first {}",
        a.random, a.first
    );
    if !a.parts.is_empty() {
        command += &format!(" --parts {}", shell_word(&a.parts.join(";")));
    }
    command += &format!(
        " --time-limit {} --check-parts {}",
        a.time_limit, a.check_parts
    );
    if let Some(r) = &a.mu_c_range {
        command += &format!(" --mu-c-range {r}");
    }
    if a.tripod {
        command += " --tripod";
    }
    command += &format!(" --out {}", a.out.display());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()
        .context("starting the worker threads")?;
    let mut rows = Vec::new();
    for (i, p) in parts.iter().enumerate() {
        super::progress::note(spin, &format!("bench designs: {} …", p.label));
        spin.set_message(format!(
            "designs: part {} of {}, {}",
            i + 1,
            parts.len(),
            p.label
        ));
        rows.push(pool.install(|| survey_part(&s, p)));
        let mut m = format!(
            "# Designs the line confirms (`pinfeed bench designs`)\n\nRegenerate:\n\n    {command}\n\n"
        );
        m += "Each cell is one run of `pinfeed plan` (the design workflow) allowed one mode — fixed pins, fences, a sensor pin with moving pins — or all of them together with lines that mix pins and fences (the default). Every other setting is `pinfeed plan`'s default: a stable-state feed with equal weights, 2° jitter, ±2 mm lateral; μc 0.5 (fences μf = μc), 2 mm pins 15 cm apart, a 10 cm belt for pins (fences may widen it: the width is reported); goal ≥ 0.99 of the parts in one ±3° window modulo the part's symmetry. A design is **confirmed** when its line check (the parts below, at the headway the workflow chose on the line) holds the goal; otherwise the best design the line measured is reported **not confirmed** with its number. Cells: verdict, line success [95% CI] of N parts; obstacles (the mode chosen); belt length × width; headway and oriented parts per minute; wall time of the whole design on this 2-core machine.\n\n";
        let title = match (&s.mu_c_range, s.tripod) {
            (None, false) => "Nominal physics".to_string(),
            (r, t) => format!(
                "Under uncertainty:{}{} (planned and checked against it)",
                r.map_or(String::new(), |(lo, hi)| format!(
                    " μc uniform in [{lo}, {hi}]"
                )),
                if t { ", random tripod supports" } else { "" }
            ),
        };
        m += &markdown(&title, &rows);
        if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        write_atomic(&a.out, m.as_bytes())
            .with_context(|| format!("writing {}", a.out.display()))?;
    }
    eprintln!("wrote {}", a.out.display());
    Ok(())
}
