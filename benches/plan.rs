//! The sensorless pin planner (issue 14): tripoly2's shortest plan with the CLI's defaults (the
//! target is < 1 s on 2 cores), from a cold memo each iteration. The exhaustive depth-8 searches
//! are measured by `pinfeed plan` itself and reported in results/plans.md.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::plan::search::Planner;
use pinfeed::plan::{Outcome, Problem};
use std::time::Duration;

fn shortest_tripoly2(c: &mut Criterion) {
    let problem = Problem::new("tripoly2");
    let mut g = c.benchmark_group("plan");
    g.sample_size(10).measurement_time(Duration::from_secs(15));
    g.bench_function(
        "tripoly2 shortest sensorless plan (defaults, cold memo)",
        |b| {
            b.iter(|| {
                let mut planner = Planner::new(&problem).unwrap();
                let (outcome, _) = planner.search();
                assert!(matches!(outcome, Outcome::Found(ref p) if p.steps.len() == 3));
            })
        },
    );
    g.finish();
}

criterion_group!(benches, shortest_tripoly2);
criterion_main!(benches);
