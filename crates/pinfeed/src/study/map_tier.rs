//! `pinfeed bench map-tier`: the certified map tier against the exact model, per contact (a
//! section of results/accuracy-vs-time.md) and on the line (a section of results/line-speed.md).
//!
//! Per contact: random pushes (θ0 uniform, d uniform in [−0.9, 0.9], point pin, μc = 0.5, uniform
//! pressure, tol 1e-6 — the accuracy study's set-up) on each part's freshly built map (default
//! grid), each push timed through the map (ray cast + interpolation, where it serves) and through
//! the exact model; the error is |θf(map) − θf(exact)| on the served pushes. On the line: one
//! scenario run exact and with `fidelity = "map"` on the same part stream, per part outcome class
//! compared, parts per second of each, the map's build time, served and fallback counts.

use crate::engine::{self, contact_map, RunOptions, RunResult};
use crate::geometry::{part_from_spec, Pose, Vec2};
use crate::maps::pass_start;
use crate::maps::tier::{self, push_with_map, Source, TierInputs, TierSpec};
use crate::mechanics::{push, ContactSettings, Pin, Support};
use crate::random::stream;
use crate::study::bench_error::{uniform_model, BenchError};
use rand::RngExt;
use std::path::Path;
use std::time::Instant;

/// One part's map against the exact model.
#[derive(Debug, Clone)]
pub struct ContactRow {
    /// The part spec.
    pub part: String,
    /// Time to build the part's map (s; NaN when it was not built here).
    pub build_s: f64,
    /// Exact pushes computed to build the map.
    pub exact_samples: u64,
    /// Fraction of the (θ0, d) rectangle covered by certified cells.
    pub certified_area: f64,
    /// Pushes drawn.
    pub contacts: usize,
    /// Pushes that touched the part (exact model).
    pub touching: usize,
    /// Touching pushes the map served.
    pub served: usize,
    /// Pushes whose contact / no-contact answer differs from exact (must be 0).
    pub class_mismatch: usize,
    /// Mean |θf(map) − θf(exact)| over the served pushes (degrees).
    pub err_mean: f64,
    /// 95th percentile of that error (degrees).
    pub err_p95: f64,
    /// Largest error (degrees).
    pub err_max: f64,
    /// µs per served push through the map and through the exact model (the same pushes timed as
    /// a batch, best of several batches).
    pub served_us: f64,
    /// µs per served push through the exact model.
    pub exact_served_us: f64,
    /// Mean µs over all pushes: through `push_with_map` and exact.
    pub mixed_us: f64,
    /// Mean µs over all pushes through the exact model.
    pub exact_us: f64,
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let out = f();
    (out, t.elapsed().as_secs_f64() * 1e6)
}

/// Measure one part.
pub fn contact_row(part: &str, contacts: usize, seed: u64) -> Result<ContactRow, BenchError> {
    let poly = part_from_spec(part).map_err(|source| BenchError::Part {
        part: part.to_string(),
        source,
    })?;
    let model = uniform_model(&poly)?;
    let settings = ContactSettings::default();
    let inputs = TierInputs {
        model: &model,
        support: &Support::Uniform,
        radius: 0.0,
        settings,
        spec: TierSpec::default(),
    };
    let loaded = tier::load_or_build(&inputs, None);
    let build_s = match loaded.source {
        Source::Built { seconds, .. } => seconds,
        _ => f64::NAN,
    };
    let map = loaded.map;
    let mut rng = stream(seed, 0);
    let (mut errs, mut served) = (Vec::new(), Vec::new());
    let (mut touching, mut mismatch, mut mixed_sum, mut exact_sum) = (0, 0, 0.0, 0.0);
    for _ in 0..contacts {
        let theta0 = rng.random::<f64>() * 360.0;
        let d = rng.random::<f64>() * 1.8 - 0.9;
        let (pose, start) = pass_start(&poly, theta0, d, 0.0);
        let (ex, t_exact) = timed(|| push(&model, pose, start, &Pin::point(), &settings, None));
        let answer = map.answer(&model, pose, start, 0.0);
        let ((mixed, _), t_mixed) =
            timed(|| push_with_map(&map, &model, pose, start, 0.0, &settings));
        exact_sum += t_exact;
        mixed_sum += t_mixed;
        touching += usize::from(ex.contact);
        mismatch += usize::from(mixed.contact != ex.contact);
        if let Ok(out) = answer {
            if out.contact {
                errs.push(
                    (out.pose_final.theta_rad - ex.pose_final.theta_rad)
                        .abs()
                        .to_degrees(),
                );
                served.push((pose, start));
            }
        }
    }
    // The served pushes as batches: best of 7 through the map, of 3 through the exact model.
    let per_push = |reps: usize, f: &dyn Fn(Pose, Vec2) -> f64| -> f64 {
        let best = (0..reps)
            .map(|_| timed(|| served.iter().map(|&(p, s)| f(p, s)).sum::<f64>()).1)
            .fold(f64::INFINITY, f64::min);
        best / served.len().max(1) as f64
    };
    let served_us = per_push(7, &|p, s| {
        map.answer(&model, p, s, 0.0)
            .map_or(0.0, |o| o.rotation_rad)
    });
    let exact_served_us = per_push(3, &|p, s| {
        push(&model, p, s, &Pin::point(), &settings, None).rotation_rad
    });
    let served = errs.len();
    let err_mean = errs.iter().sum::<f64>() / served.max(1) as f64;
    let err_max = errs.iter().fold(0.0f64, |m, &e| m.max(e));
    let err_p95 = {
        let mut e = errs.clone();
        e.sort_by(f64::total_cmp);
        e.get((e.len() as f64 * 0.95) as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    Ok(ContactRow {
        part: part.into(),
        build_s,
        exact_samples: map.stats.exact_samples,
        certified_area: map.stats.certified_area,
        contacts,
        touching,
        served,
        class_mismatch: mismatch,
        err_mean,
        err_p95,
        err_max,
        served_us,
        exact_served_us,
        mixed_us: mixed_sum / contacts as f64,
        exact_us: exact_sum / contacts as f64,
    })
}

/// The per-contact section (Markdown, between its markers).
pub fn contact_section(rows: &[ContactRow], cmd: &str) -> String {
    let mut s = format!(
        "## The certified map tier (`fidelity = \"map\"`)\n\n\
         Regenerate this section (and the map-tier section of line-speed.md) with:\n\n```\n{cmd}\n```\n\n\
         Each part's map (default grid: 36 θ0 × 12 d base cells, 4 halvings, biquadratic \
         interpolation certified at 12 check points to 0.0125° and 1e-3 a) is built fresh, then \
         random pushes (θ0 uniform, d uniform in [−0.9, 0.9], point pin, μc = 0.5, tol 1e-6) go \
         through the map and through the exact model. *Served* = touching pushes the map answered \
         (the rest, near jumps of θf or non-ok pushes, went to the exact model); the error is \
         |θf(map) − θf(exact)| on the served ones (promise: ≤ 0.05°). *Speed-up* = exact time / map \
         time per push on the same served pushes, each timed as a batch (best of 7 batches through \
         the map, of 3 exact); *mixed* = mean time per push through \
         the tier with its fallbacks, against exact on every push. Single thread, wall clock; the \
         machine (2 cores) was shared with other builds.\n\n\
         | part | build s | exact pushes in build | certified area | pushes | touching | served | class mismatch | error mean ° | p95 ° | max ° | map µs | exact µs (same pushes) | speed-up | mixed µs (mean) | exact µs (mean, all) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {:.1} | {} | {:.1}% | {} | {} | {} ({:.1}%) | {} | {:.1e} | {:.1e} | {:.1e} | {:.2} | {:.1} | {:.0}× | {:.1} | {:.1} |\n",
            r.part,
            r.build_s,
            r.exact_samples,
            100.0 * r.certified_area,
            r.contacts,
            r.touching,
            r.served,
            100.0 * r.served as f64 / r.touching.max(1) as f64,
            r.class_mismatch,
            r.err_mean,
            r.err_p95,
            r.err_max,
            r.served_us,
            r.exact_served_us,
            r.exact_served_us / r.served_us,
            r.mixed_us,
            r.exact_us,
        ));
    }
    let max_err = rows.iter().fold(0.0f64, |m, r| m.max(r.err_max));
    let min_speedup = rows
        .iter()
        .map(|r| r.exact_served_us / r.served_us)
        .fold(f64::INFINITY, f64::min);
    let mismatches: usize = rows.iter().map(|r| r.class_mismatch).sum();
    s.push_str(&format!(
        "\nTargets: every served answer within 0.05° of exact — largest error here \
         {max_err:.3}°; ≥ 100× faster per contact — here {min_speedup:.0}× or more (served pushes); \
         build time reported (above; a map is built once and then read from its cache file in \
         milliseconds); contact/no-contact never differs from exact ({mismatches} mismatches).\n"
    ));
    s
}

/// The line: one scenario exact and on the map tier.
#[derive(Debug, Clone)]
pub struct LineRow {
    /// Parts run on each model.
    pub parts: u64,
    /// Wall time of the exact run (s).
    pub exact_s: f64,
    /// Wall time of the map-tier run (s).
    pub map_s: f64,
    /// Time to prepare the scene's maps (s).
    pub build_s: f64,
    /// Parts whose outcome class is the same on both.
    pub same_class: u64,
    /// Largest final-orientation difference among those parts (degrees).
    pub max_theta_diff_deg: f64,
    /// The exact run.
    pub exact: RunResult,
    /// The map-tier run.
    pub map: RunResult,
}

/// Run `scene` for `parts` parts with the online controller's model `online` (built beforehand,
/// so that neither the timing nor the comparison includes it).
fn run_timed(
    scene: &crate::scenario::Scene,
    online: Option<&crate::engine::prepare::OnlineHandle>,
    parts: u64,
) -> Result<(RunResult, f64), BenchError> {
    let opts = RunOptions {
        parts,
        keep_records: true,
        online: online.cloned(),
        ..RunOptions::from_scene(scene)
    };
    let t = Instant::now();
    let r = engine::run(scene, &opts, &mut |_| {})?;
    Ok((r, t.elapsed().as_secs_f64()))
}

/// Run `scenario` exact (its own fidelity) and on the map tier (default grid, built fresh).
pub fn line_row(scenario: &Path, parts: u64) -> Result<LineRow, BenchError> {
    let exact_scene = crate::scenario::load(scenario)?;
    let mut map_scene = crate::scenario::load(scenario)?;
    map_scene.map_tier = Some(TierSpec::default());
    let t = Instant::now();
    contact_map::prepare(&map_scene, None);
    let build_s = t.elapsed().as_secs_f64();
    // Both lines run the controller of the scenario as written (exact physics).
    let online = crate::engine::prepare::online_model(&exact_scene)?;
    let (exact, exact_s) = run_timed(&exact_scene, online.as_ref(), parts)?;
    let (map, map_s) = run_timed(&map_scene, online.as_ref(), parts)?;
    let mut same = 0;
    let mut max_diff = 0.0f64;
    for (a, b) in exact.records.iter().zip(&map.records) {
        if a.outcome == b.outcome {
            same += 1;
            let d = (a.theta_out_deg - b.theta_out_deg).rem_euclid(360.0);
            max_diff = max_diff.max(d.min(360.0 - d));
        }
    }
    Ok(LineRow {
        parts,
        exact_s,
        map_s,
        build_s,
        same_class: same,
        max_theta_diff_deg: max_diff,
        exact,
        map,
    })
}

/// The line section (Markdown).
pub fn line_section(r: &LineRow, scenario: &Path, cmd: &str) -> String {
    let (we, wm) = (&r.exact.summary.work, &r.map.summary.work);
    let m = &wm.map_tier;
    let n = r.parts as f64;
    format!(
        "## Exact against the certified map tier ({scenario})\n\n\
         Regenerate this section (and the map-tier section of accuracy-vs-time.md) with:\n\n```\n{cmd}\n```\n\n\
         The same scenario and part stream ({parts} parts, seed {seed}) run exact and with \
         `[model] fidelity = \"map\"` (default grid), one after the other in one process on this \
         2-core machine (shared with other builds: compare the two columns, not absolute numbers \
         across reports). The map is built once before the runs (no cache file read).\n\n\
         | quantity | exact | map tier |\n|---|---|---|\n\
         | wall time of the run | {es:.2} s | {ms:.2} s |\n\
         | **parts per second** | **{eps:.0}** | **{mps:.0}** |\n\
         | map build (one map: all pins share radius and μc) | — | {bs:.1} s |\n\
         | pushes | {ec} | {mc} |\n\
         | served by the map | — | {served} ({sp:.1}%) |\n\
         | computed exactly | {ec} | {fb} ({reasons}) |\n\
         | limit-surface evaluations | {ee} | {me} |\n\
         | pushes re-run for overlap checks | {er} | {mr} |\n\
         | **parts ending in the same outcome class** | — | **{same} / {parts} ({agree:.3}%)** |\n\
         | largest final-orientation difference (same class) | — | {dt:.4}° |\n\
         | success rate | {esr:.4} | {msr:.4} |\n\n\
         Target: the outcome class equal to exact for ≥ 99.99% of parts — here \
         {agree:.3}%. The map serves {sp:.1}% of the pushes; the rest fall in cells it could not \
         certify (pushes near the centroid, grazing touches, jumps of θf) and are computed \
         exactly, which bounds the line's speed-up at about 1/(share computed exactly).\n",
        scenario = scenario.display(),
        parts = r.parts,
        seed = r.exact.summary.seed,
        es = r.exact_s,
        ms = r.map_s,
        eps = n / r.exact_s,
        mps = n / r.map_s,
        bs = r.build_s,
        ec = we.contact_solves,
        mc = wm.contact_solves,
        served = m.served,
        sp = 100.0 * m.served as f64 / wm.contact_solves.max(1) as f64,
        fb = m.fallbacks(),
        reasons = m.fallback_reasons(),
        ee = we.model_evaluations,
        me = wm.model_evaluations,
        er = we.pushes_rerun,
        mr = wm.pushes_rerun,
        same = r.same_class,
        agree = 100.0 * r.same_class as f64 / n,
        dt = r.max_theta_diff_deg,
        esr = r.exact.summary.success_rate,
        msr = r.map.summary.success_rate,
    )
}

/// Markers of the map-tier sections.
const BEGIN: &str = "<!-- map-tier:begin -->";
const END: &str = "<!-- map-tier:end -->";

/// `section` between the markers.
pub fn marked(section: &str) -> String {
    format!("{BEGIN}\n{section}{END}\n")
}

/// Put a marked section into `doc`: replace the one there, else append it.
pub fn splice(doc: &str, marked_section: &str) -> String {
    crate::study::mc::precision::splice_between(doc, marked_section, (BEGIN, END))
}

/// The marked section of `doc`, if any (so `bench accuracy` keeps it when it rewrites the file).
pub fn existing(doc: &str) -> Option<String> {
    crate::study::mc::precision::existing_between(doc, (BEGIN, END))
}
