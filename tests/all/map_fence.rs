//! Fence configuration maps (`pinfeed map --fence`, issue 5): a long fence maps every θ0 of
//! tripoly2 into a few narrow bands — the orientations in which each stable flush edge leaves the
//! fence's end — with no no-contact run; the report names the fence and regenerates itself.

use crate::support::pinfeed;
use pinfeed::geometry::{part_from_spec, wrap_deg, Pose};
use pinfeed::maps::{compute_maps, fence_pass_start, MapFence, MapSettings};
use pinfeed::mechanics::{push_fence, ContactSettings, Fidelity, PartModel, Support};
use serde_json::Value;

fn ang_diff(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

#[test]
fn a_long_fence_maps_every_orientation_into_narrow_bands() {
    let out = pinfeed(&[
        "map",
        "--part",
        "tripoly2",
        "--fence",
        "45",
        "--mu-c",
        "0.3",
        "--theta-step",
        "5",
        "--no-write",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((v["fence"]["angle"].as_f64().unwrap() - 45f64.to_radians()).abs() < 1e-12);
    assert_eq!(v["fence"]["mu_f"], 0.3);
    let maps = v["maps"].as_array().unwrap();
    assert_eq!(maps.len(), 1);
    let m = &maps[0];
    assert_eq!(m["fence"]["angle_deg"], 45.0);
    assert!(m["no_contact_ranges_deg"].as_array().unwrap().is_empty());
    let bands = m["bands"].as_array().unwrap();
    assert!((2..=3).contains(&bands.len()), "{bands:?}");
    let total: u64 = bands.iter().map(|b| b["samples"].as_u64().unwrap()).sum();
    assert_eq!(total, 72);
    // Each band is one exit orientation: a flush edge leaves the end the same way every time.
    let poly = part_from_spec("tripoly2").unwrap();
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let fence = fence_pass_start(&poly, 0.0, 45.0, None, 0.3);
    for b in bands {
        assert!(b["width_deg"].as_f64().unwrap() < 0.01, "{b}");
        // Start with the band's first θ0 and compare with one direct push.
        let th0 = b["initial_ranges_deg"][0][0].as_f64().unwrap();
        let o = push_fence(
            &model,
            Pose::new(0.0, 0.0, th0.to_radians()),
            &fence,
            &ContactSettings::default(),
            None,
        );
        let direct = wrap_deg(o.pose_final.theta_rad.to_degrees());
        assert!(
            ang_diff(direct, b["mean_deg"].as_f64().unwrap()).abs() < 1e-6,
            "θ0 {th0}: {direct} vs {b}"
        );
    }
}

#[test]
fn fence_maps_do_not_depend_on_the_thread_count_and_refuse_bad_fences() {
    let poly = part_from_spec("tripoly1").unwrap();
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let mut s = MapSettings::point_pin(Fidelity::Exact, 0.4, 10.0, 5.0);
    s.fence = Some(MapFence {
        angle_deg: -35.0,
        length: Some(6.0),
        tail: None,
    });
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| compute_maps(&poly, &model, &[0.0], &s).unwrap());
    let two = pool(2).install(|| compute_maps(&poly, &model, &[0.0], &s).unwrap());
    assert_eq!(one, two);
    assert_eq!(one[0].label(), "fence -35°:6");
    assert!(!one[0].bands.is_empty());
    for (angle, length) in [(90.0, None), (f64::NAN, None), (30.0, Some(0.0))] {
        s.fence = Some(MapFence {
            angle_deg: angle,
            length,
            tail: None,
        });
        assert!(
            compute_maps(&poly, &model, &[0.0], &s).is_err(),
            "{angle} {length:?}"
        );
    }
}

#[test]
fn fence_map_report_and_cli_errors() {
    let dir = std::env::temp_dir().join(format!("pinfeed-map-fence-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = pinfeed(&[
        "map",
        "--part",
        "tripoly1",
        "--fence",
        "30:8",
        "--theta-step",
        "10",
        "--threads",
        "1",
        "--out-dir",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("fence 30° length 8"), "{table}");
    assert!(table.contains("fence 30°:8  B1"), "{table}");
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    assert!(readme.contains("--fence 30:8"), "{readme}");
    assert!(readme.contains("a fence at 30° of length 8"), "{readme}");
    assert!(dir.join("map_fence.svg").exists());
    assert!(!dir.join("band_intervals.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
    for bad in [
        vec!["--fence", "45", "--d", "0.3"],
        vec!["--fence", "90"],
        vec!["--fence", "45", "--pin-radius", "0.1"],
    ] {
        let mut args = vec!["map", "--part", "tripoly2", "--no-write"];
        args.extend(bad.iter().copied());
        let out = pinfeed(&args);
        assert!(!out.status.success(), "{bad:?} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--fence") || err.contains("fence"), "{err}");
    }
}
