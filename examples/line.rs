//! A line run from a bundled scenario: scenarios/quickstart.toml (tripoly2 parts, three fixed pins)
//! compiled into a scene, 500 parts sent down the line, the outcome counts and success rate printed.
//!
//!     cargo run --release --example line

use pinfeed::engine::{self, PartOutcome, RunOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/quickstart.toml");
    let scene = pinfeed::scenario::load(&path)?;

    // The scene's own seed, fewer parts than its feed declares.
    let opts = RunOptions {
        parts: 500,
        ..RunOptions::from_scene(&scene)
    };
    let run = engine::run(&scene, &opts, &mut |_| {})?;

    let s = &run.summary;
    println!(
        "{}: {} parts, {} obstacles, seed {}",
        s.scenario,
        s.parts_in,
        scene.obstacles.len(),
        s.seed
    );
    for o in PartOutcome::ALL {
        let n = s.outcomes.get(o);
        if n > 0 {
            println!("  {:<20} {n}", o.name());
        }
    }
    println!(
        "success {:.1}% (95% interval {:.1}–{:.1}%), {:.2} contacts per part",
        100.0 * s.success_rate,
        100.0 * s.success_ci95[0],
        100.0 * s.success_ci95[1],
        s.contacts_per_part
    );
    Ok(())
}
