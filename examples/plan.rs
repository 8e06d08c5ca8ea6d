//! A short design search: fixed pins that orient tripoly1 parts, found within a 3 s time limit and
//! checked on the simulated line with 500 parts under the default uncertainty (friction ±0.1,
//! pins ±0.5 mm off; `o.uncertainty = UncertaintyChoice::Nominal` plans for nominal physics).
//!
//!     cargo run --release --example plan

use pinfeed::plan::design::{describe_obstacles, design, DesignOptions, Mode};
use pinfeed::plan::Problem;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut o = DesignOptions::new(Problem::new("tripoly1"));
    o.modes = vec![Mode::Pins];
    o.time_limit_s = 3.0;
    o.check_parts = 500;
    o.screen_parts = 200;
    o.refine = 0;

    let d = design(&o, &|_| {})?;

    println!("planned against {}", o.uncertainty().describe());
    println!("{}", d.message);
    if let Some(c) = d.chosen() {
        println!(
            "{} on a belt {:.3} m long, predicted success {:.1}%",
            describe_obstacles(c),
            c.belt_length_m,
            100.0 * c.predicted_success
        );
        for ob in &c.obstacles {
            println!(
                "  {} {} at x = {:.3} m, y = {:+.2} mm",
                ob.kind,
                ob.name,
                ob.x_m,
                1e3 * ob.y_m
            );
        }
        if let Some(check) = c.verdict_check() {
            println!(
                "verdict's check: {} of {} parts oriented ({:.1}%)",
                check.success,
                check.parts,
                100.0 * check.success_rate
            );
        }
    }
    Ok(())
}
