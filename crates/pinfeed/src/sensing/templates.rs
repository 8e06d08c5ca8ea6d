//! Hypotheses and their simulated templates: what each state of the part makes the sensor see.
//!
//! A *setup* fixes the push (part, pin offset d, pin radius, μc, μs, fidelity, tolerance) and the
//! physical constants of the signal (mass, belt speed, sensor height). A *hypothesis* is an initial
//! orientation of the part (by default its stable states), or a contact class (`vertex`/`edge`,
//! decided by the contact model's own first-contact feature). Under declared [`Uncertainty`] (μc
//! distribution, support model, pose jitter, lateral jitter) each hypothesis gets an *ensemble* of
//! clean signals — not one nominal curve — drawn from a seeded stream per (hypothesis, member).
//!
//! Trials (`pinfeed sense`, tests) draw their true pushes from the same uncertainty with other
//! stream indices, so a classifier is never scored on its own templates.

use super::signal::{ContactSignal, KnotRecorder, SignalScale};
use crate::geometry::{Polygon, Pose, Vec2};
use crate::mechanics::{
    push, ContactFeature, ContactOutcome, ContactSettings, Fidelity, PartModel, Pin, Support,
};
use crate::random::distribution::Distribution;
use crate::random::stream;
use rand::RngExt;
use rand_distr::{Distribution as _, StandardNormal};
use serde::Serialize;

/// One push, as the sensor's templates and trials are computed for.
#[derive(Debug, Clone)]
pub struct PushSetup {
    /// The part in metres (vertices × scale), centroid at the origin.
    pub polygon: Polygon,
    /// Contact parameter d = (y_pin − y_com)/a.
    pub d: f64,
    /// Pin radius (m).
    pub pin_radius: f64,
    /// Pin–part friction coefficient μc.
    pub mu_c: f64,
    /// Part–belt (support) friction coefficient μs.
    pub mu_s: f64,
    /// The contact model.
    pub fidelity: Fidelity,
    /// Integration tolerance per step.
    pub tol: f64,
    /// Part mass (kg), belt speed (m/s), sensor height (m).
    pub mass: f64,
    /// Belt speed (m/s).
    pub belt_speed: f64,
    /// Height of the sensor origin above the contact plane (m).
    pub height: f64,
}

impl PushSetup {
    /// The nominal push of `pinfeed sense`'s defaults for `polygon` (in metres) at offset `d`: a
    /// point pin, μc 0.5, μs 0.3, the exact model at tolerance 1e-6, a 50 g part on a 5 cm/s belt,
    /// the sensor origin 2 cm above the contact.
    pub fn nominal(polygon: Polygon, d: f64) -> PushSetup {
        PushSetup {
            polygon,
            d,
            pin_radius: 0.0,
            mu_c: 0.5,
            mu_s: 0.3,
            fidelity: Fidelity::Exact,
            tol: 1e-6,
            mass: 0.05,
            belt_speed: 0.05,
            height: 0.02,
        }
    }

    /// The signal scale of this setup (lengths already in metres).
    pub fn scale(&self) -> SignalScale {
        SignalScale {
            mass: self.mass,
            belt_speed: self.belt_speed,
            height: self.height,
            metres_per_unit: 1.0,
        }
    }
}

/// The declared uncertainty of the physics and of the part's pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Uncertainty {
    /// Contact friction μc (replaces the setup's value when not fixed).
    pub mu_c: Distribution,
    /// A random tripod support per draw instead of uniform pressure.
    pub tripod: bool,
    /// Orientation jitter σ (degrees) about the hypothesis's orientation.
    pub theta_sd_deg: f64,
    /// Lateral jitter σ of d (units of a).
    pub d_sd: f64,
}

impl Uncertainty {
    /// No uncertainty: the nominal push.
    pub fn none(mu_c: f64) -> Uncertainty {
        Uncertainty {
            mu_c: Distribution::Fixed(mu_c),
            tripod: false,
            theta_sd_deg: 0.0,
            d_sd: 0.0,
        }
    }
    /// No uncertainty at all (fixed μc, uniform support, no jitter)?
    pub fn is_none(&self) -> bool {
        self.mu_c.is_fixed() && !self.tripod && self.theta_sd_deg == 0.0 && self.d_sd == 0.0
    }
}

/// What the hypotheses are.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Hypotheses {
    /// Initial orientations (degrees) with their labels.
    Orientations {
        /// The hypotheses' labels.
        labels: Vec<String>,
        /// The orientations (degrees), one per label.
        degrees: Vec<f64>,
    },
    /// Vertex or edge first contact; the pushes are drawn over `degrees` (orientations, e.g. the
    /// stable states or a uniform sweep) and labelled by the contact model's first feature.
    VertexEdge {
        /// The orientations the pushes are drawn over (degrees).
        degrees: Vec<f64>,
    },
}

impl Hypotheses {
    /// The labels of the hypotheses (`vertex`, `edge` for a vertex/edge problem).
    pub fn labels(&self) -> Vec<String> {
        match self {
            Hypotheses::Orientations { labels, .. } => labels.clone(),
            Hypotheses::VertexEdge { .. } => vec!["vertex".into(), "edge".into()],
        }
    }
    /// Number of hypotheses.
    pub fn len(&self) -> usize {
        self.labels().len()
    }
    /// No hypotheses?
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Why a list of hypotheses is refused ([`Hypotheses::stable_states`],
/// [`Hypotheses::orientations`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HypothesesError {
    /// The part has fewer than two stable states to tell apart.
    #[error(
        "the part has {0} stable state(s): list at least two orientations (degrees) to tell apart"
    )]
    FewStates(usize),
    /// Fewer than 2 or more than [`MAX_HYPOTHESES`] orientations.
    #[error("give between 2 and {MAX_HYPOTHESES} orientations (degrees), got {0}")]
    Count(usize),
    /// An orientation that is not finite or lies outside ±360°.
    #[error("orientation {0} is out of range: each must lie in [-360, 360] degrees")]
    OutOfRange(f64),
    /// Two orientations that are the same angle (modulo 360°).
    #[error("orientations {0} and {1} are the same angle: list each hypothesis once")]
    Same(f64, f64),
}

/// Most hypotheses a sensor is asked to tell apart.
pub const MAX_HYPOTHESES: usize = 64;
/// Orientation step (degrees) of the pushes drawn for vertex/edge hypotheses over any orientation.
pub const VERTEX_EDGE_STEP_DEG: f64 = 5.0;

impl Hypotheses {
    /// The part's stable states (docs/physics.md#stable-states), labelled by their orientation; at least two are needed.
    pub fn stable_states(poly: &Polygon) -> Result<Hypotheses, HypothesesError> {
        let degrees: Vec<f64> = poly
            .stable_states()
            .iter()
            .map(|s| s.theta_rad.to_degrees())
            .collect();
        if degrees.len() < 2 {
            return Err(HypothesesError::FewStates(degrees.len()));
        }
        Hypotheses::orientations(degrees)
    }

    /// Listed orientations (degrees): each finite and within ±360, between 2 and
    /// [`MAX_HYPOTHESES`] of them, no two the same angle (modulo 360°).
    pub fn orientations(degrees: Vec<f64>) -> Result<Hypotheses, HypothesesError> {
        if degrees.len() < 2 || degrees.len() > MAX_HYPOTHESES {
            return Err(HypothesesError::Count(degrees.len()));
        }
        for (i, &x) in degrees.iter().enumerate() {
            if !(x.is_finite() && (-360.0..=360.0).contains(&x)) {
                return Err(HypothesesError::OutOfRange(x));
            }
            for &y in &degrees[..i] {
                let diff = (x - y).rem_euclid(360.0);
                if diff.min(360.0 - diff) < 1e-9 {
                    return Err(HypothesesError::Same(y, x));
                }
            }
        }
        Ok(Hypotheses::Orientations {
            labels: degrees.iter().map(|&d| orientation_label(d)).collect(),
            degrees,
        })
    }

    /// Vertex or edge first contact over orientations every [`VERTEX_EDGE_STEP_DEG`].
    pub fn vertex_edge_sweep() -> Hypotheses {
        Hypotheses::VertexEdge {
            degrees: (0..(360.0 / VERTEX_EDGE_STEP_DEG) as usize)
                .map(|i| i as f64 * VERTEX_EDGE_STEP_DEG)
                .collect(),
        }
    }
}

/// The label of an orientation hypothesis: degrees to one decimal, e.g. `135°`, `206.6°`.
pub fn orientation_label(deg: f64) -> String {
    let r = (deg * 10.0).round() / 10.0;
    if (r - r.round()).abs() < 1e-9 {
        format!("{}°", r.round())
    } else {
        format!("{r:.1}°")
    }
}

/// The contact class of a first feature: 0 = vertex, 1 = edge (fence features count as edges).
pub fn vertex_edge_class(f: ContactFeature) -> usize {
    match f {
        ContactFeature::Vertex(_) | ContactFeature::FenceVertex(_) => 0,
        _ => 1,
    }
}

/// One simulated pass: the push's outcome, its clean signal, and what was drawn for it.
#[derive(Debug, Clone)]
pub struct Pass {
    /// The push's outcome.
    pub outcome: ContactOutcome,
    /// The push's clean (noise-free) signal.
    pub signal: ContactSignal,
    /// Entry orientation drawn (degrees).
    pub theta0_deg: f64,
    /// Pin offset d drawn (units of a).
    pub d: f64,
    /// Pin–part friction μc drawn.
    pub mu_c: f64,
}

/// Runs one push of `setup` with the part at `theta0_deg`, the pin at offset `d`, friction `mu_c`
/// and support `support`, recording its signal.
pub fn simulate(setup: &PushSetup, model: &PartModel, theta0_deg: f64, d: f64, mu_c: f64) -> Pass {
    let a = setup.polygon.radius();
    let pose = Pose::new(0.0, 0.0, theta0_deg.to_radians());
    let start = Vec2::new(a * 1.01 + setup.pin_radius, d * a);
    let settings = ContactSettings {
        fidelity: setup.fidelity,
        mu_c,
        mu_s: setup.mu_s,
        tol: setup.tol,
        ..ContactSettings::default()
    };
    let pin = Pin {
        radius: setup.pin_radius,
        lateral_speed: 0.0,
    };
    let mut rec = KnotRecorder::default();
    let outcome = push(model, pose, start, &pin, &settings, Some(&mut rec));
    let signal = ContactSignal::new(&outcome, &rec.samples, &setup.scale());
    Pass {
        outcome,
        signal,
        theta0_deg,
        d,
        mu_c,
    }
}

/// Why a template or trial pass could not be drawn ([`draw_pass`], [`build_templates`]). Each
/// variant holds the error of the step that failed, printed as it is.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PassError {
    /// μc's distribution gave no value in its domain
    /// ([`crate::random::distribution::Distribution::draw`]).
    #[error("{0}")]
    MuC(crate::random::distribution::DrawError),
    /// No tripod could be drawn ([`Support::random_tripod`]).
    #[error("{0}")]
    Tripod(crate::mechanics::TripodError),
    /// The tripod's part model could not be compiled ([`PartModel::new`]).
    #[error("{0}")]
    Model(crate::mechanics::PartModelError),
}

/// Draws one pass for orientation `theta_deg` under `unc` from stream `(seed, index)`. Draw order:
/// μc, tripod (if any), θ jitter, d jitter.
pub fn draw_pass(
    setup: &PushSetup,
    uniform: &PartModel,
    unc: &Uncertainty,
    theta_deg: f64,
    seed: u64,
    index: u64,
) -> Result<Pass, PassError> {
    let mut rng = stream(seed, index);
    let (mu_c, _) = unc
        .mu_c
        .draw(&mut rng, |v| {
            let (lo, hi) = crate::mechanics::limits::MU_C;
            (lo..=hi).contains(&v)
        })
        .map_err(PassError::MuC)?;
    let tripod;
    let model = if unc.tripod {
        let support =
            Support::random_tripod(&setup.polygon, &mut rng).map_err(PassError::Tripod)?;
        tripod = PartModel::new(&setup.polygon, &support).map_err(PassError::Model)?;
        &tripod
    } else {
        uniform
    };
    let zt: f64 = StandardNormal.sample(&mut rng);
    let zd: f64 = StandardNormal.sample(&mut rng);
    let theta = theta_deg + unc.theta_sd_deg * zt;
    let d = setup.d + unc.d_sd * zd;
    let _ = rng.random::<u64>(); // reserved: keeps later draws stable if a parameter is added
    Ok(simulate(setup, model, theta, d, mu_c))
}

/// The templates of every hypothesis: `members[h]` holds hypothesis h's ensemble.
#[derive(Debug, Clone)]
pub struct TemplateSet {
    /// The hypotheses' labels.
    pub labels: Vec<String>,
    /// `members[h]`: the clean signals of hypothesis h's ensemble.
    pub members: Vec<Vec<ContactSignal>>,
}

/// Stream index of template member `m` of hypothesis `h` (trials use indices from 2⁴⁰ on).
pub fn template_stream(h: usize, m: usize) -> u64 {
    ((h as u64) << 20) | m as u64
}

/// First stream index of trials (far from every template stream).
pub const TRIAL_STREAMS: u64 = 1 << 40;

/// Builds `per_hypothesis` templates per hypothesis. For `VertexEdge`, pushes are drawn over the
/// listed orientations in turn and each lands in its first feature's class until both classes
/// hold `per_hypothesis` (or 50× as many pushes have been tried; a class that never occurs is empty).
pub fn build_templates(
    setup: &PushSetup,
    uniform: &PartModel,
    hyps: &Hypotheses,
    unc: &Uncertainty,
    per_hypothesis: usize,
    seed: u64,
) -> Result<TemplateSet, PassError> {
    let labels = hyps.labels();
    let mut members: Vec<Vec<ContactSignal>> = vec![Vec::new(); labels.len()];
    match hyps {
        Hypotheses::Orientations { degrees, .. } => {
            for (h, &deg) in degrees.iter().enumerate() {
                for m in 0..per_hypothesis {
                    let pass = draw_pass(setup, uniform, unc, deg, seed, template_stream(h, m))?;
                    members[h].push(pass.signal);
                }
            }
        }
        Hypotheses::VertexEdge { degrees } => {
            let mut tried = 0usize;
            while members.iter().any(|m| m.len() < per_hypothesis)
                && tried < 50 * per_hypothesis * degrees.len().max(1)
            {
                let deg = degrees[tried % degrees.len()];
                let pass = draw_pass(setup, uniform, unc, deg, seed, template_stream(0, tried))?;
                tried += 1;
                if let Some(f) = pass.signal.first_feature {
                    let c = vertex_edge_class(f);
                    if members[c].len() < per_hypothesis {
                        members[c].push(pass.signal);
                    }
                }
            }
        }
    }
    Ok(TemplateSet { labels, members })
}
