//! Configuration maps (docs/physics.md#configuration-maps): bands partition the contacting samples, NC intervals are
//! exactly the no-contact samples, wrap-around bands are one band, adjusted bands are mean ± sd,
//! results do not depend on the thread count, a known no-contact geometry, and the `pinfeed map`
//! command (JSON keys, report files, refusals).

use crate::support::pinfeed;
use pinfeed::geometry::{part_from_spec, wrap_deg, Polygon};
use pinfeed::maps::runs::{circular_runs, run_indices};
use pinfeed::maps::{compute_maps, ConfigurationMap, MapSample, MapSettings};
use pinfeed::mechanics::{ContactStatus, Fidelity, PartModel, Support};
use serde_json::Value;

fn settings(fidelity: Fidelity, step: f64) -> MapSettings {
    MapSettings::point_pin(fidelity, 0.5, step, 5.0)
}

fn maps_of(part: &str, ds: &[f64], s: &MapSettings) -> Vec<ConfigurationMap> {
    let poly = part_from_spec(part).unwrap();
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    compute_maps(&poly, &model, ds, s).unwrap()
}

/// A few maps of both thesis parts, at every fidelity.
fn sample_maps() -> Vec<(String, ConfigurationMap)> {
    let mut out = Vec::new();
    for part in ["tripoly1", "tripoly2"] {
        for fid in [Fidelity::Exact, Fidelity::Ellipsoid, Fidelity::Tip] {
            for m in maps_of(part, &[-0.9, -0.3, 0.1, 0.7], &settings(fid, 2.0)) {
                out.push((format!("{part} {fid} d={}", m.d), m));
            }
        }
    }
    out
}

/// Indices of the grid covered by a list of [first, last] ranges on grid `grid`.
fn covered(ranges: &[[f64; 2]], grid: &[f64]) -> Vec<usize> {
    let n = grid.len();
    let pos = |x: f64| {
        grid.iter()
            .position(|&g| g == x)
            .expect("range end on the grid")
    };
    let mut out: Vec<usize> = ranges
        .iter()
        .flat_map(|r| run_indices((pos(r[0]), pos(r[1])), n))
        .collect();
    out.sort_unstable();
    out
}

fn grid(m: &ConfigurationMap) -> Vec<f64> {
    m.samples.iter().map(|s| s.theta0_deg).collect()
}

/// Is `x` on the arc from `lo` running `width` degrees counter-clockwise (with slack `eps`)?
fn on_arc(x: f64, lo: f64, width: f64, eps: f64) -> bool {
    wrap_deg(x - lo + eps) <= width + 2.0 * eps
}

#[test]
fn bands_partition_the_contacting_samples_exactly() {
    for (what, m) in sample_maps() {
        let g = grid(&m);
        let contacting: Vec<usize> = (0..g.len()).filter(|&i| m.samples[i].contact).collect();
        assert!(!contacting.is_empty(), "{what}: no contact at all");
        let mut from_bands: Vec<usize> = Vec::new();
        for (j, b) in m.bands.iter().enumerate() {
            let k = covered(&b.initial_ranges_deg, &g);
            assert_eq!(k.len(), b.samples, "{what}: B{j} runs vs count");
            for &i in &k {
                let s = &m.samples[i];
                assert_eq!(s.band, Some(j), "{what}: sample {i} in runs of B{j}");
                assert!(
                    on_arc(s.theta_final_deg, b.final_min_deg, b.width_deg, 1e-9),
                    "{what}: θf {} outside B{j} {b:?}",
                    s.theta_final_deg
                );
                assert!(s.com_final_y >= b.com_y_min && s.com_final_y <= b.com_y_max);
            }
            assert!(
                on_arc(b.final_max_deg, b.final_min_deg, b.width_deg, 1e-9)
                    && (wrap_deg(b.final_max_deg - b.final_min_deg) - b.width_deg).abs() < 1e-9
                    || b.width_deg >= 360.0 - 1e-9,
                "{what}: B{j} ends and width disagree: {b:?}"
            );
            from_bands.extend(k);
        }
        from_bands.sort_unstable();
        assert_eq!(
            from_bands, contacting,
            "{what}: K runs must tile the contacting samples"
        );
        // Bands are separated by gaps of at least T: no contacting θf lies between two bands
        // closer than T to both.
        for (j, b) in m.bands.iter().enumerate() {
            let next = &m.bands[(j + 1) % m.bands.len()];
            if m.bands.len() > 1 {
                let gap = wrap_deg(next.final_min_deg - b.final_max_deg);
                assert!(gap >= 5.0 - 1e-9, "{what}: B{j} → next gap {gap} < T");
            }
        }
    }
}

#[test]
fn no_contact_intervals_are_exactly_the_no_contact_samples() {
    let mut seen_nc = 0;
    for (what, m) in sample_maps() {
        let g = grid(&m);
        let nc: Vec<usize> = (0..g.len()).filter(|&i| !m.samples[i].contact).collect();
        assert_eq!(covered(&m.no_contact_ranges_deg, &g), nc, "{what}");
        for &i in &nc {
            let s = &m.samples[i];
            assert_eq!(
                s.theta_final_deg, s.theta0_deg,
                "{what}: θf = θ0 without contact"
            );
            assert_eq!(s.band, None);
            assert_eq!(s.contact_length, 0.0);
        }
        // Runs are maximal: the samples just outside each run are contacts.
        let mask: Vec<bool> = m.samples.iter().map(|s| !s.contact).collect();
        assert_eq!(circular_runs(&mask).len(), m.no_contact_ranges_deg.len());
        seen_nc += nc.len();
    }
    assert!(
        seen_nc > 0,
        "the chosen d should include no-contact samples"
    );
}

fn synthetic(finals: &[f64]) -> Vec<MapSample> {
    let step = 360.0 / finals.len() as f64;
    finals
        .iter()
        .enumerate()
        .map(|(k, &f)| MapSample {
            theta0_deg: k as f64 * step,
            theta_final_deg: f,
            rotation_deg: f - k as f64 * step,
            contact: true,
            com_final_y: k as f64,
            contact_length: 1.0,
            band: None,
            status: ContactStatus::Ok,
        })
        .collect()
}

#[test]
fn a_band_straddling_zero_is_one_band() {
    // θ0 = 0, 45, …, 315 ending at 358, 359.5, 1, 2.5 (one band through 0°) and near 180°.
    let s = synthetic(&[358.0, 359.5, 1.0, 2.5, 178.0, 180.0, 181.0, 357.0]);
    let m = ConfigurationMap::from_samples(0.2, s, 5.0).unwrap();
    assert_eq!(m.bands.len(), 2, "{:?}", m.bands);
    let wrap = &m.bands[1];
    assert_eq!((wrap.final_min_deg, wrap.final_max_deg), (357.0, 2.5));
    assert!((wrap.width_deg - 5.5).abs() < 1e-12);
    assert_eq!(wrap.samples, 5);
    // Unwrapped: 357, 358, 359.5, 361, 362.5 → mean 359.6.
    assert!((wrap.mean_deg - 359.6).abs() < 1e-9, "{}", wrap.mean_deg);
    // K: θ0 = 315 and 0 … 135 form one run through 0°.
    assert_eq!(wrap.initial_ranges_deg, vec![[315.0, 135.0]]);
    assert_eq!((wrap.com_y_min, wrap.com_y_max), (0.0, 7.0));
}

#[test]
fn a_real_band_straddling_zero_is_one_band() {
    // tripoly1 given with its vertices turned by 10°: the same physics, every angle shifted by
    // −10°, so the band that started just above 0° now straddles it.
    let turned: Vec<String> = [(-1.5f64, -0.5f64), (1.5, -0.5), (0.0, 1.0)]
        .iter()
        .map(|&(x, y)| {
            let (s, c) = 10f64.to_radians().sin_cos();
            format!("{},{}", c * x - s * y, s * x + c * y)
        })
        .collect();
    let spec = format!("vertices:{}", turned.join(" "));
    let s = settings(Fidelity::Exact, 1.0);
    let plain = &maps_of("tripoly1", &[-0.3], &s)[0];
    let rotated = &maps_of(&spec, &[-0.3], &s)[0];
    assert_eq!(plain.bands.len(), rotated.bands.len());
    let straddling: Vec<_> = rotated
        .bands
        .iter()
        .filter(|b| b.final_max_deg < b.final_min_deg)
        .collect();
    assert_eq!(straddling.len(), 1, "{:?}", rotated.bands);
    let mut w0: Vec<f64> = plain.bands.iter().map(|b| b.width_deg).collect();
    let mut w1: Vec<f64> = rotated.bands.iter().map(|b| b.width_deg).collect();
    w0.sort_by(f64::total_cmp);
    w1.sort_by(f64::total_cmp);
    for (a, b) in w0.iter().zip(&w1) {
        assert!((a - b).abs() < 1e-3, "widths {w0:?} vs {w1:?}");
    }
    let b = straddling[0];
    assert!(b.mean_deg > 350.0 || b.mean_deg < 10.0, "{b:?}");
}

#[test]
fn adjusted_bands_are_mean_plus_minus_sd() {
    let s = synthetic(&[10.0, 20.0, 30.0, 200.0]);
    let m = ConfigurationMap::from_samples(0.5, s, 15.0).unwrap();
    assert_eq!(m.bands.len(), 2);
    let b = &m.bands[0];
    assert_eq!((b.mean_deg, b.sd_deg), (20.0, 10.0));
    assert_eq!((b.adjusted_min_deg, b.adjusted_max_deg), (10.0, 30.0));
    let single = &m.bands[1];
    assert_eq!((single.sd_deg, single.adjusted_min_deg), (0.0, 200.0));
    for (what, m) in sample_maps() {
        for (j, b) in m.bands.iter().enumerate() {
            let vals: Vec<f64> = m
                .samples
                .iter()
                .filter(|s| s.band == Some(j))
                .map(|s| b.final_min_deg + wrap_deg(s.theta_final_deg - b.final_min_deg))
                .collect();
            let n = vals.len() as f64;
            let mean = vals.iter().sum::<f64>() / n;
            let sd = if vals.len() > 1 {
                (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
            } else {
                0.0
            };
            let close = |x: f64, y: f64| (wrap_deg(x - y + 180.0) - 180.0).abs() < 1e-9;
            assert!(
                close(b.mean_deg, mean) && (b.sd_deg - sd).abs() < 1e-9,
                "{what} B{j}"
            );
            assert!(
                close(b.adjusted_min_deg, b.mean_deg - b.sd_deg),
                "{what} B{j}"
            );
            assert!(
                close(b.adjusted_max_deg, b.mean_deg + b.sd_deg),
                "{what} B{j}"
            );
            assert!(on_arc(b.mean_deg, b.final_min_deg, b.width_deg, 1e-9));
        }
    }
}

#[test]
fn the_same_map_at_one_and_two_threads_is_identical() {
    let poly: Polygon = part_from_spec("tripoly2").unwrap();
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let s = settings(Fidelity::Exact, 3.0);
    let ds = [-0.7, -0.2, 0.4];
    let run = |threads: usize| -> Vec<ConfigurationMap> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| compute_maps(&poly, &model, &ds, &s).unwrap())
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert_eq!(
        serde_json::to_string(&one).unwrap(),
        serde_json::to_string(&two).unwrap()
    );
}

#[test]
fn tripoly2_at_d_minus_0_3_misses_the_pin_at_theta0_zero() {
    // At θ0 = 0 tripoly2's lowest point is y = −1/3 while the pin runs at y = −0.3·a ≈ −0.412.
    let poly = part_from_spec("tripoly2").unwrap();
    assert!(-0.3 * poly.radius() < -1.0 / 3.0);
    for fid in [Fidelity::Exact, Fidelity::Ellipsoid, Fidelity::Tip] {
        let m = &maps_of("tripoly2", &[-0.3], &settings(fid, 1.0))[0];
        assert!(!m.samples[0].contact);
        let inside = |r: &[f64; 2]| {
            if r[0] <= r[1] {
                r[0] <= 0.0 && 0.0 <= r[1]
            } else {
                true // straddles 0°
            }
        };
        assert!(
            m.no_contact_ranges_deg.iter().any(inside),
            "{fid}: 0° not in {:?}",
            m.no_contact_ranges_deg
        );
        assert!(m.bands.iter().all(|b| b.samples > 0));
    }
}

#[test]
fn tripoly1_maps_at_plus_and_minus_d_are_mirror_images() {
    // tripoly1 is symmetric about its own y axis, so mirroring the world in the belt's axis maps
    // (θ0, d) to (180° − θ0, −d) and θf to 180° − θf, with the final centroid y negated.
    let ms = maps_of("tripoly1", &[-0.4, 0.4], &settings(Fidelity::Exact, 2.0));
    let (minus, plus) = (&ms[0], &ms[1]);
    let n = plus.samples.len();
    for (k, s) in plus.samples.iter().enumerate() {
        let mirror = &minus.samples[(n + n / 2 - k) % n];
        assert_eq!(wrap_deg(180.0 - s.theta0_deg), mirror.theta0_deg);
        assert_eq!(s.contact, mirror.contact, "θ0 = {}", s.theta0_deg);
        let diff = wrap_deg(180.0 - s.theta_final_deg - mirror.theta_final_deg + 180.0) - 180.0;
        assert!(diff.abs() < 1e-6, "θ0 = {}: {diff}", s.theta0_deg);
        assert!((s.com_final_y + mirror.com_final_y).abs() < 1e-6);
    }
    let mut w0: Vec<f64> = plus.bands.iter().map(|b| b.width_deg).collect();
    let mut w1: Vec<f64> = minus.bands.iter().map(|b| b.width_deg).collect();
    w0.sort_by(f64::total_cmp);
    w1.sort_by(f64::total_cmp);
    assert_eq!(w0.len(), w1.len());
    assert!(w0.iter().zip(&w1).all(|(a, b)| (a - b).abs() < 1e-6));
}

// ---- the command line ----

#[test]
fn cli_json_has_the_required_keys() {
    let out = pinfeed(&[
        "map",
        "--part",
        "tripoly2",
        "--d=-0.3,0.5",
        "--theta-step",
        "10",
        "--model",
        "ellipsoid",
        "--json",
        "--no-write",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let maps = v["maps"].as_array().expect("maps");
    assert_eq!(maps.len(), 2);
    assert_eq!(maps[0]["d"], -0.3);
    for m in maps {
        let samples = m["samples"].as_array().expect("samples");
        assert_eq!(samples.len(), 36);
        for key in [
            "theta0_deg",
            "theta_final_deg",
            "contact",
            "com_final_y",
            "contact_length",
        ] {
            assert!(
                samples.iter().all(|s| !s[key].is_null()),
                "sample key {key}"
            );
        }
        let bands = m["bands"].as_array().expect("bands");
        assert!(!bands.is_empty());
        for key in [
            "final_min_deg",
            "final_max_deg",
            "mean_deg",
            "sd_deg",
            "adjusted_min_deg",
            "adjusted_max_deg",
            "initial_ranges_deg",
            "com_y_min",
            "com_y_max",
        ] {
            assert!(bands.iter().all(|b| !b[key].is_null()), "band key {key}");
        }
        assert!(bands[0]["initial_ranges_deg"][0].as_array().unwrap().len() == 2);
        assert!(m["no_contact_ranges_deg"].is_array());
    }
    assert_eq!(maps[0]["samples"][0]["contact"], false);
}

#[test]
fn cli_writes_a_report_headed_by_its_command() {
    let dir = std::env::temp_dir().join(format!("pinfeed-map-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let dir_s = dir.to_str().unwrap();
    let out = pinfeed(&[
        "map",
        "--part",
        "tripoly1",
        "--d=-0.5,0.7",
        "--theta-step",
        "5",
        "--model",
        "tip",
        "--out-dir",
        dir_s,
        "--csv",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = String::from_utf8(out.stdout).unwrap();
    assert!(csv.starts_with("d,theta0_deg,theta_final_deg,"));
    assert_eq!(csv.lines().count(), 1 + 2 * 72);
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let command = readme
        .lines()
        .find(|l| l.trim_start().starts_with("pinfeed map"))
        .expect("README names the command");
    assert!(command.contains("--part tripoly1") && command.contains("--model tip"));
    assert!(command.contains("--d=-0.5,0.7") && command.contains("--theta-step 5"));
    for f in [
        "map.json",
        "samples.csv",
        "band_intervals.svg",
        "band_intervals_adjusted.svg",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    for f in ["map_d-0.5.svg", "map_d+0.7.svg"] {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(svg.contains("<svg") && svg.contains("</svg>"), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_refuses_bad_input() {
    let base = ["map", "--part", "tripoly1", "--model", "tip", "--no-write"];
    for (extra, words) in [
        (vec!["--d=nan"], "d"),
        (vec!["--d=1.5"], "out of range"),
        (vec!["--d=0.3,-0.2,0.3"], "twice"),
        (vec!["--d=0.3", "--theta-step", "0"], "theta step"),
        (vec!["--d=0.3", "--theta-step", "-1"], "theta step"),
        (vec!["--d=0.3", "--theta-step", "7"], "does not divide"),
        (vec!["--d=0.3", "--threshold", "0"], "threshold"),
        (vec!["--d=0.3", "--threshold", "nan"], "threshold"),
        (vec!["--d=0.3", "--mu-c", "-1"], "mu-c"),
        (vec!["--d=0.3", "--model", "magic"], "model"),
        (vec!["--d=0.3", "--part", "nonsense"], "part"),
    ] {
        let mut args: Vec<&str> = base.to_vec();
        args.extend(&extra);
        let out = pinfeed(&args);
        let err = String::from_utf8_lossy(&out.stderr).to_lowercase();
        assert!(!out.status.success(), "{extra:?} was accepted");
        assert!(out.stdout.is_empty(), "{extra:?} printed a result");
        assert!(
            err.contains(words),
            "{extra:?}: stderr should mention '{words}': {err}"
        );
    }
}
