//! The map tier at the command line: `pinfeed run` loads or builds a scene's maps before the run
//! and says where they came from; `pinfeed contact --model map` answers one pin push from the map
//! of its (part, support, pin radius, μc, tolerance), or exactly where the map cannot vouch for it,
//! and says which.

use super::contact::{case_of, ContactArgs};
use anyhow::{bail, Result};
use pinfeed::contact_case::maps::{self, TierSource};
use pinfeed::contact_case::report::report;
use pinfeed::contact_case::{case_geometry, check_geometry, check_inputs, compile_part};
use pinfeed::engine::contact_map;
use pinfeed::geometry::{Pose, Vec2};
use pinfeed::maps::tier::{self, push_with_map, Loaded};
use pinfeed::mechanics::{ContactSettings, Fidelity, PartModel, Support};
use pinfeed::scenario::Scene;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The cache folder: the one given, else the default (see [`tier::default_cache_dir`]).
fn cache_dir(dir: Option<&Path>) -> PathBuf {
    dir.map_or_else(tier::default_cache_dir, Path::to_path_buf)
}

/// For a scene with `fidelity = "map"`: read what the cache folder `dir` holds of its maps
/// before the run (the line builds the base cells its parts reach, [`persist_maps`] writes them
/// back) and return the lines that say so (empty for any other scene, which pays nothing).
pub fn prepare_maps(scene: &Scene, dir: Option<&Path>, quiet: bool) -> String {
    if scene.map_tier.is_none() {
        return String::new();
    }
    let dir = cache_dir(dir);
    if !quiet {
        eprintln!(
            "map tier: reading maps from {}; base cells not there are built as parts reach them",
            dir.display()
        );
    }
    let pins = contact_map::load(scene, Some(&dir));
    let mut seen = BTreeSet::new();
    let mut text = String::new();
    for pin in &pins {
        for w in &pin.warnings {
            eprintln!("warning: {w}");
        }
        if seen.insert(pin.map.key()) {
            let (built, all) = pin.map.cells_built();
            text.push_str(&format!(
                "map {}  before the run: {built} of {all} base cells in the cache\n",
                pin.map.key()
            ));
        }
    }
    text
}

/// After a run of a scene with `fidelity = "map"`: write the base cells its line built back to
/// the cache and return the lines that say what was built and where it went.
pub fn persist_maps(scene: &Scene) -> String {
    if scene.map_tier.is_none() {
        return String::new();
    }
    let mut text = String::new();
    for p in contact_map::persist(scene) {
        if let Some(w) = &p.warning {
            eprintln!("warning: {w}");
        }
        let (now, all) = p.cells;
        let line = if p.built == 0 {
            format!("no base cell built: the cache held every cell the parts reached ({now} of {all} built)")
        } else {
            let whereto = match &p.written {
                Some(f) => format!(", written to {}", f.display()),
                None if p.warning.is_some() => ", not written (see the warning)".to_string(),
                None => ", kept in memory only".to_string(),
            };
            format!(
                "{} base cell(s) built as parts reached them, {:.2} s of the run's wall time; {now} of {all} built now{whereto}",
                p.built, p.seconds
            )
        };
        text.push_str(&format!("map {}  {line}\n", p.key));
    }
    text
}

/// `pinfeed contact --model map`: one still-pin push from the map.
pub fn run(args: &ContactArgs) -> Result<()> {
    if args.fence.is_some() || args.pin_speed != 0.0 || args.trace.is_some() || args.plot.is_some()
    {
        bail!("--model map answers still-pin pushes only, without --trace or --plot (the map keeps no path); use --model exact for fences, moving pins, traces and plots");
    }
    let c = case_of(args, Fidelity::Exact)?;
    check_inputs(&c, &super::flag)?;
    let (poly, model) = compile_part(&c.part, &c.support)?;
    check_geometry(&c, &poly, &super::flag)?;
    let support = Support::parse(&c.support, &poly).map_err(anyhow::Error::msg)?;
    let settings = ContactSettings {
        mu_c: c.mu_c,
        mu_s: c.mu_s,
        tol: c.tol,
        ..ContactSettings::default()
    };
    let (pose, start) = case_geometry(&poly, &c);
    // Only the base cell of the query is built (and kept in the cache beside any built before).
    let source = TierSource {
        grid: args.push.map_grid.clone(),
        cache_dir: args.push.cache_dir.clone(),
    };
    let loaded = load_tier(
        (&model, &support, c.pin_radius, settings),
        &source,
        Some(&[(pose, start)]),
        args.json || args.quiet,
    )?;
    let started = Instant::now();
    let (out, why) = push_with_map(&loaded.map, &model, pose, start, c.pin_radius, &settings);
    let query_s = started.elapsed().as_secs_f64();
    let mut r = report(&c, &out);
    r.model = "map".into();
    let served = match why {
        None => "map".to_string(),
        Some(w) => format!("exact ({})", w.name()),
    };
    let file = loaded.file.as_ref().map(|p| p.display().to_string());
    if args.json {
        let mut v = serde_json::to_value(&r)?;
        v["map"] = serde_json::json!({
            "answered_by": served,
            "key": loaded.map.key.to_string(),
            "file": file,
            "source": loaded.describe(),
            "query_s": query_s,
        });
        crate::out!("{}", pinfeed::report::versioned::pretty(&v)?);
        return Ok(());
    }
    crate::outln!(
        "part {}  model map  θ0 {}°  d {}  μc {}",
        r.part,
        r.theta0_deg,
        r.d,
        r.mu_c
    );
    if r.contact {
        crate::out!("{}", r.motion_text());
    } else {
        crate::outln!("no contact: the pin passes the part");
    }
    crate::outln!("status              {}", r.status);
    crate::outln!("answered by         {served} in {:.1} µs", query_s * 1e6);
    crate::outln!(
        "map                 {}  {}",
        loaded.map.key,
        loaded.describe()
    );
    if let Some(f) = file {
        crate::outln!("map file            {f}");
    }
    Ok(())
}

/// The map of (part, support, pin radius, contact settings) on the grid `--map-grid`, read from
/// the cache folder or built there — only the base cells of `queries` when they are given
/// ([`maps::load_tier`]); its warnings (a stale or corrupted file) go to standard error.
fn load_tier(
    inputs: (&PartModel, &Support, f64, ContactSettings),
    source: &TierSource,
    queries: Option<&[(Pose, Vec2)]>,
    quiet: bool,
) -> Result<Loaded> {
    let spec = maps::tier_spec(source, &super::flag)?;
    let bar = super::progress::bar(0, "base cells of the map built", quiet);
    bar.set_message("map tier ");
    let loaded = maps::load_tier(
        inputs,
        spec,
        source,
        queries,
        &super::progress::counter(&bar),
    );
    bar.finish_and_clear();
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    Ok(loaded)
}
