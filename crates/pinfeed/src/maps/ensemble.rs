//! Ensemble maps: configuration maps under uncertain physics. Each ensemble *member*
//! is one draw of the uncertain parameters — pin–part friction μc, the support (uniform pressure,
//! or with probability `support_share` a random tripod or random smooth density, drawn as the
//! Monte Carlo studies draw them: [`crate::mechanics::support::draw_support`]), the pin radius — and
//! every pass it makes adds a pose error (normal, `jitter_deg`) to θ0. The distribution of θf at
//! (d, input state) is the pool of all members' passes; its predicted bands are the smallest set of
//! arcs holding 90% of it, gaps under 5° closed ([`super::arcs::highest_density_arcs`]).
//!
//! Random streams (docs/physics.md#determinism): member i of an ensemble seeded with s draws five
//! sub-seeds from `random::stream(s, i)`, in the order μc, support share, support shape, pin radius,
//! pose jitter; pass number p of member i draws its jitter z (and, for a θ0 arc, its uniform u) from
//! `random::stream(jitter sub-seed, p)`. A value is always `mean + sd·z`, `min + (max − min)·u` or
//! `u < share` of its own stream, so member i sees the same underlying numbers under any parameters
//! (common random numbers) — which is what lets calibration reweight one ensemble — and nothing
//! depends on the thread count.

use super::arcs::{Arc, MassArc};
use super::sample::sample_one;
use super::MapSettings;
use crate::geometry::{wrap_deg, Polygon};
use crate::mechanics::support::{draw_support, SmoothParams, SupportChoice, SupportDrawError};
use crate::mechanics::{ContactSettings, Fidelity, PartModel, Pin};
use crate::random::distribution::Distribution;
use crate::random::distribution::DrawError;
use crate::random::{stream, ChaCha8Rng};
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution as _, StandardNormal};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::Arc as Shared;

/// Mass held by the predicted bands.
pub const BAND_MASS: f64 = 0.9;
/// Resolution of the predicted bands (degrees).
pub const BAND_BIN_DEG: f64 = 1.0;
/// Gaps narrower than this between predicted bands are closed (degrees; the maps' default T).
pub const BAND_JOIN_DEG: f64 = 5.0;

/// What is uncertain, and how.
#[derive(Debug, Clone, PartialEq)]
pub struct EnsembleSpec {
    /// μc of each member.
    pub mu_c: Distribution,
    /// The non-uniform support model a member uses with probability `support_share`.
    pub support: SupportChoice,
    /// Probability that a member uses `support` (in [0, 1]).
    pub support_share: f64,
    /// Pin radius of each member (the polygon's units).
    pub pin_radius: Distribution,
    /// Standard deviation of the θ0 error of each pass (degrees).
    pub jitter_deg: f64,
    /// Contact-model fidelity of every pass.
    pub fidelity: Fidelity,
    /// Integration tolerance of the contact model.
    pub tol: f64,
}

impl EnsembleSpec {
    /// No uncertainty: one friction, uniform support, one pin radius, no jitter.
    pub fn nominal(mu_c: f64, pin_radius: f64, fidelity: Fidelity, tol: f64) -> EnsembleSpec {
        EnsembleSpec {
            mu_c: Distribution::Fixed(mu_c),
            support: SupportChoice::Uniform,
            support_share: 0.0,
            pin_radius: Distribution::Fixed(pin_radius),
            jitter_deg: 0.0,
            fidelity,
            tol,
        }
    }

    /// Apply a comma-separated list of `key=value` settings to `self`:
    /// `mu_c=DIST`, `pin_radius=DIST` (DIST: a number, `uniform:MIN:MAX`, `normal:MEAN:SD`,
    /// `triangular:MIN:MODE:MAX`), `support=uniform|tripod:SHARE|smooth:SHARE`, `jitter=SD_DEG`.
    pub fn with_settings(mut self, text: &str) -> Result<EnsembleSpec, SettingsError> {
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| SettingsError::NotKeyValue {
                    item: item.to_string(),
                })?;
            let (key, value) = (key.trim(), value.trim());
            match key {
                "mu_c" => self.mu_c = parse_distribution(value, "mu_c", 0.0, 10.0)?,
                "pin_radius" => {
                    self.pin_radius = parse_distribution(value, "pin_radius", 0.0, 1e6)?
                }
                "support" => (self.support, self.support_share) = parse_support(value)?,
                "jitter" => self.jitter_deg = parse_number(value, "jitter", 0.0, 90.0)?,
                _ => {
                    return Err(SettingsError::UnknownKey {
                        key: key.to_string(),
                    })
                }
            }
        }
        Ok(self)
    }

    /// One line per parameter.
    pub fn describe(&self) -> Vec<String> {
        let support = match self.support {
            SupportChoice::Uniform => "uniform pressure".to_string(),
            other => format!(
                "{} with probability {}, else uniform",
                other.describe(),
                self.support_share
            ),
        };
        vec![
            format!("mu_c: {}", self.mu_c.describe()),
            format!("support: {support}"),
            format!("pin_radius: {} (part units)", self.pin_radius.describe()),
            format!("pose jitter: normal sd {}° per pass", self.jitter_deg),
            format!("model: {}, tolerance {}", self.fidelity, self.tol),
        ]
    }

    /// Largest pin radius a member takes in practice (a normal no more than 8 sd above its mean:
    /// a draw beyond has probability below 1e-15).
    pub fn max_pin_radius(&self) -> f64 {
        self.pin_radius.practical_max().max(0.0)
    }
}

/// Why an `--uncertain` list is refused ([`EnsembleSpec::with_settings`]). `what` names the
/// parameter (`mu_c`, `pin_radius`, `jitter`, `support share`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SettingsError {
    /// An item without `=`.
    #[error("'{item}': expected KEY=VALUE")]
    NotKeyValue {
        /// The item.
        item: String,
    },
    /// A key that is none of the uncertain parameters.
    #[error("unknown uncertain parameter '{key}'; expected mu_c, support, pin_radius or jitter")]
    UnknownKey {
        /// The key.
        key: String,
    },
    /// A value that should be a number.
    #[error("{what}: '{value}' is not a number")]
    NotANumber {
        /// The parameter.
        what: String,
        /// The text given.
        value: String,
    },
    /// A number outside the parameter's range.
    #[error("{what}: {value} must lie in [{lo}, {hi}]")]
    OutOfRange {
        /// The parameter.
        what: String,
        /// The number given.
        value: f64,
        /// Smallest allowed value.
        lo: f64,
        /// Largest allowed value.
        hi: f64,
    },
    /// A distribution written in none of the accepted forms.
    #[error("{what}: '{value}' is not a number, uniform:MIN:MAX, normal:MEAN:SD or triangular:MIN:MODE:MAX")]
    Distribution {
        /// The parameter.
        what: String,
        /// The text given.
        value: String,
    },
    /// A distribution with no values in the parameter's range, or whose minimum exceeds its maximum.
    #[error(
        "{what}: '{value}' has no values in [{lo}, {hi}] (or its minimum exceeds its maximum)"
    )]
    EmptyRange {
        /// The parameter.
        what: String,
        /// The text given.
        value: String,
        /// Smallest allowed value.
        lo: f64,
        /// Largest allowed value.
        hi: f64,
    },
    /// A support that is none of `uniform`, `tripod:SHARE`, `smooth:SHARE`.
    #[error("support: '{value}' must be uniform, tripod:SHARE or smooth:SHARE")]
    Support {
        /// The text given.
        value: String,
    },
}

/// Why an ensemble member could not be drawn or compiled ([`draw_member`], [`Member::new`]).
/// Each variant holds the error of the step that failed, printed as it is.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MemberError {
    /// A parameter's distribution gave no value in its domain
    /// ([`crate::random::distribution::Distribution::draw`]).
    #[error("{0}")]
    Draw(DrawError),
    /// The member's support could not be drawn ([`draw_support`]).
    #[error("{0}")]
    Support(SupportDrawError),
    /// The member's part model could not be compiled ([`PartModel::new`]).
    #[error("{0}")]
    Model(crate::mechanics::PartModelError),
}

/// Why an ensemble could not be compiled ([`members`], [`ensemble_maps`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("ensemble member {index}: {cause}")]
pub struct EnsembleError {
    /// Index of the member that failed.
    pub index: u64,
    /// Why it failed. (In the message, not a `source`, so that it is printed once.)
    pub cause: MemberError,
}

fn parse_number(s: &str, what: &str, lo: f64, hi: f64) -> Result<f64, SettingsError> {
    let v: f64 = s.parse().map_err(|_| SettingsError::NotANumber {
        what: what.to_string(),
        value: s.to_string(),
    })?;
    if !(v.is_finite() && (lo..=hi).contains(&v)) {
        return Err(SettingsError::OutOfRange {
            what: what.to_string(),
            value: v,
            lo,
            hi,
        });
    }
    Ok(v)
}

/// A distribution written `V`, `uniform:MIN:MAX`, `normal:MEAN:SD` or `triangular:MIN:MODE:MAX`.
fn parse_distribution(
    s: &str,
    what: &str,
    lo: f64,
    hi: f64,
) -> Result<Distribution, SettingsError> {
    let parts: Vec<&str> = s.split(':').collect();
    let n = |k: usize| parse_number(parts[k], what, -hi, hi);
    let d = match (parts[0], parts.len()) {
        (_, 1) => Distribution::Fixed(parse_number(s, what, lo, hi)?),
        ("uniform", 3) => Distribution::Uniform {
            min: n(1)?,
            max: n(2)?,
        },
        ("normal", 3) => Distribution::Normal {
            mean: n(1)?,
            sd: parse_number(parts[2], what, 0.0, hi)?,
            lo,
            hi,
        },
        ("triangular", 4) => Distribution::Triangular {
            min: n(1)?,
            mode: n(2)?,
            max: n(3)?,
        },
        _ => {
            return Err(SettingsError::Distribution {
                what: what.to_string(),
                value: s.to_string(),
            })
        }
    };
    let (a, b) = d.range();
    if a > b || b < lo || a > hi {
        return Err(SettingsError::EmptyRange {
            what: what.to_string(),
            value: s.to_string(),
            lo,
            hi,
        });
    }
    Ok(d)
}

/// `uniform`, `tripod:SHARE` or `smooth:SHARE` (default smooth-density parameters).
fn parse_support(s: &str) -> Result<(SupportChoice, f64), SettingsError> {
    let (kind, share) = match s.split_once(':') {
        Some((k, v)) => (k, parse_number(v, "support share", 0.0, 1.0)?),
        None => (s, 1.0),
    };
    match kind {
        "uniform" => Ok((SupportChoice::Uniform, 0.0)),
        "tripod" => Ok((SupportChoice::Tripod, share)),
        "smooth" => Ok((SupportChoice::Smooth(SmoothParams::default()), share)),
        _ => Err(SettingsError::Support {
            value: s.to_string(),
        }),
    }
}

/// The input of a pass: where θ0 comes from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum InputState {
    /// Resting in stable state k (docs/physics.md#stable-states; the order of `pinfeed part`).
    State {
        /// Index of the stable state.
        index: usize,
    },
    /// θ0 uniform on an arc.
    Theta {
        /// The arc (degrees).
        arc: Arc,
    },
    /// θ0 uniform on the whole circle.
    All,
}

impl InputState {
    /// `state:K`, `theta:MIN:MAX` or `all`.
    pub fn label(&self) -> String {
        match self {
            InputState::State { index } => format!("state:{index}"),
            InputState::Theta { arc } => format!("theta:{}:{}", arc.lo, arc.hi()),
            InputState::All => "all".into(),
        }
    }

    /// The θ0 of a pass (degrees) given a uniform u ∈ [0, 1) and the stable states (degrees).
    pub fn theta0(&self, u: f64, states_deg: &[f64]) -> f64 {
        match self {
            InputState::State { index } => states_deg[*index],
            InputState::Theta { arc } => wrap_deg(arc.lo + u * arc.width),
            InputState::All => u * 360.0,
        }
    }
}

/// The stable states of a part in degrees, in the order of `pinfeed part`.
pub fn stable_states_deg(poly: &Polygon) -> Vec<f64> {
    poly.stable_states()
        .iter()
        .map(|s| s.theta_rad.to_degrees())
        .collect()
}

/// The values member i drew.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MemberDraw {
    /// Pin–part friction coefficient drawn.
    pub mu_c: f64,
    /// Does the member rest on the random support model (else uniform pressure)?
    pub random_support: bool,
    /// Pin radius drawn (the polygon's units).
    pub pin_radius: f64,
    #[serde(skip)]
    support_seed: u64,
    #[serde(skip)]
    jitter_seed: u64,
}

/// Draw member `i` of an ensemble seeded with `seed`.
pub fn draw_member(spec: &EnsembleSpec, seed: u64, i: u64) -> Result<MemberDraw, MemberError> {
    let mut master = stream(seed, i);
    let mut next = || ChaCha8Rng::seed_from_u64(master.random::<u64>());
    let (mut mu, mut share, mut shape, mut radius, mut jitter) =
        (next(), next(), next(), next(), next());
    let (mu_c, _) = spec
        .mu_c
        .draw(&mut mu, |v| v >= 0.0)
        .map_err(MemberError::Draw)?;
    let (pin_radius, _) = spec
        .pin_radius
        .draw(&mut radius, |v| v >= 0.0)
        .map_err(MemberError::Draw)?;
    Ok(MemberDraw {
        mu_c,
        random_support: share.random::<f64>() < spec.support_share,
        pin_radius,
        support_seed: shape.random::<u64>(),
        jitter_seed: jitter.random::<u64>(),
    })
}

/// Passes of one member from which [`ensemble_maps`] serves its slides from tables: a member's
/// tables (certified to a sample's tolerance, `slide_table::sampled_table_tol`; a few thousand
/// limit-surface evaluations each, a dozen for a triangle-like part) pay for themselves over a
/// few hundred passes. Measured on tripoly1, 200 members, μc ~ normal(0.5, 0.1), half on tripods
/// (`results/line-speed.md`, "Where users wait"): 180 passes per member 1.11 s without tables
/// against 1.36 s with them, 360 passes 2.20 s against 1.76 s.
pub const TABLED_PASSES: usize = 300;

/// One member: its draw and its compiled part. Members on uniform pressure share one compiled
/// part (their model does not depend on what they drew); a member on a random support has its
/// own.
pub struct Member {
    /// The values it drew.
    pub draw: MemberDraw,
    model: Shared<PartModel>,
}

impl Member {
    /// Compile member `i` (its support drawn on `poly`).
    pub fn new(
        poly: &Polygon,
        spec: &EnsembleSpec,
        seed: u64,
        i: u64,
    ) -> Result<Member, MemberError> {
        let draw = draw_member(spec, seed, i)?;
        let model = compile(poly, spec, &draw).map_err(|e| *e)?;
        Ok(Member {
            draw,
            model: Shared::new(model),
        })
    }

    /// The member with its exact slides served from tables at its μc, certified to the
    /// tolerance of a sample's tables for integration tolerance `tol`
    /// (`PartModel::with_slide_tables_to`, `slide_table::sampled_table_tol`): for a member that
    /// passes many times.
    pub fn tabled(&self, tol: f64) -> Member {
        Member {
            draw: self.draw,
            model: Shared::new(tabled_model(&self.model, self.draw.mu_c, tol)),
        }
    }

    /// The uniform u and normal z of pass number `pass`.
    fn pass_numbers(&self, pass: u64) -> (f64, f64) {
        let mut rng = stream(self.draw.jitter_seed, pass);
        let u = rng.random::<f64>();
        let z: f64 = StandardNormal.sample(&mut rng);
        (u, z)
    }

    /// θ0 (degrees) of pass number `pass` from `input`: the input's θ0 and the pass's jitter.
    pub(crate) fn theta0(
        &self,
        spec: &EnsembleSpec,
        input: &InputState,
        states_deg: &[f64],
        pass: u64,
    ) -> f64 {
        let (u, z) = self.pass_numbers(pass);
        input.theta0(u, states_deg) + spec.jitter_deg * z
    }

    /// θf (degrees, wrapped) of pass number `pass` from `input` at contact parameter `d`.
    pub fn pass(
        &self,
        poly: &Polygon,
        spec: &EnsembleSpec,
        input: &InputState,
        states_deg: &[f64],
        d: f64,
        pass: u64,
    ) -> f64 {
        let theta0 = self.theta0(spec, input, states_deg, pass);
        self.pass_from(&self.model, poly, spec, theta0, d)
    }

    /// θf (degrees, wrapped) of a pass from `theta0` at `d` on `model` (the member's own, or
    /// the tabled one its table group shares).
    fn pass_from(
        &self,
        model: &PartModel,
        poly: &Polygon,
        spec: &EnsembleSpec,
        theta0: f64,
        d: f64,
    ) -> f64 {
        let settings = MapSettings {
            theta_step_deg: 1.0,
            threshold_deg: 5.0,
            contact: ContactSettings {
                fidelity: spec.fidelity,
                mu_c: self.draw.mu_c,
                tol: spec.tol,
                ..ContactSettings::default()
            },
            pin: Pin {
                radius: self.draw.pin_radius,
                lateral_speed: 0.0,
            },
            fence: None,
        };
        wrap_deg(sample_one(poly, model, theta0, d, &settings).theta_final_deg)
    }
}

/// The part member `draw` rests on: its support drawn on `poly`, compiled.
fn compile(
    poly: &Polygon,
    spec: &EnsembleSpec,
    draw: &MemberDraw,
) -> Result<PartModel, Box<MemberError>> {
    let choice = if draw.random_support {
        spec.support
    } else {
        SupportChoice::Uniform
    };
    let mut rng = ChaCha8Rng::seed_from_u64(draw.support_seed);
    let support = draw_support(poly, &choice, &mut rng, &mut 0)
        .map_err(|e| Box::new(MemberError::Support(e)))?;
    PartModel::new(poly, &support).map_err(|e| Box::new(MemberError::Model(e)))
}

/// `model` with its slides at `mu_c` served from tables certified to a sample's tolerance.
fn tabled_model(model: &PartModel, mu_c: f64, tol: f64) -> PartModel {
    model.clone().with_slide_tables_to(
        &[mu_c],
        crate::mechanics::slide_table::sampled_table_tol(tol),
    )
}

/// Compile members 0 … n − 1 in parallel (in index order); the members on uniform pressure share
/// one compiled part. When members fail, the error is the first failing member's by index,
/// whatever the thread count and timing.
pub fn members(
    poly: &Polygon,
    spec: &EnsembleSpec,
    seed: u64,
    n: usize,
) -> Result<Vec<Member>, EnsembleError> {
    let fail = |index: u64| move |cause: MemberError| EnsembleError { index, cause };
    let draws: Vec<Result<MemberDraw, EnsembleError>> = (0..n as u64)
        .into_par_iter()
        .map(|i| draw_member(spec, seed, i).map_err(fail(i)))
        .collect();
    let random = |d: &MemberDraw| d.random_support && spec.support != SupportChoice::Uniform;
    // The shared uniform part, compiled once if any member rests on uniform pressure.
    let uniform = draws
        .iter()
        .flatten()
        .find(|d| !random(d))
        .map(|d| compile(poly, spec, d).map(Shared::new));
    let built: Vec<Result<Member, EnsembleError>> = draws
        .into_par_iter()
        .enumerate()
        .map(|(i, draw)| {
            let draw = draw?;
            let model = if random(&draw) {
                Shared::new(compile(poly, spec, &draw).map_err(|e| fail(i as u64)(*e))?)
            } else {
                match uniform.as_ref().expect("a uniform member exists") {
                    Ok(m) => m.clone(),
                    Err(e) => return Err(fail(i as u64)((**e).clone())),
                }
            };
            Ok(Member { draw, model })
        })
        .collect();
    built.into_iter().collect()
}

/// Members that serve their slides from one set of tables: those on one compiled part at one
/// μc (the tables depend on neither the pin radius nor the pass). Groups in order of their first
/// member; each lists its members in index order.
pub(crate) fn table_groups(members: &[Member]) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut index: std::collections::HashMap<(usize, u64), usize> = Default::default();
    for (i, m) in members.iter().enumerate() {
        let key = (Shared::as_ptr(&m.model) as usize, m.draw.mu_c.to_bits());
        let g = *index.entry(key).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(i);
    }
    groups
}

/// A pass to make: (member, θ0 in degrees, d).
pub(crate) type PassRequest = (usize, f64, f64);

/// The key of a push: two requests with the same key in one table group are the same push
/// (the same compiled part at the same μc, pin radius, θ0 and d).
fn push_key(members: &[Member], &(i, theta0, d): &PassRequest) -> (u64, u64, u64) {
    (
        members[i].draw.pin_radius.to_bits(),
        theta0.to_bits(),
        d.to_bits(),
    )
}

/// Make the passes of every table group — `requests_of(x)` lists group x's requests — and hand
/// each group's θf, in request order, to `deliver(x, θf)`. Within a group each push is computed
/// once (members with the same pin radius passing from the same θ0 at the same d: common inputs
/// without jitter, such as a map's grid or a stable state). A group whose distinct pushes reach
/// [`TABLED_PASSES`] serves its slides from tables of its own (certified to a sample's
/// tolerance). Groups are taken two per thread at a time, so that only their requests and
/// tables are held at once; each such chunk's pushes run in one parallel sweep. `on_pass` is
/// called once per request (as its push is made, or after the chunk for a push made for another
/// request). The answers depend on neither the thread count nor the chunks. Returns the number
/// of pushes made.
pub(crate) fn serve_passes(
    members: &[Member],
    groups: usize,
    requests_of: &(dyn Fn(usize) -> Vec<PassRequest> + Sync),
    (poly, spec): (&Polygon, &EnsembleSpec),
    on_pass: &(dyn Fn() + Sync),
    deliver: &mut dyn FnMut(usize, &[f64]),
) -> usize {
    let tabulable = poly.len() <= crate::mechanics::slide_table::MAX_TABLED_VERTICES;
    let block = 2 * rayon::current_num_threads().max(1);
    let mut made = 0;
    for x0 in (0..groups).step_by(block) {
        // Per group of the chunk: its requests, its distinct pushes (a representative request
        // each), each request's push, and the model that serves it.
        let chunk: Vec<Served> = (x0..(x0 + block).min(groups))
            .into_par_iter()
            .map(|x| {
                let requests = requests_of(x);
                let keys: Vec<_> = requests.iter().map(|r| push_key(members, r)).collect();
                let mut order: Vec<usize> = (0..requests.len()).collect();
                order.sort_by_key(|&r| keys[r]);
                let mut unique: Vec<usize> = Vec::new();
                let mut push_of = vec![0usize; requests.len()];
                for (n, &r) in order.iter().enumerate() {
                    if n == 0 || keys[order[n - 1]] != keys[r] {
                        unique.push(r);
                    }
                    push_of[r] = unique.len() - 1;
                }
                let model = requests.first().map(|&(i, _, _)| {
                    let m = &members[i];
                    if tabulable && unique.len() >= TABLED_PASSES {
                        Shared::new(tabled_model(&m.model, m.draw.mu_c, spec.tol))
                    } else {
                        m.model.clone()
                    }
                });
                Served {
                    requests,
                    unique,
                    push_of,
                    model,
                }
            })
            .collect();
        let pushes: Vec<(usize, usize)> = chunk
            .iter()
            .enumerate()
            .flat_map(|(c, g)| g.unique.iter().map(move |&r| (c, r)))
            .collect();
        let theta_f: Vec<f64> = pushes
            .par_iter()
            .map(|&(c, r)| {
                let g = &chunk[c];
                let (i, theta0, d) = g.requests[r];
                let model = g.model.as_ref().expect("a group with requests");
                let f = members[i].pass_from(model, poly, spec, theta0, d);
                on_pass();
                f
            })
            .collect();
        made += pushes.len();
        let mut at = 0;
        for (c, g) in chunk.iter().enumerate() {
            let f = &theta_f[at..at + g.unique.len()];
            at += g.unique.len();
            let out: Vec<f64> = g.push_of.iter().map(|&u| f[u]).collect();
            // The requests served by a push already made.
            (g.unique.len()..g.requests.len()).for_each(|_| on_pass());
            deliver(x0 + c, &out);
        }
    }
    made
}

/// One table group of a chunk in [`serve_passes`].
struct Served {
    requests: Vec<PassRequest>,
    unique: Vec<usize>,
    push_of: Vec<usize>,
    model: Option<Shared<PartModel>>,
}

/// An ensemble of maps: θf of every member at every (d, grid θ0).
#[derive(Debug, Clone, PartialEq)]
pub struct EnsembleMaps {
    /// Contact parameters mapped (units of a).
    pub ds: Vec<f64>,
    /// The θ0 grid (degrees).
    pub grid: Vec<f64>,
    /// The members' draws, in member order.
    pub members: Vec<MemberDraw>,
    /// θf (degrees), index (member · ds + d) · grid + θ0.
    pub theta_f: Vec<f64>,
    /// The pushes made for them: members that share a compiled part, μc and pin radius and
    /// pass from the same θ0 (no jitter) make each push once.
    pub pushes: usize,
}

/// Sample the ensemble maps: `n` members, each passing at every (d, θ0 on `grid`); pass number
/// j · grid + k for d number j and θ0 number k (its jitter). Runs on the current rayon pool.
pub fn ensemble_maps(
    poly: &Polygon,
    spec: &EnsembleSpec,
    ds: &[f64],
    grid: &[f64],
    seed: u64,
    n: usize,
) -> Result<EnsembleMaps, EnsembleError> {
    ensemble_maps_observed(poly, spec, ds, grid, seed, n, &|| {})
}

/// [`ensemble_maps`], calling `on_pass` after every pass (a progress bar counts them).
pub fn ensemble_maps_observed(
    poly: &Polygon,
    spec: &EnsembleSpec,
    ds: &[f64],
    grid: &[f64],
    seed: u64,
    n: usize,
    on_pass: &(dyn Fn() + Sync),
) -> Result<EnsembleMaps, EnsembleError> {
    let members = members(poly, spec, seed, n)?;
    let (nd, nk) = (ds.len(), grid.len());
    let states = stable_states_deg(poly);
    // Served by table group (the members of one compiled part at one μc: one member on a
    // random support, or the members on uniform pressure at a fixed μc), see `serve_passes`.
    // The tables change no answer beyond the solver's tolerance, and none with the thread count.
    let groups = table_groups(&members);
    let requests_of = |x: usize| -> Vec<PassRequest> {
        groups[x]
            .iter()
            .flat_map(|&i| (0..nd * nk).map(move |p| (i, p / nk, p % nk)))
            .map(|(i, j, k)| {
                let input = InputState::Theta {
                    arc: Arc {
                        lo: grid[k],
                        width: 0.0,
                    },
                };
                let pass = (j * nk + k) as u64;
                (i, members[i].theta0(spec, &input, &states, pass), ds[j])
            })
            .collect()
    };
    let mut theta_f: Vec<f64> = vec![f64::NAN; n * nd * nk];
    let mut deliver = |x: usize, f: &[f64]| {
        for (slot, &i) in groups[x].iter().enumerate() {
            theta_f[i * nd * nk..(i + 1) * nd * nk]
                .copy_from_slice(&f[slot * nd * nk..(slot + 1) * nd * nk]);
        }
    };
    let pushes = serve_passes(
        &members,
        groups.len(),
        &requests_of,
        (poly, spec),
        on_pass,
        &mut deliver,
    );
    Ok(EnsembleMaps {
        ds: ds.to_vec(),
        grid: grid.to_vec(),
        members: members.iter().map(|m| m.draw).collect(),
        theta_f,
        pushes,
    })
}

/// The predicted bands at one (d, input state).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PredictedBands {
    /// The contact parameter (units of a).
    pub d: f64,
    /// The input state's label (`state:K`, `theta:MIN:MAX` or `all`).
    pub input: String,
    /// Passes pooled.
    pub passes: usize,
    /// The smallest arcs holding [`BAND_MASS`] of the passes.
    pub bands: Vec<MassArc>,
    /// Share of the circle they cover.
    pub coverage: f64,
    /// The distribution of θf: shares of the passes in 1° bins [k°, k + 1°), k = 0 … 359.
    pub histogram: Vec<f64>,
}

impl PredictedBands {
    /// The predicted bands of the weighted angles `values` (degrees).
    pub fn of(d: f64, input: String, values: &[f64], weights: &[f64]) -> PredictedBands {
        let bands = super::arcs::highest_density_arcs(
            values,
            weights,
            BAND_MASS,
            BAND_BIN_DEG,
            BAND_JOIN_DEG,
        );
        let arcs: Vec<Arc> = bands.iter().map(|b| b.arc).collect();
        let mut histogram = vec![0.0; 360];
        let total: f64 = weights.iter().sum();
        for (&v, &w) in values.iter().zip(weights) {
            histogram[(wrap_deg(v) as usize).min(359)] += w / total.max(f64::MIN_POSITIVE);
        }
        PredictedBands {
            d,
            input,
            passes: values.len(),
            coverage: super::arcs::coverage_share(&arcs),
            bands,
            histogram,
        }
    }
}

impl EnsembleMaps {
    /// θf of all members at d number `j` whose grid θ0 the input state covers (a stable state:
    /// the grid θ0 nearest it).
    pub fn pooled(&self, j: usize, input: &InputState, states_deg: &[f64]) -> Vec<f64> {
        let (nd, nk) = (self.ds.len(), self.grid.len());
        let ks: Vec<usize> = match input {
            InputState::All => (0..nk).collect(),
            InputState::Theta { arc } => (0..nk)
                .filter(|&k| arc.contains_angle(self.grid[k]))
                .collect(),
            InputState::State { index } => {
                let t = states_deg[*index];
                let dist = |k: usize| super::arcs::signed_difference(self.grid[k], t).abs();
                vec![(0..nk).fold(0, |b, k| if dist(k) < dist(b) { k } else { b })]
            }
        };
        (0..self.members.len())
            .flat_map(|i| ks.iter().map(move |&k| self.theta_f[(i * nd + j) * nk + k]))
            .collect()
    }

    /// Predicted bands per d for each input state.
    pub fn predicted(&self, inputs: &[InputState], states_deg: &[f64]) -> Vec<PredictedBands> {
        let mut out = Vec::new();
        for (j, &d) in self.ds.iter().enumerate() {
            for input in inputs {
                let v = self.pooled(j, input, states_deg);
                out.push(PredictedBands::of(
                    d,
                    input.label(),
                    &v,
                    &vec![1.0; v.len()],
                ));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_parse_and_bad_ones_are_refused() {
        let base = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6);
        let s = base
            .clone()
            .with_settings(
                "mu_c=normal:0.4:0.1, support=tripod:0.3, pin_radius=uniform:0:0.1, jitter=2",
            )
            .unwrap();
        assert_eq!(s.support, SupportChoice::Tripod);
        assert_eq!(s.support_share, 0.3);
        assert_eq!(s.jitter_deg, 2.0);
        assert_eq!(s.max_pin_radius(), 0.1);
        for bad in [
            "mu_c=-1",
            "friction=0.3",
            "support=glue",
            "jitter=x",
            "mu_c=normal:1",
        ] {
            assert!(base.clone().with_settings(bad).is_err(), "{bad}");
        }
    }

    /// Every member fails (μc drawn far below 0): the error names member 0 on any number of
    /// threads, every time (the first failure by index, not the first to finish).
    #[test]
    fn a_failing_ensemble_reports_its_first_member() {
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
            .with_settings("mu_c=normal:-5:0.01")
            .unwrap();
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for _ in 0..10 {
                match pool.install(|| members(&poly, &spec, 1, 64)) {
                    Err(e) => assert_eq!(e.index, 0, "{threads} threads: {e}"),
                    Ok(_) => panic!("a negative μc was accepted"),
                }
            }
        }
    }

    #[test]
    fn members_draw_common_random_numbers() {
        let a = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
            .with_settings("mu_c=normal:0.5:0.1,support=tripod:0.5")
            .unwrap();
        let b = a.clone().with_settings("mu_c=normal:0.6:0.2").unwrap();
        for i in 0..20 {
            let (x, y) = (
                draw_member(&a, 9, i).unwrap(),
                draw_member(&b, 9, i).unwrap(),
            );
            if x.mu_c > 0.0 && y.mu_c > 0.0 {
                assert!((y.mu_c - 0.6 - 2.0 * (x.mu_c - 0.5)).abs() < 1e-12);
            }
            assert_eq!(x.random_support, y.random_support);
        }
    }

    /// A member's slides served from its own tables (uniform pressure or a tripod, certified to
    /// a sample's tolerance, 1e-8 at tol 1e-6) give the passes the solver gives, within the
    /// integration's own error: the served twists differ from the solves by up to 1e-8
    /// relative, which leaves most θf within 1e-6° but can tip a step's acceptance and move θf
    /// by up to the integration error. Where a pass moved by more than 1e-4°, both passes are
    /// compared with a reference integrated at tol 1e-9: the tabled pass is no farther from it
    /// than the integration error, and the tabled passes together are about as close as the
    /// solved ones.
    #[test]
    fn a_tabled_member_passes_as_its_solved_self() {
        let poly = crate::geometry::part_from_spec("tripoly2").unwrap();
        let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
            .with_settings("mu_c=normal:0.5:0.15,support=tripod:0.5,pin_radius=uniform:0:0.1")
            .unwrap();
        let mut fine = spec.clone();
        fine.tol = 1e-9;
        let states = stable_states_deg(&poly);
        let gap = |x: f64, y: f64| {
            let w = wrap_deg(x - y);
            w.min(360.0 - w)
        };
        // Passes within 1e-6°, within 1e-4°, and farther apart; the far ones' errors.
        let (mut close, mut near, mut far, mut tripods) = (0, 0, 0, 0);
        let (mut err_solved, mut err_tabled) = (0.0, 0.0);
        for i in 0..6 {
            let solved = Member::new(&poly, &spec, 3, i).unwrap();
            let tabled = solved.tabled(spec.tol);
            tripods += usize::from(solved.draw.random_support);
            for (j, d) in [-0.6, 0.2].into_iter().enumerate() {
                for k in 0..120 {
                    let input = InputState::Theta {
                        arc: Arc {
                            lo: 3.0 * k as f64 + 0.7,
                            width: 0.0,
                        },
                    };
                    let pass = (j * 120 + k) as u64;
                    let a = solved.pass(&poly, &spec, &input, &states, d, pass);
                    let b = tabled.pass(&poly, &spec, &input, &states, d, pass);
                    match gap(a, b) {
                        x if x <= 1e-6 => close += 1,
                        x if x <= 1e-4 => near += 1,
                        _ => {
                            far += 1;
                            let r = solved.pass(&poly, &fine, &input, &states, d, pass);
                            let (ea, eb) = (gap(a, r), gap(b, r));
                            assert!(
                                eb < 1e-2,
                                "member {i} d {d} θ0 {k}: {eb}° from the reference"
                            );
                            err_solved += ea;
                            err_tabled += eb;
                        }
                    }
                }
            }
            // The tables were built and served.
            assert!(tabled.model.slide_table_stats().unwrap().tables > 0);
        }
        assert!(
            (2..=4).contains(&tripods),
            "both supports drawn: {tripods} tripods"
        );
        assert_eq!(close + near + far, 1440);
        assert!(
            close >= 1296,
            "{close} of 1440 within 1e-6°, {near} within 1e-4°"
        );
        assert!(far <= 14, "{far} of 1440 passes farther apart than 1e-4°");
        assert!(
            err_tabled <= 2.0 * err_solved.max(1e-4),
            "errors against the reference: tabled {err_tabled}°, solved {err_solved}°"
        );
    }

    /// Members on uniform pressure share one compiled part, members on a random support each
    /// have their own, and a member of the ensemble passes exactly as the same member compiled
    /// alone.
    #[test]
    fn members_on_uniform_pressure_share_one_compiled_part() {
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
            .with_settings("mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1")
            .unwrap();
        let ms = members(&poly, &spec, 7, 12).unwrap();
        let ptr = |m: &Member| Shared::as_ptr(&m.model) as usize;
        let (uniform, random): (Vec<&Member>, Vec<&Member>) =
            ms.iter().partition(|m| !m.draw.random_support);
        assert!(uniform.len() >= 2 && random.len() >= 2, "{}", uniform.len());
        assert!(uniform.iter().all(|m| ptr(m) == ptr(uniform[0])));
        let mut own: Vec<usize> = random.iter().map(|m| ptr(m)).collect();
        own.push(ptr(uniform[0]));
        own.sort_unstable();
        own.dedup();
        assert_eq!(
            own.len(),
            random.len() + 1,
            "each random support its own part"
        );
        let states = stable_states_deg(&poly);
        let input = InputState::All;
        for (i, m) in ms.iter().enumerate() {
            let alone = Member::new(&poly, &spec, 7, i as u64).unwrap();
            for pass in 0..3 {
                let (a, b) = (
                    m.pass(&poly, &spec, &input, &states, 0.3, pass),
                    alone.pass(&poly, &spec, &input, &states, 0.3, pass),
                );
                assert_eq!(a.to_bits(), b.to_bits(), "member {i} pass {pass}");
            }
        }
    }

    /// Members of one physics (fixed μc and pin radius, uniform pressure) passing from a map's
    /// grid without jitter make each push once, and every member gets that push's θf; with
    /// jitter every pass is a push of its own. Every request is counted for the progress bar
    /// either way.
    #[test]
    fn identical_members_make_each_push_once() {
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        let spec = EnsembleSpec::nominal(0.5, 0.1, Fidelity::Exact, 1e-6);
        let grid: Vec<f64> = (0..20).map(|k| 18.0 * k as f64 + 1.5).collect();
        let ds = [-0.4, 0.3];
        let count = std::sync::atomic::AtomicUsize::new(0);
        let tick = || {
            count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        };
        let maps = ensemble_maps_observed(&poly, &spec, &ds, &grid, 3, 6, &tick).unwrap();
        assert_eq!(maps.pushes, 40);
        assert_eq!(count.load(std::sync::atomic::Ordering::Relaxed), 6 * 40);
        let lone = Member::new(&poly, &spec, 3, 0).unwrap();
        let states = stable_states_deg(&poly);
        for (j, &d) in ds.iter().enumerate() {
            for (k, &t) in grid.iter().enumerate() {
                let input = InputState::Theta {
                    arc: Arc { lo: t, width: 0.0 },
                };
                let want = lone.pass(&poly, &spec, &input, &states, d, (j * 20 + k) as u64);
                for i in 0..6 {
                    let got = maps.theta_f[(i * 2 + j) * 20 + k];
                    assert_eq!(got.to_bits(), want.to_bits(), "member {i} d {d} θ0 {t}");
                }
            }
        }
        let mut jittered = spec.clone();
        jittered.jitter_deg = 1.0;
        let maps = ensemble_maps(&poly, &jittered, &ds, &grid, 3, 6).unwrap();
        assert_eq!(maps.pushes, 6 * 40);
        assert!(maps.theta_f[0] != maps.theta_f[40]);
    }

    /// Members passing TABLED_PASSES times or more are tabled and taken a few at a time, a
    /// number that depends on the threads: the maps do not.
    #[test]
    fn tabled_ensemble_maps_are_the_same_on_any_number_of_threads() {
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
            .with_settings("mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1")
            .unwrap();
        let grid: Vec<f64> = (0..500).map(|k| 0.72 * k as f64).collect();
        let ds = [-0.4, 0.3];
        assert!(ds.len() * grid.len() >= TABLED_PASSES);
        // And members of one physics, with jitter: one tabled group of 5 000 pushes.
        let fixed = EnsembleSpec::nominal(0.5, 0.05, Fidelity::Exact, 1e-6)
            .with_settings("jitter=1")
            .unwrap();
        for spec in [spec, fixed] {
            let maps: Vec<EnsembleMaps> = [1, 3]
                .into_iter()
                .map(|threads| {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap();
                    pool.install(|| ensemble_maps(&poly, &spec, &ds, &grid, 5, 5))
                        .unwrap()
                })
                .collect();
            assert_eq!(maps[0].theta_f.len(), 5 * 1000);
            assert_eq!(maps[0].pushes, 5 * 1000);
            assert!(maps[0] == maps[1]);
        }
    }
}
