//! `pinfeed contact`: one pin pass over one part, or a batch of them from a CSV file.
//!
//! The part starts with its centroid at the origin of the belt frame at orientation θ0; the pin
//! starts just clear of the part's circumscribed circle, at x = a + ρ + 0.01a, y = d·a, and travels
//! in −x relative to the belt (plus w per unit travel for a moving pin). All lengths in the output
//! are in the part's units.

use crate::geometry::{named, wrap_deg, Polygon, Pose, Vec2};
use crate::mechanics::{
    push, push_fence, ContactOutcome, ContactSettings, FenceSpec, Fidelity, PartModel, Pin,
    Support, TraceSample,
};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `pinfeed contact`.
#[derive(Debug, Args)]
pub struct ContactArgs {
    /// Part: tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, or vertices:"x,y x,y ...".
    #[arg(long, required_unless_present = "cases")]
    pub part: Option<String>,
    /// Initial orientation θ0 (degrees).
    #[arg(long, allow_hyphen_values = true, required_unless_present = "cases")]
    pub theta0: Option<f64>,
    /// Contact parameter d = (y_pin − y_com)/a.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "cases")]
    pub d: Option<f64>,
    /// Pin–part friction coefficient μc (≥ 0).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Part–belt friction coefficient μs (> 0; scales forces only).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub mu_s: f64,
    /// Fidelity: exact, ellipsoid or tip.
    #[arg(long, default_value = "exact")]
    pub model: String,
    /// Pin radius in part units (0: point pin).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Lateral pin speed as a fraction of the belt speed (moving pin).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_speed: f64,
    /// Support: uniform or tripod:SEED.
    #[arg(long, default_value = "uniform")]
    pub support: String,
    /// Integration tolerance (absolute, radians / units of a, per step).
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Write the trajectory and contact force per step to this CSV file.
    #[arg(long, value_name = "FILE.csv")]
    pub trace: Option<PathBuf>,
    /// Draw the part's successive poses against the pin into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Push with a fence instead of a pin: angle from the belt direction in degrees (−90 < α < 90;
    /// positive fences deflect parts to the left) and optional length in part units (default 20a).
    /// The fence line crosses the part's path at y = d·a; `--mu-c` is the fence friction μf.
    #[arg(long, value_name = "ANGLE_DEG[:LENGTH]", allow_hyphen_values = true)]
    pub fence: Option<String>,
    /// Batch mode: a CSV with columns part,theta0,d,mu_c (+ optional model,pin_radius,mu_s); one
    /// output row per case goes to stdout.
    #[arg(long, value_name = "FILE.csv", conflicts_with_all = ["part", "theta0", "d", "json", "trace", "plot"])]
    pub cases: Option<PathBuf>,
}

/// The JSON printed by `pinfeed contact --json`.
#[derive(Debug, Serialize)]
pub struct ContactReport {
    pub part: String,
    pub model: String,
    pub theta0_deg: f64,
    pub d: f64,
    pub mu_c: f64,
    pub mu_s: f64,
    pub pin_radius: f64,
    pub pin_speed: f64,
    pub contact: bool,
    pub theta_final_deg: f64,
    pub rotation_deg: f64,
    pub com_final: [f64; 2],
    pub travel_to_contact: f64,
    pub contact_length: f64,
    pub contacts: u32,
    pub segments: Vec<crate::mechanics::Segment>,
    pub evaluations: u64,
    pub steps: u32,
    pub status: String,
    pub status_detail: crate::mechanics::ContactStatus,
}

/// One fully specified contact case.
#[derive(Debug, Clone)]
pub struct Case {
    pub part: String,
    pub theta0_deg: f64,
    pub d: f64,
    pub mu_c: f64,
    pub mu_s: f64,
    pub model: Fidelity,
    pub pin_radius: f64,
    pub pin_speed: f64,
    pub support: String,
    pub tol: f64,
    /// A fence (angle in degrees, length in part units; None = default length) instead of a pin.
    pub fence: Option<(f64, Option<f64>)>,
}

/// Parse `ANGLE_DEG[:LENGTH]`.
pub fn parse_fence(spec: &str) -> Result<(f64, Option<f64>)> {
    let mut it = spec.splitn(2, ':');
    let angle: f64 = it
        .next()
        .unwrap_or("")
        .trim()
        .parse()
        .with_context(|| format!("--fence '{spec}': the angle is not a number"))?;
    if !(angle.is_finite() && angle.abs() < 90.0) {
        bail!("--fence '{spec}': the angle must be strictly between -90 and 90 degrees");
    }
    let length = match it.next() {
        None => None,
        Some(l) => {
            let l: f64 = l
                .trim()
                .parse()
                .with_context(|| format!("--fence '{spec}': the length is not a number"))?;
            if !(l.is_finite() && l > 0.0) {
                bail!("--fence '{spec}': the length must be a positive number");
            }
            Some(l)
        }
    };
    Ok((angle, length))
}

/// The fence of a case: the convention of [`crate::maps::fence_pass_start`] (its line 1.01a clear of
/// the centroid, crossing y = d·a; its upstream end 1.5a beyond the part's band on the side it
/// comes from), with the case's μc as the fence friction μf.
pub fn case_fence(poly: &Polygon, c: &Case, angle_deg: f64, length: Option<f64>) -> FenceSpec {
    crate::maps::fence_pass_start(poly, c.d, angle_deg, length, c.mu_c)
}

/// Refuse non-finite or out-of-range settings of a case with a message naming the option.
pub(crate) fn check_inputs(c: &Case) -> Result<()> {
    let finite = |name: &str, v: f64| -> Result<()> {
        if !v.is_finite() {
            bail!("{name} must be a finite number, got {v}");
        }
        Ok(())
    };
    finite("theta0", c.theta0_deg)?;
    finite("d", c.d)?;
    finite("mu-c", c.mu_c)?;
    finite("mu-s", c.mu_s)?;
    finite("pin-radius", c.pin_radius)?;
    finite("pin-speed", c.pin_speed)?;
    finite("tol", c.tol)?;
    if c.mu_c < 0.0 {
        bail!("mu-c (contact friction) must be >= 0, got {}", c.mu_c);
    }
    if c.mu_s <= 0.0 {
        bail!("mu-s (support friction) must be > 0, got {}", c.mu_s);
    }
    if c.pin_radius < 0.0 {
        bail!("pin-radius must be >= 0, got {}", c.pin_radius);
    }
    if !(c.tol > 0.0 && c.tol <= 1e-2) {
        bail!("tol must be in (0, 0.01], got {}", c.tol);
    }
    if c.d.abs() > 100.0 {
        bail!(
            "d must be within [-100, 100] (it is in units of a), got {}",
            c.d
        );
    }
    Ok(())
}

/// The initial pose and pin start for a case (part centred at the origin, pin just clear of it):
/// the convention of [`crate::maps::pass_start`], shared with configuration maps.
pub fn case_geometry(poly: &Polygon, c: &Case) -> (Pose, Vec2) {
    crate::maps::pass_start(poly, c.theta0_deg, c.d, c.pin_radius)
}

/// Resolve a part spec and a support spec into the polygon and its compiled contact model.
pub(crate) fn compile_part(part: &str, support: &str) -> Result<(Polygon, PartModel)> {
    let poly = named::part_from_spec(part).with_context(|| format!("part '{part}'"))?;
    let support = Support::parse(support, &poly).map_err(anyhow::Error::msg)?;
    let model = PartModel::new(&poly, &support).map_err(anyhow::Error::msg)?;
    Ok((poly, model))
}

/// The contact-model settings and the pin of a case.
pub(crate) fn settings_and_pin(c: &Case) -> (ContactSettings, Pin) {
    let settings = ContactSettings {
        fidelity: c.model,
        mu_c: c.mu_c,
        mu_s: c.mu_s,
        tol: c.tol,
        ..ContactSettings::default()
    };
    let pin = Pin {
        radius: c.pin_radius,
        lateral_speed: c.pin_speed,
    };
    (settings, pin)
}

/// Run one case; returns the polygon, the outcome and (if asked) the trace.
pub fn run_case(c: &Case, want_trace: bool) -> Result<(Polygon, ContactOutcome, Vec<TraceSample>)> {
    check_inputs(c)?;
    let (poly, model) = compile_part(&c.part, &c.support)?;
    let (out, trace) = run_compiled(c, &poly, &model, want_trace);
    Ok((poly, out, trace))
}

/// Run a validated case on an already compiled part.
fn run_compiled(
    c: &Case,
    poly: &Polygon,
    model: &PartModel,
    want_trace: bool,
) -> (ContactOutcome, Vec<TraceSample>) {
    let (settings, pin) = settings_and_pin(c);
    let (pose, start) = case_geometry(poly, c);
    let mut trace: Vec<TraceSample> = Vec::new();
    let recorder: Option<&mut dyn crate::mechanics::Recorder> =
        if want_trace { Some(&mut trace) } else { None };
    let out = match c.fence {
        Some((angle, length)) => {
            let fence = case_fence(poly, c, angle, length);
            push_fence(model, pose, &fence, &settings, recorder)
        }
        None => push(model, pose, start, &pin, &settings, recorder),
    };
    (out, trace)
}

fn report(c: &Case, out: &ContactOutcome) -> ContactReport {
    ContactReport {
        part: c.part.clone(),
        model: c.model.name().into(),
        theta0_deg: c.theta0_deg,
        d: c.d,
        mu_c: c.mu_c,
        mu_s: c.mu_s,
        pin_radius: c.pin_radius,
        pin_speed: c.pin_speed,
        contact: out.contact,
        theta_final_deg: wrap_deg(out.pose_final.theta.to_degrees()),
        rotation_deg: out.rotation.to_degrees(),
        com_final: [out.pose_final.x, out.pose_final.y],
        travel_to_contact: out.travel_to_contact,
        contact_length: out.contact_length,
        contacts: out.contacts,
        segments: out.segments.clone(),
        evaluations: out.evaluations,
        steps: out.steps,
        status: out.status.name().into(),
        status_detail: out.status,
    }
}

/// Parse `--model`: exact, ellipsoid or tip.
pub(crate) fn parse_model(s: &str) -> Result<Fidelity> {
    Fidelity::parse(s.trim())
        .with_context(|| format!("unknown model '{s}'; expected exact, ellipsoid or tip"))
}

pub fn run(args: &ContactArgs) -> Result<()> {
    if let Some(path) = &args.cases {
        return run_batch(args, path);
    }
    let c = Case {
        part: args.part.clone().unwrap_or_default(),
        theta0_deg: args.theta0.unwrap_or(0.0),
        d: args.d.unwrap_or(0.0),
        mu_c: args.mu_c,
        mu_s: args.mu_s,
        model: parse_model(&args.model)?,
        pin_radius: args.pin_radius,
        pin_speed: args.pin_speed,
        support: args.support.clone(),
        tol: args.tol,
        fence: args.fence.as_deref().map(parse_fence).transpose()?,
    };
    let want_trace = args.trace.is_some() || args.plot.is_some();
    let (poly, out, trace) = run_case(&c, want_trace)?;
    if let Some(path) = &args.trace {
        write_trace(path, &trace).with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        let (pose, start) = case_geometry(&poly, &c);
        crate::report::plot_contact::plot_contact(&poly, pose, start, &out, &trace, &c, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let r = report(&c, &out);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        println!(
            "part {}  model {}  θ0 {}°  d {}  μc {}",
            r.part, r.model, r.theta0_deg, r.d, r.mu_c
        );
        if !r.contact {
            println!("no contact: the pin passes the part");
        } else {
            println!("final orientation   {:.4}°", r.theta_final_deg);
            println!("rotation            {:+.4}°", r.rotation_deg);
            println!(
                "final centroid      ({:.5}, {:.5})",
                r.com_final[0], r.com_final[1]
            );
            println!("contact length      {:.5}", r.contact_length);
            let segs: Vec<String> = r
                .segments
                .iter()
                .map(|s| {
                    format!(
                        "{} {} {}",
                        s.feature.kind(),
                        s.feature.index(),
                        s.mode.name()
                    )
                })
                .collect();
            println!("segments            {}", segs.join(" → "));
            println!("evaluations         {} ({} steps)", r.evaluations, r.steps);
        }
        println!("status              {}", r.status);
    }
    if !out.status.is_ok() && !args.json {
        eprintln!("warning: contact ended with status {:?}", out.status);
    }
    Ok(())
}

fn write_trace(path: &std::path::Path, trace: &[TraceSample]) -> Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        f,
        "s,x,y,theta_deg,pin_x,pin_y,contact_x,contact_y,force_x,force_y,mode,feature,index"
    )?;
    for t in trace {
        let (kind, idx) = (t.feature.kind(), t.feature.index());
        writeln!(
            f,
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            t.s,
            t.pose.x,
            t.pose.y,
            t.pose.theta.to_degrees(),
            t.pin_centre.x,
            t.pin_centre.y,
            t.contact_point.x,
            t.contact_point.y,
            t.force.x,
            t.force.y,
            t.mode.name(),
            kind,
            idx
        )?;
    }
    Ok(())
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseRow {
    part: String,
    theta0: f64,
    d: f64,
    mu_c: f64,
    model: Option<String>,
    pin_radius: Option<f64>,
    mu_s: Option<f64>,
}

#[derive(Debug, Serialize)]
struct CaseOut<'a> {
    part: &'a str,
    theta0: f64,
    d: f64,
    mu_c: f64,
    model: &'a str,
    pin_radius: f64,
    mu_s: f64,
    contact: bool,
    theta_final_deg: f64,
    rotation_deg: f64,
    com_final_x: f64,
    com_final_y: f64,
    contact_length: f64,
    segments: usize,
    evaluations: u64,
    status: &'a str,
}

fn run_batch(args: &ContactArgs, path: &std::path::Path) -> Result<()> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut wtr = csv::Writer::from_writer(std::io::stdout().lock());
    let mut compiled: std::collections::HashMap<String, (Polygon, PartModel)> = Default::default();
    for (i, row) in rdr.deserialize::<CaseRow>().enumerate() {
        let row = row.map_err(|e| {
            let line = e.position().map(|p| p.line()).unwrap_or(i as u64 + 2);
            anyhow::anyhow!("{}:{}: {}", path.display(), line, e)
        })?;
        let line = i + 2;
        let model = match &row.model {
            Some(m) if !m.is_empty() => parse_model(m)
                .with_context(|| format!("{}:{line}: field 'model'", path.display()))?,
            _ => parse_model(&args.model)?,
        };
        let c = Case {
            part: row.part.clone(),
            theta0_deg: row.theta0,
            d: row.d,
            mu_c: row.mu_c,
            mu_s: row.mu_s.unwrap_or(args.mu_s),
            model,
            pin_radius: row.pin_radius.unwrap_or(args.pin_radius),
            pin_speed: args.pin_speed,
            support: args.support.clone(),
            tol: args.tol,
            fence: None,
        };
        check_inputs(&c).with_context(|| format!("{}:{line}", path.display()))?;
        // Compile each distinct part once for the whole batch.
        if !compiled.contains_key(&c.part) {
            let pm = compile_part(&c.part, &c.support)
                .with_context(|| format!("{}:{line}", path.display()))?;
            compiled.insert(c.part.clone(), pm);
        }
        let (poly, model) = &compiled[&c.part];
        let (out, _) = run_compiled(&c, poly, model, false);
        wtr.serialize(CaseOut {
            part: &c.part,
            theta0: c.theta0_deg,
            d: c.d,
            mu_c: c.mu_c,
            model: c.model.name(),
            pin_radius: c.pin_radius,
            mu_s: c.mu_s,
            contact: out.contact,
            theta_final_deg: wrap_deg(out.pose_final.theta.to_degrees()),
            rotation_deg: out.rotation.to_degrees(),
            com_final_x: out.pose_final.x,
            com_final_y: out.pose_final.y,
            contact_length: out.contact_length,
            segments: out.segments.len(),
            evaluations: out.evaluations,
            status: out.status.name(),
        })?;
    }
    wtr.flush()?;
    Ok(())
}
