//! How far the physics may drift before a design fails: its **margins**, measured on the line.
//!
//! A design is confirmed at the friction and positions it was planned for; a real floor's friction
//! is known to ±0.1 at best and pins stand a fraction of a millimetre off the drawing. Two sweeps
//! of Monte Carlo runs (each sample one part through the line, as `pinfeed mc` runs a study built
//! in code, [`crate::study::mc::Study::of_scene`]) say how far each may go:
//!
//! * **friction**: the pins' μc and the fences' μf shifted together by δ = ±0.05, ±0.10, … (up
//!   to ±[`MU_REACH`]), stepping out from the nominal on each side until a step fails; the
//!   interval is the steps that held on both sides of the nominal;
//! * **placement**: every pin's and fence's position off by a uniform error in ±e (each
//!   coordinate, drawn per obstacle and part) and every fence's angle by ±e degrees, for e in
//!   [`PLACEMENT_MM`], until a step fails; the margin is the largest e that held.
//!
//! A step runs its parts in blocks ([`FIRST_BLOCK`] parts, then as many again as it has run, up to
//! its cap) and stops as soon as its 95% Wilson interval lies wholly on one side of the design's
//! target: it *holds* when the interval lies at or above it, fails when the interval lies below;
//! at the cap it holds when its success rate is at least the target — the verdict's own rule. A
//! step far from the target is decided by its first block (500 parts without a failure hold a
//! target of 0.99), one near it runs every part of the cap. Whatever the design was planned
//! against (random tripods, a μc range) stays in every step; a friction step fixes μ to its
//! value.

use crate::mechanics::support::SupportChoice;
use crate::random::distribution::Distribution;
use crate::scenario::raw::SupportKind;
use crate::scenario::{Obstacle, Scene};
use crate::statistics::wilson_interval;
use crate::study::mc::{Perturbations, StudyError};
use serde::Serialize;
use std::time::Instant;

/// The friction steps (δ added to the nominal μ).
pub const MU_STEP: f64 = 0.05;
/// How far the friction sweep reaches on each side of the nominal.
pub const MU_REACH: f64 = 0.3;
/// The placement errors tried (± mm on positions; the same number in degrees on fence angles).
pub const PLACEMENT_MM: [f64; 4] = [0.25, 0.5, 1.0, 2.0];
/// The parts of a step's first block.
pub const FIRST_BLOCK: u64 = 500;

/// The seed of a step's block `k`: the design's seed for the first, then a stream of their own.
fn block_seed(seed: u64, k: u64) -> u64 {
    use rand::Rng;
    if k == 0 {
        seed
    } else {
        crate::random::substream(seed, 0x6d61_7267, k).next_u64()
    }
}

/// Is a step of `success` of `n` parts decided against `target` with `cap` parts at most:
/// Some(holds) once the 95% Wilson interval lies wholly on one side of the target or the cap is
/// reached (then: the rate at least the target), None while more parts are to be run.
pub fn step_decided(success: u64, n: u64, target: f64, cap: u64) -> Option<bool> {
    let [lo, hi] = wilson_interval(success, n);
    if n >= cap {
        Some(success as f64 >= target * n as f64)
    } else if lo >= target {
        Some(true)
    } else if hi < target {
        Some(false)
    } else {
        None
    }
}

/// One step of a sweep: the line under one shift of its physics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Step {
    /// The step: μ of the pins (friction), or ±mm and ±degrees (placement).
    pub at: f64,
    /// Parts run (one per sample).
    pub samples: u64,
    /// Parts that ended in success.
    pub success: u64,
    /// `success` / `samples`.
    pub success_rate: f64,
    /// 95% Wilson interval of the success rate.
    pub ci95: [f64; 2],
    /// Did it hold the target?
    pub holds: bool,
}

/// A design's margins: the friction interval and the placement error over which it holds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Margins {
    /// The target each step is held to.
    pub target: f64,
    /// The pins' nominal μc (the fences' μf moves with it by the same δ).
    pub mu_nominal: f64,
    /// The fences' nominal μf, if the line has fences.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu_f_nominal: Option<f64>,
    /// The pins' μ over which every step held: from the lowest to the highest step that held
    /// without a failing step between them and the nominal. None when the nominal itself fails.
    pub mu_holds: Option<[f64; 2]>,
    /// Did the sweep end on each side (low, high) still holding — at the end of its reach, the
    /// edge of the valid range or the time limit — so that the margin may be wider?
    pub mu_open: [bool; 2],
    /// The friction steps, in increasing μ.
    pub friction: Vec<Step>,
    /// The largest placement error (± mm, ± degrees) at which the line held, if any.
    pub placement_mm: Option<f64>,
    /// The placement steps, in increasing error.
    pub placement: Vec<Step>,
    /// The time limit stopped the sweeps before they ended: what is reported is what was run.
    pub cut_short: bool,
}

impl Margins {
    /// The parts its steps ran: "500" or "500–2000".
    pub fn parts_per_step(&self) -> String {
        let n = self
            .friction
            .iter()
            .chain(&self.placement)
            .map(|s| s.samples);
        match (n.clone().min(), n.max()) {
            (Some(lo), Some(hi)) if lo < hi => format!("{lo}–{hi}"),
            (Some(lo), _) => lo.to_string(),
            _ => "0".into(),
        }
    }

    /// "holds for μ 0.45–0.60 (pins; fences μf 0.45–0.60) and placement ±0.5 mm / ±0.5°".
    pub fn describe(&self) -> String {
        let mu = match self.mu_holds {
            None => "fails at its nominal friction".to_string(),
            Some([lo, hi]) => {
                let fences = self.mu_f_nominal.map_or(String::new(), |f| {
                    let d = f - self.mu_nominal;
                    format!(" (fences' μf {:.2}–{:.2})", lo + d, hi + d)
                });
                let beyond = match self.mu_open {
                    [true, true] => ", or wider: the sweep ended on both sides still holding",
                    [true, false] => ", or lower: the sweep ended below it still holding",
                    [false, true] => ", or higher: the sweep ended above it still holding",
                    [false, false] => "",
                };
                if lo == hi {
                    // No step off the nominal held: say of each side whether a step there
                    // failed or none was run (the time limit, or the edge of the valid range).
                    let at = format!("at its nominal friction μ {lo:.2}{fences}");
                    match self.mu_open {
                        [false, false] => format!("holds only {at} (fails ±{MU_STEP} off it)"),
                        [true, true] => format!("holds {at}; the sweep ran no step off it"),
                        [true, false] => format!(
                            "holds {at}, fails +{MU_STEP} off it; the sweep ran no step below"
                        ),
                        [false, true] => format!(
                            "holds {at}, fails −{MU_STEP} off it; the sweep ran no step above"
                        ),
                    }
                } else {
                    format!("holds for friction μ {lo:.2}–{hi:.2}{fences}{beyond}")
                }
            }
        };
        let place = match self.placement_mm {
            Some(e) => format!("placement errors up to ±{e} mm / ±{e}°"),
            None if self.placement.is_empty() => "placement not measured".into(),
            None => format!(
                "fails at a placement error of ±{} mm / ±{}°",
                PLACEMENT_MM[0], PLACEMENT_MM[0]
            ),
        };
        let cut = if self.cut_short {
            " (the time limit cut the sweeps short)"
        } else {
            ""
        };
        format!("{mu}; {place}{cut}")
    }
}

/// Measure the margins of `scene` against `target`: `samples` parts per step with `seed`, under
/// `base` (the uncertainty the design was planned against, or none), stopping at `deadline`.
pub fn measure(
    scene: &Scene,
    base: Option<&Perturbations>,
    target: f64,
    seed: u64,
    samples: u64,
    deadline: Instant,
) -> Result<Margins, StudyError> {
    let (mut pins, mut fences) = (false, None);
    for o in &scene.obstacles {
        match o {
            Obstacle::Pin(_) => pins = true,
            Obstacle::Fence(f) => fences = fences.or(Some(f.mu_f)),
        }
    }
    // Without a planned uncertainty: the scenario's own support, as a study without
    // `[uncertain.support]` keeps it.
    let base = base.cloned().unwrap_or_else(|| {
        Perturbations::none(match scene.part.support {
            SupportKind::Tripod => SupportChoice::Tripod,
            SupportKind::Uniform => SupportChoice::Uniform,
        })
    });
    let mu0 = scene.part.mu_c;
    let run = |p: Perturbations, at: f64| -> Result<Step, StudyError> {
        // Blocks of parts, each from a stream of its own, until the step is decided.
        let (mut success, mut n, mut block) = (0u64, 0u64, 0u64);
        let holds = loop {
            let more = (if n == 0 { FIRST_BLOCK } else { n })
                .min(samples - n)
                .max(1);
            let (counts, m) =
                super::check::check_uncertain(scene, p.clone(), block_seed(seed, block), more)?;
            success += counts.success;
            n += m;
            block += 1;
            if let Some(h) = step_decided(success, n, target, samples.max(1)) {
                break h;
            }
        };
        Ok(Step {
            at,
            samples: n,
            success,
            success_rate: success as f64 / n.max(1) as f64,
            ci95: wilson_interval(success, n),
            holds,
        })
    };
    let mut cut_short = false;
    // Friction: the nominal, then outwards on each side until a step fails.
    let shifted = |d: f64| {
        let mut p = base.clone();
        if pins {
            p.mu_c = Some(Distribution::Fixed(mu0 + d));
        }
        if let Some(f) = fences {
            p.fence_mu_f = Some(Distribution::Fixed(f + d));
        }
        p
    };
    let valid = |d: f64| {
        let (lo, hi) = crate::mechanics::limits::MU_C;
        let ok = |m: f64| m > lo && m <= hi;
        ok(mu0 + d) && fences.is_none_or(|f| ok(f + d))
    };
    let nominal = run(shifted(0.0), mu0)?;
    let mut friction = vec![nominal.clone()];
    let mut open = [false, false];
    if nominal.holds {
        for (side, sign) in [(0, -1.0), (1, 1.0)] {
            let mut k = 1;
            loop {
                let d = sign * MU_STEP * k as f64;
                if d.abs() > MU_REACH + 1e-9 || !valid(d) {
                    open[side] = true;
                    break;
                }
                if Instant::now() >= deadline {
                    open[side] = true;
                    cut_short = true;
                    break;
                }
                let s = run(shifted(d), mu0 + d)?;
                let held = s.holds;
                friction.push(s);
                if !held {
                    break;
                }
                k += 1;
            }
        }
    }
    friction.sort_by(|a, b| a.at.total_cmp(&b.at));
    let mu_holds = nominal.holds.then(|| {
        // The contiguous run of held steps around the nominal.
        let i0 = friction.iter().position(|s| s.at == mu0).unwrap_or(0);
        let mut lo = i0;
        while lo > 0 && friction[lo - 1].holds {
            lo -= 1;
        }
        let mut hi = i0;
        while hi + 1 < friction.len() && friction[hi + 1].holds {
            hi += 1;
        }
        [friction[lo].at, friction[hi].at]
    });
    // Placement: growing errors until one fails.
    let mut placement = Vec::new();
    let mut placement_mm = None;
    for e in PLACEMENT_MM {
        if Instant::now() >= deadline {
            cut_short = true;
            break;
        }
        let mut p = base.clone();
        let m = e * 1e-3;
        let u = |w: f64| Some(Distribution::Uniform { min: -w, max: w });
        if pins {
            p.pin_x = u(m);
            p.pin_y = u(m);
        }
        if fences.is_some() {
            p.fence_x = u(m);
            p.fence_y = u(m);
            p.fence_angle = u(e);
        }
        let s = run(p, e)?;
        let held = s.holds;
        placement.push(s);
        if !held {
            break;
        }
        placement_mm = Some(e);
    }
    Ok(Margins {
        target,
        mu_nominal: mu0,
        mu_f_nominal: fences,
        mu_holds,
        mu_open: open,
        friction,
        placement_mm,
        placement,
        cut_short,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step stops as soon as its interval lies on one side of the target, and at its cap
    /// goes by the rate: 500 parts without a failure hold 0.99 (Wilson's lower end 0.9924), 495
    /// of 500 do not decide it, 480 of 500 fail it; at the cap, 1980 of 2000 hold 0.99 and 1979
    /// do not.
    #[test]
    fn a_step_is_decided_once_its_interval_clears_the_target() {
        assert_eq!(step_decided(500, 500, 0.99, 2000), Some(true));
        assert_eq!(step_decided(499, 500, 0.99, 2000), None);
        assert_eq!(step_decided(495, 500, 0.99, 2000), None);
        assert_eq!(step_decided(480, 500, 0.99, 2000), Some(false));
        assert_eq!(step_decided(1980, 2000, 0.99, 2000), Some(true));
        assert_eq!(step_decided(1979, 2000, 0.99, 2000), Some(false));
        // The interval's ends decide, not the rate: 998 of 1000 (rate above 0.99) is not yet a
        // hold at 0.995 (lower end 0.9928).
        assert_eq!(step_decided(998, 1000, 0.995, 2000), None);
        assert_eq!(step_decided(0, 1, 0.5, 1), Some(false));
    }

    /// The margins say where the sweep ended: at a failing step (a closed end), or still holding
    /// at its reach (an open end, "or lower"/"or higher"), never that it "stopped holding".
    #[test]
    fn the_margins_say_which_end_of_the_friction_sweep_still_held() {
        let m = |open: [bool; 2]| Margins {
            target: 0.99,
            mu_nominal: 0.5,
            mu_f_nominal: None,
            mu_holds: Some([0.2, 0.55]),
            mu_open: open,
            friction: Vec::new(),
            placement_mm: Some(0.5),
            placement: Vec::new(),
            cut_short: false,
        };
        assert_eq!(
            m([true, false]).describe(),
            "holds for friction μ 0.20–0.55, or lower: the sweep ended below it still holding; placement errors up to ±0.5 mm / ±0.5°"
        );
        assert!(m([false, true])
            .describe()
            .contains("or higher: the sweep ended above it"));
        assert!(m([true, true]).describe().contains("or wider"));
        assert!(!m([false, false]).describe().contains(", or"));
        // Held at the nominal alone: a side on which no step ran is not said to fail.
        let only = |open: [bool; 2]| {
            let mut x = m(open);
            x.mu_holds = Some([0.5, 0.5]);
            x.describe()
        };
        assert!(only([false, false]).contains("(fails ±0.05 off it)"));
        let none = only([true, true]);
        assert!(
            none.contains("the sweep ran no step off it") && !none.contains("fails"),
            "{none}"
        );
        assert!(only([true, false]).contains("fails +0.05 off it; the sweep ran no step below"));
        assert!(only([false, true]).contains("fails −0.05 off it; the sweep ran no step above"));
    }
}
