//! The planner's inputs ([`Problem`]), their defaults (the quickstart line's belt, feed and pins)
//! and their checks. Lengths are metres, angles degrees (SPEC §1).

use super::PlanError;
use crate::geometry::cad::PartFileOptions;
use crate::geometry::{part_from_spec_with, Polygon};

/// How the parts arrive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedKind {
    /// In one of the part's stable states (equal weights), with normal jitter.
    Stable,
    /// At any orientation (uniform on the circle).
    Uniform,
}

impl FeedKind {
    /// `stable` or `uniform`.
    pub fn from_name(s: &str) -> Option<FeedKind> {
        match s.trim() {
            "stable" => Some(FeedKind::Stable),
            "uniform" => Some(FeedKind::Uniform),
            _ => None,
        }
    }
}

/// An uncertain-μc range that is not `LO:HI` with two numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeSpecError {
    /// The range is not two values separated by `:`.
    #[error("'{0}': expected LO:HI, e.g. 0.3:0.7")]
    Form(String),
    /// A bound of the range is not a number.
    #[error("'{spec}': '{token}' is not a number")]
    Number {
        /// The range as given.
        spec: String,
        /// The bound that is not a number.
        token: String,
    },
}

/// Parse an uncertain μc range `LO:HI` (its bounds are checked with the problem).
pub fn parse_mu_c_range(s: &str) -> Result<(f64, f64), RangeSpecError> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| RangeSpecError::Form(s.to_string()))?;
    let p = |t: &str| {
        t.trim().parse::<f64>().map_err(|_| RangeSpecError::Number {
            spec: s.to_string(),
            token: t.to_string(),
        })
    };
    Ok((p(a)?, p(b)?))
}

/// Everything the sensorless planner needs. [`Problem::new`] gives the defaults.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Problem {
    /// Part specification (`tripoly2`, `rect:2:1`, `vertices:...`).
    pub part: String,
    /// Metres per unit of the part's coordinates.
    pub scale: f64,
    /// How a part file (`part` = `FILE.dxf` or `FILE.csv`) is read: its flattening tolerance
    /// and its unit when the file does not state it (left out of the JSON when the defaults).
    #[serde(skip_serializing_if = "PartFileOptions::is_default")]
    pub part_file: PartFileOptions,
    /// How parts arrive: in their stable states, or uniformly oriented.
    pub feed: FeedKind,
    /// Standard deviation of the orientation jitter of a stable feed (degrees).
    pub jitter_deg: f64,
    /// Half-width of the uniform lateral offset range at entry (m): y ∈ [−lateral, lateral].
    pub lateral_m: f64,
    /// Particles per stable state: `jitter_samples` orientations × `offset_samples` offsets.
    pub jitter_samples: usize,
    /// Lateral offsets per orientation (stratified over ±`lateral_m`).
    pub offset_samples: usize,
    /// Orientations of a uniform feed (each with `offset_samples` offsets).
    pub orientation_samples: usize,
    /// Pin–part friction (the nominal value; see `mu_c_range`).
    pub mu_c: f64,
    /// Robustness: each particle carries its own μc drawn uniformly from [lo, hi].
    pub mu_c_range: Option<(f64, f64)>,
    /// Robust against the fences' μf: each particle draws its own fence μf uniformly in this
    /// range (None: the fence planner's own μf).
    pub mu_f_range: Option<(f64, f64)>,
    /// Robust against the fences' angle error (degrees, added to every fence's angle): the
    /// particles plan against its ends and middle (None: fences at their angles).
    pub fence_angle_range: Option<(f64, f64)>,
    /// Robustness: each particle carries its own random tripod support.
    pub tripod: bool,
    /// Pin radius (m; 0 = point pin).
    pub pin_radius_m: f64,
    /// Belt width (m): pins and parts' centroids stay within ±width/2.
    pub belt_width_m: f64,
    /// Distance between consecutive pins along the belt (m).
    pub spacing_m: f64,
    /// Most pins (search depth).
    pub max_pins: usize,
    /// Goal: half-width of the orientation window (degrees).
    pub tolerance_deg: f64,
    /// Goal: share of the parts inside the window.
    pub target: f64,
    /// Minimise the number of orientation sets instead of requiring one.
    pub fewest_sets: bool,
    /// Goal: the exit orientation the next station needs (degrees, taken modulo the part's
    /// symmetry): the window is centred there. None: the planner chooses the window.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal_deg: Option<f64>,
    /// Smallest robustness margin of an action (m).
    pub min_margin_m: f64,
    /// Lateral quantum of particles and of the pin grid (m).
    pub y_quantum_m: f64,
    /// Orientation quantum of particles (degrees); must divide 360.
    pub theta_quantum_deg: f64,
    /// The per-orientation outcome over the pin grid is sampled every `coarse` grid steps and
    /// bisected where the qualitative outcome changes (1 = every step).
    pub coarse: usize,
    /// Branch and bound ([`super::bound`]): do not expand states that cannot beat the best
    /// effort within the pins left. Off, every state is expanded (same outcome, more work).
    pub bound: bool,
    /// Search limit: most distinct states kept.
    pub max_states: usize,
    /// Wall-time limit of the search (s).
    pub time_limit_s: f64,
    /// Integration tolerance of the contact model while planning.
    pub contact_tol: f64,
    /// Seed of the planner's random draws (feed particles, physics samples) and of the emitted scenario; the same seed gives the same plan.
    pub seed: u64,
    /// Extra feed particles (θ degrees, y metres) after the stratified ones: parts the line
    /// check found failing, added where the abstraction missed them (see [`super::design`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub extra_samples: Vec<(f64, f64)>,
    /// No contact pass is computed past this instant (the whole command's time limit); the
    /// search then ends with its time limit.
    #[serde(skip)]
    pub deadline: Option<std::time::Instant>,
}

impl Problem {
    /// The defaults for a part (the quickstart line: 2 cm per unit, 10 cm belt, pins 15 cm apart).
    pub fn new(part: &str) -> Problem {
        Problem {
            part: part.to_string(),
            scale: 0.02,
            part_file: PartFileOptions::default(),
            feed: FeedKind::Stable,
            jitter_deg: 2.0,
            lateral_m: 0.002,
            jitter_samples: 5,
            offset_samples: 5,
            orientation_samples: 72,
            mu_c: 0.5,
            mu_c_range: None,
            mu_f_range: None,
            fence_angle_range: None,
            tripod: false,
            pin_radius_m: 0.002,
            belt_width_m: 0.1,
            spacing_m: 0.15,
            max_pins: 8,
            tolerance_deg: 3.0,
            target: 0.99,
            fewest_sets: false,
            goal_deg: None,
            min_margin_m: 0.0005,
            y_quantum_m: 0.00025,
            theta_quantum_deg: 0.25,
            coarse: 4,
            bound: true,
            max_states: 1_000_000,
            time_limit_s: 600.0,
            contact_tol: 1e-5,
            seed: 1,
            extra_samples: Vec::new(),
            deadline: None,
        }
    }

    /// Set the pin radius from a length in part units (the unit of the part's vertices, as every
    /// command takes it): metres = `r` × [`Problem::scale`], so set the scale first. A radius
    /// that is negative, not finite or larger than the part (its a, in part units) is refused;
    /// a part that cannot be built is left to [`Problem::compile`].
    pub fn set_pin_radius_units(&mut self, r: f64) -> Result<(), PlanError> {
        let a = part_from_spec_with(&self.part, &self.part_file)
            .map(|p| p.radius())
            .ok();
        if !(r.is_finite() && r >= 0.0 && a.is_none_or(|a| r <= a)) {
            let bound = a.map_or(String::new(), |a| format!(", a = {a:.6}"));
            return Err(PlanError::input(
                "pin_radius",
                r,
                format!(
                    "must lie in [0, a] part units (a: the part's largest centroid–vertex \
                     distance{bound}; metres = part units × scale)"
                ),
            ));
        }
        self.pin_radius_m = r * self.scale;
        Ok(())
    }

    /// Check every value and build the part in metres. Errors name the field.
    pub fn compile(&self) -> Result<Compiled, PlanError> {
        check_finite_pos("scale", self.scale)?;
        let unit =
            part_from_spec_with(&self.part, &self.part_file).map_err(|err| PlanError::Part {
                part: self.part.clone(),
                reason: err.to_string(),
            })?;
        let polygon = unit.try_scaled(self.scale).map_err(|err| PlanError::Part {
            part: self.part.clone(),
            reason: err.to_string(),
        })?;
        let a = polygon.radius();
        if !(1e-4..=1.0).contains(&a) {
            return Err(PlanError::input(
                "scale",
                self.scale,
                format!("gives a part of size a = {a} m; it must lie in [0.1 mm, 1 m]"),
            ));
        }
        self.check_feed()?;
        self.check_line(a)?;
        self.check_goal_and_search(a)?;
        let q = self.theta_quantum_deg;
        let n = (360.0 / q).round();
        // Rotational symmetry of the outline: orientations a symmetry apart are the same part
        // pose for the next station, whatever the support. A tripod is fixed in the part frame,
        // but random tripods are drawn uniformly inside the outline
        // ([`crate::mechanics::Support::random_tripod`]), a distribution with the outline's
        // symmetry: a particle whose orientation is taken modulo the period carries a tripod
        // that is as likely turned by the period as not, so the particles stay a sample of the
        // same physics (the verdict comes from the line, which keeps each part's own tripod).
        let mut symmetry = rotational_symmetry(&polygon);
        let mut period_steps = 360.0 / symmetry as f64 / q;
        if (period_steps - period_steps.round()).abs() > 1e-9 {
            symmetry = 1;
            period_steps = n;
        }
        let stable: Vec<f64> = unit
            .stable_states()
            .iter()
            .map(|s| s.theta_rad.to_degrees())
            .collect();
        if self.feed == FeedKind::Stable && stable.is_empty() {
            return Err(PlanError::input(
                "feed",
                "stable",
                "the part has no stable state",
            ));
        }
        Ok(Compiled {
            polygon,
            radius: a,
            stable_deg: stable,
            theta_steps: period_steps.round() as i32,
            symmetry,
        })
    }

    /// Check the feed's settings and the friction: jitter, lateral offset, particle counts, μc
    /// and its range.
    fn check_feed(&self) -> Result<(), PlanError> {
        if !(self.jitter_deg.is_finite() && (0.0..=45.0).contains(&self.jitter_deg)) {
            return Err(PlanError::input(
                "jitter",
                self.jitter_deg,
                "must lie in [0, 45] degrees",
            ));
        }
        if !(self.lateral_m.is_finite() && self.lateral_m >= 0.0) {
            return Err(PlanError::input(
                "lateral",
                self.lateral_m,
                "must be a finite length ≥ 0 (m)",
            ));
        }
        for (field, n) in [
            ("jitter_samples", self.jitter_samples),
            ("offset_samples", self.offset_samples),
            ("orientation_samples", self.orientation_samples),
        ] {
            if !(1..=2000).contains(&n) {
                return Err(PlanError::input(field, n, "must lie in 1..=2000"));
            }
        }
        let (mu_lo, mu_hi) = crate::mechanics::limits::MU_C;
        if !(self.mu_c.is_finite() && (mu_lo..=mu_hi).contains(&self.mu_c)) {
            let range = crate::scenario::limits::show((mu_lo, mu_hi));
            return Err(PlanError::input(
                "mu_c",
                self.mu_c,
                format!("must lie in {range}"),
            ));
        }
        for (field, range) in [
            ("mu_c_range", self.mu_c_range),
            ("mu_f_range", self.mu_f_range),
        ] {
            if let Some((lo, hi)) = range {
                if !(lo.is_finite() && hi.is_finite() && mu_lo <= lo && lo <= hi && hi <= mu_hi) {
                    return Err(PlanError::input(
                        field,
                        format!("{lo}:{hi}"),
                        format!("must be LO:HI with {mu_lo} ≤ LO ≤ HI ≤ {mu_hi}"),
                    ));
                }
            }
        }
        if let Some((lo, hi)) = self.fence_angle_range {
            if !(lo.is_finite() && hi.is_finite() && -10.0 <= lo && lo <= hi && hi <= 10.0) {
                return Err(PlanError::input(
                    "fence_angle_range",
                    format!("{lo}:{hi}"),
                    "must be LO:HI degrees with −10 ≤ LO ≤ HI ≤ 10 (an error in a fence's angle)",
                ));
            }
        }
        Ok(())
    }

    /// Is the problem robust against uncertain physics (a friction range at the pins or the
    /// fences, an error in the fences' angles, or tripods)? Then the particles carry physics
    /// samples ([`super::transition::Transition::new`]).
    pub fn is_robust(&self) -> bool {
        self.tripod
            || self.mu_c_range.is_some()
            || self.mu_f_range.is_some()
            || self.fence_angle_range.is_some()
    }

    /// Check the line's settings against the part's size `a` (m): pin radius, belt width (and
    /// the lateral offset on it), spacing and the most pins.
    fn check_line(&self, a: f64) -> Result<(), PlanError> {
        if !(self.pin_radius_m.is_finite() && self.pin_radius_m >= 0.0 && self.pin_radius_m <= a) {
            return Err(PlanError::input(
                "pin_radius",
                self.pin_radius_m,
                format!("must lie in [0, a = {a:.4} m] (m)"),
            ));
        }
        check_finite_pos("belt_width", self.belt_width_m)?;
        if self.belt_width_m > 10.0 {
            return Err(PlanError::input(
                "belt_width",
                self.belt_width_m,
                "must lie in (0, 10] m",
            ));
        }
        if let Some(mm) = crate::scenario::limits::mm_scale_fit(a, self.scale, self.belt_width_m)
            .filter(|_| self.belt_width_m < 2.0 * a)
        {
            return Err(PlanError::input(
                "scale",
                self.scale,
                format!(
                    "the part (2a = {:.4} m) is wider than the belt ({} m): vertices in mm? add --scale 0.001 (2a = {:.4} m)",
                    2.0 * a,
                    self.belt_width_m,
                    mm
                ),
            ));
        }
        if self.belt_width_m < 2.0 * a {
            return Err(PlanError::input(
                "belt_width",
                self.belt_width_m,
                format!(
                    "the belt is narrower than the part (2a = {:.4} m at scale {})",
                    2.0 * a,
                    self.scale
                ),
            ));
        }
        if self.lateral_m + a > self.belt_width_m / 2.0 {
            return Err(PlanError::input(
                "lateral",
                self.lateral_m,
                format!(
                    "parts at ±{} m would overhang the belt (half-width {} m, a = {a:.4} m)",
                    self.lateral_m,
                    self.belt_width_m / 2.0
                ),
            ));
        }
        check_finite_pos("spacing", self.spacing_m)?;
        if self.spacing_m > 10.0 {
            return Err(PlanError::input(
                "spacing",
                self.spacing_m,
                "must lie in [2.5a, 10] m",
            ));
        }
        if self.spacing_m < 2.5 * a {
            return Err(PlanError::input(
                "spacing",
                self.spacing_m,
                format!(
                    "pins closer than 2.5a = {:.4} m can touch a part at once",
                    2.5 * a
                ),
            ));
        }
        if self.max_pins == 0 {
            return Err(PlanError::input(
                "max_pins",
                0,
                "the plan must be allowed at least one pin",
            ));
        }
        if self.max_pins > 64 {
            return Err(PlanError::input(
                "max_pins",
                self.max_pins,
                "at most 64 pins",
            ));
        }
        Ok(())
    }

    /// Check the goal and the search settings (`a`: the part's size, m): tolerance, target,
    /// margin, quanta, coarse sampling, states, time limit and contact tolerance.
    fn check_goal_and_search(&self, a: f64) -> Result<(), PlanError> {
        if !(self.tolerance_deg.is_finite()
            && self.tolerance_deg > 0.0
            && self.tolerance_deg < 180.0)
        {
            return Err(PlanError::input(
                "tolerance",
                self.tolerance_deg,
                "the goal window would be empty: the tolerance must lie in (0, 180) degrees",
            ));
        }
        if !(self.target.is_finite() && self.target > 0.0 && self.target <= 1.0) {
            return Err(PlanError::input(
                "target",
                self.target,
                "must lie in (0, 1]",
            ));
        }
        if let Some(g) = self.goal_deg {
            if !(g.is_finite() && g.abs() <= 1e6) {
                return Err(PlanError::input(
                    "goal",
                    g,
                    "must be a finite angle in degrees (the part's exit orientation, modulo its symmetry)",
                ));
            }
            if self.fewest_sets {
                return Err(PlanError::input(
                    "goal",
                    g,
                    "a goal orientation asks for one window; fewest_sets asks for the fewest windows anywhere: choose one",
                ));
            }
        }
        if !(self.min_margin_m.is_finite() && self.min_margin_m >= 0.0 && self.min_margin_m < a) {
            return Err(PlanError::input(
                "min_margin",
                self.min_margin_m,
                format!("must lie in [0, a = {a:.4} m)"),
            ));
        }
        if !(self.y_quantum_m.is_finite()
            && self.y_quantum_m >= 1e-6
            && self.y_quantum_m <= a / 4.0)
        {
            return Err(PlanError::input(
                "y_quantum",
                self.y_quantum_m,
                format!("must lie in [1 µm, a/4 = {:.4} m]", a / 4.0),
            ));
        }
        let q = self.theta_quantum_deg;
        let n = (360.0 / q).round();
        if !(q.is_finite() && (0.01..=10.0).contains(&q)) || (n * q - 360.0).abs() > 1e-9 {
            return Err(PlanError::input(
                "theta_quantum",
                q,
                "must lie in [0.01, 10] degrees and divide 360",
            ));
        }
        if !(1..=64).contains(&self.coarse) {
            return Err(PlanError::input(
                "coarse",
                self.coarse,
                "must lie in 1..=64",
            ));
        }
        if self.max_states == 0 {
            return Err(PlanError::input("max_states", 0, "must be at least 1"));
        }
        if !(self.time_limit_s.is_finite() && self.time_limit_s > 0.0) {
            return Err(PlanError::input(
                "time_limit",
                self.time_limit_s,
                "must be a positive number of seconds",
            ));
        }
        let tol = crate::mechanics::limits::TOL;
        if !crate::scenario::limits::contains(tol, self.contact_tol) {
            let range = crate::scenario::limits::show(tol);
            return Err(PlanError::input(
                "contact_tol",
                self.contact_tol,
                format!("must lie in {range}"),
            ));
        }
        Ok(())
    }
}

/// A checked problem's derived data.
#[derive(Debug, Clone)]
pub struct Compiled {
    /// The part in metres, part frame (centroid at the origin).
    pub polygon: Polygon,
    /// `a` (m).
    pub radius: f64,
    /// Stable states (degrees), as `pinfeed part` lists them.
    pub stable_deg: Vec<f64>,
    /// Orientation quanta per symmetry period (360 / symmetry / theta_quantum_deg): particle
    /// orientations are kept modulo the period.
    pub theta_steps: i32,
    /// Order of the outline's rotational symmetry (1: none; 4 for a square, with tripod supports
    /// too; forced to 1 when the period is not a whole number of quanta).
    pub symmetry: u32,
}

impl Compiled {
    /// The symmetry period (degrees).
    pub fn period_deg(&self) -> f64 {
        360.0 / self.symmetry as f64
    }
}

/// How close (units of a) a turned vertex must come to a vertex for [`rotational_symmetry`]: a
/// part drawn to 4 decimals of a millimetre is as symmetric as its drawing (a regular hexagon of
/// 20 mm written to 0.1 µm is 8 µm, 4·10⁻⁶ a, off exact), and no push tells 10⁻⁴ a apart.
pub const SYMMETRY_TOL_A: f64 = 1e-4;

/// The order k of the polygon's rotational symmetry about its centroid: the largest k ≥ 1 such
/// that a rotation by 360°/k maps every vertex onto a vertex (to [`SYMMETRY_TOL_A`]·a).
pub fn rotational_symmetry(poly: &Polygon) -> u32 {
    let v = poly.vertices();
    let n = v.len();
    let eps = SYMMETRY_TOL_A * poly.radius();
    for k in (2..=n).rev() {
        if n % k != 0 {
            continue;
        }
        let (s, c) = crate::geometry::sin_cos(std::f64::consts::TAU / k as f64);
        let all = v.iter().all(|p| {
            let r = crate::geometry::Vec2::new(c * p.x - s * p.y, s * p.x + c * p.y);
            v.iter().any(|q| (*q - r).norm() < eps)
        });
        if all {
            return k as u32;
        }
    }
    1
}

/// Check that `v` (the setting `field`) is a positive finite number.
fn check_finite_pos(field: &'static str, v: f64) -> Result<(), PlanError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(PlanError::input(
            field,
            v,
            "must be a positive finite number",
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_compile_and_bad_values_name_their_flag() {
        let p = Problem::new("tripoly2");
        let c = p.compile().unwrap();
        assert_eq!(c.stable_deg.len(), 3);
        assert_eq!(c.theta_steps, 1440);
        assert_eq!(c.symmetry, 1);
        let sym = |part: &str| Problem::new(part).compile().unwrap().symmetry;
        assert_eq!(sym("square"), 4);
        assert_eq!(sym("rect:2:1"), 2);
        assert_eq!(sym("lshape"), 1);
        assert_eq!(sym("ngon:6"), 6);
        // A hexagon drawn to 4 decimals of a millimetre is a hexagon; one vertex 0.01 mm off
        // (5·10⁻⁴ a) is not.
        let hexagon = |nudge: f64| {
            let v: Vec<String> = (0..6)
                .map(|k| {
                    let t = (60.0 * k as f64).to_radians();
                    let x = 20.0 * t.cos() + if k == 2 { nudge } else { 0.0 };
                    format!("{x:.4},{:.4}", 20.0 * t.sin())
                })
                .collect();
            let mut p = Problem::new(&format!("vertices:{}", v.join(" ")));
            p.scale = 0.001;
            p.compile().unwrap().symmetry
        };
        assert_eq!(hexagon(0.0), 6);
        assert_eq!(hexagon(0.01), 1);
        let bad = |f: &dyn Fn(&mut Problem), flag: &str| {
            let mut q = Problem::new("tripoly2");
            f(&mut q);
            let msg = q.compile().unwrap_err().to_string();
            assert!(msg.starts_with(flag), "{msg}");
        };
        bad(&|q| q.belt_width_m = 0.03, "belt_width");
        bad(&|q| q.tolerance_deg = 0.0, "tolerance");
        bad(&|q| q.max_pins = 0, "max_pins");
        bad(&|q| q.mu_c = f64::NAN, "mu_c");
        bad(&|q| q.theta_quantum_deg = 0.7, "theta_quantum");
        bad(&|q| q.mu_c_range = Some((0.7, 0.3)), "mu_c_range");
        bad(&|q| q.part = "blob".into(), "part");
    }
}
