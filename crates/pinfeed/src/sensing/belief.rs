//! A belief per part: the posterior over what the line does not know about a part
//! (docs/physics.md#belief-and-online-replanning).
//!
//! The hypotheses are a finite set fixed when the controller is built (for the online
//! controller: stable state × lateral-offset bin × pin–part friction × support class, see
//! [`crate::engine::online`]); the belief holds one weight per hypothesis, in log space so that
//! many small likelihoods do not underflow. Every observation multiplies the weights by its
//! likelihood and renormalises (Bayes' rule):
//!
//! * a reading r of a sensor: p(h | r) ∝ p(h) · p(r | h); two independent readings (their noise
//!   drawn independently given h) fuse as the product of their likelihoods;
//! * a pass without contact: p(h | no touch) ∝ p(h) · (1 − p_touch(h)), where p_touch(h) is the
//!   share of the hypothesis's simulated members that touch the sensor pin — a hypothesis whose
//!   members all touch is removed exactly.
//!
//! What the part does between observations (the pushes of the pins in between) is not an update
//! of the belief: the hypotheses are defined at the feed, and their predictions run the part
//! through the whole line.
//!
//! An observation no hypothesis explains (every weight would become 0) leaves the belief as it
//! was and is reported as [`Update::Inconsistent`], so that a caller can count it.

/// The result of one update.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Update {
    /// The weights were updated.
    Updated,
    /// No hypothesis explains the observation (all likelihoods 0 or not finite): the belief is
    /// unchanged.
    Inconsistent,
}

/// A posterior over `n` hypotheses.
#[derive(Debug, Clone, PartialEq)]
pub struct Belief {
    /// Natural-log weights, normalised so that Σ exp = 1; −∞ for a removed hypothesis.
    log_w: Vec<f64>,
}

impl Belief {
    /// The prior: weights proportional to `prior` (non-negative, not all 0). `None` when no
    /// weight is positive or one is negative or not finite.
    pub fn new(prior: &[f64]) -> Option<Belief> {
        if prior.iter().any(|&p| !(p.is_finite() && p >= 0.0)) {
            return None;
        }
        let log_w: Vec<f64> = prior.iter().map(|p| p.ln()).collect();
        let mut b = Belief { log_w };
        (b.normalise() == Update::Updated).then_some(b)
    }

    /// Number of hypotheses.
    pub fn len(&self) -> usize {
        self.log_w.len()
    }

    /// True without hypotheses (never for a belief built by [`Belief::new`]).
    pub fn is_empty(&self) -> bool {
        self.log_w.is_empty()
    }

    /// The posterior probabilities (they sum to 1).
    pub fn probabilities(&self) -> Vec<f64> {
        self.log_w.iter().map(|l| l.exp()).collect()
    }

    /// Probability of hypothesis `h`.
    pub fn probability(&self, h: usize) -> f64 {
        self.log_w[h].exp()
    }

    /// Shannon entropy in bits.
    pub fn entropy_bits(&self) -> f64 {
        self.entropy_bits_of(&self.probabilities())
    }

    /// The posterior probabilities and the entropy in bits, one exponential per hypothesis for
    /// both: [`Belief::probabilities`] and [`Belief::entropy_bits`], bit for bit.
    pub fn probabilities_and_entropy(&self) -> (Vec<f64>, f64) {
        let p = self.probabilities();
        let h = self.entropy_bits_of(&p);
        (p, h)
    }

    /// The entropy in bits from the probabilities `p` (= exp of the log weights).
    fn entropy_bits_of(&self, p: &[f64]) -> f64 {
        -self
            .log_w
            .iter()
            .zip(p)
            .filter(|(l, _)| l.is_finite())
            .map(|(&l, &p)| p * l)
            .sum::<f64>()
            / std::f64::consts::LN_2
    }

    /// Σ_h p(h) · value(h): the expectation of a per-hypothesis quantity.
    pub fn expect(&self, values: &[f64]) -> f64 {
        debug_assert_eq!(values.len(), self.log_w.len());
        self.log_w
            .iter()
            .zip(values)
            .filter(|(l, _)| l.is_finite())
            .map(|(l, v)| l.exp() * v)
            .sum()
    }

    /// The marginal over a grouping of the hypotheses: `group[h]` < `groups`.
    pub fn marginal(&self, group: &[usize], groups: usize) -> Vec<f64> {
        Belief::marginal_of(&self.probabilities(), group, groups)
    }

    /// [`Belief::marginal`] from the probabilities `p` ([`Belief::probabilities`]).
    pub fn marginal_of(p: &[f64], group: &[usize], groups: usize) -> Vec<f64> {
        let mut m = vec![0.0; groups];
        for (p, &g) in p.iter().zip(group) {
            m[g] += p;
        }
        m
    }

    /// Multiply by a likelihood given in log space (`-∞` excludes a hypothesis); a NaN counts as
    /// −∞. Bayes' rule for one observation.
    pub fn observe_log_likelihood(&mut self, log_lik: &[f64]) -> Update {
        debug_assert_eq!(log_lik.len(), self.log_w.len());
        let before = self.log_w.clone();
        for (w, &l) in self.log_w.iter_mut().zip(log_lik) {
            *w += if l.is_nan() { f64::NEG_INFINITY } else { l };
        }
        let u = self.normalise();
        if u == Update::Inconsistent {
            self.log_w = before;
        }
        u
    }

    /// A pass of the sensor without contact: multiply by 1 − p_touch(h) (`p_touch` in [0, 1]).
    pub fn observe_no_contact(&mut self, p_touch: &[f64]) -> Update {
        let ll: Vec<f64> = p_touch.iter().map(|p| (1.0 - p).max(0.0).ln()).collect();
        self.observe_log_likelihood(&ll)
    }

    /// A reading by a sensor that touched: multiply by p_touch(h) · p(reading | h, touch), the
    /// latter given in log space (`None`: the reading carries no usable signal, only the touch).
    pub fn observe_reading(&mut self, p_touch: &[f64], log_lik: Option<&[f64]>) -> Update {
        let ll: Vec<f64> = p_touch
            .iter()
            .enumerate()
            .map(|(h, p)| p.ln() + log_lik.map_or(0.0, |l| l[h]))
            .collect();
        self.observe_log_likelihood(&ll)
    }

    /// Renormalise so that Σ exp(log_w) = 1 (log-sum-exp); Inconsistent when nothing is left.
    fn normalise(&mut self) -> Update {
        let max = self.log_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !max.is_finite() {
            return Update::Inconsistent;
        }
        let s: f64 = self.log_w.iter().map(|l| (l - max).exp()).sum();
        let z = max + s.ln();
        for l in &mut self.log_w {
            *l -= z;
        }
        Update::Updated
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prior_normalises_and_refuses_nonsense() {
        let b = Belief::new(&[1.0, 3.0]).unwrap();
        assert!((b.probability(1) - 0.75).abs() < 1e-15);
        assert!(Belief::new(&[0.0, 0.0]).is_none());
        assert!(Belief::new(&[1.0, -1.0]).is_none());
        assert!(Belief::new(&[1.0, f64::NAN]).is_none());
    }

    #[test]
    fn inconsistent_observation_leaves_belief_unchanged() {
        let mut b = Belief::new(&[1.0, 1.0]).unwrap();
        let before = b.clone();
        assert_eq!(b.observe_no_contact(&[1.0, 1.0]), Update::Inconsistent);
        assert_eq!(b, before);
    }

    /// The probabilities, entropy and marginal from one set of exponentials are those computed
    /// apart, bit for bit, with removed hypotheses among them.
    #[test]
    fn probabilities_and_entropy_at_once_are_those_apart() {
        let mut b = Belief::new(&[0.1, 0.0, 2.0, 0.7, 1e-200, 3.0]).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for ll in [[0.0; 6], [-3.0, 0.0, -900.0, 1.5, 2.0, -0.25]] {
            b.observe_log_likelihood(&ll);
            let (p, h) = b.probabilities_and_entropy();
            assert_eq!(bits(&p), bits(&b.probabilities()));
            assert_eq!(h.to_bits(), b.entropy_bits().to_bits());
            let group = [0, 1, 0, 2, 1, 2];
            let m = Belief::marginal_of(&p, &group, 3);
            assert_eq!(bits(&m), bits(&b.marginal(&group, 3)));
        }
    }

    #[test]
    fn entropy_of_uniform_is_log2_n() {
        let b = Belief::new(&[1.0; 8]).unwrap();
        assert!((b.entropy_bits() - 3.0).abs() < 1e-12);
        let one = Belief::new(&[0.0, 1.0, 0.0]).unwrap();
        assert_eq!(one.entropy_bits(), 0.0);
    }
}
