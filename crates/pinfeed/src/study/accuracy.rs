//! What accuracy costs in time: every fidelity tier against a tightly converged exact reference.
//!
//! Cases: `n` random contacts split evenly over the reference parts (θ0 uniform in [0°, 360°),
//! d uniform in [−0.9, 0.9], point pin, μc = 0.5, uniform pressure), drawn from the reproducible
//! stream (seed, part index). Reference: the exact model at tolerance 1e-10. Tiers:
//!
//! * `tip` and `ellipsoid` at the default tolerance (model error dominates);
//! * `exact` at tolerances 1e-3 … 1e-8 (integration error only);
//! * `exact+tables` at 1e-4, 1e-6, 1e-8: the exact model with its slide tables
//!   (`mechanics::slide_table`, built before the timing), as a scene's model runs;
//! * `map` — a precomputed configuration map of the exact model (1° × 0.05 grid in θ0 × d) read by
//!   nearest grid point: the fastest tier, whose error is the map's resolution across band edges.
//!   Its one-off build time is reported separately.
//!
//! For each tier: error |θf − θf_ref| (wrapped, degrees): mean, 95th percentile, max; the share of
//! contacts that end more than one band threshold (5°, the maps' default) from the reference — "a
//! different band"; wall time per contact (single thread; median and mean) and evaluations per
//! contact. Contacts where the reference itself reports a non-ok status are left out and counted.

use crate::geometry::{part_from_spec, wrap_deg, Pose, Vec2};
use crate::mechanics::{push, ContactSettings, Fidelity, PartModel, Pin, Support};
use crate::study::bench_error::{uniform_model, BenchError};
use rand::RngExt;
use serde::Serialize;
use std::time::Instant;

/// The band threshold (degrees) used to call a final orientation "a different band".
pub const BAND_THRESHOLD_DEG: f64 = 5.0;

/// One tier's row.
#[derive(Debug, Clone, Serialize)]
pub struct TierRow {
    /// The tier's name (`tip`, `exact tol=1e-6`, `exact+tables tol=1e-6`, `map`, …).
    pub tier: String,
    /// The contact model the tier runs.
    pub fidelity: String,
    /// Integration tolerance per step.
    pub tol: f64,
    /// Contacts compared with the reference.
    pub contacts: usize,
    /// Mean of |θf − θf_ref| (degrees, wrapped).
    pub error_mean_deg: f64,
    /// 95th percentile of |θf − θf_ref| (degrees).
    pub error_p95_deg: f64,
    /// Largest |θf − θf_ref| (degrees).
    pub error_max_deg: f64,
    /// Share of contacts more than [`BAND_THRESHOLD_DEG`] from the reference, in [0, 1].
    pub different_band_share: f64,
    /// Median wall time per contact (µs, one thread).
    pub median_us: f64,
    /// Mean wall time per contact (µs, one thread).
    pub mean_us: f64,
    /// Mean limit-surface evaluations per contact.
    pub mean_evaluations: f64,
}

/// The whole study.
#[derive(Debug, Clone, Serialize)]
pub struct AccuracyStudy {
    /// The reference parts' specs.
    pub parts: Vec<String>,
    /// Contacts drawn (split evenly over the parts).
    pub contacts: usize,
    /// Contacts left out because the reference itself did not end `ok`.
    pub reference_excluded: usize,
    /// One-off build time of the map tier's maps (s).
    pub map_build_seconds: f64,
    /// The map tier's grid, in words.
    pub map_grid: String,
    /// One row per tier.
    pub rows: Vec<TierRow>,
}

struct Case {
    part: usize,
    theta0: f64,
    d: f64,
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

fn ang_err(a_deg: f64, b_deg: f64) -> f64 {
    (wrap_deg(a_deg - b_deg + 180.0) - 180.0).abs()
}

/// Run the study.
pub fn run(parts: &[&str], n: usize, seed: u64) -> Result<AccuracyStudy, BenchError> {
    let bench = Bench::new(parts)?;
    let cases = draw_cases(parts.len(), n.div_ceil(parts.len()), seed);
    // Reference.
    let reference: Vec<Option<f64>> = cases
        .iter()
        .map(|c| {
            let o = bench.push(c, Fidelity::Exact, 1e-10, false);
            o.status
                .is_ok()
                .then(|| o.pose_final.theta_rad.to_degrees())
        })
        .collect();
    let kept: Vec<usize> = (0..cases.len())
        .filter(|&i| reference[i].is_some())
        .collect();
    let excluded = cases.len() - kept.len();

    let mut rows = Vec::new();
    for tier in &tiers() {
        rows.push(bench.time_tier(&cases, &kept, &reference, tier));
    }
    let (map_row, map_build, d_count) = bench.map_tier(&cases, &kept, &reference);
    rows.push(map_row);
    Ok(AccuracyStudy {
        parts: parts.iter().map(|s| s.to_string()).collect(),
        contacts: kept.len(),
        reference_excluded: excluded,
        map_build_seconds: map_build,
        map_grid: format!("{} parts × {} d × 360 θ0", parts.len(), d_count),
        rows,
    })
}

/// `per` random contacts per part (θ0 and d), each part's from the stream (seed, part index).
fn draw_cases(n_parts: usize, per: usize, seed: u64) -> Vec<Case> {
    let mut cases = Vec::new();
    for pi in 0..n_parts {
        let mut rng = crate::random::stream(seed, pi as u64);
        for _ in 0..per {
            cases.push(Case {
                part: pi,
                theta0: rng.random::<f64>() * 360.0,
                d: -0.9 + 1.8 * rng.random::<f64>(),
            });
        }
    }
    cases
}

/// The timed tiers: name, fidelity, tolerance and whether the exact model uses its slide tables.
fn tiers() -> Vec<(String, Fidelity, f64, bool)> {
    let mut tiers: Vec<(String, Fidelity, f64, bool)> = vec![
        ("tip".into(), Fidelity::Tip, 1e-6, false),
        ("ellipsoid".into(), Fidelity::Ellipsoid, 1e-6, false),
    ];
    for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-8] {
        tiers.push((format!("exact tol={tol:e}"), Fidelity::Exact, tol, false));
    }
    for tol in [1e-4, 1e-6, 1e-8] {
        tiers.push((
            format!("exact+tables tol={tol:e}"),
            Fidelity::Exact,
            tol,
            true,
        ));
    }
    tiers
}

/// The parts of a study with their models, plain and with slide tables.
struct Bench {
    polys: Vec<crate::geometry::Polygon>,
    models: Vec<PartModel>,
    /// The exact model with its slide tables (built before any timing).
    tabled: Vec<PartModel>,
}

impl Bench {
    /// Build the parts' models and their slide tables.
    fn new(parts: &[&str]) -> Result<Bench, BenchError> {
        let polys: Vec<_> = parts
            .iter()
            .map(|p| part_from_spec(p))
            .collect::<Result<_, _>>()?;
        let models: Vec<PartModel> = polys.iter().map(uniform_model).collect::<Result<_, _>>()?;
        // The exact model with its slide tables (built here, before any timing).
        let mu_c = ContactSettings::default().mu_c;
        let tabled: Vec<PartModel> = models
            .iter()
            .map(|m| m.clone().with_slide_tables(&[mu_c]))
            .collect();
        tabled.iter().for_each(PartModel::build_all_tables);
        Ok(Bench {
            polys,
            models,
            tabled,
        })
    }

    /// One case's push at this fidelity and tolerance, with or without slide tables.
    fn push(
        &self,
        c: &Case,
        fid: Fidelity,
        tol: f64,
        tables: bool,
    ) -> crate::mechanics::ContactOutcome {
        let a = self.polys[c.part].radius();
        let s = ContactSettings {
            fidelity: fid,
            tol,
            ..ContactSettings::default()
        };
        push(
            if tables {
                &self.tabled[c.part]
            } else {
                &self.models[c.part]
            },
            Pose::new(0.0, 0.0, c.theta0.to_radians()),
            Vec2::new(1.01 * a, c.d * a),
            &Pin::point(),
            &s,
            None,
        )
    }

    /// Time one tier (see [`tiers`]) over the kept cases (after a warm-up) against the reference.
    fn time_tier(
        &self,
        cases: &[Case],
        kept: &[usize],
        reference: &[Option<f64>],
        tier: &(String, Fidelity, f64, bool),
    ) -> TierRow {
        let (name, fid, tol, tables) = (tier.0.as_str(), tier.1, tier.2, tier.3);
        // Warm-up.
        for &i in kept.iter().take(20) {
            std::hint::black_box(self.push(&cases[i], fid, tol, tables));
        }
        let mut errors = Vec::with_capacity(kept.len());
        let mut times = Vec::with_capacity(kept.len());
        let mut evals = 0u64;
        for &i in kept {
            let t0 = Instant::now();
            let o = std::hint::black_box(self.push(&cases[i], fid, tol, tables));
            times.push(t0.elapsed().as_secs_f64() * 1e6);
            evals += o.evaluations;
            errors.push(ang_err(
                o.pose_final.theta_rad.to_degrees(),
                reference[i].expect("kept cases have a reference"),
            ));
        }
        summarise(name, fid.name(), tol, errors, times, evals)
    }

    /// The map tier: exact configuration maps on a 1° × 0.05 grid, looked up by nearest point.
    /// Its row, the maps' build time (s) and the number of d values.
    fn map_tier(
        &self,
        cases: &[Case],
        kept: &[usize],
        reference: &[Option<f64>],
    ) -> (TierRow, f64, usize) {
        let t_build = Instant::now();
        let d_steps: Vec<f64> = (0..=36).map(|k| -0.9 + 0.05 * k as f64).collect();
        let mut maps: Vec<Vec<f64>> = Vec::new(); // [part][d_index * 360 + theta]
        for pi in 0..self.polys.len() {
            let mut grid = vec![0.0; d_steps.len() * 360];
            for (di, &d) in d_steps.iter().enumerate() {
                for th in 0..360 {
                    let c = Case {
                        part: pi,
                        theta0: th as f64,
                        d,
                    };
                    grid[di * 360 + th] = self
                        .push(&c, Fidelity::Exact, 1e-6, false)
                        .pose_final
                        .theta_rad
                        .to_degrees();
                }
            }
            maps.push(grid);
        }
        let map_build = t_build.elapsed().as_secs_f64();
        let lookup = |c: &Case| {
            let di = (((c.d + 0.9) / 0.05).round() as usize).min(d_steps.len() - 1);
            let ti = (c.theta0.round() as usize) % 360;
            let stored = maps[c.part][di * 360 + ti];
            // The map stores the final angle for θ0 = ti; apply the same turn to the actual θ0.
            stored - ti as f64 + c.theta0
        };
        let mut errors = Vec::new();
        let mut times = Vec::new();
        for &i in kept {
            let t0 = Instant::now();
            let th = std::hint::black_box(lookup(&cases[i]));
            times.push(t0.elapsed().as_secs_f64() * 1e6);
            errors.push(ang_err(th, reference[i].expect("kept")));
        }
        let row = summarise("map (1° × 0.05, nearest)", "exact", 1e-6, errors, times, 0);
        (row, map_build, d_steps.len())
    }
}

fn summarise(
    name: &str,
    fid: &str,
    tol: f64,
    mut errors: Vec<f64>,
    mut times: Vec<f64>,
    evals: u64,
) -> TierRow {
    errors.sort_by(f64::total_cmp);
    times.sort_by(f64::total_cmp);
    let n = errors.len().max(1) as f64;
    TierRow {
        tier: name.into(),
        fidelity: fid.into(),
        tol,
        contacts: errors.len(),
        error_mean_deg: errors.iter().sum::<f64>() / n,
        error_p95_deg: percentile(&errors, 0.95),
        error_max_deg: errors.last().copied().unwrap_or(0.0),
        different_band_share: errors.iter().filter(|&&e| e > BAND_THRESHOLD_DEG).count() as f64 / n,
        median_us: percentile(&times, 0.5),
        mean_us: times.iter().sum::<f64>() / n,
        mean_evaluations: evals as f64 / n,
    }
}

/// Markdown table of the tiers.
pub fn markdown_table(st: &AccuracyStudy) -> String {
    let mut s = String::from(
        "| tier | error mean ° | p95 ° | max ° | different band | median µs | mean µs | evaluations |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in &st.rows {
        s.push_str(&format!(
            "| {} | {:.2e} | {:.2e} | {:.2e} | {:.1}% | {:.2} | {:.2} | {:.0} |\n",
            r.tier,
            r.error_mean_deg,
            r.error_p95_deg,
            r.error_max_deg,
            100.0 * r.different_band_share,
            r.median_us,
            r.mean_us,
            r.mean_evaluations
        ));
    }
    s
}

/// CSV of the tiers.
pub fn csv(st: &AccuracyStudy) -> String {
    let mut s = String::from("tier,fidelity,tol,contacts,error_mean_deg,error_p95_deg,error_max_deg,different_band_share,median_us,mean_us,mean_evaluations\n");
    for r in &st.rows {
        s.push_str(&format!(
            "{},{},{:e},{},{},{},{},{},{},{},{}\n",
            r.tier,
            r.fidelity,
            r.tol,
            r.contacts,
            r.error_mean_deg,
            r.error_p95_deg,
            r.error_max_deg,
            r.different_band_share,
            r.median_us,
            r.mean_us,
            r.mean_evaluations
        ));
    }
    s
}

/// Exact/ellipsoid rotation-rate ratio for a near-central frictionless push (docs/physics.md#limit-surface):
/// (part, θ0, measured ratio, closed-form ratio c²/((1/A)∫x∥² dA)).
pub fn central_push_gap() -> Vec<(String, f64, f64, f64)> {
    let mut out = Vec::new();
    for (name, theta, along) in [
        ("square", 0.0, 1.0),
        ("rect:2:1", 0.0, 2.0),
        ("rect:2:1", 90.0, 1.0),
    ] {
        let poly = part_from_spec(name).expect("named part");
        let model = PartModel::new(&poly, &Support::Uniform).expect("valid part");
        let a = poly.radius();
        let rate = |fid: Fidelity| {
            let s = ContactSettings {
                fidelity: fid,
                mu_c: 0.0,
                ..ContactSettings::default()
            };
            crate::mechanics::first_instant(
                &model,
                Pose::new(0.0, 0.0, f64::to_radians(theta)),
                Vec2::new(1.01 * a, 1e-4 * a),
                &Pin::point(),
                &s,
            )
            .map(|(g, i)| i.twist[2] / g.v_pin.norm())
            .unwrap_or(f64::NAN)
        };
        let c = model.ellipsoid_c() * a;
        out.push((
            name.to_string(),
            theta,
            rate(Fidelity::Exact) / rate(Fidelity::Ellipsoid),
            c * c / (along * along / 12.0),
        ));
    }
    out
}

/// The full Markdown report, headed by the command that regenerates it.
pub fn report_markdown(st: &AccuracyStudy, cmd: &str) -> String {
    let find = |prefix: &str| st.rows.iter().find(|r| r.tier.starts_with(prefix));
    let exact_default = st
        .rows
        .iter()
        .find(|r| r.fidelity == "exact" && r.tol == 1e-6 && r.tier.starts_with("exact"));
    let mut s = format!(
        "# What accuracy costs in time\n\nRegenerate (writes this file, the .csv and the .svg):\n\n```\n{cmd}\n```\n\n\
         {} contacts (θ0 uniform, d uniform in [−0.9, 0.9], point pin, μc = 0.5, uniform pressure) \
         over {}; reference: the exact model at tolerance 1e-10 ({} contacts whose reference did not \
         end `ok` — two-contact notches of the L — left out). Times are single-thread wall-clock per \
         contact on this machine ({} cores). \"Different band\" = final angle more than {}° (the \
         maps' band threshold) from the reference.\n\n![error vs time](accuracy-vs-time.svg)\n\n",
        st.contacts,
        st.parts.join(", "),
        st.reference_excluded,
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        BAND_THRESHOLD_DEG
    );
    s.push_str(&markdown_table(st));
    s.push_str("\n## What each tier costs and what it gets wrong\n\n");
    if let (Some(tip), Some(ell), Some(ex)) = (find("tip"), find("ellipsoid"), exact_default) {
        s.push_str(&format!(
            "- **tip** (the thesis's COR-locus tip): {:.1} µs median, {:.1}× the exact model's time saved; \
             but mean error {:.1}°, p95 {:.1}°, and {:.0}% of contacts end in a different band. It is the \
             slowest rotation any pressure distribution allows, so it systematically under-rotates: a bound, \
             not a predictor.\n",
            tip.median_us,
            ex.median_us / tip.median_us.max(1e-9),
            tip.error_mean_deg,
            tip.error_p95_deg,
            100.0 * tip.different_band_share
        ));
        s.push_str(&format!(
            "- **ellipsoid** (Lynch et al. 1992): {:.1} µs median ({:.1}× faster than exact); mean error \
             {:.1}°, p95 {:.1}°, {:.0}% in a different band. Its error is largest for near-central pushes, \
             where it under-predicts the rotation rate by a fixed, shape-dependent factor (below).\n",
            ell.median_us,
            ex.median_us / ell.median_us.max(1e-9),
            ell.error_mean_deg,
            ell.error_p95_deg,
            100.0 * ell.different_band_share
        ));
        s.push_str(&format!(
            "- **exact** at the default tolerance 1e-6: {:.1} µs median, {:.0} evaluations per contact, \
             error mean {:.1e}°, max {:.1e}° — integration error only, far below any band. Looser \
             tolerances buy little time (the table): events and the limit-surface solves, not the step \
             count, dominate the cost.\n",
            ex.median_us, ex.mean_evaluations, ex.error_mean_deg, ex.error_max_deg
        ));
    }
    let tabled_default = st.rows.iter().find(|r| r.tier == "exact+tables tol=1e-6");
    if let (Some(t), Some(ex)) = (tabled_default, exact_default) {
        s.push_str(&format!(
            "- **exact+tables** (the exact model with its slide tables, as a scene's, a \
             map's and a planner's model run): at 1e-6 {:.1} µs median ({:.1}× faster than the \
             solves), {:.0} evaluations per contact, error mean {:.1e}°, max {:.1e}°: the same \
             accuracy, since a table serves a slide to 1e-10 of its converged solve.\n",
            t.median_us,
            ex.median_us / t.median_us.max(1e-9),
            t.mean_evaluations,
            t.error_mean_deg,
            t.error_max_deg
        ));
    }
    if let Some(map) = find("map") {
        s.push_str(&format!(
            "- **map** (precomputed exact configuration maps, nearest grid point): {:.3} µs per lookup, \
             after a one-off build of {:.1} s ({}); mean error {:.2}°, p95 {:.2}°, max {:.1}°, {:.1}% in a \
             different band — the misses sit on band edges, where the map jumps between grid points.\n",
            map.median_us,
            st.map_build_seconds,
            st.map_grid,
            map.error_mean_deg,
            map.error_p95_deg,
            map.error_max_deg,
            100.0 * map.different_band_share
        ));
    }
    s.push_str(
        "\n### The ellipsoid's near-central-push gap\n\n\
         For a push through (almost) the centroid the exact uniform model has (COR distance)·(force-line \
         offset) → (1/A)∫x∥² dA with x∥ along the push; the ellipsoid has c² = (m_max/f_max)². The exact \
         model therefore turns c²/((1/A)∫x∥² dA) times faster. Measured rotation rates at d = 1e-4, μc = 0:\n\n\
         | part | θ0 | exact / ellipsoid (measured) | closed form |\n|---|---|---|---|\n",
    );
    for (name, th, measured, formula) in central_push_gap() {
        s.push_str(&format!(
            "| {name} | {th}° | {measured:.3} | {formula:.3} |\n"
        ));
    }
    s.push_str(
        "\nA 2×1 rectangle struck on a short side is pushed along its long axis (ratio ≈ 1.06); struck on \
         a long side it is pushed along its short axis (ratio ≈ 4.22).\n",
    );
    s
}

/// The markers of the report's section on what a map-tier build costs, which a criterion
/// benchmark measures (`cargo bench --features bench --bench map_tier -- map_tier_build`).
pub const MAP_TIER_BUILD_SECTION: (&str, &str) = (
    "<!-- map-tier-build:begin -->",
    "<!-- map-tier-build:end -->",
);

/// The accuracy report of `st` (regenerated by `cmd`) keeping the sections other commands add to
/// it (`bench mc-precision`, `bench map-tier`, the map-tier build's criterion benchmark) from the
/// `old` report's text.
pub fn report_keeping(st: &AccuracyStudy, cmd: &str, old: &str) -> String {
    keep_sections(report_markdown(st, cmd), old)
}

/// `md` with the marked sections of the `old` report spliced in (see [`report_keeping`]).
fn keep_sections(mut md: String, old: &str) -> String {
    use crate::study::mc::precision::{existing_between, splice_between};
    if let Some(section) = crate::study::mc::precision::existing(old) {
        md = crate::study::mc::precision::splice(&md, &section);
    }
    if let Some(section) = crate::study::map_tier::existing(old) {
        md = crate::study::map_tier::splice(&md, &section);
    }
    if let Some(section) = existing_between(old, MAP_TIER_BUILD_SECTION) {
        md = splice_between(&md, &section, MAP_TIER_BUILD_SECTION);
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sections other commands measure survive a rewrite, each once, in the old order; the
    /// old report's own text does not.
    #[test]
    fn a_rewritten_report_keeps_the_sections_other_commands_measure() {
        let (pb, pe) = (
            crate::study::mc::precision::BEGIN,
            crate::study::mc::precision::END,
        );
        let (bb, be) = MAP_TIER_BUILD_SECTION;
        let old = format!(
            "# Old\n\n| old tiers |\n\n{pb}\nprecision\n{pe}\n\n{bb}\n## Build\n| 10.0 ms |\n{be}\n"
        );
        let kept = keep_sections("# New\n\n| new tiers |\n".to_string(), &old);
        assert!(!kept.contains("old tiers") && kept.starts_with("# New"));
        for marker in [pb, pe, bb, be] {
            assert_eq!(kept.matches(marker).count(), 1, "{marker} in\n{kept}");
        }
        assert!(kept.find(pe) < kept.find(bb));
        assert!(kept.contains("| 10.0 ms |"));
        assert_eq!(
            keep_sections("# New\n\n| new tiers |\n".to_string(), &kept),
            kept
        );
    }
}
