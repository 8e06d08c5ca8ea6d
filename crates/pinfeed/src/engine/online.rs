//! The online controller's model (docs/physics.md#belief-and-online-replanning): hypotheses
//! about a part, what each makes the sensors read, and what each does on the line under every
//! joint command of the dynamic pins.
//!
//! Built once per scene from its **nominal** physics and the declared `[controller.belief]`:
//! * **Hypotheses** h = stable state × lateral-offset bin × pin–part friction μ × support class,
//!   each with a prior (the feed's state weight × the bin's share of the lateral distribution,
//!   uniform over μ and support classes).
//! * **Members**: `samples` simulated parts per hypothesis, drawn from the controller's own
//!   streams (seed, 3·2⁶¹ | h·2¹⁶ | m): the feed's orientation jitter about the state, an offset
//!   uniform within the bin, and a random tripod for the tripod class. The member is the unit of
//!   prediction; the hypothesis averages its members (what the controller cannot resolve).
//! * **Sensors**: each member is run through the line (the same engine, [`super::run_entry`]);
//!   its push at each sensor pin, replayed with a knot recorder, is that member's template. Per
//!   sensor, p_touch(h) is the share of h's members that touch it, and a likelihood classifier
//!   ([`crate::sensing::classify::likelihood`]) over the hypotheses' templates gives
//!   log p(reading | h, touch).
//! * **Actions**: the joint commands of the dynamic pins: each moving pin on a grid of `targets`
//!   positions over its travel plus its home and the targets its rules name, each retractable
//!   pin raised or withdrawn. For every action and member the line is run with the pins standing
//!   at the action's targets; `success[a][h]` is the share of h's members that end in the goal.
//!
//! A decision is then a dot product per action: P(goal | a) = Σ_h p(h | readings) · `success[a][h]`,
//! maximised over the actions (ties: the least travel from where the pins stand).

use super::line::{run_entry, run_single, Entry};
use super::outcome::PartOutcome;
use super::sensing::nearest;
use crate::mechanics::{PartModel, Support};
use crate::random::stream;
use crate::scenario::raw::SupportKind;
use crate::scenario::{
    Actuator, BeliefSpec, Lateral, Obstacle, Orientation, PinObstacle, Scene, Target,
};
use crate::sensing::belief::Belief;
use crate::sensing::classify::likelihood::Likelihood;
use crate::sensing::classify::ClassifierOptions;
use crate::sensing::reading::{read, Reading};
use crate::sensing::signal::{ContactSignal, KnotRecorder, SignalScale};
use crate::sensing::templates::{Hypotheses, TemplateSet};
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// First stream index of the online model's members.
const MEMBER_STREAMS: u64 = 3 << 61;
/// First stream index of the held-out members' readings.
const HELD_OUT_READINGS: u64 = 5 << 60;
/// Largest joint action set a model may have (larger beliefs are refused).
pub const MAX_ACTIONS: usize = 4096;
/// Largest number of line runs the model's build may take (larger beliefs are refused).
pub const MAX_RUNS: usize = 4_000_000;
/// Predictions closer than this are a tie: they are shares of a few simulated members, and a
/// belief that is all but certain leaves differences far below it.
pub const TIE: f64 = 1e-3;
/// Orientation sectors standing for the states of a uniform feed.
const UNIFORM_SECTORS: usize = 12;

/// One hypothesis about a part.
#[derive(Debug, Clone, PartialEq)]
pub struct Hypothesis {
    /// State index (into the part's stable states, or a sector of a uniform feed).
    pub state: usize,
    /// The state's orientation (degrees).
    pub state_deg: f64,
    /// The lateral-offset bin [lo, hi] (m).
    pub offset: [f64; 2],
    /// Pin–part friction coefficient of the hypothesis.
    pub mu_c: f64,
    /// Support class of the hypothesis.
    pub support: SupportKind,
}

/// What one sensor tells about the hypotheses.
pub struct SensorModel {
    /// The sensor pin's obstacle index.
    pub obstacle: usize,
    /// Per hypothesis: the share of its members that touch the pin.
    pub p_touch: Vec<f64>,
    /// The likelihood over the hypotheses that touch (None: no member touches).
    likelihood: Option<Likelihood>,
    /// Hypothesis of each of the likelihood's labels.
    rows: Vec<usize>,
    /// The power the likelihood is raised to (1: trusted as it is, 0: not used; see `temper`).
    pub temper: f64,
    /// Per hypothesis, the sensor's own classifier's label for its stable state (None when the
    /// classifier's labels are not orientations).
    state_label: Option<Vec<usize>>,
    /// The power the classifier's posterior over the states is raised to as a second likelihood
    /// (0: not used; see `temper`).
    pub classifier_power: f64,
}

/// The online controller's model; see the module notes.
pub struct OnlineModel {
    /// The hypotheses, in the order of the belief's entries.
    pub hypotheses: Vec<Hypothesis>,
    /// The belief before any observation.
    pub prior: Belief,
    /// One per sensor pin, in obstacle order.
    pub sensors: Vec<SensorModel>,
    /// The dynamic pins (obstacle indices).
    pub pins: Vec<usize>,
    /// The joint actions: one target per dynamic pin (in the order of `pins`).
    pub actions: Vec<Vec<Target>>,
    /// Number of options per pin (the actions are their product, the last pin fastest).
    options: Vec<usize>,
    /// Each dynamic pin's state before any command.
    homes: Vec<Target>,
    /// success[a · H + h].
    success: Vec<f64>,
    /// The same table hypothesis by hypothesis: success[h · A + a] (what a decision reads).
    by_hypothesis: Vec<f64>,
    /// The prior's entropy (bits), computed once when the model is built.
    prior_entropy_bits: f64,
    /// Members per hypothesis.
    pub samples: usize,
    /// Line runs the build took (a run through one stretch of the line counts one).
    pub runs: u64,
    /// Contact-model evaluations of the runs that predict success.
    pub evaluations: u64,
}

/// Why the online controller's model cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OnlineModelError {
    /// Every hypothesis has prior weight 0.
    #[error("the belief's prior has no positive weight")]
    NoPrior,
    /// The joint commands of the dynamic pins exceed [`MAX_ACTIONS`].
    #[error("the dynamic pins have {0} joint commands on the action grid (at most {MAX_ACTIONS}): lower controller.belief.targets")]
    TooManyActions(usize),
    /// The build would exceed [`MAX_RUNS`] line runs.
    #[error("the online model would run the line {runs} times ({hypotheses} hypotheses × {samples} samples × {actions} actions; at most {MAX_RUNS}): lower controller.belief.offsets, samples or targets, or the friction values")]
    TooManyRuns {
        /// Line runs the build would take.
        runs: usize,
        /// Hypotheses of the belief.
        hypotheses: usize,
        /// Members per hypothesis.
        samples: usize,
        /// Joint commands.
        actions: usize,
    },
    /// A member's part or run could not be simulated (the simulator's message).
    #[error("{0}")]
    Simulation(String),
}

/// The controller's choice for one part.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// Index into [`OnlineModel::actions`].
    pub action: usize,
    /// P(goal | action, belief).
    pub predicted: f64,
}

/// Per member of the online model: its signal at each sensor (None: no touch), its success per
/// action, and its line runs and contact-model evaluations.
type MemberOut = (Vec<Option<ContactSignal>>, Vec<bool>, [u64; 2]);

/// success[a · H + h]: the share of hypothesis h's `s` members that end in the goal under joint
/// action a (`order[a]`: the action's index in each member's successes).
fn success_table(
    outs: &[MemberOut],
    order: &[usize],
    n_actions: usize,
    n_h: usize,
    s: usize,
) -> Vec<f64> {
    let mut success = vec![0.0; n_actions * n_h];
    for (k, (_, ok, _)) in outs.iter().enumerate() {
        for (a, &p) in order.iter().enumerate() {
            success[a * n_h + k / s] += f64::from(u8::from(ok[p])) / s as f64;
        }
    }
    success
}

/// `table` (rows × cols, row-major) column by column: out[c · rows + r] = table[r · cols + c].
fn transpose(table: &[f64], rows: usize, cols: usize) -> Vec<f64> {
    (0..cols * rows)
        .map(|k| table[(k % rows) * cols + k / rows])
        .collect()
}

/// A sensor's held-out trials: each one's hypothesis and the evidence of its reading.
type HeldTrials = Vec<(usize, Evidence)>;

/// The model of sensor `i` (obstacle `j`) from the members' signals (`outs`, `s` per
/// hypothesis), and its held-out trials (reading, hypothesis) for tempering; None when the
/// obstacle is not a pin.
fn sensor_model(
    scene: &Scene,
    hypotheses: &[Hypothesis],
    i: usize,
    j: usize,
    outs: &[MemberOut],
    s: usize,
    held_out: &[(usize, Vec<Option<ContactSignal>>)],
) -> Result<Option<(SensorModel, HeldTrials)>, OnlineModelError> {
    let n_h = hypotheses.len();
    let Obstacle::Pin(pin) = &scene.obstacles[j] else {
        return Ok(None);
    };
    let sensor = pin.sensor.as_ref().expect("a sensor pin");
    let mut p_touch = vec![0.0; n_h];
    let mut set = TemplateSet {
        labels: Vec::new(),
        members: Vec::new(),
    };
    let mut rows = Vec::new();
    for h in 0..n_h {
        let sigs: Vec<ContactSignal> = (0..s)
            .filter_map(|m| outs[h * s + m].0[i].clone())
            .collect();
        p_touch[h] = sigs.len() as f64 / s as f64;
        if !sigs.is_empty() {
            rows.push(h);
            set.labels.push(format!("h{h}"));
            set.members.push(sigs);
        }
    }
    let likelihood = if rows.is_empty() {
        None
    } else {
        Some(Likelihood::new(
            &set,
            &sensor.settings,
            &ClassifierOptions::default(),
        ))
    };
    let state_label = match &sensor.hypotheses {
        Hypotheses::Orientations { degrees, .. } => hypotheses
            .iter()
            .map(|x| nearest(degrees, x.state_deg))
            .collect::<Option<Vec<usize>>>(),
        Hypotheses::VertexEdge { .. } => None,
    };
    let sm = SensorModel {
        obstacle: j,
        p_touch,
        likelihood,
        rows,
        temper: 1.0,
        state_label,
        classifier_power: 1.0,
    };
    let trials: Vec<(usize, Evidence)> = held_out
        .iter()
        .enumerate()
        .filter_map(|(k, (h, sigs))| {
            let sig = sigs[i].as_ref()?;
            let mut rng = stream(scene.seed, HELD_OUT_READINGS | ((k as u64) << 8) | i as u64);
            let r = read(sig, &sensor.settings, &mut rng)?;
            let post = sensor.classifier.classify(&r).posterior;
            Some((*h, Evidence::of(&sm, Some(&r), post.as_deref(), true)))
        })
        .collect();
    Ok(Some((sm, trials)))
}

impl OnlineModel {
    /// Build the model of `scene` (its nominal physics) for `spec`. Errors name the size that is
    /// too large or the hypothesis set that is empty.
    pub fn build(scene: &Scene, spec: &BeliefSpec) -> Result<OnlineModel, OnlineModelError> {
        Self::build_with(scene, spec, true)
    }

    /// As [`OnlineModel::build`]; with `staged`, each member crosses the line stretch by stretch
    /// ([`stages`]), else once per joint action from the line's start.
    fn build_with(
        scene: &Scene,
        spec: &BeliefSpec,
        staged: bool,
    ) -> Result<OnlineModel, OnlineModelError> {
        let (hypotheses, prior) = hypotheses(scene, spec);
        let prior = Belief::new(&prior).ok_or(OnlineModelError::NoPrior)?;
        // The members with uniform pressure push with the part's own model at their hypothesis's
        // μc: one model with slide tables for every such μc (built lazily, shared by every
        // variant of the scene below), as the scene's own model has them for its pins' μc.
        let tabled = with_hypotheses_tables(scene, &hypotheses);
        let scene = &tabled;
        let pins = indices(scene, |p| p.actuator.is_some());
        let (actions, per_pin) = joint_actions(scene, &pins, spec.targets)?;
        let options: Vec<usize> = per_pin.iter().map(Vec::len).collect();
        let s = spec.samples;
        let n_members = hypotheses.len() * s;
        let runs = n_members * (actions.len() + 1);
        if runs > MAX_RUNS {
            return Err(OnlineModelError::TooManyRuns {
                runs,
                hypotheses: hypotheses.len(),
                samples: s,
                actions: actions.len(),
            });
        }
        let members: Vec<(usize, Entry)> = (0..n_members)
            .map(|k| member(scene, &hypotheses[k / s], k / s, k % s).map(|e| (k / s, e)))
            .collect::<Result<_, OnlineModelError>>()?;
        let mus = distinct(hypotheses.iter().map(|h| h.mu_c));
        let variant_of = |a: Option<&[Target]>, mu: f64| variant(scene, &pins, a, mu);
        let sensing: Vec<Scene> = mus.iter().map(|&m| variant_of(None, m)).collect();
        let homes: Vec<Target> = pins.iter().map(|&j| home_of(&scene.obstacles[j])).collect();
        let stretches = if staged {
            stages(scene, &pins)
        } else {
            vec![Stage {
                pins: (0..pins.len()).collect(),
                end: None,
            }]
        };
        let staging = Staging::new(
            &stretches,
            &per_pin,
            &homes,
            |targets, end, mu| {
                let mut v = variant_of(Some(targets), mu);
                if let Some(x) = end {
                    v.belt.length = x;
                }
                v
            },
            &mus,
        );
        let mu_index = |mu: f64| mus.iter().position(|&m| m == mu).expect("listed μ");
        let sensor_obstacles = indices(scene, |p| p.sensor.is_some());
        let signals_of =
            |h: usize, e: &Entry| -> Result<Vec<Option<ContactSignal>>, OnlineModelError> {
                let base = &sensing[mu_index(hypotheses[h].mu_c)];
                sensor_signals(scene, base, &sensor_obstacles, e)
            };
        // Per member: its signal at each sensor (None: no touch) and its success per action. The
        // parallel results are gathered in member order before the first error is taken, so a
        // failing model names the same member on any number of threads.
        let outs: Vec<MemberOut> = members
            .par_iter()
            .map(|(h, e)| -> Result<MemberOut, OnlineModelError> {
                let mi = mu_index(hypotheses[*h].mu_c);
                let signals = signals_of(*h, e)?;
                let (ok, member_runs) = staging.success(mi, e)?;
                Ok((signals, ok, member_runs))
            })
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<_, OnlineModelError>>()?;
        let runs_taken: u64 = outs.iter().map(|o| o.2[0] + 1).sum();
        let evaluations: u64 = outs.iter().map(|o| o.2[1]).sum();
        // Held-out members (other streams) calibrate how far each sensor's likelihood can be
        // trusted (see `temper`).
        let v = (s / 2).max(2);
        let held_out: Vec<(usize, Vec<Option<ContactSignal>>)> = (0..hypotheses.len() * v)
            .into_par_iter()
            .map(|k| {
                let (h, m) = (k / v, s + k % v);
                let e = member(scene, &hypotheses[h], h, m)?;
                Ok((h, signals_of(h, &e)?))
            })
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<_, OnlineModelError>>()?;
        let n_h = hypotheses.len();
        let order = staging.prefix_of_actions(&options);
        let success = success_table(&outs, &order, actions.len(), n_h, s);
        let actions_len = actions.len();
        let mut sensors = Vec::new();
        let mut held_trials = Vec::new();
        for (i, &j) in sensor_obstacles.iter().enumerate() {
            let Some((sm, trials)) = sensor_model(scene, &hypotheses, i, j, &outs, s, &held_out)?
            else {
                continue;
            };
            held_trials.push(trials);
            sensors.push(sm);
        }
        let mut model = OnlineModel {
            hypotheses,
            prior_entropy_bits: prior.entropy_bits(),
            prior,
            sensors,
            pins,
            actions,
            options,
            homes,
            by_hypothesis: transpose(&success, actions_len, n_h),
            success,
            samples: s,
            runs: runs_taken + held_out.len() as u64,
            evaluations,
        };
        for (i, trials) in held_trials.iter().enumerate() {
            let (tau, sigma) = temper(&model, i, trials);
            model.sensors[i].temper = tau;
            model.sensors[i].classifier_power = sigma;
        }
        Ok(model)
    }

    /// What the model says the line can do for the hypotheses of support class `support` (all
    /// with None), weighted by the prior: (the best single command with no information, the mean
    /// of each hypothesis's best command — a belief certain of the hypothesis, which still cannot
    /// know the member: the tripod, the jitter, the offset within its bin).
    pub fn bounds(&self, support: Option<SupportKind>) -> (f64, f64) {
        let w: Vec<f64> = self
            .hypotheses
            .iter()
            .enumerate()
            .map(|(h, hy)| {
                if support.is_none_or(|s| s == hy.support) {
                    self.prior.probability(h)
                } else {
                    0.0
                }
            })
            .collect();
        let total: f64 = w.iter().sum();
        if total <= 0.0 {
            return (0.0, 0.0);
        }
        let blind = (0..self.actions.len())
            .map(|a| {
                let row = self.success_of(a);
                w.iter().zip(row).map(|(w, s)| w * s).sum::<f64>()
            })
            .fold(0.0, f64::max);
        let informed: f64 = (0..self.hypotheses.len())
            .map(|h| {
                let best = (0..self.actions.len())
                    .map(|a| self.success_of(a)[h])
                    .fold(0.0, f64::max);
                w[h] * best
            })
            .sum();
        (blind / total, informed / total)
    }

    /// The entropy of [`OnlineModel::prior`] in bits ([`Belief::entropy_bits`]).
    pub fn prior_entropy_bits(&self) -> f64 {
        self.prior_entropy_bits
    }

    /// The model of sensor pin `obstacle`, if it is one.
    pub fn sensor(&self, obstacle: usize) -> Option<&SensorModel> {
        self.sensors.iter().find(|s| s.obstacle == obstacle)
    }

    /// The action that maximises P(goal) under `belief`. Ties (within [`TIE`]) go to the action whose grid
    /// neighbours (one step of one pin) do best on average — the middle of a range of good
    /// positions, the most robust to what the model does not know — then to the least travel
    /// from the pins' homes. The choice is a function of the belief alone (not of where the pins
    /// happen to stand), so a rule table can reproduce it.
    pub fn choose(&self, belief: &Belief) -> Choice {
        self.choose_from(&belief.probabilities())
    }

    /// [`OnlineModel::choose`] for the belief whose probabilities are `probabilities`
    /// ([`Belief::probabilities`]).
    pub fn choose_from(&self, probabilities: &[f64]) -> Choice {
        let current = &self.homes;
        let p = self.predictions(probabilities);
        // The tie-breakers are computed only for actions within TIE of the best so far: the
        // same sequential comparison, without the neighbours of every action.
        let around = |a: usize| self.around(&p, a);
        let mut best = 0;
        let mut best_around: Option<f64> = None;
        for a in 1..self.actions.len() {
            let better = if (p[a] - p[best]).abs() > TIE {
                p[a] > p[best]
            } else {
                let (ka, kb) = (around(a), *best_around.get_or_insert_with(|| around(best)));
                if (ka - kb).abs() > TIE {
                    ka > kb
                } else {
                    -travel(&self.actions[a], current)
                        > -travel(&self.actions[best], current) + 1e-12
                }
            };
            if better {
                best = a;
                best_around = None;
            }
        }
        Choice {
            action: best,
            predicted: p[best].clamp(0.0, 1.0),
        }
    }

    /// P(goal | a) = Σ_h p(h) · success[a][h] for every action a, each sum in the order of the
    /// hypotheses, all actions at once (hypothesis by hypothesis over the transposed table). A
    /// hypothesis of probability 0 is skipped: its products are +0, which leave every sum as it
    /// was (each is +0 or positive).
    fn predictions(&self, w: &[f64]) -> Vec<f64> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { self.predictions_avx2(w) };
        }
        self.predictions_plain(w)
    }

    /// [`OnlineModel::predictions`] compiled for AVX2's wider registers: the same products and
    /// sums in the same order, four actions at a time instead of two.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn predictions_avx2(&self, probabilities: &[f64]) -> Vec<f64> {
        self.predictions_plain(probabilities)
    }

    /// The loop of [`OnlineModel::predictions`] over the belief's `probabilities`.
    #[inline(always)]
    fn predictions_plain(&self, probabilities: &[f64]) -> Vec<f64> {
        let n_a = self.actions.len();
        let mut p = vec![0.0; n_a];
        for (h, &w) in probabilities.iter().enumerate() {
            if w == 0.0 {
                continue;
            }
            let row = &self.by_hypothesis[h * n_a..(h + 1) * n_a];
            for (pa, s) in p.iter_mut().zip(row) {
                *pa += w * s;
            }
        }
        p
    }

    /// The mean of the predictions `p` over the actions one grid step of one pin away from
    /// action `a` (summed pin by pin, the last pin first, the step down before the step up).
    fn around(&self, p: &[f64], a: usize) -> f64 {
        let (mut sum, mut n) = (-0.0, 0usize);
        let mut stride = 1;
        for size in self.options.iter().rev() {
            let digit = (a / stride) % size;
            if digit > 0 {
                sum += p[a - stride];
                n += 1;
            }
            if digit + 1 < *size {
                sum += p[a + stride];
                n += 1;
            }
            stride *= size;
        }
        sum / n.max(1) as f64
    }

    /// `success[a][h]` for every hypothesis.
    pub fn success_of(&self, action: usize) -> &[f64] {
        let n_h = self.hypotheses.len();
        &self.success[action * n_h..(action + 1) * n_h]
    }
}

impl SensorModel {
    /// log p(reading | h, touch) per hypothesis, as the belief takes it: the matched filter over
    /// the hypotheses' templates raised to [`SensorModel::temper`] (−∞ for a hypothesis that
    /// never touches), plus the sensor classifier's log posterior of h's state (`posterior`,
    /// over its labels under a uniform prior, so proportional to the likelihood of each state)
    /// raised to [`SensorModel::classifier_power`]. A channel with power 0 is not computed. None
    /// when neither channel has anything to say (no contact detected in the reading).
    pub fn log_likelihood(
        &self,
        reading: Option<&Reading>,
        posterior: Option<&[f64]>,
    ) -> Option<Vec<f64>> {
        let raw = Evidence::of(self, reading, posterior, self.temper > 0.0);
        raw.combine(self.temper, self.classifier_power)
    }
}

/// The raw evidence of one reading per hypothesis, before the powers: the matched filter's log
/// likelihood and the classifier's log posterior of the hypothesis's state.
#[derive(Debug, Clone)]
struct Evidence {
    filter: Option<Vec<f64>>,
    classifier: Option<Vec<f64>>,
}

impl Evidence {
    fn of(
        sm: &SensorModel,
        reading: Option<&Reading>,
        posterior: Option<&[f64]>,
        with_filter: bool,
    ) -> Evidence {
        let filter = with_filter
            .then(|| reading.and_then(|r| sm.likelihood.as_ref()?.log_likelihoods(r)))
            .flatten()
            .map(|ll| {
                let mut out = vec![f64::NEG_INFINITY; sm.p_touch.len()];
                for (k, &h) in sm.rows.iter().enumerate() {
                    out[h] = ll[k];
                }
                out
            });
        let classifier = match (&sm.state_label, posterior) {
            (Some(labels), Some(p)) => {
                // The log of each label's posterior once (a few labels, many hypotheses).
                let n = labels.iter().copied().max().map_or(0, |m| m + 1);
                let logs: Vec<f64> = (0..n)
                    .map(|l| p.get(l).copied().unwrap_or(0.0).max(1e-300).ln())
                    .collect();
                Some(labels.iter().map(|&l| logs[l]).collect())
            }
            _ => None,
        };
        Evidence { filter, classifier }
    }

    fn combine(&self, tau: f64, sigma: f64) -> Option<Vec<f64>> {
        let filter = self.filter.as_ref().filter(|_| tau > 0.0);
        let classifier = self.classifier.as_ref().filter(|_| sigma > 0.0);
        if filter.is_none() && classifier.is_none() {
            return None;
        }
        let n = filter.or(classifier).map_or(0, Vec::len);
        Some(
            (0..n)
                .map(|h| {
                    filter.map_or(0.0, |f| tau * f[h]) + classifier.map_or(0.0, |c| sigma * c[h])
                })
                .collect(),
        )
    }
}

/// The powers sensor `i`'s two channels are raised to: τ for the matched filter over the
/// hypotheses' templates, σ for the sensor classifier's posterior over the states. The filter's
/// noise model knows the sensor's noise only, not how far a real push strays from every simulated
/// member (another tripod, another jitter), so its raw likelihood is far too sharp and one reading
/// would make the belief certain of a wrong hypothesis; the classifier, trained on many templates
/// per state, names the state more robustly but says nothing of the offset, friction or support.
/// Both powers are chosen together on held-out members (readings neither channel was built from;
/// `trials` holds their true hypothesis and raw evidence), each from 1 down to 10⁻⁶ in
/// half-decades or 0 (the channel unused): the pair whose decisions do best on them (the mean
/// success(a*, h_true) of the command the belief after their reading chooses), within [`TIE`] the
/// best mean log posterior of their true hypothesis. The matched filter costs far more per reading
/// than the classifier (a channel with power 0 is not computed), so the best pair with it is
/// taken over the best without it only when its decisions do better by more than twice the
/// standard error of the paired differences over the held-out trials — a tempered likelihood,
/// calibrated by cross-validation on what the controller does with it.
fn temper(model: &OnlineModel, i: usize, trials: &[(usize, Evidence)]) -> (f64, f64) {
    if trials.is_empty() {
        return (1.0, 1.0);
    }
    let p_touch = &model.sensors[i].p_touch;
    // Per trial: the success of the command chosen, and the log posterior of the truth.
    let score = |tau: f64, sigma: f64| -> (Vec<f64>, f64, f64) {
        let mut won = Vec::with_capacity(trials.len());
        let mut log = 0.0;
        for (h, ev) in trials {
            let mut b = model.prior.clone();
            b.observe_reading(p_touch, ev.combine(tau, sigma).as_deref());
            won.push(model.success_of(model.choose(&b).action)[*h]);
            log += b.probability(*h).max(1e-300).ln();
        }
        let n = trials.len() as f64;
        let mean = won.iter().sum::<f64>() / n;
        (won, mean, log / n)
    };
    let powers: Vec<f64> = std::iter::once(0.0)
        .chain((0..=12).rev().map(|k| 10f64.powf(-(k as f64) / 2.0)))
        .collect();
    let pairs: Vec<(f64, f64)> = powers
        .iter()
        .flat_map(|&tau| powers.iter().map(move |&sigma| (tau, sigma)))
        .collect();
    let scores: Vec<(Vec<f64>, f64, f64)> = pairs.par_iter().map(|&(t, s)| score(t, s)).collect();
    // The best pair of a class: the best mean success, within TIE the best log score.
    let best_of = |filter: bool| -> usize {
        let mut best: Option<usize> = None;
        for (k, sc) in scores.iter().enumerate() {
            if (pairs[k].0 > 0.0) != filter {
                continue;
            }
            let better = best.is_none_or(|b| {
                let b = &scores[b];
                if (sc.1 - b.1).abs() > TIE {
                    sc.1 > b.1
                } else {
                    sc.2 > b.2 + 1e-9
                }
            });
            if better {
                best = Some(k);
            }
        }
        best.expect("both classes have pairs")
    };
    let (cheap, costly) = (best_of(false), best_of(true));
    // The filter costs far more per reading than the classifier: it is kept only when its
    // decisions beat the best without it by more than twice the standard error of the paired
    // differences over the held-out trials.
    let d: Vec<f64> = scores[costly]
        .0
        .iter()
        .zip(&scores[cheap].0)
        .map(|(a, b)| a - b)
        .collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    if mean > 2.0 * (var / n).sqrt() && mean > TIE {
        pairs[costly]
    } else {
        pairs[cheap]
    }
}

/// Each sensor's clean signal when a part entering as `e` meets it on the line `base` (None:
/// the part passes without touching).
fn sensor_signals(
    scene: &Scene,
    base: &Scene,
    sensors: &[usize],
    e: &Entry,
) -> Result<Vec<Option<ContactSignal>>, OnlineModelError> {
    let (_, pushes) = run_entry(base, e.clone(), true)
        .map_err(|e| OnlineModelError::Simulation(e.to_string()))?;
    Ok(sensors
        .iter()
        .map(|&j| {
            let p = pushes.iter().find(|p| p.obstacle == j)?;
            let Obstacle::Pin(pin) = &scene.obstacles[j] else {
                return None;
            };
            let sensor = pin.sensor.as_ref()?;
            let model = p.model.as_ref().unwrap_or(&base.part.model);
            let mut knots = KnotRecorder::default();
            let out = p.pusher.push(model, p.pose, &p.settings, Some(&mut knots));
            out.contact.then(|| {
                let scale = SignalScale {
                    mass: scene.part.mass,
                    belt_speed: scene.belt.speed,
                    height: sensor.settings.height,
                    metres_per_unit: 1.0,
                };
                ContactSignal::new(&out, &knots.samples, &scale)
            })
        })
        .collect())
}

/// The hypotheses and their prior weights.
fn hypotheses(scene: &Scene, spec: &BeliefSpec) -> (Vec<Hypothesis>, Vec<f64>) {
    let states: Vec<(f64, f64)> = match &scene.feed.orientation {
        Orientation::Stable {
            thetas_rad: thetas,
            weights,
            ..
        } => thetas
            .iter()
            .zip(weights)
            .map(|(t, w)| (t.to_degrees(), *w))
            .collect(),
        Orientation::Uniform => (0..UNIFORM_SECTORS)
            .map(|k| ((k as f64 + 0.5) * 360.0 / UNIFORM_SECTORS as f64, 1.0))
            .collect(),
    };
    let bins = offset_bins(&scene.feed.lateral, spec.offsets);
    let mus = if spec.mu_c.is_empty() {
        vec![scene.contact.mu_c]
    } else {
        spec.mu_c.clone()
    };
    let supports = if spec.support.is_empty() {
        vec![scene.part.support]
    } else {
        spec.support.clone()
    };
    let mut hs = Vec::new();
    let mut prior = Vec::new();
    for (state, &(deg, w)) in states.iter().enumerate() {
        for &(lo, hi, mass) in &bins {
            for &mu in &mus {
                for &support in &supports {
                    hs.push(Hypothesis {
                        state,
                        state_deg: deg,
                        offset: [lo, hi],
                        mu_c: mu,
                        support,
                    });
                    prior.push(w * mass);
                }
            }
        }
    }
    (hs, prior)
}

/// Lateral-offset bins (lo, hi, probability mass) over the feed's lateral range.
fn offset_bins(lateral: &Lateral, n: usize) -> Vec<(f64, f64, f64)> {
    let (lo, hi, pdf): (f64, f64, Box<dyn Fn(f64) -> f64>) = match *lateral {
        Lateral::Fixed(y) => return vec![(y, y, 1.0)],
        Lateral::Uniform { min, max } => (min, max, Box::new(|_| 1.0)),
        Lateral::Normal { mean, sd, lo, hi } => (
            lo.max(mean - 3.0 * sd),
            hi.min(mean + 3.0 * sd),
            Box::new(move |y: f64| (-0.5 * ((y - mean) / sd).powi(2)).exp()),
        ),
    };
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return vec![(lo, lo, 1.0)];
    }
    let w = (hi - lo) / n as f64;
    (0..n)
        .map(|k| {
            let (a, b) = (lo + k as f64 * w, lo + (k + 1) as f64 * w);
            // Midpoint rule over 32 sub-intervals: the bin's share of the density.
            let mass: f64 = (0..32).map(|i| pdf(a + (i as f64 + 0.5) * w / 32.0)).sum();
            (a, b, mass)
        })
        .collect()
}

/// Member `m` of hypothesis `h`: its entry pose and support.
fn member(scene: &Scene, hyp: &Hypothesis, h: usize, m: usize) -> Result<Entry, OnlineModelError> {
    let mut rng = stream(scene.seed, MEMBER_STREAMS | ((h as u64) << 16) | m as u64);
    let theta_deg = match &scene.feed.orientation {
        Orientation::Stable {
            jitter_rad: jitter, ..
        } => {
            let z: f64 = StandardNormal.sample(&mut rng);
            hyp.state_deg + jitter.to_degrees() * z
        }
        Orientation::Uniform => {
            let u: f64 = rng.random();
            hyp.state_deg + (u - 0.5) * 360.0 / UNIFORM_SECTORS as f64
        }
    };
    let u: f64 = rng.random();
    let y = hyp.offset[0] + u * (hyp.offset[1] - hyp.offset[0]);
    let model = match hyp.support {
        SupportKind::Uniform => None,
        SupportKind::Tripod => {
            let support =
                Support::random_tripod(&scene.part.polygon, &mut rng).map_err(simulation)?;
            Some(PartModel::new(&scene.part.polygon, &support).map_err(simulation)?)
        }
    };
    Ok(Entry {
        x: 0.0,
        theta_rad: theta_deg.to_radians().rem_euclid(std::f64::consts::TAU),
        y,
        model,
    })
}

/// A simulator's error as the model's.
fn simulation(e: impl std::fmt::Display) -> OnlineModelError {
    OnlineModelError::Simulation(e.to_string())
}

/// A stretch of the line that a part crosses after the previous one: the dynamic pins acting in
/// it and where it ends.
#[derive(Debug, Clone, PartialEq)]
struct Stage {
    /// Positions (into the model's `pins`) of the dynamic pins that stand in this stretch.
    pins: Vec<usize>,
    /// Where the stretch ends along the belt (m; None: at the line's end).
    end: Option<f64>,
}

/// Cut the line into stretches a part crosses one after another, so that a member's path up to
/// a dynamic pin is simulated once rather than once per command of the pins downstream, and
/// members that leave a stretch in the same pose (a pin command that never touched them) go on
/// as one. A cut lies where no obstacle is within 1.25·a of it on either side, so a part whose
/// centroid crosses it touches nothing: in a line whose pins stand still the part is then free,
/// and its pose (x, y, θ) is all there is to carry to the next stretch. Stretches end at every
/// such gap before the last dynamic pin; the last runs to the line's end.
fn stages(scene: &Scene, pins: &[usize]) -> Vec<Stage> {
    let reach = 1.25 * scene.part.radius;
    let mut spans: Vec<(f64, f64, Option<usize>)> = scene
        .obstacles
        .iter()
        .enumerate()
        .map(|(j, o)| {
            let [lo, hi] = o.x_range();
            (lo - reach, hi + reach, pins.iter().position(|&p| p == j))
        })
        .collect();
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Blocks of overlapping spans: (lo, hi, dynamic pins in it).
    let mut blocks: Vec<(f64, f64, Vec<usize>)> = Vec::new();
    for (lo, hi, pin) in spans {
        match blocks.last_mut() {
            Some(b) if lo <= b.1 => {
                b.1 = b.1.max(hi);
                b.2.extend(pin);
            }
            _ => blocks.push((lo, hi, pin.into_iter().collect())),
        }
    }
    let Some(last) = blocks.iter().rposition(|b| !b.2.is_empty()) else {
        return vec![Stage {
            pins: Vec::new(),
            end: None,
        }];
    };
    let mut out: Vec<Stage> = Vec::new();
    for (i, b) in blocks.iter().enumerate().take(last) {
        let cut = 0.5 * (b.1 + blocks[i + 1].0);
        if cut > 0.0 {
            out.push(Stage {
                pins: b.2.clone(),
                end: Some(cut),
            });
        }
    }
    // Pins upstream of the first positive cut (a line starting inside a block) join the next
    // stretch; the last stretch takes the rest.
    let placed: Vec<usize> = out.iter().flat_map(|st| st.pins.clone()).collect();
    out.push(Stage {
        pins: (0..pins.len()).filter(|k| !placed.contains(k)).collect(),
        end: None,
    });
    out
}

/// The stretches' line variants and how a member's results across them map to joint actions.
struct Staging {
    stages: Vec<Stage>,
    /// Per stretch, per command of its pins (mixed radix, first pin slowest), per μ: the line.
    scenes: Vec<Vec<Vec<Scene>>>,
}

/// Where a member stands after a stretch: gone from the line (and whether in the goal), or free
/// at a pose for the next stretch.
#[derive(Debug, Clone, Copy)]
enum Cont {
    Done(bool),
    Going(crate::geometry::Pose),
}

impl Staging {
    fn new(
        stages: &[Stage],
        per_pin: &[Vec<Target>],
        homes: &[Target],
        line: impl Fn(&[Target], Option<f64>, f64) -> Scene,
        mus: &[f64],
    ) -> Staging {
        let scenes = stages
            .iter()
            .map(|st| {
                let n: usize = st.pins.iter().map(|&k| per_pin[k].len()).product();
                (0..n)
                    .map(|c| {
                        let mut targets = homes.to_vec();
                        let mut rest = c;
                        for &k in st.pins.iter().rev() {
                            targets[k] = per_pin[k][rest % per_pin[k].len()];
                            rest /= per_pin[k].len();
                        }
                        mus.iter().map(|&mu| line(&targets, st.end, mu)).collect()
                    })
                    .collect()
            })
            .collect();
        Staging {
            stages: stages.to_vec(),
            scenes,
        }
    }

    /// A member's success for every command sequence (indexed stretch by stretch, as
    /// [`Staging::prefix_of_actions`] maps them), and the line runs it took.
    fn success(&self, mu: usize, e: &Entry) -> Result<(Vec<bool>, [u64; 2]), OnlineModelError> {
        use std::collections::HashMap;
        let mut states = vec![Cont::Going(crate::geometry::Pose::new(
            e.x,
            e.y,
            e.theta_rad,
        ))];
        let mut prefix: Vec<usize> = vec![0];
        let mut runs = [0, 0];
        for (s, stage) in self.scenes.iter().enumerate() {
            let last = s + 1 == self.scenes.len();
            let mut next: Vec<Cont> = Vec::new();
            let mut seen: HashMap<(u64, u64, u64), usize> = HashMap::new();
            let mut done = [None, None];
            let mut id_of = |c: Cont, next: &mut Vec<Cont>| -> usize {
                let push = || {
                    next.push(c);
                    next.len() - 1
                };
                match c {
                    Cont::Done(b) => *done[usize::from(b)].get_or_insert_with(push),
                    Cont::Going(p) => *seen
                        .entry((p.x.to_bits(), p.y.to_bits(), p.theta_rad.to_bits()))
                        .or_insert_with(push),
                }
            };
            let mut table: Vec<Vec<usize>> = Vec::with_capacity(states.len());
            for c in &states {
                let row = match *c {
                    Cont::Done(b) => vec![id_of(Cont::Done(b), &mut next); stage.len()],
                    Cont::Going(pose) => {
                        let mut row = Vec::with_capacity(stage.len());
                        for per_mu in stage {
                            runs[0] += 1;
                            let entry = Entry {
                                theta_rad: pose.theta_rad,
                                y: pose.y,
                                x: pose.x,
                                model: e.model.clone(),
                            };
                            let r = run_single(&per_mu[mu], entry).map_err(simulation)?;
                            runs[1] += r.model_evaluations;
                            let c = if !last && r.outcome.exited() {
                                Cont::Going(r.pose)
                            } else {
                                Cont::Done(r.outcome == PartOutcome::Success)
                            };
                            row.push(id_of(c, &mut next));
                        }
                        row
                    }
                };
                table.push(row);
            }
            prefix = prefix
                .iter()
                .flat_map(|&p| table[p].iter().copied())
                .collect();
            states = next;
        }
        let ok = prefix
            .iter()
            .map(|&i| matches!(states[i], Cont::Done(true)))
            .collect();
        Ok((ok, runs))
    }

    /// For each joint action (its pins' options in `pins` order, the last fastest), its index
    /// among the stretch-by-stretch command sequences of [`Staging::success`].
    fn prefix_of_actions(&self, options: &[usize]) -> Vec<usize> {
        let n: usize = options.iter().product();
        (0..n)
            .map(|a| {
                let mut digit = vec![0; options.len()];
                let mut rest = a;
                for k in (0..options.len()).rev() {
                    digit[k] = rest % options[k];
                    rest /= options[k];
                }
                self.stages
                    .iter()
                    .flat_map(|st| st.pins.iter())
                    .fold(0, |p, &k| p * options[k] + digit[k])
            })
            .collect()
    }
}

/// The scene as a static line: every dynamic pin standing at `action` (or at home), every pin
/// pushing with friction `mu`, sensor pins plain pins, no controller.
fn variant(scene: &Scene, pins: &[usize], action: Option<&[Target]>, mu: f64) -> Scene {
    let mut v = scene.clone();
    v.controller = None;
    v.contact.mu_c = mu;
    v.effects.event_log = false;
    for (k, &j) in pins.iter().enumerate() {
        let target = action.map(|a| a[k]);
        if let Obstacle::Pin(p) = &mut v.obstacles[j] {
            match (&mut p.actuator, target) {
                (Some(Actuator::Moving(m)), Some(Target::Y(y))) => {
                    m.home = y;
                    p.centre.y = y;
                }
                (Some(Actuator::Retractable(r)), Some(Target::Raised(up))) => r.raised = up,
                _ => {}
            }
        }
    }
    for o in &mut v.obstacles {
        if let Obstacle::Pin(p) = o {
            p.mu_c = mu;
            p.sensor = None;
        }
    }
    v
}

/// Each dynamic pin's options, in the order of the model's `pins`.
type PinOptions = Vec<Vec<Target>>;

/// The joint actions over `pins`, and each pin's options.
fn joint_actions(
    scene: &Scene,
    pins: &[usize],
    targets: usize,
) -> Result<(Vec<Vec<Target>>, PinOptions), OnlineModelError> {
    let mut per_pin: Vec<Vec<Target>> = Vec::new();
    for &j in pins {
        let Obstacle::Pin(p) = &scene.obstacles[j] else {
            continue;
        };
        let named = scene
            .controller
            .iter()
            .flat_map(|c| c.rules.iter())
            .filter(|r| r.pin == j)
            .map(|r| r.target);
        let options = match p.actuator {
            Some(Actuator::Moving(m)) => {
                let [lo, hi] = m.travel;
                let mut ys: Vec<f64> = (0..targets)
                    .map(|k| lo + (hi - lo) * k as f64 / (targets - 1) as f64)
                    .chain([m.home])
                    .chain(named.filter_map(|t| match t {
                        Target::Y(y) => Some(y),
                        Target::Raised(_) => None,
                    }))
                    .collect();
                ys.sort_by(f64::total_cmp);
                ys.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
                ys.into_iter().map(Target::Y).collect()
            }
            _ => vec![Target::Raised(true), Target::Raised(false)],
        };
        per_pin.push(options);
    }
    let n: usize = per_pin.iter().map(Vec::len).product();
    if n > MAX_ACTIONS {
        return Err(OnlineModelError::TooManyActions(n));
    }
    let mut out: Vec<Vec<Target>> = vec![Vec::new()];
    for options in &per_pin {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                options.iter().map(move |t| {
                    let mut a = prefix.clone();
                    a.push(*t);
                    a
                })
            })
            .collect();
    }
    Ok((out, per_pin))
}

/// A dynamic pin's state before any command.
fn home_of(o: &Obstacle) -> Target {
    match o {
        Obstacle::Pin(p) => match p.actuator {
            Some(Actuator::Moving(m)) => Target::Y(m.home),
            Some(Actuator::Retractable(r)) => Target::Raised(r.raised),
            None => Target::Y(p.centre.y),
        },
        Obstacle::Fence(_) => Target::Raised(true),
    }
}

/// Total travel from `current` to `action` (a retractable switch counts 1 mm).
fn travel(action: &[Target], current: &[Target]) -> f64 {
    action
        .iter()
        .zip(current)
        .map(|(a, c)| match (a, c) {
            (Target::Y(a), Target::Y(c)) => (a - c).abs(),
            (Target::Raised(a), Target::Raised(c)) => f64::from(u8::from(a != c)) * 1e-3,
            _ => 0.0,
        })
        .sum()
}

/// The obstacle indices of the pins for which `pick` holds.
fn indices(scene: &Scene, pick: impl Fn(&PinObstacle) -> bool) -> Vec<usize> {
    scene
        .obstacles
        .iter()
        .enumerate()
        .filter(|(_, o)| matches!(o, Obstacle::Pin(p) if pick(p)))
        .map(|(j, _)| j)
        .collect()
}

/// `scene` with a part model whose slide tables serve every hypothesis's μc as well as the
/// scene's own obstacles' (a model without tables — a tripod support, another fidelity — is kept).
fn with_hypotheses_tables(scene: &Scene, hypotheses: &[Hypothesis]) -> Scene {
    let mut tabled = scene.clone();
    if scene.part.model.has_slide_tables() {
        let own = scene.obstacles.iter().map(|o| match o {
            Obstacle::Pin(p) => p.mu_c,
            Obstacle::Fence(f) => f.mu_f,
        });
        let mus = distinct(own.chain(hypotheses.iter().map(|h| h.mu_c)));
        tabled.part.model = scene.part.model.clone().with_slide_tables(&mus);
    }
    tabled
}

fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::raw::SupportKind;

    /// tripoly2's online line with its controller in policy mode (no model built at parse).
    fn tripoly2_line() -> Scene {
        let path = &crate::project_path("scenarios/tripoly2_online.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let cut = text.find("[controller.belief]").unwrap();
        let end = text[cut..].find("[goal]").unwrap() + cut;
        let text = format!("{}{}", &text[..cut], &text[end..])
            .replace("mode = \"online\"", "mode = \"policy\"");
        crate::scenario::parse(path, &text).unwrap()
    }

    fn small_spec() -> BeliefSpec {
        BeliefSpec {
            mu_c: vec![0.3, 0.7],
            support: vec![SupportKind::Uniform, SupportKind::Tripod],
            offsets: 2,
            samples: 2,
            targets: 5,
        }
    }

    /// The typed errors read as the model's messages always have.
    #[test]
    fn model_errors_keep_their_messages() {
        let e = OnlineModelError::TooManyRuns {
            runs: 5_000_000,
            hypotheses: 54,
            samples: 6,
            actions: 256,
        };
        assert_eq!(
            e.to_string(),
            format!("the online model would run the line 5000000 times (54 hypotheses × 6 samples × 256 actions; at most {MAX_RUNS}): lower controller.belief.offsets, samples or targets, or the friction values")
        );
        assert_eq!(
            OnlineModelError::TooManyActions(5000).to_string(),
            format!("the dynamic pins have 5000 joint commands on the action grid (at most {MAX_ACTIONS}): lower controller.belief.targets")
        );
        assert_eq!(
            OnlineModelError::NoPrior.to_string(),
            "the belief's prior has no positive weight"
        );
        assert_eq!(simulation("a reason").to_string(), "a reason");
    }

    #[test]
    fn the_line_is_cut_between_its_pins_and_never_within_reach_of_one() {
        let scene = tripoly2_line();
        let pins = indices(&scene, |p| p.actuator.is_some());
        assert_eq!(pins.len(), 2);
        let st = stages(&scene, &pins);
        // The sensor's stretch, mover1's, then mover2's to the line's end.
        assert_eq!(
            st.iter().map(|s| s.pins.clone()).collect::<Vec<_>>(),
            [vec![], vec![0], vec![1]]
        );
        let reach = 1.25 * scene.part.radius;
        for s in &st {
            let Some(cut) = s.end else { continue };
            for o in &scene.obstacles {
                let [lo, hi] = o.x_range();
                assert!(
                    hi + reach < cut || lo - reach > cut,
                    "{} at the cut {cut}",
                    o.name()
                );
            }
        }
        // Move mover2 within reach of mover1: one stretch holds both.
        let mut near = scene.clone();
        let x1 = near.obstacles[pins[0]].x_range()[1];
        if let Obstacle::Pin(p) = &mut near.obstacles[pins[1]] {
            p.centre.x = x1 + 0.5 * scene.part.radius + p.radius;
        }
        let st = stages(&near, &pins);
        assert_eq!(st.last().unwrap().pins, [0, 1]);
        assert!(st.iter().rev().skip(1).all(|s| s.pins.is_empty()));
    }

    /// The uniform members at every hypothesis's μc (0.3 and 0.7 here; the line's pins push at
    /// 0.5) slide on slide tables: the same success table as the part's untabled model gives, to
    /// the tables' 1e-10, with fewer contact-model evaluations.
    #[test]
    fn members_at_every_hypothesis_mu_slide_on_tables() {
        let scene = tripoly2_line();
        assert!(scene.part.model.has_slide_tables());
        let mut plain = scene.clone();
        plain.part.model = PartModel::new(&scene.part.polygon, &Support::Uniform).unwrap();
        let spec = small_spec();
        let tabled = OnlineModel::build(&scene, &spec).unwrap();
        let solved = OnlineModel::build(&plain, &spec).unwrap();
        assert_eq!(tabled.success.len(), solved.success.len());
        let worst = tabled
            .success
            .iter()
            .zip(&solved.success)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "success entries differ by up to {worst}");
        assert!(
            tabled.evaluations * 10 < solved.evaluations * 9,
            "{} evaluations with tables, {} without",
            tabled.evaluations,
            solved.evaluations
        );
    }

    #[test]
    fn crossing_the_line_stretch_by_stretch_predicts_what_whole_runs_do() {
        let scene = tripoly2_line();
        // One friction and one support: the stretches, not the hypotheses, are under test.
        let spec = BeliefSpec {
            mu_c: vec![0.5],
            support: vec![SupportKind::Uniform],
            ..small_spec()
        };
        let staged = OnlineModel::build_with(&scene, &spec, true).unwrap();
        let whole = OnlineModel::build_with(&scene, &spec, false).unwrap();
        assert_eq!(staged.actions, whole.actions);
        let differ = staged
            .success
            .iter()
            .zip(&whole.success)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "of {} success entries", whole.success.len());
        assert!(staged.success.iter().any(|&p| p > 0.0) && staged.success.iter().any(|&p| p < 1.0));
        // More runs (one per stretch), each through a part of the line: less contact work.
        assert!(
            staged.evaluations < whole.evaluations,
            "{} vs {}",
            staged.evaluations,
            whole.evaluations
        );
    }
}
