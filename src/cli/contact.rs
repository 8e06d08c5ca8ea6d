//! `pinfeed contact`: one pin pass over one part, or a batch of them from a CSV file.
//!
//! The part starts with its centroid at the origin of the belt frame at orientation θ0; the pin
//! starts just clear of the part's circumscribed circle, at x = a + ρ + 0.01a, y = d·a, and travels
//! in −x relative to the belt (plus w per unit travel for a moving pin). All lengths in the output
//! are in the part's units.

use anyhow::{Context, Result};
use clap::Args;
use pinfeed::contact_case::batch::run_batch;
use pinfeed::contact_case::report::{report, trace_csv};
use pinfeed::contact_case::{parse_fence, run_case, stop_travel, Case};
use pinfeed::mechanics::Fidelity;
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
    #[command(flatten)]
    pub push: super::physics::PushArgs,
    /// Part–belt friction coefficient μs (> 0; scales forces only).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub mu_s: f64,
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
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// No progress bar while a map-tier build runs (as with --json, or when standard error is not
    /// a terminal).
    #[arg(long, short)]
    pub quiet: bool,
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
    #[command(flatten)]
    pub tail: super::physics::TailArgs,
    /// Batch mode: a CSV with columns part,theta0,d,mu_c (+ optional model,pin_radius,mu_s); one
    /// output row per case goes to stdout. `--fence`, `--pin-speed`, `--support`, `--tol` and the
    /// defaults of the optional columns apply to every row.
    #[arg(long, value_name = "FILE.csv", conflicts_with_all = ["part", "theta0", "d", "json", "trace", "plot"])]
    pub cases: Option<PathBuf>,
}

/// The single case the arguments describe, with fidelity `model`.
pub(crate) fn case_of(args: &ContactArgs, model: Fidelity) -> Result<Case> {
    let d = args.d.unwrap_or(0.0);
    let pin_stop = match args.pin_stop_at {
        Some(y) => Some(stop_travel(y, d, args.pin_speed, "--pin-stop-at")?),
        None => args.pin_stop,
    };
    let part = args.part.clone().unwrap_or_default();
    Ok(Case {
        theta0_deg: args.theta0.unwrap_or(0.0),
        d,
        mu_s: args.mu_s,
        pin_speed: args.pin_speed,
        pin_stop,
        pin_stop_after_touch: args.pin_stop_after_touch,
        fence: (args.fence.as_deref())
            .map(|f| parse_fence(f, "--fence"))
            .transpose()?,
        fence_tail: args.tail.tail,
        ..args.push.case(part, model)
    })
}

pub fn run(args: &ContactArgs) -> Result<()> {
    if let Some(path) = &args.cases {
        let model = args
            .push
            .fidelity("the map tier does not run --cases batches")?;
        let defaults = case_of(args, model)?;
        return Ok(run_batch(
            &defaults,
            path,
            super::stdout::writer(),
            &super::flag,
        )?);
    }
    let pinfeed::contact_case::ModelChoice::Model(model) = args.push.model else {
        return super::contact_map::run(args);
    };
    let c = case_of(args, model)?;
    let want_trace = args.trace.is_some() || args.plot.is_some();
    let (poly, out, trace) = run_case(&c, want_trace, &super::flag)?;
    if let Some(path) = &args.trace {
        pinfeed::output::write_atomic(path, trace_csv(&trace))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        pinfeed::report::plot_contact::plot_case(&c, &poly, &out, &trace, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let r = report(&c, &out).with_pin_positions(&c, poly.radius(), &out);
    if args.json {
        crate::out!("{}", pinfeed::report::versioned::pretty(&r)?);
    } else {
        crate::out!("{}", r.text());
    }
    if !out.status.is_ok() && !args.json {
        eprintln!("warning: contact ended with status {:?}", out.status);
    }
    Ok(())
}
