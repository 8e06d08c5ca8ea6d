//! The certified map tier: answers within 0.05° of the exact model where it
//! serves, the exact model near a jump, a cache keyed by every input, corrupted files refused and
//! rebuilt, a build independent of the thread count, a line with `fidelity = "map"` that
//! ends every part in the class the exact line does, and maps built cell by cell as queries reach
//! them that answer as the whole map.

use crate::support::pinfeed_json;
use pinfeed::engine::{self, contact_map, RunOptions};
use pinfeed::geometry::{named, Pose, Vec2};
use pinfeed::maps::tier::{
    self, push_with_map, Fallback, Source, TierInputs, TierKey, TierMap, TierSpec,
};
use pinfeed::mechanics::{push_path, ContactSettings, PartModel, PinPath, Support};
use pinfeed::random::stream;
use rand::RngExt;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// tripoly2 (a = 1) with a pin of radius 0.1 a at μc 0.5, tolerance 1e-6.
fn model() -> &'static PartModel {
    static M: OnceLock<PartModel> = OnceLock::new();
    M.get_or_init(|| {
        let poly = named::part_from_spec("tripoly2").unwrap();
        let poly = poly.scaled(1.0 / poly.radius());
        PartModel::new(&poly, &Support::Uniform).unwrap()
    })
}

const RADIUS: f64 = 0.1;

fn inputs(spec: TierSpec) -> TierInputs<'static> {
    static UNIFORM: Support = Support::Uniform;
    TierInputs {
        model: model(),
        support: &UNIFORM,
        radius: RADIUS,
        settings: ContactSettings::default(),
        spec,
    }
}

/// The map the accuracy tests share (coarse: 15° × 0.18 a base cells, two halvings).
fn shared_map() -> &'static TierMap {
    static MAP: OnceLock<TierMap> = OnceLock::new();
    MAP.get_or_init(|| {
        tier::build(&inputs(TierSpec {
            theta_cells: 24,
            d_cells: 12,
            max_depth: 2,
            ..TierSpec::default()
        }))
    })
}

fn exact(pose: Pose, pin: Vec2) -> pinfeed::mechanics::ContactOutcome {
    let path = PinPath::constant(0.0);
    push_path(
        model(),
        pose,
        pin,
        RADIUS,
        &path,
        &ContactSettings::default(),
        None,
    )
}

/// A part at `pose` and a pin at offset d, well upstream.
fn query(theta: f64, d: f64) -> (Pose, Vec2) {
    let pose = Pose::new(0.37, -0.21, theta);
    (pose, Vec2::new(pose.x + 3.1, pose.y + d))
}

#[test]
fn served_answers_are_within_0_05_degrees_of_exact_and_fallbacks_are_exact() {
    let map = shared_map();
    let mut rng = stream(15, 0);
    let (mut served, mut missed, mut fallbacks) = (0, 0, 0);
    for _ in 0..300 {
        let theta = rng.random::<f64>() * 720.0 - 360.0;
        let d = (rng.random::<f64>() * 2.0 - 1.0) * 1.1;
        let (pose, pin) = query(theta.to_radians(), d);
        let ex = exact(pose, pin);
        let (out, why) = push_with_map(map, model(), pose, pin, RADIUS, &Default::default());
        if why.is_some() {
            fallbacks += 1;
            assert_eq!(out, ex, "a fallback is the exact model's answer");
            continue;
        }
        assert_eq!(out.contact, ex.contact, "θ0 {theta} d {d}");
        assert_eq!(out.status, ex.status);
        if !out.contact {
            missed += 1;
            assert_eq!(out.pose_final, ex.pose_final);
            continue;
        }
        served += 1;
        let err = (out.pose_final.theta_rad - ex.pose_final.theta_rad)
            .abs()
            .to_degrees();
        assert!(err <= 0.05, "θ0 {theta} d {d}: θf off by {err}°");
        assert_eq!(out.travel_to_contact, ex.travel_to_contact);
        for (a, b) in [
            (out.pose_final.x, ex.pose_final.x),
            (out.pose_final.y, ex.pose_final.y),
            (out.contact_length, ex.contact_length),
        ] {
            assert!((a - b).abs() <= 4e-3, "θ0 {theta} d {d}: {a} vs {b}");
        }
    }
    // The map must actually serve: most touching queries of this grid are certified.
    assert!(served > 100, "served {served}, fallbacks {fallbacks}");
    assert!(
        missed > 30 && fallbacks > 5,
        "missed {missed}, fallbacks {fallbacks}"
    );
}

/// Where θf jumps (d = 0.3: near θ0 = 27° the push switches the edge it ends on), the map hands
/// the push to the exact model.
#[test]
fn near_a_jump_the_exact_model_answers() {
    let map = shared_map();
    let d = 0.3;
    let rot = |t: f64| {
        let (pose, pin) = query(t.to_radians(), d);
        exact(pose, pin).rotation_rad.to_degrees()
    };
    let (mut lo, mut hi) = (20.0, 34.0);
    assert!((rot(hi) - rot(lo)).abs() > 30.0, "no jump where expected");
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if (rot(mid) - rot(lo)).abs() > 30.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    for t in [lo - 1e-3, lo, hi, hi + 1e-3] {
        let (pose, pin) = query(t.to_radians(), d);
        assert_eq!(
            map.answer(model(), pose, pin, RADIUS).err(),
            Some(Fallback::Uncertified),
            "θ0 {t}° sits at the jump"
        );
        let (out, why) = push_with_map(map, model(), pose, pin, RADIUS, &Default::default());
        assert_eq!(why, Some(Fallback::Uncertified));
        assert_eq!(out, exact(pose, pin));
    }
}

/// A map small enough to build in milliseconds.
fn tiny() -> TierSpec {
    TierSpec {
        theta_cells: 4,
        d_cells: 2,
        max_depth: 0,
        ..TierSpec::default()
    }
}

/// 32 base cells (more than one batch of a build), refined once.
fn small() -> TierSpec {
    TierSpec {
        theta_cells: 8,
        d_cells: 4,
        max_depth: 1,
        ..TierSpec::default()
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("pinfeed-map-tier-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn the_key_changes_with_every_input_and_only_then() {
    let base = inputs(tiny());
    let key = TierKey::of(&base);
    assert_eq!(key, TierKey::of(&inputs(tiny())), "a pure function");
    let other_part = PartModel::new(
        &named::part_from_spec("tripoly1").unwrap(),
        &Support::Uniform,
    )
    .unwrap();
    let tripod = Support::parse("tripod:3", model().polygon()).unwrap();
    let s = base.settings;
    let variants: Vec<(&str, TierInputs)> = vec![
        (
            "part",
            TierInputs {
                model: &other_part,
                ..base
            },
        ),
        (
            "support",
            TierInputs {
                support: &tripod,
                ..base
            },
        ),
        (
            "radius",
            TierInputs {
                radius: 0.11,
                ..base
            },
        ),
        (
            "mu_c",
            TierInputs {
                settings: ContactSettings { mu_c: 0.4, ..s },
                ..base
            },
        ),
        (
            "tol",
            TierInputs {
                settings: ContactSettings { tol: 1e-7, ..s },
                ..base
            },
        ),
        (
            "max_travel",
            TierInputs {
                settings: ContactSettings {
                    max_travel: 40.0,
                    ..s
                },
                ..base
            },
        ),
        (
            "max_evaluations",
            TierInputs {
                settings: ContactSettings {
                    max_evaluations: 1000,
                    ..s
                },
                ..base
            },
        ),
        (
            "max_events",
            TierInputs {
                settings: ContactSettings {
                    max_events: 100,
                    ..s
                },
                ..base
            },
        ),
        (
            "theta_cells",
            TierInputs {
                spec: TierSpec {
                    theta_cells: 5,
                    ..tiny()
                },
                ..base
            },
        ),
        (
            "d_cells",
            TierInputs {
                spec: TierSpec {
                    d_cells: 3,
                    ..tiny()
                },
                ..base
            },
        ),
        (
            "max_depth",
            TierInputs {
                spec: TierSpec {
                    max_depth: 1,
                    ..tiny()
                },
                ..base
            },
        ),
        (
            "check_deg",
            TierInputs {
                spec: TierSpec {
                    check_deg: 0.01,
                    ..tiny()
                },
                ..base
            },
        ),
        (
            "check_pos",
            TierInputs {
                spec: TierSpec {
                    check_pos: 1e-4,
                    ..tiny()
                },
                ..base
            },
        ),
    ];
    for (name, v) in &variants {
        assert_ne!(TierKey::of(v), key, "changing {name} must change the key");
    }
    // μs scales forces only: the motion, and so the map, does not depend on it.
    let mu_s = TierInputs {
        settings: ContactSettings { mu_s: 0.9, ..s },
        ..base
    };
    assert_eq!(TierKey::of(&mu_s), key);
}

#[test]
fn a_changed_input_does_not_read_the_old_file() {
    let dir = temp_dir("invalidate");
    let a = inputs(tiny());
    let first = tier::load_or_build(&a, Some(&dir));
    assert!(matches!(first.source, Source::Built { .. }));
    assert!(first.warnings.is_empty(), "{:?}", first.warnings);
    let again = tier::load_or_build(&a, Some(&dir));
    assert_eq!(again.source, Source::Disk(first.file.clone().unwrap()));
    assert_eq!(*again.map, *first.map, "what is read is what was written");

    let b = TierInputs {
        settings: ContactSettings {
            mu_c: 0.3,
            ..a.settings
        },
        ..a
    };
    let other = tier::load_or_build(&b, Some(&dir));
    assert!(matches!(other.source, Source::Built { .. }));
    assert_ne!(other.map.key, first.map.key);
    assert_ne!(other.file, first.file, "one file per key");
    let a_again = tier::load_or_build(&a, Some(&dir));
    assert_eq!(a_again.source, Source::Disk(first.file.clone().unwrap()));
    // Even a file of other inputs put under this key's name is refused and rebuilt.
    let b_file = other.file.clone().unwrap();
    std::fs::copy(first.file.as_ref().unwrap(), &b_file).unwrap();
    let refused = tier::load_or_build(&b, Some(&dir));
    assert!(matches!(refused.source, Source::Built { .. }));
    assert!(
        refused.warnings[0].contains("its key does not match its inputs"),
        "{:?}",
        refused.warnings
    );
    assert_eq!(*refused.map, *other.map);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn corrupt(path: &Path, at: usize) {
    let mut bytes = std::fs::read(path).unwrap();
    let i = at.min(bytes.len() - 1);
    bytes[i] ^= 0x5a;
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn a_corrupted_file_is_refused_with_a_clear_message_and_rebuilt() {
    let dir = temp_dir("corrupt");
    let a = inputs(tiny());
    let built = tier::load_or_build(&a, Some(&dir));
    let file = built.file.clone().unwrap();
    let len = std::fs::metadata(&file).unwrap().len() as usize;
    for (at, reason) in [
        (len / 2, "checksum mismatch"),
        (3, "not a pinfeed map file"),
        (len - 1, "checksum mismatch"),
    ] {
        corrupt(&file, at);
        let again = tier::load_or_build(&a, Some(&dir));
        assert!(matches!(again.source, Source::Built { .. }), "byte {at}");
        let w = again.warnings.join("\n");
        assert!(
            w.contains(&file.display().to_string())
                && w.contains("corrupted")
                && w.contains(reason),
            "byte {at}: {w}"
        );
        assert_eq!(*again.map, *built.map, "rebuilt to the same map");
        // The rebuilt file is valid again.
        let read = tier::load_or_build(&a, Some(&dir));
        assert_eq!(read.source, Source::Disk(file.clone()));
    }
    // A truncated file too.
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() / 3]).unwrap();
    let again = tier::load_or_build(&a, Some(&dir));
    assert!(
        again.warnings[0].contains("corrupted"),
        "{:?}",
        again.warnings
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The bundled quickstart with `fidelity = "map"` (a coarse grid, built in memory) against the
/// same scenario exact: every part ends in the same class, and the summary says how many pushes
/// the map served and why the others fell back. The exact scenario's summary has no map counters.
#[test]
fn the_quickstart_on_the_map_tier_ends_every_part_in_the_exact_class() {
    let text = std::fs::read_to_string("scenarios/quickstart.toml").unwrap();
    let line = "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"";
    assert!(text.contains(line));
    let map_text = text.replace(line, "fidelity = \"map\"\nmap_grid = [24, 12, 2]");
    let exact_scene = pinfeed::scenario::parse(Path::new("q.toml"), &text).unwrap();
    let map_scene = pinfeed::scenario::parse(Path::new("q.toml"), &map_text).unwrap();
    let prepared = contact_map::prepare(&map_scene, None);
    assert_eq!(prepared.len(), 3, "one map per pin (the three share it)");
    let opts = |scene| RunOptions {
        parts: 300,
        keep_records: true,
        ..RunOptions::from_scene(scene)
    };
    let ex = engine::run(&exact_scene, &opts(&exact_scene), &mut |_| {}).unwrap();
    let mp = engine::run(&map_scene, &opts(&map_scene), &mut |_| {}).unwrap();
    let classes = |r: &engine::RunResult| -> Vec<&str> {
        r.records.iter().map(|p| p.outcome.name()).collect()
    };
    assert_eq!(classes(&ex), classes(&mp));
    for (a, b) in ex.records.iter().zip(&mp.records) {
        assert!(
            (a.theta_out_deg - b.theta_out_deg).abs() < 0.5
                || (a.theta_out_deg - b.theta_out_deg).abs() > 359.5,
            "part {}: {} vs {}",
            a.part,
            a.theta_out_deg,
            b.theta_out_deg
        );
    }
    let w = mp.summary.work;
    assert_eq!(mp.summary.fidelity, "map");
    assert!(w.map_tier.served > 100, "{:?}", w.map_tier);
    assert_eq!(w.map_tier.served + w.map_tier.fallbacks(), w.contact_solves);
    // Served contacts cost no evaluation; the fallbacks (about 30% of the contacts, those near a
    // discontinuity of the map and so among the longest) cost the rest: with the slide tables
    // (both runs use them) about half of the exact run's evaluations, 24 301 against 46 655 here.
    assert!(
        w.model_evaluations * 100 < ex.summary.work.model_evaluations * 85,
        "map {} exact {}",
        w.model_evaluations,
        ex.summary.work.model_evaluations
    );
    let json = serde_json::to_string(&ex.summary).unwrap();
    assert!(!json.contains("map_tier"), "an exact scene pays nothing");
    assert!(serde_json::to_string(&mp.summary)
        .unwrap()
        .contains("fallback_uncertified"));
}

#[test]
fn map_keys_in_a_scenario_are_checked() {
    let text = std::fs::read_to_string("scenarios/quickstart.toml").unwrap();
    let line = "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"";
    for (to, needle) in [
        (
            "fidelity = \"exact\"\nmap_grid = [24, 12, 2]",
            "model.map_grid",
        ),
        (
            "fidelity = \"map\"\nmap_grid = [2, 12, 2]",
            "model.map_grid",
        ),
        ("fidelity = \"mapp\"", "fidelity"),
    ] {
        let bad = text.replace(line, to);
        let err = pinfeed::scenario::parse(Path::new("q.toml"), &bad)
            .unwrap_err()
            .to_string();
        assert!(err.contains("q.toml:") && err.contains(needle), "{err}");
    }
}

#[test]
fn the_build_does_not_depend_on_the_thread_count() {
    let spec = TierSpec {
        theta_cells: 6,
        d_cells: 3,
        max_depth: 1,
        ..TierSpec::default()
    };
    let on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| tier::cache::encode(&tier::build(&inputs(spec))))
    };
    let one = on(1);
    assert!(one.len() > 1000);
    assert_eq!(one, on(2), "same file byte for byte");
}

#[test]
fn configuration_maps_from_the_map_tier_match_exact_and_refuse_what_it_cannot_tabulate() {
    // `pinfeed map --model map`: every θf within 0.05° of the exact map (served answers by the
    // certificate, fallbacks because they are exact), the same bands; fences refused.
    let dir = temp_dir("cli-map");
    let common = [
        "map",
        "--part",
        "tripoly2",
        "--d=-0.5,0.3",
        "--theta-step",
        "4",
        "--json",
        "--no-write",
    ];
    let mut a = common.to_vec();
    a.extend(["--model", "map", "--map-grid", "24,8,2", "--cache-dir"]);
    a.push(dir.to_str().unwrap());
    let map = pinfeed_json(&a);
    let exact = pinfeed_json(&common);
    assert_eq!(map["model"], "map");
    // Without --json, from an empty cache: the 48 base cells' build is forecast before the
    // rest is built, and the forecast is shown again beside the build's time.
    let fresh = temp_dir("cli-map-forecast");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(&common[..common.len() - 2])
        .args([
            "--no-write",
            "--model",
            "map",
            "--map-grid",
            "24,8,2",
            "--cache-dir",
        ])
        .arg(&fresh)
        .output()
        .unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let said = err.find("map tier: 48 base cells to build; their first level");
    let built = err.find("map tier: 48 base cell(s) built in");
    assert!(
        matches!((said, built), (Some(s), Some(b)) if s < b),
        "{err}"
    );
    assert!(
        err.contains("forecast after its first level and a"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&fresh);
    for (m, e) in map["maps"]
        .as_array()
        .unwrap()
        .iter()
        .zip(exact["maps"].as_array().unwrap())
    {
        assert_eq!(
            m["bands"].as_array().unwrap().len(),
            e["bands"].as_array().unwrap().len()
        );
        for (sm, se) in m["samples"].as_array().unwrap().iter().zip(se_samples(e)) {
            let (a, b) = (
                sm["theta_final_deg"].as_f64().unwrap(),
                se["theta_final_deg"].as_f64().unwrap(),
            );
            let diff = ((a - b + 180.0).rem_euclid(360.0) - 180.0).abs();
            assert!(diff <= 0.05, "θ0 {}: map {a} exact {b}", sm["theta0_deg"]);
        }
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args([
            "map", "--part", "tripoly2", "--fence", "36", "--model", "map",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--model map"));
    let _ = std::fs::remove_dir_all(&dir);
}

fn se_samples(e: &serde_json::Value) -> impl Iterator<Item = &serde_json::Value> {
    e["samples"].as_array().unwrap().iter()
}

/// A map built cell by cell, as single queries need them (and kept in the cache between
/// queries), answers every query in a built cell exactly as the whole map does; a query in a cell
/// not built yet is answered exactly, with the reason `unbuilt`.
#[test]
fn cells_built_on_demand_answer_as_the_whole_map() {
    let spec = small();
    let a = inputs(spec);
    let whole = tier::build(&a);
    assert!(whole.is_complete());
    let dir = temp_dir("on-demand");
    let mut rng = stream(7, 0);
    let mut built = std::collections::BTreeSet::new();
    for _ in 0..24 {
        let theta = rng.random::<f64>() * std::f64::consts::TAU;
        let d = (rng.random::<f64>() - 0.5) * 1.8;
        let (pose, pin) = query(theta, d);
        let cell = tier::cell_of_query(&a, pose, pin).expect("inside the d range");
        let loaded = tier::load_or_build_cells(&a, Some(&dir), Some(&[cell]), &|_, _| {});
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        match (built.insert(cell), &loaded.source) {
            (true, Source::Built { cells, .. }) => assert_eq!(*cells, 1),
            (false, Source::Disk(_)) => {}
            (new, s) => panic!("cell {cell} new {new}: {s:?}"),
        }
        assert_eq!(loaded.map.stats.built_cells as usize, built.len());
        let want = whole.answer(model(), pose, pin, RADIUS);
        let got = loaded.map.answer(model(), pose, pin, RADIUS);
        match (want, got) {
            (Ok(w), Ok(g)) => assert_eq!(
                (w.pose_final, w.contact, w.contact_length),
                (g.pose_final, g.contact, g.contact_length)
            ),
            (w, g) => assert_eq!(w.err(), g.err()),
        }
        // Some cell not built yet answers exactly, saying why (a miss is the ray cast's answer).
        let unbuilt = loaded
            .map
            .unbuilt_cells()
            .next()
            .expect("not all cells built");
        let (nd, reach) = (spec.d_cells as usize, loaded.map.reach);
        let t = ((unbuilt / nd) as f64 + 0.5) / spec.theta_cells as f64 * std::f64::consts::TAU;
        let dd = -reach + 2.0 * reach * ((unbuilt % nd) as f64 + 0.5) / nd as f64;
        let (pose, pin) = query(t, dd);
        assert_eq!(tier::cell_of_query(&a, pose, pin), Some(unbuilt));
        if let Err(why) = loaded.map.answer(model(), pose, pin, RADIUS) {
            assert!(
                matches!(why, Fallback::Unbuilt | Fallback::PinInside),
                "{why:?}"
            );
        }
    }
    // The rest, all at once (in batches, counted): now whole, with the whole map's certified area.
    let missing = 32 - built.len() as u64;
    let seen = std::sync::Mutex::new(Vec::new());
    let report = |done: u64, total: u64| seen.lock().unwrap().push((done, total));
    let rest = tier::load_or_build_cells(&a, Some(&dir), None, &report);
    let seen = seen.into_inner().unwrap();
    assert_eq!(seen.first(), Some(&(0, missing)));
    assert_eq!(seen.last(), Some(&(missing, missing)));
    assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0));
    assert!(rest.map.is_complete());
    assert!((rest.map.stats.certified_area - whole.stats.certified_area).abs() < 1e-12);
    assert_eq!(rest.map.stats.certified_cells, whole.stats.certified_cells);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The same answer, field by field that the line uses, or the same reason for the exact model.
fn same_answer(
    want: Result<pinfeed::mechanics::ContactOutcome, Fallback>,
    got: Result<pinfeed::mechanics::ContactOutcome, Fallback>,
    what: &str,
) {
    match (want, got) {
        (Ok(w), Ok(g)) => assert_eq!(
            (
                w.pose_final,
                w.contact,
                w.contact_length,
                w.travel_to_contact
            ),
            (
                g.pose_final,
                g.contact,
                g.contact_length,
                g.travel_to_contact
            ),
            "{what}"
        ),
        (w, g) => assert_eq!(w.err(), g.err(), "{what}"),
    }
}

/// A lazy map (what a line on the map tier uses) builds a base cell only when a query that needs
/// it falls there — not for a miss (the ray cast answers) — answers every query as the whole map
/// does, and writes back exactly the cells it built: the merged map answers as the whole map in
/// them, keeps the others unbuilt, and survives its file.
#[test]
fn a_lazy_map_builds_only_the_cells_its_queries_need_and_answers_as_the_whole_map() {
    let spec = TierSpec {
        theta_cells: 10,
        d_cells: 4,
        max_depth: 1,
        ..TierSpec::default()
    };
    let a = inputs(spec);
    let whole = tier::build(&a);
    let dir = temp_dir("lazy");
    std::fs::create_dir_all(&dir).unwrap();
    let file = tier::cache::file_of(&dir, &whole.key);
    let lazy = tier::LazyMap::new(
        std::sync::Arc::new(TierMap::unbuilt(&a)),
        Some(file.clone()),
    );
    assert_eq!(
        lazy.persist().unwrap(),
        None,
        "nothing built, nothing written"
    );
    let mut rng = stream(11, 0);
    let mut needed = std::collections::BTreeSet::new();
    let mut queries = Vec::new();
    for k in 0..30 {
        let theta = rng.random::<f64>() * std::f64::consts::TAU;
        let d = (rng.random::<f64>() - 0.5) * 2.4;
        let (pose, pin) = query(theta, d);
        let want = whole.answer(model(), pose, pin, RADIUS);
        // The cell is needed when the whole map looked it up: a touch, served or not certified.
        if matches!(&want, Ok(o) if o.contact) || want == Err(Fallback::Uncertified) {
            if let Some(c) = tier::cell_of_query(&a, pose, pin) {
                needed.insert(c);
            }
        }
        same_answer(want, lazy.answer(&a, pose, pin), &format!("query {k}"));
        assert_eq!(lazy.built_now().0 as usize, needed.len(), "query {k}");
        queries.push((pose, pin));
    }
    let all = (spec.theta_cells * spec.d_cells) as usize;
    assert!(!needed.is_empty() && needed.len() < all, "{needed:?}");
    assert_eq!(lazy.cells_built(), (needed.len() as u64, all as u64));
    // Asked again, nothing more is built.
    for &(pose, pin) in &queries {
        let _ = lazy.answer(&a, pose, pin);
    }
    assert_eq!(lazy.built_now().0 as usize, needed.len());
    let merged = lazy.merged().expect("cells were built");
    assert_eq!(merged.stats.built_cells as usize, needed.len());
    let unbuilt: Vec<usize> = merged.unbuilt_cells().collect();
    assert_eq!(unbuilt.len(), all - needed.len());
    assert!(unbuilt.iter().all(|c| !needed.contains(c)));
    for (k, &(pose, pin)) in queries.iter().enumerate() {
        same_answer(
            whole.answer(model(), pose, pin, RADIUS),
            merged.answer(model(), pose, pin, RADIUS),
            &format!("merged, query {k}"),
        );
    }
    // Adopting a cell already built changes nothing; a cell adopted from the whole map into an
    // empty one answers as the whole map there.
    let root = *needed.first().unwrap();
    let mut again = merged.clone();
    again.adopt(root, &whole.cell(root).unwrap());
    assert_eq!(again, merged);
    let mut one = TierMap::unbuilt(&a);
    one.adopt(root, &whole.cell(root).unwrap());
    assert_eq!(one.stats.built_cells, 1);
    let (mine, theirs) = (one.cell(root).unwrap(), whole.cell(root).unwrap());
    assert_eq!((mine.nodes, mine.samples), (theirs.nodes, theirs.samples));
    for (k, &(pose, pin)) in queries.iter().enumerate() {
        if tier::cell_of_query(&a, pose, pin) == Some(root) {
            same_answer(
                whole.answer(model(), pose, pin, RADIUS),
                one.answer(model(), pose, pin, RADIUS),
                &format!("adopted, query {k}"),
            );
        }
    }
    // Written once, read back whole; a second write has nothing new to write.
    assert_eq!(lazy.persist().unwrap(), Some(file.clone()));
    assert_eq!(tier::cache::read(&file, &whole.key).unwrap(), merged);
    assert_eq!(lazy.persist().unwrap(), None);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A line on the map tier builds only the base cells its parts reach, and ends every part exactly
/// as the same line with the whole map built beforehand: the same records and the same work.
#[test]
fn a_map_scene_builds_only_the_cells_its_parts_reach_with_the_same_results() {
    let text = std::fs::read_to_string("scenarios/quickstart.toml").unwrap();
    let line = "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"";
    // A grid no other test uses: this process's lazy map of it starts empty.
    let map_text = text.replace(line, "fidelity = \"map\"\nmap_grid = [20, 10, 1]");
    let scene = pinfeed::scenario::parse(Path::new("q.toml"), &map_text).unwrap();
    let pins = contact_map::load(&scene, None);
    assert_eq!(pins.len(), 3);
    assert_eq!(pins[0].map.cells_built(), (0, 200));
    let opts = RunOptions {
        parts: 200,
        keep_records: true,
        ..RunOptions::from_scene(&scene)
    };
    let lazy = engine::run(&scene, &opts, &mut |_| {}).unwrap();
    let (built, all) = pins[0].map.cells_built();
    assert!(built > 0 && built * 2 < all, "{built} of {all} cells built");
    assert_eq!(pins[0].map.built_now().0, built);
    // The whole map, built before the run, replaces the lazy one in this process.
    let prepared = contact_map::prepare(&scene, None);
    assert!(prepared[0].1.map.is_complete());
    assert_eq!(
        contact_map::load(&scene, None)[0].map.cells_built(),
        (200, 200)
    );
    let whole = engine::run(&scene, &opts, &mut |_| {}).unwrap();
    assert_eq!(lazy.records.len(), whole.records.len());
    for (a, b) in lazy.records.iter().zip(&whole.records) {
        assert_eq!(
            (a.outcome, a.theta_out_deg.to_bits()),
            (b.outcome, b.theta_out_deg.to_bits()),
            "part {}",
            a.part
        );
    }
    assert_eq!(
        serde_json::to_string(&lazy.summary.work).unwrap(),
        serde_json::to_string(&whole.summary.work).unwrap()
    );
}

/// A fresh folder `name` holding the quickstart on a small map grid (`q.toml`).
fn quickstart_on_a_small_map(name: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string("scenarios/quickstart.toml")
        .unwrap()
        .replace(
            "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"",
            "fidelity = \"map\"\nmap_grid = [12, 6, 1]",
        );
    let scene = dir.join("q.toml");
    std::fs::write(&scene, text).unwrap();
    (dir, scene)
}

/// `pinfeed run` on a map scene says what the cache held before the run and how many cells the
/// line built, writes them to the cache folder, and a second run finds them all there and builds
/// nothing, with the same summary.
#[test]
fn run_builds_the_cells_its_parts_reach_into_the_cache_and_reuses_them() {
    let (dir, scene) = quickstart_on_a_small_map("run-lazy");
    let cache = dir.join("cache");
    let run = |out: &str| {
        let o = crate::support::pinfeed_ok(&[
            "run",
            scene.to_str().unwrap(),
            "--parts",
            "60",
            "--out",
            dir.join(out).to_str().unwrap(),
            "--cache-dir",
            cache.to_str().unwrap(),
        ]);
        let text = String::from_utf8(o.stdout).unwrap();
        let summary =
            std::fs::read_to_string(dir.join(out).join("quickstart/summary.json")).unwrap();
        (text, summary)
    };
    let number = |text: &str, after: &str| -> u64 {
        let at = text
            .find(after)
            .unwrap_or_else(|| panic!("{after:?} in {text}"));
        let digits: String = text[at + after.len()..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        digits.parse().unwrap()
    };
    let (first, s1) = run("a");
    assert!(
        first.contains("before the run: 0 of 72 base cells in the cache"),
        "{first}"
    );
    let line = first
        .lines()
        .find(|l| l.contains("built as parts reached them"))
        .expect(&first);
    let built = number(line, "  ");
    assert!(built > 0 && built < 72, "{line}");
    assert!(line.contains("written to"), "{line}");
    let files: Vec<_> = std::fs::read_dir(&cache).unwrap().collect();
    assert_eq!(files.len(), 1);
    let (second, s2) = run("b");
    assert!(
        second.contains(&format!(
            "before the run: {built} of 72 base cells in the cache"
        )),
        "{second}"
    );
    assert!(second.contains("no base cell built"), "{second}");
    assert_eq!(s1, s2);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A cache folder that cannot be written costs the next run its cells, nothing else: the run
/// succeeds, says the cells were not written, and warns once.
#[test]
fn a_cache_that_cannot_be_written_warns_once_and_the_run_goes_on() {
    let (dir, scene) = quickstart_on_a_small_map("run-unwritable");
    // A file where the folder should be: nothing can be created under it.
    let blocker = dir.join("file");
    std::fs::write(&blocker, "").unwrap();
    let o = crate::support::pinfeed(&[
        "run",
        scene.to_str().unwrap(),
        "--parts",
        "30",
        "--out",
        dir.join("out").to_str().unwrap(),
        "--cache-dir",
        blocker.join("cache").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (out, err) = (
        String::from_utf8(o.stdout).unwrap(),
        String::from_utf8(o.stderr).unwrap(),
    );
    assert!(out.contains("not written (see the warning)"), "{out}");
    assert_eq!(err.matches("warning: map cache file").count(), 1, "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// What a build told its observer, in order.
#[derive(Debug, Clone, PartialEq)]
enum Told {
    Progress(u64, u64),
    Forecast(pinfeed::progress::Forecast),
}

#[derive(Default)]
struct Watcher(std::sync::Mutex<Vec<Told>>);

impl pinfeed::progress::Observer for Watcher {
    fn progress(&self, done: u64, total: u64) {
        self.0.lock().unwrap().push(Told::Progress(done, total));
    }
    fn forecast(&self, forecast: &pinfeed::progress::Forecast) {
        self.0
            .lock()
            .unwrap()
            .push(Told::Forecast(forecast.clone()));
    }
}

/// A build of more than one batch of base cells computes every cell's first level, refines a
/// probe of the cells that need it, and says how long the rest will take before building it:
/// the forecast comes once, right after the probe's cells are counted, and its pushes (the first
/// level and the probe's, measured; the rest's, forecast) are those of the build within a factor
/// of two. A build of one batch forecasts nothing.
#[test]
fn a_build_of_many_cells_forecasts_the_rest_before_building_it() {
    let a = inputs(small());
    let watch = Watcher::default();
    let loaded = tier::load_or_build_cells(&a, None, None, &watch);
    let told = watch.0.into_inner().unwrap();
    let Source::Built {
        cells: 32,
        forecast: Some(f),
        ..
    } = loaded.source
    else {
        panic!("{:?}", loaded.source)
    };
    assert_eq!(f.cells, 32);
    assert!(f.refining > 0 && f.refining <= 32, "{f:?}");
    let probe = f.refining.div_ceil(16).clamp(8, 24).min(f.refining);
    assert_eq!(f.probe_cells, probe);
    // Told in order: none built, the probe built, the forecast, then the rest to the end.
    assert_eq!(told[0], Told::Progress(0, 32));
    assert_eq!(told[1], Told::Progress(probe, 32));
    match &told[2] {
        Told::Forecast(g) => {
            assert_eq!(g.seconds_left, f.seconds_left);
            assert!(
                g.said.contains("32 base cells to build")
                    && g.said.contains(&format!("leaves {} to refine", f.refining))
                    && g.said.contains(&format!("about {} pushes", f.pushes_left)),
                "{}",
                g.said
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        told.iter()
            .filter(|t| matches!(t, Told::Forecast(_)))
            .count(),
        1
    );
    assert_eq!(told.last(), Some(&Told::Progress(32, 32)));
    // The forecast's pushes against the build's.
    let made = loaded.map.stats.exact_samples;
    let forecast = f.first_pushes + f.probe_pushes + f.pushes_left;
    assert!(f.first_pushes + f.probe_pushes <= made);
    assert!(
        forecast as f64 <= 2.0 * made as f64 && made as f64 <= 2.0 * forecast as f64,
        "forecast {forecast} pushes, built with {made}"
    );
    assert!(f.seconds_left.is_finite() && f.seconds_left >= 0.0);
    assert!(loaded.describe().contains("forecast after its first level"));
    // The same map as a build told nothing.
    assert_eq!(*loaded.map, tier::build(&a));
    // One batch: no forecast.
    let watch = Watcher::default();
    let few: Vec<usize> = (0..24).collect();
    let loaded = tier::load_or_build_cells(&a, None, Some(&few), &watch);
    assert!(matches!(
        loaded.source,
        Source::Built {
            cells: 24,
            forecast: None,
            ..
        }
    ));
    let told = watch.0.into_inner().unwrap();
    assert!(
        told.iter().all(|t| matches!(t, Told::Progress(..))),
        "{told:?}"
    );
}
