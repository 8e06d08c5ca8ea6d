//! A design's margins ([`pinfeed::plan::margins`]): the friction interval and the placement error
//! `pinfeed plan` reports hold when another study sweeps them with another seed, and the step
//! past each end fails there too.

use crate::plan_cli::{mc_successes, plan_ok, tmp};
use serde_json::Value;

/// `pinfeed mc` of a study of `scenario` (another seed) at each value of `parameter`: the
/// (success, samples) of each point, in order.
fn swept(
    scenario: &std::path::Path,
    name: &str,
    parameter: &str,
    values: &[f64],
) -> Vec<(u64, u64)> {
    let study = scenario.with_file_name(format!("{name}.study.toml"));
    let list: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
    std::fs::write(
        &study,
        format!(
            "scenario = \"{}\"\nseed = 4242\nsamples = 1500\n\n[[sweep]]\nparameter = \"{parameter}\"\nvalues = [{}]\n",
            scenario.file_name().unwrap().to_string_lossy(),
            list.join(", ")
        ),
    )
    .unwrap();
    mc_successes(&study, &format!("{name}_mc"))
}

#[test]
fn a_reported_friction_margin_holds_when_swept_independently() {
    let design = tmp("margins_tripoly2.toml");
    let v: Value = plan_ok(&[
        "plan",
        "--nominal",
        "--part",
        "tripoly2",
        "--pins",
        "--check-parts",
        "2000",
        "--out",
        design.to_str().unwrap(),
        "--json",
    ]);
    let m = &v["chosen"]["margins"];
    let target = m["target"].as_f64().unwrap();
    let [lo, hi] = [0, 1].map(|k| m["mu_holds"][k].as_f64().expect("the nominal holds"));
    let nominal = m["mu_nominal"].as_f64().unwrap();
    assert!(lo <= nominal && nominal <= hi, "{m}");
    // Every step the sweep ran is in the JSON with its number, and `holds` is its number
    // against the target.
    for s in m["friction"].as_array().unwrap() {
        let rate = s["success_rate"].as_f64().unwrap();
        assert_eq!(s["holds"].as_bool().unwrap(), rate >= target, "{s}");
    }
    // The ends hold under another seed (not significantly below the target), and a step past
    // an end that the sweep saw fail fails again (not significantly above it).
    let step = 0.05;
    let closed = |k: usize| !m["mu_open"][k].as_bool().unwrap();
    let mut values = vec![lo, hi];
    if closed(0) {
        values.push(lo - step);
    }
    if closed(1) {
        values.push(hi + step);
    }
    let values: Vec<f64> = values
        .iter()
        .map(|x| (x * 1000.0).round() / 1000.0)
        .collect();
    let results = swept(&design, "margins_mu", "mu_c", &values);
    for (k, (&mu, &(ok, n))) in values.iter().zip(&results).enumerate() {
        let [a, b] = pinfeed::statistics::wilson_interval(ok, n);
        if k < 2 {
            assert!(
                b >= target,
                "μ {mu}: {ok}/{n} is below the target {target}: {m}"
            );
        } else {
            assert!(
                a < target,
                "μ {mu}: {ok}/{n} holds past the reported margin: {m}"
            );
        }
    }
    // The text and the scenario's header say it.
    let text = std::fs::read_to_string(&design).unwrap();
    assert!(
        text.contains(&format!("holds for friction μ {lo:.2}–{hi:.2}")),
        "{text}"
    );
    let placed = m["placement_mm"].as_f64();
    if let Some(e) = placed {
        assert!(
            text.contains(&format!("placement errors up to ±{e} mm")),
            "{text}"
        );
    }
}
