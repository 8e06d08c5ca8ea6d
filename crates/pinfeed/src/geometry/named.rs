//! Named parts (docs/physics.md#the-part) and the textual part specifications the CLI and scenarios accept.
//!
//! | spec | shape |
//! |---|---|
//! | `tripoly1` | right isosceles triangle, hypotenuse down: (−1.5,−0.5), (1.5,−0.5), (0,1) |
//! | `tripoly2` | right triangle, legs 2:1, long leg down: (−2/3,−1/3), (4/3,−1/3), (−2/3,2/3) |
//! | `square` | unit square |
//! | `rect:W:H` | W × H rectangle |
//! | `ngon:N` | regular N-gon of circumradius 1 with a flat bottom edge (3 ≤ N ≤ 1000) |
//! | `lshape` | concave L made of three unit squares |
//! | `random:SEED` or `random:SEED:N` | a seeded random star-shaped polygon (see [`random_vertices`]) |
//! | `vertices:x1,y1 x2,y2 …` | any simple polygon (also accepted by `--vertices`) |
//! | `FILE.dxf`, `FILE.csv` | the outline in a drawing or a CSV of `x,y` rows, in millimetres ([`super::cad`]) |

use super::cad::{is_part_file, read_part_file, PartFileOptions};
use super::polygon::{Polygon, PolygonError};
use super::vec2::Vec2;
use thiserror::Error;

/// Why a part specification could not be turned into a polygon.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PartSpecError {
    /// Not a known part name or form.
    #[error("unknown part '{0}'; expected one of tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, random:SEED[:N], vertices:\"x1,y1 x2,y2 ...\", FILE.dxf, FILE.csv")]
    Unknown(String),
    /// A known form with a parameter out of range or malformed (e.g. `ngon:2`).
    #[error("bad part '{spec}': {reason}")]
    BadParameter {
        /// The specification as given.
        spec: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A `vertices:` list that does not parse as `x,y` pairs.
    #[error("bad vertex list: {0}")]
    BadVertexList(String),
    /// The vertices do not make a valid polygon.
    #[error(transparent)]
    Polygon(#[from] PolygonError),
    /// A part file (`.dxf`, `.csv`) that could not be read into an outline.
    #[error(transparent)]
    File(#[from] super::cad::CadError),
}

/// Names accepted by [`part_from_spec`] (for help texts).
pub const PART_NAMES: &[&str] = &[
    "tripoly1",
    "tripoly2",
    "square",
    "rect:W:H",
    "ngon:N",
    "lshape",
    "random:SEED[:N]",
];

fn positive(spec: &str, what: &str, s: &str) -> Result<f64, PartSpecError> {
    let v: f64 = s.trim().parse().map_err(|_| PartSpecError::BadParameter {
        spec: spec.into(),
        reason: format!("{what} '{s}' is not a number"),
    })?;
    if !(v.is_finite() && v > 0.0) {
        return Err(PartSpecError::BadParameter {
            spec: spec.into(),
            reason: format!("{what} must be a positive finite number, got {s}"),
        });
    }
    Ok(v)
}

/// Vertex list of a part specification (before validation); an error for an unknown name or bad parameters.
pub fn named_vertices(spec: &str) -> Result<Vec<Vec2>, PartSpecError> {
    let s = spec.trim();
    let lower = s.to_ascii_lowercase();
    let v = |pts: &[(f64, f64)]| {
        pts.iter()
            .map(|&(x, y)| Vec2::new(x, y))
            .collect::<Vec<_>>()
    };
    match lower.as_str() {
        "tripoly1" => return Ok(v(&[(-1.5, -0.5), (1.5, -0.5), (0.0, 1.0)])),
        "tripoly2" => {
            return Ok(v(&[
                (-2.0 / 3.0, -1.0 / 3.0),
                (4.0 / 3.0, -1.0 / 3.0),
                (-2.0 / 3.0, 2.0 / 3.0),
            ]))
        }
        "square" => return Ok(v(&[(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)])),
        "lshape" => {
            return Ok(v(&[
                (0.0, 0.0),
                (2.0, 0.0),
                (2.0, 1.0),
                (1.0, 1.0),
                (1.0, 2.0),
                (0.0, 2.0),
            ]))
        }
        _ => {}
    }
    if let Some(rest) = lower.strip_prefix("rect:") {
        let parts: Vec<&str> = rest.split(':').collect();
        if parts.len() != 2 {
            return Err(PartSpecError::BadParameter {
                spec: s.into(),
                reason: "expected rect:W:H".into(),
            });
        }
        let w = positive(s, "width", parts[0])?;
        let h = positive(s, "height", parts[1])?;
        return Ok(v(&[
            (-w / 2.0, -h / 2.0),
            (w / 2.0, -h / 2.0),
            (w / 2.0, h / 2.0),
            (-w / 2.0, h / 2.0),
        ]));
    }
    if let Some(rest) = lower.strip_prefix("ngon:") {
        let n: usize = rest
            .trim()
            .parse()
            .map_err(|_| PartSpecError::BadParameter {
                spec: s.into(),
                reason: format!("'{rest}' is not a whole number of sides"),
            })?;
        if !(3..=1000).contains(&n) {
            return Err(PartSpecError::BadParameter {
                spec: s.into(),
                reason: format!("number of sides must be between 3 and 1000, got {n}"),
            });
        }
        let step = std::f64::consts::TAU / n as f64;
        let start = -std::f64::consts::FRAC_PI_2 - step / 2.0;
        return Ok((0..n)
            .map(|k| Vec2::from_angle(start + step * k as f64))
            .collect());
    }
    if let Some(rest) = lower.strip_prefix("random:") {
        return random_spec(s, rest);
    }
    if lower.starts_with("vertices:") {
        return parse_vertex_list(&s["vertices:".len()..]);
    }
    Err(PartSpecError::Unknown(s.into()))
}

fn random_spec(spec: &str, rest: &str) -> Result<Vec<Vec2>, PartSpecError> {
    let bad = |reason: String| PartSpecError::BadParameter {
        spec: spec.into(),
        reason,
    };
    let mut it = rest.split(':');
    let seed_text = it.next().unwrap_or("").trim();
    let seed: u64 = seed_text
        .parse()
        .map_err(|_| bad(format!("seed '{seed_text}' is not a whole number ≥ 0")))?;
    let n = match it.next() {
        None => None,
        Some(t) => {
            let n: usize = t
                .trim()
                .parse()
                .map_err(|_| bad(format!("'{t}' is not a whole number of vertices")))?;
            if !(3..=64).contains(&n) {
                return Err(bad(format!(
                    "number of vertices must be between 3 and 64, got {n}"
                )));
            }
            Some(n)
        }
    };
    if it.next().is_some() {
        return Err(bad("expected random:SEED or random:SEED:N".into()));
    }
    Ok(random_vertices(seed, n))
}

/// The vertices of `random:SEED[:N]`: a star-shaped polygon around the origin, drawn from the
/// seed's own stream ([`crate::random::stream`]`(seed, 0x706f6c79)`), the same on every machine.
/// N (default: drawn uniformly from 3…8) vertices at polar angles `φ0 + (k + u_k)·2π/N` with
/// `u_k` uniform in ±0.3 (so consecutive angles stay at least 0.4·2π/N apart and the polygon is
/// simple) and radii uniform in [0.6, 1.4]; φ0 uniform. About half the polygons of 5 or more
/// vertices come out concave. The parts a survey of "which polygons can pins orient" runs over.
pub fn random_vertices(seed: u64, n: Option<usize>) -> Vec<Vec2> {
    use rand::RngExt;
    let mut rng = crate::random::stream(seed, 0x706f_6c79);
    let n = n.unwrap_or_else(|| rng.random_range(3..=8usize));
    let step = std::f64::consts::TAU / n as f64;
    let phase = rng.random_range(0.0..std::f64::consts::TAU);
    (0..n)
        .map(|k| {
            let a = phase + step * (k as f64 + rng.random_range(-0.3..0.3));
            let r = rng.random_range(0.6..1.4);
            Vec2::from_angle(a) * r
        })
        .collect()
}

/// Parse `"x1,y1 x2,y2 ..."` (pairs separated by whitespace or semicolons).
pub fn parse_vertex_list(text: &str) -> Result<Vec<Vec2>, PartSpecError> {
    let mut out = Vec::new();
    for (k, tok) in text
        .split(|c: char| c.is_whitespace() || c == ';')
        .filter(|t| !t.is_empty())
        .enumerate()
    {
        let xy: Vec<&str> = tok.split(',').collect();
        if xy.len() != 2 {
            return Err(PartSpecError::BadVertexList(format!(
                "vertex {k} '{tok}' is not of the form x,y"
            )));
        }
        let parse = |s: &str| -> Result<f64, PartSpecError> {
            s.trim().parse::<f64>().map_err(|_| {
                PartSpecError::BadVertexList(format!("vertex {k}: '{s}' is not a number"))
            })
        };
        out.push(Vec2::new(parse(xy[0])?, parse(xy[1])?));
    }
    Ok(out)
}

/// Build a validated part from a specification (see the module table); a part file is read
/// with the default [`PartFileOptions`] (see [`part_from_spec_with`]).
pub fn part_from_spec(spec: &str) -> Result<Polygon, PartSpecError> {
    part_from_spec_with(spec, &PartFileOptions::default())
}

/// Build a validated part from a specification; a part file (`FILE.dxf`, `FILE.csv`, a path
/// relative to the working folder) is read with `file` ([`super::cad`]), its coordinates in
/// millimetres.
pub fn part_from_spec_with(spec: &str, file: &PartFileOptions) -> Result<Polygon, PartSpecError> {
    if is_part_file(spec) {
        let part = read_part_file(std::path::Path::new(spec.trim()), file)?;
        return Ok(part.polygon()?);
    }
    let v = named_vertices(spec)?;
    Ok(Polygon::new(&v)?)
}

/// The name of a vertex-list part (`vertices:…`): `custom-` and a hash of its text (FNV-1a over
/// the list with its spaces normalised, stable across runs and platforms), so that different parts
/// never share a folder or a design name.
pub fn custom_name(part: &str) -> String {
    let norm: String = part.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in norm.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("custom-{:08x}", (h >> 32) as u32 ^ h as u32)
}

/// The folder name of a part's reports: the part spec with anything but letters, digits, `-` and
/// `.` replaced by `_` (`rect:2:1` → `rect_2_1`); a vertex list is [`custom_name`].
pub fn part_folder(part: &str) -> String {
    let p = part.trim();
    if p.to_lowercase().starts_with("vertices:") {
        return custom_name(p);
    }
    // A part file: its name without folder and extension.
    let stem = std::path::Path::new(p)
        .file_stem()
        .map(|s| s.to_string_lossy());
    let p = match stem {
        Some(s) if is_part_file(p) => s.into_owned(),
        _ => p.to_string(),
    };
    p.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_parts_are_valid() {
        for n in [
            "tripoly1",
            "tripoly2",
            "square",
            "lshape",
            "rect:2:1",
            "ngon:7",
            "ngon:1000",
        ] {
            let p = part_from_spec(n).unwrap();
            assert!(p.area() > 0.0, "{n}");
        }
        assert!(!part_from_spec("lshape").unwrap().is_convex());
        let tri = part_from_spec("tripoly2").unwrap();
        assert!(tri.offset().norm() < 1e-15);
    }

    #[test]
    fn random_parts_are_seeded_valid_and_varied() {
        let mut concave = 0;
        let mut sizes = std::collections::BTreeSet::new();
        for seed in 0..200u64 {
            let spec = format!("random:{seed}");
            let p = part_from_spec(&spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
            assert_eq!(
                named_vertices(&spec).unwrap(),
                named_vertices(&spec).unwrap()
            );
            sizes.insert(p.vertices().len());
            concave += usize::from(!p.is_convex());
        }
        assert_eq!(sizes, (3..=8).collect());
        assert!((40..160).contains(&concave), "{concave} concave of 200");
        assert_ne!(
            named_vertices("random:1").unwrap(),
            named_vertices("random:2").unwrap()
        );
        assert_eq!(named_vertices("random:5:12").unwrap().len(), 12);
        for bad in [
            "random:",
            "random:x",
            "random:1:2",
            "random:1:65",
            "random:1:5:6",
        ] {
            assert!(
                matches!(part_from_spec(bad), Err(PartSpecError::BadParameter { .. })),
                "{bad}"
            );
        }
    }

    #[test]
    fn ngon_has_flat_bottom() {
        let p = part_from_spec("ngon:5").unwrap();
        let s = p.stable_states();
        assert_eq!(s.len(), 5);
        assert!(s[0].theta_rad.abs() < 1e-12);
    }

    #[test]
    fn bad_specs() {
        assert!(matches!(
            part_from_spec("blob"),
            Err(PartSpecError::Unknown(_))
        ));
        assert!(matches!(
            part_from_spec("rect:2:-1"),
            Err(PartSpecError::BadParameter { .. })
        ));
        assert!(matches!(
            part_from_spec("ngon:2"),
            Err(PartSpecError::BadParameter { .. })
        ));
        assert!(matches!(
            part_from_spec("vertices:0,0 1,x 0,1"),
            Err(PartSpecError::BadVertexList(_))
        ));
    }
}
