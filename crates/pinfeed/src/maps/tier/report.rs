//! What the map tier tells a user: where a map came from, how many passes of a configuration map
//! it answered, and the grid of `--map-grid T,D,DEPTH`.

use super::{Loaded, Source, TierMap, TierSpec};
use crate::geometry::Polygon;
use crate::maps::MapSettings;
use crate::mechanics::PartModel;

impl Loaded {
    /// One line on where the map came from.
    pub fn describe(&self) -> String {
        let st = &self.map.stats;
        let spec = &self.map.spec;
        let what = format!(
            "{} of {} base cells, {} exact pushes, {:.1}% of θ0 × d certified",
            st.built_cells,
            spec.theta_cells * spec.d_cells,
            st.exact_samples,
            100.0 * st.certified_area
        );
        match &self.source {
            Source::Built {
                seconds,
                cells,
                forecast,
            } => {
                let told = forecast.map_or(String::new(), |f| {
                    format!(
                        "; forecast after its first level and a probe of {} cells ({:.2} s): {:.1} s in all",
                        f.probe_cells,
                        f.first_seconds + f.probe_seconds,
                        f.seconds_in_all()
                    )
                });
                format!("{cells} base cell(s) built in {seconds:.2} s{told} ({what})")
            }
            Source::Disk(p) => format!("read from {} ({what})", p.display()),
            Source::Memory => format!("already loaded ({what})"),
        }
    }
}

/// How many of a configuration map's passes (`pinfeed map --model map`) the map answered, how
/// many the exact model computed and why.
pub fn served_line(
    map: &TierMap,
    poly: &Polygon,
    model: &PartModel,
    ds: &[f64],
    settings: &MapSettings,
) -> String {
    let grid = crate::maps::theta_grid(settings.theta_step_deg).unwrap_or_default();
    let mut served = 0usize;
    let mut why: std::collections::BTreeMap<&'static str, usize> = Default::default();
    for &d in ds {
        for &t in &grid {
            let (pose, start) = crate::maps::pass_start(poly, t, d, settings.pin.radius);
            match map.answer(model, pose, start, settings.pin.radius) {
                Ok(_) => served += 1,
                Err(w) => *why.entry(w.name()).or_default() += 1,
            }
        }
    }
    let total = ds.len() * grid.len();
    let exact: Vec<String> = why.iter().map(|(k, n)| format!("{k} {n}")).collect();
    format!(
        "map tier: {served} of {total} passes ({:.1}%) answered by the map (misses by the exact ray cast), {} exact ({})",
        100.0 * served as f64 / total.max(1) as f64,
        total - served,
        if exact.is_empty() { "none".to_string() } else { exact.join(", ") }
    )
}

/// A map grid (`T,D,DEPTH`) that is not three whole numbers in range. Its `Display` names the
/// setting `map_grid`; [`GridError::describe`] by the caller's name (`pinfeed contact`'s
/// `--map-grid`).
#[derive(Debug, Clone, PartialEq)]
pub enum GridError {
    /// A value that is not a whole number (the text given).
    Numbers(String),
    /// Not three values (the text given).
    Count(String),
    /// A value outside [4, 720] × [2, 200] × [0, 8] (θ0 cells, d cells, depth).
    Range(u32, u32, u32),
}

impl GridError {
    /// The message, with the grid setting named `name`.
    pub fn describe(&self, name: &str) -> String {
        match self {
            GridError::Numbers(t) => format!("{name} '{t}': expected T,D,DEPTH (whole numbers)"),
            GridError::Count(t) => format!("{name} '{t}': expected three numbers T,D,DEPTH"),
            GridError::Range(a, b, c) => {
                format!("{name} must lie in [4, 720] × [2, 200] × [0, 8], got {a},{b},{c}")
            }
        }
    }
}

impl std::fmt::Display for GridError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe("map_grid"))
    }
}

impl std::error::Error for GridError {}

impl TierSpec {
    /// Parse `T,D,DEPTH`: θ0 base cells, d base cells, refinement depth (the rest default).
    pub fn parse_grid(s: &str) -> Result<TierSpec, GridError> {
        let v: Vec<u32> = s
            .split(',')
            .map(|x| x.trim().parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|_| GridError::Numbers(s.to_string()))?;
        let [t, d, depth] = v[..] else {
            return Err(GridError::Count(s.to_string()));
        };
        if !((4..=720).contains(&t) && (2..=200).contains(&d) && depth <= 8) {
            return Err(GridError::Range(t, d, depth));
        }
        Ok(TierSpec {
            theta_cells: t,
            d_cells: d,
            max_depth: depth,
            ..TierSpec::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_errors_name_the_setting_by_its_field_or_by_the_callers_name() {
        for (text, start) in [
            ("a,b,c", "map_grid 'a,b,c': expected T,D,DEPTH"),
            ("4,2", "map_grid '4,2': expected three numbers"),
            (
                "3,2,0",
                "map_grid must lie in [4, 720] × [2, 200] × [0, 8], got 3,2,0",
            ),
        ] {
            let e = TierSpec::parse_grid(text).unwrap_err();
            let msg = e.to_string();
            assert!(msg.starts_with(start), "{msg}");
            assert_eq!(
                e.describe("--map-grid"),
                msg.replacen("map_grid", "--map-grid", 1)
            );
        }
        assert!(TierSpec::parse_grid("4,2,0").is_ok());
    }
}
