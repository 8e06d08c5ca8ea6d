//! `pinfeed contact`: one pin pass over one part, or a batch of them from a CSV file.
//!
//! The part starts with its centroid at the origin of the belt frame at orientation θ0; the pin
//! starts just clear of the part's circumscribed circle, at x = a + ρ + 0.01a, y = d·a, and travels
//! in −x relative to the belt (plus w per unit travel for a moving pin). All lengths in the output
//! are in the part's units.

use crate::geometry::{named, wrap_deg, Polygon, Pose, Vec2};
use crate::mechanics::limits;
use crate::mechanics::{
    push, push_fence, push_path, ContactOutcome, ContactSettings, FenceSpec, Fidelity, PartModel,
    Pin, PinPath, Support, TraceSample, Turn,
};
use crate::report::plot_contact::{plot_contact, PassObstacle};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `pinfeed contact`.
#[derive(Debug, Args)]
pub struct ContactArgs {
    /// Part: tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, random:SEED[:N], or vertices:"x,y x,y ...".
    #[arg(long, required_unless_present = "cases")]
    pub part: Option<String>,
    /// Initial orientation θ0 (degrees).
    #[arg(long, allow_hyphen_values = true, required_unless_present = "cases")]
    pub theta0: Option<f64>,
    /// Contact parameter d = (y_pin − y_com)/a: the pin's lateral offset from the part's centroid in units of a (its
    /// largest centroid–vertex distance), a ratio without a length unit.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "cases")]
    pub d: Option<f64>,
    /// Pin–part friction coefficient μc (≥ 0).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Part–belt friction coefficient μs (> 0; scales forces only).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub mu_s: f64,
    /// Fidelity: exact, ellipsoid or tip; or map (the certified map tier over exact, still pins).
    #[arg(long, default_value = "exact")]
    pub model: String,
    /// With --model map: the folder of the map cache files (default $XDG_CACHE_HOME/pinfeed/maps
    /// or ~/.cache/pinfeed/maps).
    #[arg(long, value_name = "DIR", env = "PINFEED_CACHE")]
    pub cache_dir: Option<PathBuf>,
    /// With --model map: the map's grid, θ0 base cells, d base cells, refinement depth
    /// (default 36,12,4).
    #[arg(long, value_name = "T,D,DEPTH")]
    pub map_grid: Option<String>,
    /// Pin radius in part units: the coordinates the part is given in,
    /// not metres (`plan` and `sense`, which take `--scale`, use metres); 0: point pin.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Lateral pin speed as a fraction of the belt speed (moving pin).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_speed: f64,
    /// The thesis's app. E set-up: the pin moves across the belt at `--pin-speed` for this much
    /// belt travel (units of a, from its start just clear of the part at offset d), then stands
    /// still at d + w·S — one push with the true relative velocity, the stop mid-contact included
    /// (docs/physics.md#moving-and-retractable-pins).
    #[arg(
        long = "pin-stop-after",
        value_name = "S",
        allow_hyphen_values = true,
        requires = "pin_speed"
    )]
    pub pin_stop: Option<f64>,
    /// Where the moving pin stops, instead of when: it moves at `--pin-speed` from its start at
    /// offset d until it stands at lateral offset Y (units of a, the frame of `--d`), i.e. after
    /// `--pin-stop-after (Y − d)/w` of belt travel. Not with `--cases` (d differs per row).
    #[arg(
        long = "pin-stop-at",
        value_name = "Y",
        allow_hyphen_values = true,
        requires = "pin_speed",
        conflicts_with_all = ["pin_stop", "cases"]
    )]
    pub pin_stop_at: Option<f64>,
    /// When the moving pin stops, counted from its first touch: it moves at `--pin-speed` from its
    /// start, touches the part, and stops after T more units of a of belt travel (0: at the
    /// touch). A pin that never touches keeps moving. With `--cases`, T counts from each row's
    /// own first touch.
    #[arg(
        long = "pin-stop-after-touch",
        value_name = "T",
        allow_hyphen_values = true,
        requires = "pin_speed",
        conflicts_with_all = ["pin_stop", "pin_stop_at", "fence"]
    )]
    pub pin_stop_after_touch: Option<f64>,
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
    /// Draw the part's successive poses against the pin (or the fence) into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Push with a fence instead of a pin: angle from the belt direction in degrees (−90 < α < 90;
    /// positive fences deflect parts to the left) and optional length in part units (default 20a).
    /// The fence line crosses the part's path at y = d·a; `--mu-c` is the fence friction μf.
    #[arg(long, value_name = "ANGLE_DEG[:LENGTH]", allow_hyphen_values = true)]
    pub fence: Option<String>,
    /// Batch mode: a CSV with columns part,theta0,d,mu_c (+ optional model,pin_radius,mu_s); one
    /// output row per case goes to stdout. `--fence`, `--pin-speed`, `--support`, `--tol` and the
    /// defaults of the optional columns apply to every row.
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
    /// Belt travel (units of a) from the pin's start to where it stops.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_stop: Option<f64>,
    /// `--pin-stop-after-touch`: belt travel (units of a) from the first touch to the stop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_stop_after_touch: Option<f64>,
    /// A moving pin's lateral offset (units of a, the frame of `d`) at its first touch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_touch_d: Option<f64>,
    /// A moving pin's lateral offset (units of a) where it stops.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_stop_d: Option<f64>,
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
    /// A moving pin stops after this much belt travel (units of a).
    pub pin_stop: Option<f64>,
    /// A moving pin stops after this much belt travel (units of a) past its first touch.
    pub pin_stop_after_touch: Option<f64>,
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
        bail!(
            "--fence '{spec}': the angle must be strictly between -90 and 90 degrees, got {}",
            num(angle)
        );
    }
    let length = match it.next() {
        None => None,
        Some(l) => {
            let l: f64 = l
                .trim()
                .parse()
                .with_context(|| format!("--fence '{spec}': the length is not a number"))?;
            if !(l.is_finite() && l > 0.0) {
                bail!(
                    "--fence '{spec}': the length must be a positive number (part units), got {}",
                    num(l)
                );
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

/// A number for a message: plain when moderate, in exponent notation when huge or tiny (so that
/// 1e308 does not print as 309 digits).
pub(crate) fn num(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// `name must lie in [lo, hi] (what), got v` unless `lo ≤ v ≤ hi` (and v finite).
pub(crate) fn in_range(name: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<()> {
    if !(v.is_finite() && v >= lo && v <= hi) {
        let kind = if v.is_finite() {
            ""
        } else {
            "a finite number "
        };
        bail!(
            "{name} must be {kind}in [{}, {}] ({what}), got {}",
            num(lo),
            num(hi),
            num(v)
        );
    }
    Ok(())
}

/// The flag naming a setting (`mu_c` → `--mu-c`).
fn flag(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

/// Refuse non-finite or out-of-range settings of a case (the ones that do not depend on the part)
/// with a message naming the option, its range and the value.
pub(crate) fn check_inputs(c: &Case) -> Result<()> {
    check_inputs_named(c, &flag)
}

/// [`check_inputs`] with the settings named by `name` (a flag, or a CSV column).
fn check_inputs_named(c: &Case, name: &dyn Fn(&str) -> String) -> Result<()> {
    use limits::*;
    in_range(
        &name("theta0"),
        c.theta0_deg,
        -THETA0_DEG,
        THETA0_DEG,
        "degrees",
    )?;
    if !c.d.is_finite() {
        bail!("{} must be a finite number, got {}", name("d"), num(c.d));
    }
    in_range(
        &name("mu_c"),
        c.mu_c,
        MU_C.0,
        MU_C.1,
        "friction coefficient",
    )?;
    in_range(
        &name("mu_s"),
        c.mu_s,
        MU_S.0,
        MU_S.1,
        "support friction; it scales forces only",
    )?;
    if !(c.pin_radius.is_finite() && c.pin_radius >= 0.0) {
        bail!(
            "{} must be a finite number >= 0 (part units, at most {PIN_RADIUS_A}·a), got {}",
            name("pin_radius"),
            num(c.pin_radius)
        );
    }
    check_flag_settings(c.pin_speed, c.pin_stop, c.tol, name)?;
    check_stop_after_touch(c.pin_stop_after_touch)
}

/// `--pin-stop-after-touch T`: T in [0, 1000] units of a.
fn check_stop_after_touch(t: Option<f64>) -> Result<()> {
    if let Some(t) = t {
        in_range(
            "--pin-stop-after-touch",
            t,
            0.0,
            1e3,
            "units of a of belt travel after the first touch",
        )?;
    }
    Ok(())
}

/// The settings a batch takes from flags only (the pin's path and the tolerance), named by `name`.
fn check_flag_settings(
    pin_speed: f64,
    pin_stop: Option<f64>,
    tol: f64,
    name: &dyn Fn(&str) -> String,
) -> Result<()> {
    use limits::*;
    in_range(
        &name("pin_speed"),
        pin_speed,
        -PIN_SPEED,
        PIN_SPEED,
        "fraction of the belt speed",
    )?;
    if let Some(s_stop) = pin_stop {
        in_range(
            "--pin-stop-after",
            s_stop,
            1e-9,
            1e3,
            "units of a of belt travel",
        )?;
    }
    in_range(
        &name("tol"),
        tol,
        TOL.0,
        TOL.1,
        "integration tolerance per step",
    )?;
    Ok(())
}

/// Largest |d| at which the pin of a case can touch the part: the disc's reach 1 + ρ/a, widened for
/// a moving pin by the lateral distance it covers while crossing the part (about 2.02·(a + ρ) of
/// belt travel at |w| per unit).
pub fn reach(c: &Case, a: f64) -> f64 {
    (1.0 + c.pin_radius / a) * (1.0 + 2.02 * c.pin_speed.abs())
}

/// Refuse settings of a case that are out of range relative to the part (`a` = its size): pin
/// radius, d beyond what can touch, fence length.
pub(crate) fn check_geometry(c: &Case, poly: &Polygon) -> Result<()> {
    check_geometry_named(c, poly, &flag)
}

fn check_geometry_named(c: &Case, poly: &Polygon, name: &dyn Fn(&str) -> String) -> Result<()> {
    use limits::*;
    let a = poly.radius();
    let rmax = PIN_RADIUS_A * a;
    if c.pin_radius > rmax {
        bail!(
            "{} must lie in [0, {}] (part units: at most {PIN_RADIUS_A}·a, a = {}), got {}",
            name("pin_radius"),
            num(rmax),
            num(a),
            num(c.pin_radius)
        );
    }
    match c.fence {
        Some((_, length)) => {
            in_range(&name("d"), c.d, -FENCE_D, FENCE_D, "units of a")?;
            if let Some(l) = length {
                let (lo, hi) = (FENCE_LENGTH_A.0 * a, FENCE_LENGTH_A.1 * a);
                if !(l >= lo && l <= hi) {
                    bail!(
                        "--fence: the length must lie in [{}, {}] (part units: {}·a to {}·a, a = {}), got {}",
                        num(lo),
                        num(hi),
                        FENCE_LENGTH_A.0,
                        FENCE_LENGTH_A.1,
                        num(a),
                        num(l)
                    );
                }
            }
        }
        None => {
            let limit = reach(c, a);
            if c.d.abs() > limit {
                bail!(
                    "{} = {} is out of range: it must lie in [-{}, {}] (units of a: beyond it this pin cannot touch the part)",
                    name("d"),
                    num(c.d),
                    num(limit),
                    num(limit)
                );
            }
        }
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
    check_geometry(c, &poly)?;
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
        None => match c.pin_stop {
            _ if c.pin_stop_after_touch.is_some() => {
                let t = c.pin_stop_after_touch.unwrap_or(0.0) * poly.radius();
                let path = crate::mechanics::stop_after_touch(
                    model,
                    pose,
                    start,
                    pin.radius,
                    c.pin_speed,
                    t,
                )
                .expect("checked by check_inputs");
                push_path(model, pose, start, pin.radius, &path, &settings, recorder)
            }
            Some(s_stop) => {
                let turn = Turn {
                    s: s_stop * poly.radius(),
                    w: 0.0,
                };
                let path = PinPath::new(c.pin_speed, vec![turn]).expect("checked by check_inputs");
                push_path(model, pose, start, pin.radius, &path, &settings, recorder)
            }
            None => push(model, pose, start, &pin, &settings, recorder),
        },
    };
    (out, trace)
}

/// The initial pose of a case and its obstacle as the plot draws it: the pin (start, radius,
/// lateral speed) or the fence segment.
fn pass_obstacle(poly: &Polygon, c: &Case) -> (Pose, PassObstacle) {
    let (pose, start) = case_geometry(poly, c);
    let obstacle = match c.fence {
        Some((angle, length)) => {
            let fence = case_fence(poly, c, angle, length);
            PassObstacle::Fence {
                start: fence.start,
                end: fence.start + Vec2::from_angle(fence.angle) * fence.length,
            }
        }
        None => PassObstacle::Pin {
            start,
            radius: c.pin_radius,
            lateral_speed: c.pin_speed,
        },
    };
    (pose, obstacle)
}

/// The plot's title: the part, θ0, d, the friction and the model (and the fence's angle).
fn plot_title(c: &Case) -> String {
    match c.fence {
        Some((angle, _)) => format!(
            "{} θ0={}° d={} fence α={}° μf={} ({})",
            c.part,
            c.theta0_deg,
            c.d,
            angle,
            c.mu_c,
            c.model.name()
        ),
        None => format!(
            "{} θ0={}° d={} μc={} ({})",
            c.part,
            c.theta0_deg,
            c.d,
            c.mu_c,
            c.model.name()
        ),
    }
}

pub(crate) fn report(c: &Case, out: &ContactOutcome) -> ContactReport {
    ContactReport {
        part: c.part.clone(),
        model: c.model.name().into(),
        theta0_deg: c.theta0_deg,
        d: c.d,
        mu_c: c.mu_c,
        mu_s: c.mu_s,
        pin_radius: c.pin_radius,
        pin_speed: c.pin_speed,
        pin_stop: c.pin_stop,
        pin_stop_after_touch: c.pin_stop_after_touch,
        pin_touch_d: None,
        pin_stop_d: None,
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

impl ContactReport {
    /// A moving pin's travel to its stop and its lateral offsets at the first touch and at the
    /// stop (units of a; `a` is the part's size), from the case and its outcome.
    pub(crate) fn with_pin_positions(mut self, c: &Case, a: f64, out: &ContactOutcome) -> Self {
        if c.fence.is_some() || c.pin_speed == 0.0 {
            return self;
        }
        let touch = out.contact.then(|| out.travel_to_contact / a);
        let stop = match (c.pin_stop, c.pin_stop_after_touch) {
            (Some(s), _) => Some(s),
            (None, Some(t)) => touch.map(|s| s + t),
            (None, None) => None,
        };
        let at = |s: f64| c.d + c.pin_speed * stop.map_or(s, |e| s.min(e));
        self.pin_stop = stop;
        self.pin_touch_d = touch.map(at);
        self.pin_stop_d = stop.map(at);
        self
    }
}

/// Parse `--model`: exact, ellipsoid or tip.
pub(crate) fn parse_model(s: &str) -> Result<Fidelity> {
    Fidelity::parse(s.trim())
        .with_context(|| format!("unknown model '{s}'; expected exact, ellipsoid or tip"))
}

/// The single case the arguments describe, with fidelity `model`.
pub(crate) fn case_of(args: &ContactArgs, model: Fidelity) -> Result<Case> {
    let d = args.d.unwrap_or(0.0);
    let pin_stop = match args.pin_stop_at {
        Some(y) => Some(stop_travel(y, d, args.pin_speed)?),
        None => args.pin_stop,
    };
    Ok(Case {
        part: args.part.clone().unwrap_or_default(),
        theta0_deg: args.theta0.unwrap_or(0.0),
        d,
        mu_c: args.mu_c,
        mu_s: args.mu_s,
        model,
        pin_radius: args.pin_radius,
        pin_speed: args.pin_speed,
        pin_stop,
        pin_stop_after_touch: args.pin_stop_after_touch,
        support: args.support.clone(),
        tol: args.tol,
        fence: args.fence.as_deref().map(parse_fence).transpose()?,
    })
}

/// The belt travel (units of a) after which a pin starting at lateral offset `d` and moving at
/// `w` (lateral per unit of travel) stands at offset `y`: (y − d)/w, in `--pin-stop-after`'s range.
fn stop_travel(y: f64, d: f64, w: f64) -> Result<f64> {
    let s = (y - d) / w;
    if !(y.is_finite() && s.is_finite() && (1e-9..=1e3).contains(&s)) {
        bail!(
            "--pin-stop-at {}: a pin starting at d = {} and moving {} per unit of travel reaches it after {} units of a; that must lie in [1e-9, 1000] (Y on the side the pin moves to, within 1000·|w| of d)",
            num(y),
            num(d),
            num(w),
            num(s)
        );
    }
    Ok(s)
}

pub fn run(args: &ContactArgs) -> Result<()> {
    if let Some(path) = &args.cases {
        return run_batch(args, path);
    }
    if args.model.trim() == "map" {
        return super::contact_map::run(args);
    }
    let c = case_of(args, parse_model(&args.model)?)?;
    let want_trace = args.trace.is_some() || args.plot.is_some();
    let (poly, out, trace) = run_case(&c, want_trace)?;
    if let Some(path) = &args.trace {
        write_trace(path, &trace).with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        let (pose, obstacle) = pass_obstacle(&poly, &c);
        plot_contact(&poly, pose, &obstacle, &out, &trace, &plot_title(&c), path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let r = report(&c, &out).with_pin_positions(&c, poly.radius(), &out);
    if args.json {
        print!("{}", crate::report::versioned::pretty(&r)?);
    } else {
        println!(
            "part {}  model {}  θ0 {}°  d {}  μc {}",
            r.part, r.model, r.theta0_deg, r.d, r.mu_c
        );
        if !r.contact {
            println!("no contact: the pin passes the part");
        } else {
            print_motion(&r);
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

/// The final pose, rotation and contact length of a push that touched.
pub(crate) fn print_motion(r: &ContactReport) {
    println!("final orientation   {:.4}°", r.theta_final_deg);
    println!("rotation            {:+.4}°", r.rotation_deg);
    println!(
        "final centroid      ({:.5}, {:.5})",
        r.com_final[0], r.com_final[1]
    );
    println!("contact length      {:.5}", r.contact_length);
    if let Some(y) = r.pin_touch_d {
        println!("pin at first touch  d = {y:.5}");
    }
    if let Some(y) = r.pin_stop_d {
        println!("pin stops at        d = {y:.5}");
    }
}

fn write_trace(path: &std::path::Path, trace: &[TraceSample]) -> Result<()> {
    let mut f = Vec::new();
    writeln!(
        f,
        "s,x,y,theta_deg,pin_x,pin_y,contact_x,contact_y,force_x,force_y,mode,feature,index,normal_x,normal_y,rotation_rate"
    )?;
    for t in trace {
        let (kind, idx) = (t.feature.kind(), t.feature.index());
        writeln!(
            f,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
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
            idx,
            t.normal.x,
            t.normal.y,
            t.rotation_rate
        )?;
    }
    crate::report::atomic::write_atomic(path, f)?;
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
    let text =
        crate::input::read_text(path).with_context(|| format!("reading {}", path.display()))?;
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let mut wtr = csv::Writer::from_writer(std::io::stdout().lock());
    let mut compiled: std::collections::HashMap<String, (Polygon, PartModel)> = Default::default();
    let fence = args.fence.as_deref().map(parse_fence).transpose()?;
    // Flags that apply to every row are checked once, before any row (an error there is the
    // flag's, not a row's).
    check_flag_settings(args.pin_speed, args.pin_stop, args.tol, &flag)?;
    check_stop_after_touch(args.pin_stop_after_touch)?;
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
            pin_stop: args.pin_stop,
            pin_stop_after_touch: args.pin_stop_after_touch,
            support: args.support.clone(),
            tol: args.tol,
            fence,
        };
        // A setting given in the row is named by its column, one taken from a flag by the flag.
        let in_row = |field: &str| match field {
            "theta0" | "d" | "mu_c" => true,
            "pin_radius" => row.pin_radius.is_some(),
            "mu_s" => row.mu_s.is_some(),
            _ => false,
        };
        let name = |field: &str| {
            if in_row(field) {
                format!("column {field}")
            } else {
                flag(field)
            }
        };
        let at = || format!("{}:{line}", path.display());
        check_inputs_named(&c, &name).with_context(at)?;
        // Compile each distinct part once for the whole batch.
        if !compiled.contains_key(&c.part) {
            let pm = compile_part(&c.part, &c.support).with_context(at)?;
            compiled.insert(c.part.clone(), pm);
        }
        let (poly, model) = &compiled[&c.part];
        check_geometry_named(&c, poly, &name).with_context(at)?;
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
