//! The accuracy-vs-time study orders the tiers the way the physics says it must.

use pinfeed::study::accuracy;

/// Exact integration error shrinks with the tolerance and stays far below 0.01° at the default; the
/// COR-tip baseline is worse than the ellipsoid, which is worse than exact; accuracy costs work:
/// contact-model evaluations per push grow as the tolerance tightens, and the approximate tiers
/// need fewer than the exact model.
///
/// Cost is compared in evaluations (deterministic), not in wall-clock time: a timing comparison
/// fails or passes with the machine's load. The speed of each tier, the map's lookup included, is
/// measured and reported in results/accuracy-vs-time.md (`pinfeed bench accuracy`), not asserted.
#[test]
fn tiers_are_ordered() {
    let st = accuracy::run(&["tripoly2"], 60, 3).unwrap();
    let row = |p: &str| st.rows.iter().find(|r| r.tier.starts_with(p)).unwrap();
    let (tip, ell) = (row("tip"), row("ellipsoid"));
    let (loose, default, tight) = (
        row("exact tol=1e-3"),
        row("exact tol=1e-6"),
        row("exact tol=1e-8"),
    );
    assert!(default.error_max_deg < 0.01, "{}", default.error_max_deg);
    assert!(tight.error_mean_deg < default.error_mean_deg);
    assert!(default.error_mean_deg < loose.error_mean_deg);
    assert!(ell.error_mean_deg < tip.error_mean_deg);
    assert!(loose.error_mean_deg < ell.error_mean_deg);
    assert!(
        tip.different_band_share > 0.2,
        "the tip model under-rotates badly"
    );
    // Fails if tightening the tolerance stopped refining the integration (same work, so the
    // error ordering above would be luck), or if an approximation cost as much as the exact model.
    let evals = |r: &accuracy::TierRow| r.mean_evaluations;
    assert!(
        evals(loose) < evals(default) && evals(default) < evals(tight),
        "evaluations per push: tol 1e-3 {}, 1e-6 {}, 1e-8 {}",
        evals(loose),
        evals(default),
        evals(tight)
    );
    assert!(evals(tip) < evals(default) && evals(ell) < evals(default));
    assert!(evals(tip) > 0.0 && evals(ell) > 0.0);
    // The slide tables serve (fewer evaluations) without changing the accuracy.
    let tabled = row("exact+tables tol=1e-6");
    assert!(
        evals(tabled) < 0.75 * evals(default),
        "{} vs {}",
        evals(tabled),
        evals(default)
    );
    assert!((tabled.error_mean_deg - default.error_mean_deg).abs() < 1e-6);
    assert!((tabled.error_max_deg - default.error_max_deg).abs() < 1e-6);
    // Every tier, the map's included, is scored on the same contacts.
    row("map");
    assert!(st.rows.iter().all(|r| r.contacts == st.contacts));
}

/// The ellipsoid's near-central gap matches the closed form c²/((1/A)∫x∥² dA) to 1%.
#[test]
fn central_gap_matches_closed_form() {
    for (name, th, measured, formula) in accuracy::central_push_gap() {
        assert!(
            (measured - formula).abs() < 0.01 * formula,
            "{name} {th}: {measured} vs {formula}"
        );
    }
}
