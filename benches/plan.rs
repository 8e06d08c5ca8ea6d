//! The sensorless pin planner: tripoly2's shortest plan with the CLI's defaults (the
//! target is < 1 s on 2 cores), and an exhaustive depth-8 search (random:18, whose answer is
//! "none up to depth 8"; the target is < 30 s), and the robust depth-8 search of tripoly2 under
//! μc ∈ [0.3, 0.7] and random tripods (75 physics samples, each with its own slide tables; the
//! target is ≤ 10 s), each from a cold memo every iteration. The other exhaustive searches are
//! measured by `pinfeed plan` itself and reported in results/plans.md.

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

/// A cold planner's search of `problem` whose answer is "none up to depth 8", timed over
/// `secs` seconds of samples.
fn none_up_to_depth_8(c: &mut Criterion, name: &str, problem: &Problem, secs: u64) {
    let mut g = c.benchmark_group("plan");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(secs));
    g.bench_function(name, |b| {
        b.iter(|| {
            let mut planner = Planner::new(problem).unwrap();
            let (outcome, _) = planner.search();
            assert!(matches!(outcome, Outcome::NoneUpTo { depth: 8, .. }));
        })
    });
    g.finish();
}

fn exhaustive_random18(c: &mut Criterion) {
    none_up_to_depth_8(
        c,
        "random:18 exhaustive depth-8 search (defaults, none up to depth 8)",
        &Problem::new("random:18"),
        180,
    );
}

fn robust_tripoly2(c: &mut Criterion) {
    let mut problem = Problem::new("tripoly2");
    problem.mu_c_range = Some((0.3, 0.7));
    problem.tripod = true;
    none_up_to_depth_8(
        c,
        "tripoly2 robust depth-8 search (mu_c 0.3-0.7, tripods, none up to depth 8)",
        &problem,
        90,
    );
}

criterion_group!(
    benches,
    shortest_tripoly2,
    exhaustive_random18,
    robust_tripoly2
);
criterion_main!(benches);
