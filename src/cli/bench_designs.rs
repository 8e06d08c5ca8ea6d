//! `pinfeed bench designs`: maps its arguments to [`pinfeed::plan::design::survey`] and writes the
//! Markdown report (rewritten after every part, so a long survey shows its progress).

use anyhow::{anyhow, bail, Context, Result};
use pinfeed::plan::design::survey::{page, survey_part, SurveyPart, SurveySettings};
use pinfeed::plan::design::UncertaintyChoice;
use pinfeed::plan::problem::parse_mu_c_range;
use std::path::PathBuf;

/// The arguments of `bench designs`.
#[derive(Debug, Clone, clap::Args)]
pub struct DesignsArgs {
    /// Polygons random:FIRST … random:FIRST+N−1 (0: none).
    #[arg(long, default_value_t = 20)]
    pub random: u64,
    #[arg(long, default_value_t = 1)]
    pub first: u64,
    /// More parts (`;`-separated specs, each `SPEC` or `SPEC@SCALE`, e.g.
    /// "tripoly1;vertices:0,0 40,0 20,30@0.001").
    #[arg(long, value_delimiter = ';')]
    pub parts: Vec<String>,
    /// Each design's time limit (s).
    #[arg(long, default_value_t = 110.0)]
    pub time_limit: f64,
    /// Parts of each line check.
    #[arg(long, default_value_t = 10_000)]
    pub check_parts: u64,
    /// Robust designs: μc uniform in LO:HI per part, checked the same way.
    #[arg(long, value_name = "LO:HI")]
    pub mu_c_range: Option<String>,
    /// Robust designs: random tripod supports.
    #[arg(long)]
    pub tripod: bool,
    /// Design against the harsh uncertainty, as `pinfeed plan --robust`.
    #[arg(long, conflicts_with = "nominal")]
    pub robust: bool,
    /// Design for nominal physics, as `pinfeed plan --nominal` [default: plan's default
    /// uncertainty].
    #[arg(long)]
    pub nominal: bool,
    /// Worker threads (0: one per core); the results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    #[arg(long, default_value = "pinfeed-out/designs.md")]
    pub out: PathBuf,
}

/// Run the survey.
pub fn run(a: &DesignsArgs, spin: &indicatif::ProgressBar, cmd: &str) -> Result<()> {
    if a.random > 10_000 {
        bail!("--random {}: must lie in 0..=10000", a.random);
    }
    let mu_c_range = (a.mu_c_range.as_deref().map(parse_mu_c_range).transpose())
        .map_err(|e| anyhow!("--mu-c-range {e}"))?;
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
        uncertainty: if a.robust {
            UncertaintyChoice::Robust
        } else if a.nominal {
            UncertaintyChoice::Nominal
        } else {
            UncertaintyChoice::Default
        },
        seed: 1,
    };
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
        let m = page(cmd, &s, &rows);
        pinfeed::output::write_file(&a.out, m)?;
    }
    eprintln!("wrote {}", a.out.display());
    Ok(())
}
