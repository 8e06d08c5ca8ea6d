//! Fuzzing the command line and polygon validation, bounded to run in CI.
//!
//! * Random and mutated argument vectors for `part`, `contact` and `map --no-write` (small grids),
//!   built from the real flags with numbers drawn across every magnitude and from the awkward
//!   values (NaN, ±inf, −0, 5e-324, 1e308, words that are not numbers), run through the built
//!   binary: never a panic (exit status 101, "panicked"), exit status 0, 1 (a refusal whose first
//!   stderr line is `error: ` and a cause) or 2 (clap's usage error), and no NaN or infinity in
//!   any JSON or CSV printed.
//! * (The same argument vectors in process, many more of them, are run by `cli_in_process`; the
//!   strategies are `argv`.)
//! * Random polygons across magnitudes 1e-300 … 1e300: a scaled copy is accepted or refused with
//!   the polygon at unit size, with the same stable states and the same a / scale; where its mass
//!   properties cannot be represented it is refused for that reason and no other.
//! * Contacts on copies scaled by powers of two give bit-identical rotations.
//!
//! Failing cases proptest finds are kept in `fuzz_cli.proptest-regressions` and re-run first.

use pinfeed::contact_case::{run_case, Case};
use pinfeed::geometry::{Polygon, PolygonError};
use proptest::prelude::*;
use std::process::Command;

use crate::argv::*;

// ---------------------------------------------------------------------------------------------
// Checks.

/// Every number of a JSON document is finite and no value is null (part and contact reports have
/// no optional fields; serde_json writes a non-finite float as null).
fn assert_json_finite(v: &serde_json::Value, path: &str) -> Result<(), TestCaseError> {
    match v {
        serde_json::Value::Null => Err(TestCaseError::fail(format!("{path} is null"))),
        serde_json::Value::Number(n) => {
            prop_assert!(n.as_f64().is_some_and(f64::is_finite), "{path} = {n}");
            Ok(())
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                assert_json_finite(x, &format!("{path}[{i}]"))?;
            }
            Ok(())
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                assert_json_finite(x, &format!("{path}.{k}"))?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Run the binary and check the outcome contract; `csv` output is checked for non-finite fields,
/// `--json` output must be one JSON document of finite numbers, a table must show no NaN or inf.
fn check_binary(args: &[String], csv: bool) -> Result<(), TestCaseError> {
    // In a scratch directory: whatever a mutated command line might write stays out of the
    // repository.
    let dir = std::env::temp_dir().join(format!("pinfeed-fuzz-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let out = Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .current_dir(&dir)
        .output()
        .expect("run pinfeed");
    let err = String::from_utf8_lossy(&out.stderr);
    let code = out.status.code();
    prop_assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    prop_assert!(
        matches!(code, Some(0..=2)),
        "{args:?}: exit status {code:?}: {err}"
    );
    match code {
        Some(0) => {
            let text = String::from_utf8_lossy(&out.stdout);
            if csv {
                for line in text.lines() {
                    for field in line.split(',') {
                        let f = field.to_ascii_lowercase();
                        prop_assert!(
                            !(f.contains("nan") || f.contains("inf")),
                            "{args:?}: non-finite field in {line}"
                        );
                    }
                }
            } else if args.iter().any(|a| a == "--json") {
                let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
                    TestCaseError::fail(format!("{args:?}: not JSON ({e}): {text}"))
                })?;
                assert_json_finite(&v, "")?;
            } else {
                // A mutation dropped --json: the table must not show a non-finite number either.
                let bad = text
                    .split(|c: char| c.is_whitespace() || "(),°".contains(c))
                    .any(|w| matches!(w.trim_start_matches(['+', '-']), "NaN" | "inf"));
                prop_assert!(!bad, "{args:?}: non-finite number in {text}");
            }
        }
        Some(1) => {
            // After any warnings (`--vertices` is deprecated), the first line is the cause.
            let first = err
                .lines()
                .find(|l| !l.starts_with("warning: "))
                .unwrap_or("");
            prop_assert!(
                first.starts_with("error: ") && first.len() > "error: ".len() + 5,
                "{args:?}: the first stderr line should be the cause: {err}"
            );
            prop_assert!(
                out.stdout.is_empty(),
                "{args:?}: printed a result and failed"
            );
        }
        _ => prop_assert!(err.starts_with("error:"), "{args:?}: {err}"),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, rng_seed: proptest::test_runner::RngSeed::Fixed(20261128), .. ProptestConfig::default() })]

    #[test]
    fn part_argv_through_the_binary(args in part_args()) {
        check_binary(&args, false)?;
    }

    #[test]
    fn contact_argv_through_the_binary(args in contact_args()) {
        check_binary(&args, false)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(20261129), .. ProptestConfig::default() })]

    #[test]
    fn map_argv_through_the_binary(args in map_args()) {
        check_binary(&args, true)?;
    }
}

// ---------------------------------------------------------------------------------------------
// Magnitudes.

/// Can a polygon of this unit-size shape be represented at scale k? Its size, area and polar
/// moment must be normal doubles — with a margin of 2^±8 either side, where rounding of the
/// scaled coordinates could tip a borderline case.
fn representable_at(unit: &Polygon, k: f64, margin: f64) -> bool {
    let fits = |v: f64| {
        v.is_normal() && v.abs() < f64::MAX / margin && v.abs() > f64::MIN_POSITIVE * margin
    };
    fits(unit.radius() * k)
        && fits(unit.area() * k * k)
        && fits(unit.polar_moment() * k * k * k * k)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, rng_seed: proptest::test_runner::RngSeed::Fixed(20261131), .. ProptestConfig::default() })]

    /// Scaled copies are accepted or refused together, with the same stable states and a / k;
    /// beyond the representable range the refusal says so.
    #[test]
    fn scaled_copies_are_accepted_or_refused_together(
        v in star(), e in -300i32..300, frac in 0.0f64..1.0, mutation in 0usize..3,
        at in any::<prop::sample::Index>(),
    ) {
        let mut v = v;
        // Sometimes a degenerate shape, to check that refusals do not depend on the scale either.
        let i = at.index(v.len());
        match mutation {
            1 => { let p = v[i]; v.insert(i, p); }
            2 => { let j = (i + 1) % v.len(); v[j] = v[i]; }
            _ => {}
        }
        let k = 10f64.powf(f64::from(e) + frac);
        let unit = Polygon::from_xy(&v);
        let scaled: Vec<(f64, f64)> = v.iter().map(|&(x, y)| (x * k, y * k)).collect();
        let got = Polygon::from_xy(&scaled);
        match (&unit, &got) {
            (Ok(u), Ok(p)) => {
                prop_assert!((p.radius() / k / u.radius() - 1.0).abs() < 1e-12, "a: {} vs {}", p.radius(), u.radius());
                for x in [p.area(), p.polar_moment(), p.radius(), p.offset().x, p.offset().y] {
                    prop_assert!(x.is_finite());
                }
                prop_assert!(p.area().is_normal() && p.polar_moment().is_normal());
                let (su, sp) = (u.stable_states(), p.stable_states());
                prop_assert_eq!(su.len(), sp.len());
                for (a, b) in su.iter().zip(&sp) {
                    prop_assert!((a.theta_rad - b.theta_rad).abs() < 1e-9, "{} vs {}", a.theta_rad, b.theta_rad);
                    prop_assert_eq!(a.hull_edge, b.hull_edge);
                }
                prop_assert!(representable_at(u, k, 1.0));
            }
            (Ok(u), Err(err)) => {
                prop_assert!(matches!(err, PolygonError::NotRepresentable { .. }), "k = {k:e}: {err}");
                prop_assert!(!representable_at(u, k, 256.0), "k = {k:e} fits but was refused: {err}");
            }
            (Err(eu), Err(ep)) => {
                if !matches!(ep, PolygonError::NotRepresentable { .. }) {
                    prop_assert_eq!(std::mem::discriminant(eu), std::mem::discriminant(ep), "{} vs {}", eu, ep);
                }
            }
            (Err(eu), Ok(_)) => prop_assert!(false, "unit refused ({eu}) but accepted at k = {k:e}"),
        }
    }

    /// `try_scaled` agrees with building the scaled copy, and never panics.
    #[test]
    fn try_scaled_refuses_exactly_the_unrepresentable(v in star(), e in -320i32..310) {
        let u = Polygon::from_xy(&v).unwrap();
        let k = 10f64.powi(e);
        match u.try_scaled(k) {
            Ok(p) => {
                prop_assert!(representable_at(&u, k, 1.0));
                prop_assert!((p.radius() / k / u.radius() - 1.0).abs() < 1e-12);
            }
            Err(err) => {
                prop_assert!(matches!(err, PolygonError::NotRepresentable { .. } | PolygonError::BadScale(_)), "{err}");
                prop_assert!(!representable_at(&u, k, 256.0), "k = {k:e}: {err}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, rng_seed: proptest::test_runner::RngSeed::Fixed(20261132), .. ProptestConfig::default() })]

    /// A contact on a copy scaled by 2^j is the contact at unit size, bit for bit: the polygon is
    /// validated and measured in normalised coordinates and the contact model works in units of a.
    #[test]
    fn contacts_on_power_of_two_copies_are_bit_identical(
        v in star(), j in -220i32..220, theta0 in 0.0f64..360.0, d in -0.95f64..0.95,
        mu_c in 0.0f64..1.5, rho in prop_oneof![Just(0.0), 0.01f64..0.3],
    ) {
        let k = 2f64.powi(j);
        let case = |scale: f64| Case {
            pin_radius: rho * scale,
            ..Case::new(
                &format!(
                    "vertices:{}",
                    vertex_text(&v.iter().map(|&(x, y)| (x * scale, y * scale)).collect::<Vec<_>>())
                ),
                theta0,
                d,
                mu_c,
            )
        };
        let (pu, u, _) = run_case(&case(1.0), false, &|f| f.to_string()).map_err(|e| TestCaseError::fail(format!("{e:#}")))?;
        let (pk, s, _) = run_case(&case(k), false, &|f| f.to_string()).map_err(|e| TestCaseError::fail(format!("{e:#}")))?;
        prop_assert_eq!(pk.radius(), pu.radius() * k);
        prop_assert_eq!(u.status.name(), s.status.name());
        prop_assert_eq!(u.contact, s.contact);
        prop_assert_eq!(u.rotation_rad, s.rotation_rad);
        prop_assert_eq!(u.pose_final.x * k, s.pose_final.x);
        prop_assert_eq!(u.pose_final.y * k, s.pose_final.y);
    }
}
