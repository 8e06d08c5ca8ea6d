//! What one contact costs and how accurate it is at a given tolerance, per fidelity and part.
//!
//! For each part and fidelity, `n` random contacts (θ0 uniform in [0°, 360°), d uniform in
//! [−0.9, 0.9], from the reproducible stream (seed, part index)) are run at the tolerance under test
//! and again at a 1000× tighter one with the same fidelity. The *self-accuracy* is the difference in
//! final orientation between the two (it measures integration error, not model error: how far each
//! fidelity is from the exact model is the accuracy-vs-time study's business). Times are wall-clock
//! per contact on the calling thread (each contact's fastest of three passes over them all),
//! reported as median and 90th percentile.

use crate::geometry::{part_from_spec, wrap_deg, Pose, Vec2};
use crate::mechanics::{push, ContactOutcome, ContactSettings, Fidelity, PartModel, Pin};
use crate::study::bench_error::{uniform_model, BenchError};
use rand::RngExt;
use serde::Serialize;
use std::time::Instant;

/// One (part, fidelity) row of the contact-cost table.
#[derive(Debug, Clone, Serialize)]
pub struct ContactCostRow {
    /// The part spec.
    pub part: String,
    /// The fidelity (`exact`, `exact+tables`, `exact+sticks`, `ellipsoid`, `tip`).
    pub fidelity: String,
    /// Contacts run.
    pub contacts: usize,
    /// Contacts that touched the part (the rest passed it).
    pub touching: usize,
    /// Median wall time per contact (µs).
    pub median_us: f64,
    /// 90th percentile of wall time per contact (µs).
    pub p90_us: f64,
    /// Mean limit-surface evaluations per contact.
    pub mean_evaluations: f64,
    /// Mean accepted integration steps per contact.
    pub mean_steps: f64,
    /// |θf(tol) − θf(tol/1000)| in degrees: mean, 95th percentile, max.
    pub self_error_mean_deg: f64,
    /// 95th percentile of the self-error (degrees).
    pub self_error_p95_deg: f64,
    /// Largest self-error (degrees).
    pub self_error_max_deg: f64,
    /// Contacts whose status was not ok, by status name.
    pub non_ok: Vec<(String, usize)>,
    /// The tables (`exact+tables` and `exact+sticks` rows only).
    pub tables: Option<TableCost>,
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let idx = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[idx]
}

/// The exact model's tables in a [`ContactCostRow`] of model `exact+tables` or `exact+sticks`.
#[derive(Debug, Clone, Serialize)]
pub struct TableCost {
    /// Wall time to build every slide table (edge or vertex, side) of the part at μc and every
    /// cell of its stick tables (ms), before the timed runs.
    pub build_ms: f64,
    /// Nodes over the part's slide tables, and dissipation evaluations spent building them.
    pub nodes: usize,
    /// Dissipation evaluations spent building the slide tables.
    pub build_evaluations: u64,
    /// Slide-table intervals left to the solver (not certified).
    pub uncertified: usize,
    /// Certified pieces of the stick tables, pieces left to the solver, and dissipation
    /// evaluations spent building them.
    pub stick_pieces: usize,
    /// Pieces of the stick tables left to the solver.
    pub stick_open: usize,
    /// Dissipation evaluations spent building the stick tables.
    pub stick_evaluations: u64,
    /// max and mean |θf(tables) − θf(solves)| over the touching contacts at the same tolerance (°):
    /// what the tables change.
    pub vs_solves_max_deg: f64,
    /// Mean |θf(tables) − θf(solves)| over the touching contacts (degrees).
    pub vs_solves_mean_deg: f64,
}

/// Measure the contact cost table: per part, one row per fidelity, and after the exact row one
/// for the exact model with its tables (`exact+tables`, see `mechanics::slide_table` and
/// `mechanics::stick_table`) when
/// `tables` is set.
pub fn measure(
    parts: &[&str],
    fidelities: &[Fidelity],
    n: usize,
    tol: f64,
    seed: u64,
    tables: bool,
) -> Result<Vec<ContactCostRow>, BenchError> {
    let mut rows = Vec::new();
    for (pi, part) in parts.iter().enumerate() {
        let poly = part_from_spec(part)?;
        let model = uniform_model(&poly)?;
        let mut rng = crate::random::stream(seed, pi as u64);
        let cases: Vec<(f64, f64)> = (0..n)
            .map(|_| {
                (
                    rng.random::<f64>() * 360.0,
                    -0.9 + 1.8 * rng.random::<f64>(),
                )
            })
            .collect();
        for &fid in fidelities {
            let s = ContactSettings {
                fidelity: fid,
                tol,
                ..ContactSettings::default()
            };
            let bench = Bench {
                part,
                cases: &cases,
                a: poly.radius(),
                settings: s,
            };
            rows.push(bench.row(&model, fid.name(), None));
            if tables && fid == Fidelity::Exact {
                let tabled = model.clone().with_slide_tables(&[s.mu_c]);
                let t0 = Instant::now();
                tabled.build_all_tables();
                let build_ms = t0.elapsed().as_secs_f64() * 1e3;
                rows.push(bench.row(&tabled, "exact+tables", Some((&model, build_ms))));
                // With stick tables as well (as a map tier's build has them), every cell built
                // before the timed runs.
                let sticks = tabled.clone().with_stick_tables();
                let t0 = Instant::now();
                sticks.build_all_tables();
                let build_ms = t0.elapsed().as_secs_f64() * 1e3;
                rows.push(bench.row(&sticks, "exact+sticks", Some((&model, build_ms))));
            }
        }
    }
    Ok(rows)
}

/// The contacts are timed in this many passes and each keeps its fastest run: a contact is a pure
/// function of its inputs, so the spread between passes is the machine's (interrupts, another
/// process), which a single timing would put into the medians.
const TIMED_PASSES: usize = 3;

/// One part's contacts at one setting.
struct Bench<'a> {
    part: &'a str,
    cases: &'a [(f64, f64)],
    a: f64,
    settings: ContactSettings,
}

impl Bench<'_> {
    fn push(&self, model: &PartModel, st: &ContactSettings, th: f64, d: f64) -> ContactOutcome {
        let pose = Pose::new(0.0, 0.0, th.to_radians());
        push(
            model,
            pose,
            Vec2::new(1.01 * self.a, d * self.a),
            &Pin::point(),
            st,
            None,
        )
    }

    /// The row of `model` under the name `name`; `solves` (the same model without tables, and
    /// the tables' build time) adds the tables' columns.
    fn row(
        &self,
        model: &PartModel,
        name: &str,
        solves: Option<(&PartModel, f64)>,
    ) -> ContactCostRow {
        let s = self.settings;
        let tight = ContactSettings {
            tol: s.tol * 1e-3,
            ..s
        };
        // Warm up caches and the branch predictor.
        for &(th, d) in self.cases.iter().take(20) {
            std::hint::black_box(self.push(model, &s, th, d));
        }
        let n = self.cases.len();
        let mut times = Vec::with_capacity(n);
        let mut evals = 0u64;
        let mut steps = 0u64;
        let mut errors = Vec::with_capacity(n);
        let mut table_diffs = Vec::new();
        let mut touching = 0;
        let mut non_ok: std::collections::BTreeMap<String, usize> = Default::default();
        for &(th, d) in self.cases {
            let t0 = Instant::now();
            let o = std::hint::black_box(self.push(model, &s, th, d));
            times.push(t0.elapsed().as_secs_f64() * 1e6);
            if !o.status.is_ok() {
                *non_ok.entry(o.status.name().to_string()).or_default() += 1;
            }
            if !o.contact {
                continue;
            }
            touching += 1;
            evals += o.evaluations;
            steps += o.steps as u64;
            let r = self.push(model, &tight, th, d);
            errors.push(angle_between_deg(
                o.pose_final.theta_rad,
                r.pose_final.theta_rad,
            ));
            if let Some((plain, _)) = solves {
                let p = self.push(plain, &s, th, d);
                table_diffs.push(angle_between_deg(
                    o.pose_final.theta_rad,
                    p.pose_final.theta_rad,
                ));
            }
        }
        // Further passes over all the contacts (not one contact again and again, which would
        // train the branch predictor on it): each contact keeps its fastest run.
        for _ in 1..TIMED_PASSES {
            for (t, &(th, d)) in times.iter_mut().zip(self.cases) {
                let t0 = Instant::now();
                std::hint::black_box(self.push(model, &s, th, d));
                *t = t.min(t0.elapsed().as_secs_f64() * 1e6);
            }
        }
        times.sort_by(f64::total_cmp);
        errors.sort_by(f64::total_cmp);
        let k = touching.max(1) as f64;
        let tables = solves.map(|(_, build_ms)| {
            let st = model.slide_table_stats().unwrap_or_default();
            let sticks = model.stick_table_stats().unwrap_or_default();
            TableCost {
                build_ms,
                nodes: st.nodes,
                build_evaluations: st.evaluations,
                uncertified: st.uncertified,
                stick_pieces: sticks.pieces,
                stick_open: sticks.open,
                stick_evaluations: sticks.evaluations,
                vs_solves_max_deg: table_diffs.iter().copied().fold(0.0, f64::max),
                vs_solves_mean_deg: table_diffs.iter().sum::<f64>()
                    / table_diffs.len().max(1) as f64,
            }
        });
        ContactCostRow {
            part: self.part.to_string(),
            fidelity: name.into(),
            contacts: n,
            touching,
            median_us: percentile(&times, 0.5),
            p90_us: percentile(&times, 0.9),
            mean_evaluations: evals as f64 / k,
            mean_steps: steps as f64 / k,
            self_error_mean_deg: errors.iter().sum::<f64>() / errors.len().max(1) as f64,
            self_error_p95_deg: percentile(&errors, 0.95),
            self_error_max_deg: errors.last().copied().unwrap_or(0.0),
            non_ok: non_ok.into_iter().collect(),
            tables,
        }
    }
}

/// |θa − θb| in degrees, the short way round.
fn angle_between_deg(a: f64, b: f64) -> f64 {
    (wrap_deg(a.to_degrees() - b.to_degrees() + 180.0) - 180.0).abs()
}

/// Render the table as Markdown.
pub fn markdown(rows: &[ContactCostRow]) -> String {
    let mut s = String::new();
    s.push_str("| part | model | touching / contacts | median µs | p90 µs | evaluations | steps | self-error mean ° | p95 ° | max ° | not ok |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        let bad: Vec<String> = r.non_ok.iter().map(|(k, v)| format!("{k}: {v}")).collect();
        s.push_str(&format!(
            "| {} | {} | {}/{} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2e} | {:.2e} | {:.2e} | {} |\n",
            r.part,
            r.fidelity,
            r.touching,
            r.contacts,
            r.median_us,
            r.p90_us,
            r.mean_evaluations,
            r.mean_steps,
            r.self_error_mean_deg,
            r.self_error_p95_deg,
            r.self_error_max_deg,
            if bad.is_empty() {
                "—".into()
            } else {
                bad.join(", ")
            }
        ));
    }
    s
}

/// The tables' own table: build time and size, and what they change against the solves.
pub fn tables_markdown(rows: &[ContactCostRow]) -> String {
    let mut s = String::from(
        "| part | tables built (ms) | slide: nodes | evaluations to build | intervals left to the solver | stick: pieces | evaluations to build | pieces left to the solver | max \\|θf(tables) − θf(solves)\\| ° | mean ° |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        if let Some(t) = &r.tables {
            s.push_str(&format!(
                "| {} | {:.1} | {} | {} | {} | {} | {} | {} | {:.2e} | {:.2e} |\n",
                r.part,
                t.build_ms,
                t.nodes,
                t.build_evaluations,
                t.uncertified,
                t.stick_pieces,
                t.stick_evaluations,
                t.stick_open,
                t.vs_solves_max_deg,
                t.vs_solves_mean_deg
            ));
        }
    }
    s
}

/// How the exact model's cost grows with the vertex count (regular N-gons): the cost of one
/// evaluation of D, ∇D and H with the centre of rotation near the part (closed form, per edge)
/// and far from it (quadrature), and the cost of a whole contact.
#[derive(Debug, Clone, Serialize)]
pub struct ScalingRow {
    /// Vertices of the regular polygon.
    pub vertices: usize,
    /// ns per evaluation with the Hessian: centre of rotation within 2a, and at 8a.
    pub near_ns: f64,
    /// ns per evaluation with the centre of rotation at 8a.
    pub far_ns: f64,
    /// The contact table's row for the exact model on this part.
    pub contact: ContactCostRow,
}

/// Time `n` evaluations at twists whose centre of rotation lies at distance `r` (units of a) in
/// directions spread round the part, returning ns per evaluation.
fn eval_ns(model: &PartModel, r: f64, n: usize) -> f64 {
    let twists: Vec<[f64; 3]> = (0..n)
        .map(|k| {
            let phi = k as f64 * 2.399_963; // golden angle
            let rr = r * (0.25 + 0.75 * ((k * 7919) % 101) as f64 / 100.0);
            let c = Vec2::new(phi.cos(), phi.sin()) * rr;
            // ω = 1 about the centre c: v = −ẑ×c.
            [c.y, -c.x, 1.0]
        })
        .collect();
    let t0 = Instant::now();
    let mut acc = 0.0;
    for xi in &twists {
        acc += model.dissipation(*xi, true).value;
    }
    std::hint::black_box(acc);
    t0.elapsed().as_secs_f64() * 1e9 / n as f64
}

/// The vertex-count scaling for the regular N-gons of `vertices`.
pub fn vertex_scaling(
    vertices: &[usize],
    n: usize,
    tol: f64,
    seed: u64,
) -> Result<Vec<ScalingRow>, BenchError> {
    let mut rows = Vec::new();
    for &m in vertices {
        let name = format!("ngon:{m}");
        let model = uniform_model(&part_from_spec(&name)?)?;
        let near_ns = eval_ns(&model, 2.0, 20_000);
        let far_ns = eval_ns(&model, 8.0, 20_000);
        let contact = measure(&[name.as_str()], &[Fidelity::Exact], n, tol, seed, false)?
            .pop()
            .expect("one row per part and fidelity");
        rows.push(ScalingRow {
            vertices: m,
            near_ns,
            far_ns,
            contact,
        });
    }
    Ok(rows)
}

/// The scaling table as Markdown, with each cost relative to the first row's.
pub fn scaling_markdown(rows: &[ScalingRow]) -> String {
    let mut s = String::from(
        "| vertices | evaluation, centre near (ns) | × | evaluation, centre far (ns) | × | contact median µs | × | evaluations per contact |\n|---|---|---|---|---|---|---|---|\n",
    );
    let Some(first) = rows.first() else {
        return s;
    };
    for r in rows {
        s.push_str(&format!(
            "| {} | {:.0} | {:.1} | {:.0} | {:.1} | {:.1} | {:.1} | {:.0} |\n",
            r.vertices,
            r.near_ns,
            r.near_ns / first.near_ns,
            r.far_ns,
            r.far_ns / first.far_ns,
            r.contact.median_us,
            r.contact.median_us / first.contact.median_us,
            r.contact.mean_evaluations
        ));
    }
    s
}

/// Where the contact targets land, from the reference parts' rows.
pub fn targets(rows: &[ContactCostRow], scaling: &[ScalingRow]) -> String {
    let medians = |fid: &str| -> Vec<String> {
        rows.iter()
            .filter(|r| r.fidelity == fid)
            .map(|r| format!("{} {:.1}", r.part, r.median_us))
            .collect()
    };
    let worst = |fid: &str| {
        rows.iter()
            .filter(|r| r.fidelity == fid)
            .map(|r| r.median_us)
            .fold(0.0, f64::max)
    };
    let exact = |r: &&ContactCostRow| r.fidelity.starts_with("exact");
    let self_err = rows
        .iter()
        .filter(exact)
        .map(|r| r.self_error_p95_deg)
        .fold(0.0, f64::max);
    let self_max = rows
        .iter()
        .filter(exact)
        .map(|r| r.self_error_max_deg)
        .fold(0.0, f64::max);
    let tabled = rows.iter().any(|r| r.fidelity == "exact+tables");
    let growth = match (scaling.first(), scaling.last()) {
        (Some(a), Some(b)) if b.vertices > a.vertices => format!(
            "from {} to {} vertices ({:.0}×) one near-field evaluation costs {:.1}×, a far-field one {:.1}×, a whole contact {:.1}×",
            a.vertices,
            b.vertices,
            b.vertices as f64 / a.vertices as f64,
            b.near_ns / a.near_ns,
            b.far_ns / a.far_ns,
            b.contact.median_us / a.contact.median_us
        ),
        _ => "not measured".into(),
    };
    format!(
        "## Targets and where they land\n\n\
         | target | measured here | met |\n|---|---|---|\n\
         | exact ≤ 20 µs median per contact (slides solved) | {} µs | {} |\n\
         {}\
         | at ≤ 1e-3° self-accuracy (both) | p95 ≤ {:.1e}°, worst contact {:.1e}° | {} |\n\
         | ellipsoid ≤ 3 µs | {} µs | {} |\n\
         | tip ≤ 3 µs | {} µs | {} |\n\
         | exact cost sub-linear in the vertex count up to 48 | {growth} | see the table below |\n",
        medians("exact").join(", "),
        if worst("exact") <= 20.0 { "yes" } else { "no" },
        if tabled {
            let met = |fid: &str| if worst(fid) <= 20.0 { "yes" } else { "no" };
            format!(
                "| exact ≤ 20 µs median per contact (slides from the tables: a scene's model) | {} µs | {} |\n\
                 | exact ≤ 20 µs median per contact (slides and sticks from the tables: a map build's model) | {} µs | {} |\n",
                medians("exact+tables").join(", "),
                met("exact+tables"),
                medians("exact+sticks").join(", "),
                met("exact+sticks"),
            )
        } else {
            String::new()
        },
        self_err,
        self_max,
        if self_err <= 1e-3 { "p95 yes" } else { "no" },
        medians("ellipsoid").join(", "),
        if worst("ellipsoid") <= 3.0 {
            "yes"
        } else {
            "no"
        },
        medians("tip").join(", "),
        if worst("tip") <= 3.0 { "yes" } else { "no" },
    )
}

/// The report `bench contact` writes (its Markdown document) and the main table it prints, from
/// the measured rows, the vertex-count scaling and the settings (`out` is named in the command).
pub fn report(
    rows: &[ContactCostRow],
    scaling: &[ScalingRow],
    contacts: usize,
    cmd: &str,
) -> (String, String) {
    let table = markdown(rows);
    let targets = targets(rows, scaling);
    let tables = tables_markdown(rows);
    let scaling_table = scaling_markdown(scaling);
    let doc = format!(
        "# Contact model: cost and self-accuracy per contact\n\n\
         Regenerate with:\n\n```\n{cmd}\n```\n\n\
         Machine: {} cores. Each row: {contacts} random contacts (θ0 uniform, d uniform in \
         [−0.9, 0.9], point pin, μc = 0.5, uniform pressure). Times are wall-clock per contact \
         (single thread; each contact's fastest of three passes over them all, so that the \
         machine's spread stays out of the medians), including contacts where the pin \
         misses. *Evaluations* are limit-surface evaluations per touching contact (exact: dissipation evaluations \
         inside the Newton solves; tip/ellipsoid: closed-form solves). *Self-error* is \
         |θf(tol) − θf(tol/1000)| with the same model: the integration error at the \
         default tolerance, not the model error (see the accuracy-vs-time report for that).\n\n\
         `exact+tables` is the exact model with its tables (the default for a scene's, a \
         map's and a planner's model): a pin sliding on an edge (or a disc riding a \
         vertex) gets the exact twist from per-(μc, edge or vertex, side) tables of \
         certified cubic Hermite pieces (`crates/pinfeed/src/mechanics/slide_table.rs`) instead of a \
         Newton solve. `exact+sticks` adds what a map tier's build uses: a pin sticking on \
         an edge gets its twist from per-edge tables over (ℓ, direction of the pin's \
         velocity) of certified Chebyshev pieces (`crates/pinfeed/src/mechanics/stick_table.rs`). The \
         tables are built before the timed runs (a line or a map build builds them on \
         first use); the build is in the table below, with what the tables change against \
         the solves at the same tolerance.\n\n\
         {table}\n### Tables (exact+tables rows)\n\n{tables}\n{targets}\n\
         ### Cost against the vertex count (exact model, regular N-gons)\n\n\
         One evaluation of D, ∇D and H (20 000 twists, the centre of rotation within 2a: the \
         closed form, one term per edge; at 8a: the far-field quadrature, 64 nodes per \
         triangle of the part), and whole contacts ({quarter} per part, as above). × is \
         relative to the triangle.\n\n{scaling_table}\n",
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        quarter = (contacts / 4).max(1),
    );
    (table, doc)
}

/// `pinfeed bench contact`: `contacts` contacts (1 to 10⁶) per part and model at tolerance `tol`
/// (in (0, 0.01]) and the cost against the vertex count, written to `out` headed by `cmd`.
/// Returns the table printed.
pub fn bench(
    contacts: usize,
    tol: f64,
    seed: u64,
    cmd: &str,
    out: &std::path::Path,
    stage: &dyn Fn(&str),
) -> Result<String, BenchError> {
    if contacts == 0 || contacts > 1_000_000 {
        return Err(BenchError::argument(
            "contacts",
            "between 1 and 1000000",
            contacts,
        ));
    }
    if !(tol > 0.0 && tol <= 1e-2) {
        return Err(BenchError::argument("tol", "in (0, 0.01]", tol));
    }
    let parts = ["tripoly1", "tripoly2", "square", "lshape"];
    let fids = [Fidelity::Tip, Fidelity::Ellipsoid, Fidelity::Exact];
    stage(&format!("contact: {contacts} contacts per part and model"));
    let rows = measure(&parts, &fids, contacts, tol, seed, true)?;
    stage("contact: cost against the vertex count");
    let scaling = vertex_scaling(&[3, 6, 12, 24, 48], (contacts / 4).max(1), tol, seed)?;
    let (table, doc) = report(&rows, &scaling, contacts, cmd);
    let old = std::fs::read_to_string(out).unwrap_or_default();
    crate::output::write_file(out, keep_batch_section(&doc, &old))?;
    Ok(table)
}

/// The markers of the report's section on batches of contacts, which a criterion benchmark
/// measures (`cargo bench --features bench --bench contact -- contact_batch`) and
/// `bench contact` keeps when it rewrites the report.
pub const BATCH_SECTION: (&str, &str) =
    ("<!-- contact-batch:begin -->", "<!-- contact-batch:end -->");

/// `doc` with the batch section of the `old` report, if it has one, spliced in.
pub fn keep_batch_section(doc: &str, old: &str) -> String {
    use crate::study::mc::precision::{existing_between, splice_between};
    match existing_between(old, BATCH_SECTION) {
        Some(section) => splice_between(doc, &section, BATCH_SECTION),
        None => doc.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rewriting the report keeps the section another command measures, in place or appended,
    /// and nothing of the old report's own tables.
    #[test]
    fn the_report_keeps_its_batch_section() {
        let (b, e) = BATCH_SECTION;
        let old = format!("# Old\n\n| old table |\n\n{b}\n## Batches\n\n| 24.5 ms |\n{e}\n");
        let kept = keep_batch_section("# New\n\n| new table |\n", &old);
        assert_eq!(
            kept,
            format!("# New\n\n| new table |\n\n{b}\n## Batches\n\n| 24.5 ms |\n{e}\n")
        );
        assert!(!kept.contains("old table"));
        // Rewritten again: the section stays, once.
        assert_eq!(keep_batch_section("# New\n\n| new table |\n", &kept), kept);
        // Nothing to keep: the new report as it is.
        assert_eq!(keep_batch_section("# New\n", "# Old\n"), "# New\n");
    }
}
