//! The extension module `pinfeed._native` of the Python package `pinfeed` (docs/python.md): the
//! library's front door — a part, one push, a line run, a Monte Carlo study and a design — called
//! through the same library entry points as the `pinfeed` command (src/cli/), with the results as
//! the JSON documents the command prints with `--json` (the Python layer, python/pinfeed/, turns
//! them into dicts and NumPy arrays).
//!
//! Every error is a `pinfeed.PinfeedError` (a `ValueError`) whose message is the command line's
//! message with its causes (`error: …` on standard error, without the `error: `); a setting is
//! named by its Python keyword (`mu_c`) where the command names its flag (`--mu-c`). The GIL is
//! released while the library works.

use pinfeed::contact_case::report::report;
use pinfeed::contact_case::{parse_fence, parse_model, run_case, Case, CaseError};
use pinfeed::engine::RunOptions;
use pinfeed::geometry::named;
use pinfeed::plan::design::{
    self, DesignOptions, FenceSettings, Mode, Objective, UncertaintyChoice,
};
use pinfeed::plan::problem::parse_mu_c_range;
use pinfeed::plan::{FeedKind, Problem};
use pinfeed::report::part_report::PartReport;
use pinfeed::report::plan_summary::{self, write_design, DesignPaths};
use pinfeed::report::versioned;
use pinfeed::study::mc::report as mc_report;
use pinfeed::study::mc::{run as mc_run, MAX_SAMPLES};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyCFunction, PyDict, PyTuple};
use pyo3::IntoPyObjectExt;
use std::ffi::CStr;
use std::path::PathBuf;

create_exception!(
    pinfeed,
    PinfeedError,
    PyValueError,
    "An input pinfeed refuses, or a run that could not be carried out; the message is the command \
     line's (with the Python keyword where the command names a flag)."
);

/// An error and its causes, as the command line prints it (anyhow's `{:#}`: each cause after a
/// colon).
fn message(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

fn error(e: &dyn std::error::Error) -> PyErr {
    PinfeedError::new_err(message(e))
}

fn refuse(text: String) -> PyErr {
    PinfeedError::new_err(text)
}

/// A setting's name in messages: the Python keyword, which is the library's field name.
fn keyword(field: &str) -> String {
    field.to_string()
}

/// The part a spec names (`tripoly1`, `rect:2:1`, `vertices:0,0 4,0 …`): what `pinfeed part
/// --json` prints, as JSON text. A spec that names no part is refused with the reason, as
/// `pinfeed contact` refuses it (`part 'SPEC': …`).
fn part(py: Python<'_>, spec: &str) -> PyResult<String> {
    py.detach(|| {
        let poly = named::part_from_spec(spec).map_err(|source| {
            error(&CaseError::Part {
                part: spec.to_string(),
                source,
            })
        })?;
        let name = if spec.trim().to_lowercase().starts_with("vertices:") {
            "vertices"
        } else {
            spec
        };
        versioned::pretty(&PartReport::of(&poly, name)).map_err(|e| error(&e))
    })
}

/// One pin (or fence) pass, as `pinfeed contact --json` prints it (JSON text).
#[allow(clippy::too_many_arguments)]
fn push(
    py: Python<'_>,
    part: &str,
    theta0: f64,
    d: f64,
    mu_c: f64,
    model: &str,
    mu_s: f64,
    pin_radius: f64,
    pin_speed: f64,
    support: &str,
    tol: f64,
    fence: Option<&str>,
    tail: Option<f64>,
) -> PyResult<String> {
    py.detach(|| {
        let model = parse_model(model).map_err(|e| error(&e))?;
        let fence = fence
            .map(|f| parse_fence(f, "fence"))
            .transpose()
            .map_err(|e| error(&e))?;
        let c = Case {
            model,
            mu_s,
            pin_radius,
            pin_speed,
            support: support.to_string(),
            tol,
            fence,
            fence_tail: tail,
            ..Case::new(part, theta0, d, mu_c)
        };
        let (poly, out, _) = run_case(&c, false, &keyword).map_err(|e| error(&e))?;
        let r = report(&c, &out).with_pin_positions(&c, poly.radius(), &out);
        versioned::pretty(&r).map_err(|e| error(&e))
    })
}

/// The per-part records of a run as columns (sorted by part index), the per-part CSV's.
#[derive(Default)]
struct Columns {
    part: Vec<u64>,
    arrival_s: Vec<f64>,
    end_s: Vec<f64>,
    outcome: Vec<&'static str>,
    cause: Vec<&'static str>,
    contacts: Vec<u32>,
    theta_in_deg: Vec<f64>,
    theta_out_deg: Vec<f64>,
    y_in_m: Vec<f64>,
    y_out_m: Vec<f64>,
}

/// A line run of a scenario file or bundled scenario, as `pinfeed run SCENARIO` runs it (same
/// seed, same numbers): the summary's JSON (`pinfeed run --json`) and the per-part records as a
/// dict of lists. Writes no file.
fn run<'py>(
    py: Python<'py>,
    scenario: PathBuf,
    parts: Option<u64>,
    seed: Option<u64>,
) -> PyResult<(String, Bound<'py, PyDict>)> {
    let (json, cols) = py.detach(|| -> PyResult<(String, Columns)> {
        let scene = pinfeed::study::bundled::load_scenario(&scenario).map_err(|e| error(&e))?;
        let mut opts = RunOptions::from_scene(&scene);
        opts.online = pinfeed::engine::prepare::online_model(&scene).map_err(|e| error(&e))?;
        if let Some(n) = parts {
            if !(1..=1_000_000_000).contains(&n) {
                return Err(refuse(format!(
                    "parts must lie in [1, 1000000000], got {n}"
                )));
            }
            opts.parts = n;
        }
        if let Some(s) = seed {
            opts.seed = s;
        }
        opts.keep_records = true;
        let result = pinfeed::engine::run(&scene, &opts, &mut |_| {})
            .map_err(|e| refuse(format!("running {}: {}", scenario.display(), message(&e))))?;
        let json = versioned::pretty(&result.summary).map_err(|e| error(&e))?;
        let mut records: Vec<_> = result.records.iter().collect();
        records.sort_by_key(|r| r.part);
        let mut c = Columns::default();
        for r in records {
            c.part.push(r.part);
            c.arrival_s.push(r.arrival_s);
            c.end_s.push(r.end_s);
            c.outcome.push(r.outcome.name());
            c.cause.push(r.cause.name());
            c.contacts.push(r.contacts);
            c.theta_in_deg.push(r.theta_in_deg);
            c.theta_out_deg.push(r.theta_out_deg);
            c.y_in_m.push(r.y_in_m);
            c.y_out_m.push(r.y_out_m);
        }
        Ok((json, c))
    })?;
    let d = PyDict::new(py);
    d.set_item("part", cols.part)?;
    d.set_item("arrival_s", cols.arrival_s)?;
    d.set_item("end_s", cols.end_s)?;
    d.set_item("outcome", cols.outcome)?;
    d.set_item("cause", cols.cause)?;
    d.set_item("contacts", cols.contacts)?;
    d.set_item("theta_in_deg", cols.theta_in_deg)?;
    d.set_item("theta_out_deg", cols.theta_out_deg)?;
    d.set_item("y_in_m", cols.y_in_m)?;
    d.set_item("y_out_m", cols.y_out_m)?;
    Ok((json, d))
}

/// A Monte Carlo study (a study file or a bundled study), as `pinfeed mc STUDY` runs it: the
/// report's JSON (`pinfeed mc --json`, the same numbers for any number of threads) and the
/// study's warnings. Writes no file.
fn mc(
    py: Python<'_>,
    study: PathBuf,
    samples: Option<u64>,
    threads: Option<usize>,
) -> PyResult<(String, Vec<String>)> {
    py.detach(|| {
        if let Some(n) = samples {
            if !(1..=MAX_SAMPLES).contains(&n) {
                return Err(refuse(format!(
                    "samples must lie in [1, {}], got {n}",
                    MAX_SAMPLES
                )));
            }
        }
        if let Some(t) = threads {
            if !(1..=1024).contains(&t) {
                return Err(refuse(format!("threads must lie in [1, 1024], got {t}")));
            }
        }
        let s = pinfeed::study::bundled::load_study(&study, samples).map_err(|e| error(&e))?;
        let header = mc_report::StudyHeader::of(&s);
        let total = s.total_samples();
        let tallies = mc_run::run_range_with_threads(&s, 0..total, threads, &|| {})
            .map_err(|e| refuse(format!("running {}: {}", study.display(), message(&e))))?;
        let tallies: Vec<_> = (0..s.points.len())
            .map(|j| tallies.get(&j).cloned().unwrap_or_default())
            .collect();
        let r = mc_report::build(&header, &tallies);
        Ok((mc_report::json(&r), s.warnings()))
    })
}

/// The settings of a design, by the names of `pinfeed plan`'s flags (`--time-limit` →
/// `time_limit`); None keeps the command's default.
#[derive(Debug, Default)]
struct PlanSettings {
    scale: Option<f64>,
    name: Option<String>,
    modes: Option<Vec<String>>,
    objective: Option<String>,
    feed: Option<String>,
    jitter: Option<f64>,
    lateral: Option<f64>,
    mu_c: Option<f64>,
    uncertainty: Option<String>,
    mu_c_range: Option<String>,
    tripod: Option<bool>,
    pin_radius: Option<f64>,
    belt_width: Option<f64>,
    spacing: Option<f64>,
    max_pins: Option<usize>,
    tolerance: Option<f64>,
    target: Option<f64>,
    goal: Option<f64>,
    time_limit: Option<f64>,
    check_parts: Option<u64>,
    screen_parts: Option<u64>,
    refine: Option<usize>,
    margins: Option<bool>,
    mu_f: Option<f64>,
    seed: Option<u64>,
    command: Option<String>,
}

/// The design options of `part` and the settings: the command's defaults (`pinfeed plan --part
/// PART`) for what is not given.
fn options(part: &str, s: PlanSettings) -> PyResult<DesignOptions> {
    let mut p = Problem::new(part);
    let default_time = DesignOptions::new(Problem::new(part)).time_limit_s;
    p.scale = s.scale.unwrap_or(p.scale);
    if let Some(f) = &s.feed {
        p.feed = FeedKind::from_name(f).ok_or_else(|| {
            refuse(format!(
                "feed '{}': expected 'stable' or 'uniform'",
                f.trim()
            ))
        })?;
    }
    p.jitter_deg = s.jitter.unwrap_or(p.jitter_deg);
    p.lateral_m = s.lateral.unwrap_or(p.lateral_m);
    p.mu_c = s.mu_c.unwrap_or(p.mu_c);
    if let Some(r) = &s.mu_c_range {
        p.mu_c_range = Some(parse_mu_c_range(r).map_err(|e| refuse(format!("mu_c_range {e}")))?);
    }
    p.tripod = s.tripod.unwrap_or(false);
    if let Some(r) = s.pin_radius {
        p.set_pin_radius_units(r).map_err(|e| error(&e))?;
    }
    p.belt_width_m = s.belt_width.unwrap_or(p.belt_width_m);
    p.spacing_m = s.spacing.unwrap_or(p.spacing_m);
    p.max_pins = s.max_pins.unwrap_or(p.max_pins);
    p.tolerance_deg = s.tolerance.unwrap_or(p.tolerance_deg);
    p.target = s.target.unwrap_or(p.target);
    p.goal_deg = s.goal;
    let time_limit = s.time_limit.unwrap_or(default_time);
    p.time_limit_s = time_limit;
    p.seed = s.seed.unwrap_or(p.seed);
    p.compile().map_err(|e| error(&e))?;
    let mut o = DesignOptions::new(p);
    if let Some(modes) = &s.modes {
        let mut chosen = Vec::new();
        for m in modes {
            match m.trim() {
                "pins" => chosen.push(Mode::Pins),
                "fences" => chosen.push(Mode::Fences),
                "sensor" => chosen.push(Mode::Sensor),
                other => {
                    return Err(refuse(format!(
                        "modes: '{other}': expected 'pins', 'fences' or 'sensor'"
                    )))
                }
            }
        }
        let has = |m: Mode| chosen.contains(&m);
        let selected = Mode::selected(has(Mode::Pins), has(Mode::Fences), has(Mode::Sensor));
        if !selected.is_empty() {
            o.modes = selected;
        }
    }
    if let Some(obj) = &s.objective {
        o.objective = obj
            .parse::<Objective>()
            .map_err(|e| refuse(format!("objective {e}")))?;
    }
    if let Some(n) = s.check_parts {
        o.check_parts = n;
    }
    let screen = s.screen_parts.unwrap_or(o.screen_parts);
    o.screen_parts = screen.min(o.check_parts.max(1));
    if let Some(n) = s.refine {
        o.refine = n;
    }
    o.time_limit_s = time_limit;
    o.fences = FenceSettings {
        mu_f: s.mu_f,
        ..FenceSettings::default()
    };
    o.belt_width_given = s.belt_width.is_some();
    o.margins = s.margins.unwrap_or(true);
    o.uncertainty = match s.uncertainty.as_deref().map(str::trim) {
        None | Some("default") => UncertaintyChoice::Default,
        Some("robust") => UncertaintyChoice::Robust,
        Some("nominal") => UncertaintyChoice::Nominal,
        Some(other) => {
            return Err(refuse(format!(
                "uncertainty '{other}': expected 'default', 'robust' or 'nominal'"
            )))
        }
    };
    if let Some(n) = s.name {
        o.name = n;
    }
    if let Some(c) = s.command {
        o.command = c;
    }
    Ok(o)
}

/// A design for a part, as `pinfeed plan --part PART --json` prints it (JSON text, its
/// `scenario` the design's scenario as TOML text). Writes the design's files (scenario, policy,
/// drawing) only when `out` is given (the scenario's path, as `--out`).
fn plan(
    py: Python<'_>,
    part: &str,
    settings: PlanSettings,
    out: Option<PathBuf>,
) -> PyResult<String> {
    py.detach(|| {
        let o = options(part, settings)?;
        let d = design::design(&o, &|_| {}).map_err(|e| error(&e))?;
        let files = match &out {
            None => Vec::new(),
            Some(path) => {
                let sensor = d
                    .chosen()
                    .is_some_and(|c| matches!(c.layout, design::Layout::Contingent(_)));
                let paths = DesignPaths::new(Some(path.as_path()), None, &o, sensor);
                write_design(&o, &d, &paths).map_err(|e| error(&e))?
            }
        };
        plan_summary::json(&o, &d, files).map_err(|e| error(&e))
    })
}

/// The bundled scenarios and studies: (name, kind, description).
fn examples() -> Vec<(String, String, String)> {
    pinfeed::study::bundled::all()
        .iter()
        .map(|b| {
            let kind = match b.kind() {
                pinfeed::study::bundled::Kind::Scenario => "scenario",
                pinfeed::study::bundled::Kind::Study => "study",
            };
            (b.name().into(), kind.into(), b.description().into())
        })
        .collect()
}

/// A positional argument of a native function (the Python layer passes every one).
fn arg<'py, T: FromPyObjectOwned<'py>>(args: &Bound<'py, PyTuple>, i: usize) -> PyResult<T>
where
    for<'a> <T as FromPyObject<'a, 'py>>::Error: Into<PyErr>,
{
    args.get_item(i)?.extract::<T>().map_err(Into::into)
}

/// An item of a settings dict: None when missing or None.
fn item<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Option<T>>
where
    for<'a> <T as FromPyObject<'a, 'py>>::Error: Into<PyErr>,
{
    match d.get_item(key)? {
        Some(v) if !v.is_none() => v.extract::<T>().map(Some).map_err(Into::into),
        _ => Ok(None),
    }
}

impl PlanSettings {
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<PlanSettings> {
        Ok(PlanSettings {
            scale: item(d, "scale")?,
            name: item(d, "name")?,
            modes: item(d, "modes")?,
            objective: item(d, "objective")?,
            feed: item(d, "feed")?,
            jitter: item(d, "jitter")?,
            lateral: item(d, "lateral")?,
            mu_c: item(d, "mu_c")?,
            uncertainty: item(d, "uncertainty")?,
            mu_c_range: item(d, "mu_c_range")?,
            tripod: item(d, "tripod")?,
            pin_radius: item(d, "pin_radius")?,
            belt_width: item(d, "belt_width")?,
            spacing: item(d, "spacing")?,
            max_pins: item(d, "max_pins")?,
            tolerance: item(d, "tolerance")?,
            target: item(d, "target")?,
            goal: item(d, "goal")?,
            time_limit: item(d, "time_limit")?,
            check_parts: item(d, "check_parts")?,
            screen_parts: item(d, "screen_parts")?,
            refine: item(d, "refine")?,
            margins: item(d, "margins")?,
            mu_f: item(d, "mu_f")?,
            seed: item(d, "seed")?,
            command: item(d, "command")?,
        })
    }
}

/// A function of the module: its positional arguments to a Python object.
type Native = fn(&Bound<'_, PyTuple>) -> PyResult<Py<PyAny>>;

/// A Rust value as a Python object.
fn object<'py, T: IntoPyObject<'py>>(py: Python<'py>, value: T) -> PyResult<Py<PyAny>> {
    value.into_py_any(py)
}

/// The module's functions: name, docstring, body. Written without PyO3's procedural macros,
/// whose `syn` features would make cargo compile the library a second time for this crate
/// instead of reusing the command's build (crates/pinfeed-py/Cargo.toml).
const FUNCTIONS: [(&CStr, &CStr, Native); 6] = [
    (c"part", c"part(spec) -> JSON of `pinfeed part --json`", |a| {
        object(a.py(), part(a.py(), &arg::<String>(a, 0)?)?)
    }),
    (
        c"push",
        c"push(part, theta0, d, mu_c, model, mu_s, pin_radius, pin_speed, support, tol, fence, tail) -> JSON of `pinfeed contact --json`",
        |a| {
            let json = push(
                a.py(),
                &arg::<String>(a, 0)?,
                arg(a, 1)?,
                arg(a, 2)?,
                arg(a, 3)?,
                &arg::<String>(a, 4)?,
                arg(a, 5)?,
                arg(a, 6)?,
                arg(a, 7)?,
                &arg::<String>(a, 8)?,
                arg(a, 9)?,
                arg::<Option<String>>(a, 10)?.as_deref(),
                arg(a, 11)?,
            )?;
            object(a.py(), json)
        },
    ),
    (
        c"run",
        c"run(scenario, parts, seed) -> (JSON of `pinfeed run --json`, per-part columns)",
        |a| {
            let out = run(a.py(), arg(a, 0)?, arg(a, 1)?, arg(a, 2)?)?;
            object(a.py(), out)
        },
    ),
    (
        c"mc",
        c"mc(study, samples, threads) -> (JSON of `pinfeed mc --json`, warnings)",
        |a| object(a.py(), mc(a.py(), arg(a, 0)?, arg(a, 1)?, arg(a, 2)?)?),
    ),
    (
        c"plan",
        c"plan(part, settings, out) -> JSON of `pinfeed plan --json`",
        |a| {
            let settings = PlanSettings::from_dict(&arg::<Bound<'_, PyDict>>(a, 1)?)?;
            let json = plan(a.py(), &arg::<String>(a, 0)?, settings, arg(a, 2)?)?;
            object(a.py(), json)
        },
    ),
    (
        c"examples",
        c"examples() -> [(name, kind, description)]",
        |a| object(a.py(), examples()),
    ),
];

/// The module's definition, which CPython reads when it creates the module and keeps.
static mut DEFINITION: pyo3::ffi::PyModuleDef = pyo3::ffi::PyModuleDef {
    m_base: pyo3::ffi::PyModuleDef_HEAD_INIT,
    m_name: c"pinfeed._native".as_ptr(),
    m_doc: c"The library's entry points for the Python package pinfeed (docs/python.md).".as_ptr(),
    // No per-module state: the functions hold none.
    m_size: -1,
    m_methods: std::ptr::null_mut(),
    m_slots: std::ptr::null_mut(),
    m_traverse: None,
    m_clear: None,
    m_free: None,
};

/// The module `pinfeed._native` with the exception, the versions and [`FUNCTIONS`].
fn module(py: Python<'_>) -> PyResult<Bound<'_, PyModule>> {
    // SAFETY: the definition is a static that lives as long as the process and that only
    // CPython touches; a null result is turned into the error CPython set.
    let m = unsafe {
        let raw = pyo3::ffi::PyModule_Create(std::ptr::addr_of_mut!(DEFINITION));
        Bound::from_owned_ptr_or_err(py, raw)?.cast_into_unchecked::<PyModule>()
    };
    m.add("PinfeedError", py.get_type::<PinfeedError>())?;
    m.add("__version__", pinfeed::PINFEED_VERSION)?;
    m.add("SCHEMA_VERSION", pinfeed::SCHEMA_VERSION)?;
    for (name, doc, f) in FUNCTIONS {
        let function = PyCFunction::new_closure(py, Some(name), Some(doc), move |a, _| f(a))?;
        m.add(name.to_str().unwrap_or_default(), function)?;
    }
    Ok(m)
}

/// The module's initialisation, which CPython calls on `import pinfeed._native`: the module,
/// or NULL with the exception set (an error here is an ImportError's cause, never a panic).
#[no_mangle]
pub extern "C" fn PyInit__native() -> *mut pyo3::ffi::PyObject {
    Python::attach(|py| match module(py) {
        Ok(m) => m.into_ptr(),
        Err(e) => {
            e.restore(py);
            std::ptr::null_mut()
        }
    })
}
