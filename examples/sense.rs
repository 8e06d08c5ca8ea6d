//! A sensing evaluation: how well a force/torque sensor in a fixed pin tells the stable state of a
//! tripoly1 part from one push at d = −0.2, for the default classifiers at two noise levels
//! (accuracy with its 95% interval and the mutual information between state and decision).
//!
//!     cargo run --release --example sense

use pinfeed::geometry::part_from_spec;
use pinfeed::mechanics::{PartModel, Support};
use pinfeed::sensing::evaluate::{applicable, evaluate, noise_sweep, Config, Problem, TruthDraw};
use pinfeed::sensing::templates::{Hypotheses, PushSetup, Uncertainty};
use pinfeed::sensing::SensorSettings;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let polygon = part_from_spec("tripoly1")?.scaled(0.02);
    let model = PartModel::new(&polygon, &Support::Uniform)?;

    // The hypotheses: the part's stable states, labelled by their orientation.
    let hypotheses = Hypotheses::stable_states(&polygon)?;
    let setup = PushSetup::nominal(polygon, -0.2);
    let uncertainty = Uncertainty::none(0.5);
    let problem = Problem {
        setup: &setup,
        model: &model,
        hypotheses: &hypotheses,
        uncertainty: &uncertainty,
    };

    let sensor = SensorSettings::default();
    let classifiers = applicable(sensor.kind, &hypotheses);
    let points = noise_sweep(&sensor, &[1.0, 4.0], &classifiers);
    let config = Config {
        templates_per_hypothesis: 4,
        trials: 60,
        truth: TruthDraw::Cycle,
        seed: 1,
        options: Default::default(),
    };
    let (_, ev) = evaluate(&problem, &points, &config)?;

    println!(
        "tripoly1, {} stable states, {} trials, chance accuracy {:.2}",
        ev.labels.len(),
        ev.trials,
        ev.chance_accuracy
    );
    for c in &ev.cells {
        println!(
            "  {:<16} noise ×{}: accuracy {:.2} [{:.2}, {:.2}], information {:.2} of {:.2} bits",
            c.classifier,
            c.noise_factor,
            c.accuracy,
            c.accuracy_ci95[0],
            c.accuracy_ci95[1],
            c.mutual_information_bits,
            ev.state_entropy_bits
        );
    }
    Ok(())
}
