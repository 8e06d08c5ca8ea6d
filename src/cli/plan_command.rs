//! The command line recorded in a design's files: `pinfeed plan` with the part and every setting
//! given that differs from its default (the output options are not part of it).

use super::plan::PlanArgs;
use crate::plan::Problem;
use crate::report::shell_word;
use std::fmt::Display;

/// The command line that reproduces a design: the part and every setting given (the output
/// options are not part of it).
pub fn command_line(args: &PlanArgs) -> String {
    let mut w = vec!["pinfeed plan --part".to_string(), shell_word(&args.part)];
    let d = Problem::new(&args.part);
    let a = args;
    let mut opt = |flag: &str, v: &dyn Display, default: &dyn Display| {
        let v = v.to_string();
        if v != default.to_string() {
            w.push(format!("{flag} {}", shell_word(&v)));
        }
    };
    opt("--scale", &a.scale, &d.scale);
    opt("--objective", &a.objective, &"belt-length");
    opt("--feed", &a.feed, &"stable");
    opt("--jitter", &a.jitter, &d.jitter_deg);
    opt("--lateral", &a.lateral, &d.lateral_m);
    opt("--jitter-samples", &a.jitter_samples, &"5");
    opt("--offset-samples", &a.offset_samples, &"5");
    opt("--orientation-samples", &a.orientation_samples, &"72");
    opt("--mu-c", &a.mu_c, &d.mu_c);
    opt(
        "--mu-c-range",
        &a.mu_c_range.clone().unwrap_or_default(),
        &"",
    );
    opt(
        "--pin-radius",
        &a.pin_radius.map_or(String::new(), |r| r.to_string()),
        &"",
    );
    opt(
        "--belt-width",
        &a.belt_width.map_or(String::new(), |b| b.to_string()),
        &"",
    );
    opt("--spacing", &a.spacing, &d.spacing_m);
    opt("--max-pins", &a.max_pins, &d.max_pins);
    opt("--tolerance", &a.tolerance, &d.tolerance_deg);
    opt("--target", &a.target, &d.target);
    opt("--min-margin", &a.min_margin, &"0.5");
    opt("--y-quantum", &a.y_quantum, &"0.25");
    opt("--theta-quantum", &a.theta_quantum, &"0.25");
    opt("--coarse", &a.coarse, &"4");
    opt("--refine", &a.refine, &"2");
    opt("--max-states", &a.max_states, &d.max_states);
    opt("--time-limit", &a.time_limit, &"110");
    opt("--contact-tol", &a.contact_tol, &d.contact_tol);
    opt("--seed", &a.seed, &"1");
    opt("--check-parts", &a.check_parts, &"10000");
    opt("--screen-parts", &a.screen_parts, &"2000");
    opt(
        "--mu-f",
        &a.mu_f.map_or(String::new(), |m| m.to_string()),
        &"",
    );
    opt("--fence-overhang", &a.fence_overhang, &"0");
    opt("--max-fence-angle", &a.max_fence_angle, &"55");
    opt("--fence-angle-step", &a.fence_angle_step, &"5");
    opt("--max-moving", &a.max_moving, &"3");
    opt("--sensor-candidates", &a.sensor_candidates, &"6");
    for (on, flag) in [
        (args.tripod, "--tripod"),
        (args.fewest_sets, "--fewest-sets"),
        (args.no_bound, "--no-bound"),
        (args.pins, "--pins"),
        (args.fences, "--fences"),
        (args.sensor, "--sensor"),
    ] {
        if on {
            w.push(flag.into());
        }
    }
    w.join(" ")
}
