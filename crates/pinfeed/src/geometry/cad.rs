//! Parts from files (docs/cad.md): a part's outline read from a DXF drawing or from a CSV of `x,y`
//! rows, in millimetres.
//!
//! A DXF part is the drawing's one outer closed loop: a closed LWPOLYLINE or POLYLINE (bulges are
//! arcs), a CIRCLE, or LINE, ARC and open polyline entities chained end to end (endpoints join
//! when they lie within [`JOIN_TOLERANCE`] of the drawing's size). Arcs are flattened to chords
//! whose distance from the arc is at most [`PartFileOptions::flatten_mm`]; the chords' ends lie on
//! the arc, so the flattened part lies inside the drawn one. The drawing's unit is its `$INSUNITS`
//! header, or [`PartFileOptions::units`] when the header says none (unitless or absent); with
//! neither the drawing is refused. Loops inside the outer loop are holes: the planar model has
//! none, so they are dropped and [`PartFile::notes`] says so. Every error names the entity (its
//! handle and layer) and what to change.
//!
//! A CSV part is one `x,y` row per vertex (a header row, blank lines and `#` comments are
//! skipped), in [`PartFileOptions::units`] (millimetres when not given).

use super::polygon::{Polygon, PolygonError};
use super::vec2::Vec2;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The default chordal tolerance of flattened arcs: 0.05 mm.
pub const DEFAULT_FLATTEN_MM: f64 = 0.05;

/// Endpoints of chained entities join when they are this close, relative to the drawing's size
/// (the diagonal of the box around every endpoint read).
pub const JOIN_TOLERANCE: f64 = 1e-6;

/// The most chords one arc is flattened into (a tolerance finer than this allows is refused).
const MAX_CHORDS_PER_ARC: f64 = 100_000.0;

/// The most vertices a part file's outline may have, flattened arcs included (the part's checks
/// and its contact model grow with the count).
pub const MAX_VERTICES: usize = 10_000;

/// The largest coordinate of a part file, in millimetres (1 km).
const MAX_COORD_MM: f64 = 1e6;

/// Is this part specification a file (`….dxf` or `….csv`, any case)?
pub fn is_part_file(spec: &str) -> bool {
    let s = spec.trim().to_ascii_lowercase();
    s.ends_with(".dxf") || s.ends_with(".csv")
}

/// A length unit of a drawing: its name and millimetres per unit.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Unit {
    /// The unit's name as the options and messages write it (`mm`, `inch`, ...).
    pub name: &'static str,
    /// Millimetres per unit.
    pub mm: f64,
}

/// The units a drawing may be in, by name (the `--units` values), with their aliases.
const UNITS: &[(&str, &str, f64)] = &[
    ("mm", "millimetre", 1.0),
    ("cm", "centimetre", 10.0),
    ("dm", "decimetre", 100.0),
    ("m", "metre", 1000.0),
    ("um", "micron", 1e-3),
    ("inch", "in", 25.4),
    ("ft", "foot", 304.8),
    ("mil", "thou", 0.0254),
    ("yd", "yard", 914.4),
];

impl Unit {
    /// The unit named `name` (mm, cm, dm, m, um, inch or in, ft, mil, yd; any case).
    pub fn parse(name: &str) -> Result<Unit, CadError> {
        let n = name.trim().to_ascii_lowercase();
        UNITS
            .iter()
            .find(|(a, b, _)| n == *a || n == *b || n == format!("{b}s"))
            .map(|&(a, _, mm)| Unit { name: a, mm })
            .ok_or_else(|| CadError::Units {
                given: name.to_string(),
            })
    }
    fn named(name: &'static str) -> Unit {
        let mm = UNITS.iter().find(|u| u.0 == name).map_or(1.0, |u| u.2);
        Unit { name, mm }
    }
}

/// How a part file is read.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PartFileOptions {
    /// Chordal tolerance of flattened arcs and bulges (mm): no point of an arc lies farther than
    /// this from the polygon's edges. In (0, 10].
    pub flatten_mm: f64,
    /// The drawing's unit when the file does not state it (a DXF without `$INSUNITS`, or with
    /// `$INSUNITS` 0, unitless; a CSV). A DXF whose header states a unit is read in that unit, and
    /// a different one given here is refused.
    pub units: Option<Unit>,
}

impl PartFileOptions {
    /// Are these the default options?
    pub fn is_default(&self) -> bool {
        *self == PartFileOptions::default()
    }
}

impl Default for PartFileOptions {
    fn default() -> Self {
        PartFileOptions {
            flatten_mm: DEFAULT_FLATTEN_MM,
            units: None,
        }
    }
}

/// A part read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct PartFile {
    /// The outline's vertices in millimetres, in the drawing's coordinates.
    pub vertices: Vec<Vec2>,
    /// The unit the file was read in.
    pub unit: Unit,
    /// Where the unit came from (`$INSUNITS`, `--units`, or `default` for a CSV).
    pub unit_source: &'static str,
    /// What the reader dropped or assumed, one sentence each (holes ignored, entities not read).
    pub notes: Vec<String>,
}

impl PartFile {
    /// The validated polygon of the outline (millimetres).
    pub fn polygon(&self) -> Result<Polygon, PolygonError> {
        Polygon::new(&self.vertices)
    }
}

/// An entity of a drawing, as errors name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EntityRef {
    /// The entity's type (`LINE`, `ARC`, `LWPOLYLINE`, ...).
    pub kind: &'static str,
    /// Its handle (hexadecimal, as CAD tools show it).
    pub handle: String,
    /// Its layer.
    pub layer: String,
}

impl std::fmt::Display for EntityRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} (handle {}, layer '{}')",
            self.kind, self.handle, self.layer
        )
    }
}

/// Why a part file could not be read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CadError {
    /// The file could not be read (missing, too large, not a regular file).
    #[error("{}: {reason}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The file is not a readable DXF drawing.
    #[error("{}: not a readable DXF drawing: {reason} (save it again from the CAD tool as ASCII DXF)", path.display())]
    Dxf {
        /// The file.
        path: PathBuf,
        /// The DXF library's reason.
        reason: String,
    },
    /// A unit name that is not known.
    #[error("unknown unit '{given}': expected one of mm, cm, dm, m, um, inch, ft, mil, yd")]
    Units {
        /// The name given.
        given: String,
    },
    /// The outline is not one closed simple loop, or the file's values are out of range.
    #[error("{}: {what}", path.display())]
    Outline {
        /// The file.
        path: PathBuf,
        /// What is wrong, which entity or line, and the likely fix.
        what: String,
    },
}

/// Read a part file (`.dxf` or `.csv`) into its outline in millimetres.
pub fn read_part_file(path: &Path, options: &PartFileOptions) -> Result<PartFile, CadError> {
    check_options(path, options)?;
    let bytes =
        crate::input::read_bounded(path, crate::input::TEXT_CAP).map_err(|e| CadError::Read {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
    let lower = path.to_string_lossy().to_ascii_lowercase();
    if lower.ends_with(".csv") {
        csv_outline(path, &bytes, options)
    } else {
        dxf_outline(path, &bytes, options)
    }
}

fn check_options(path: &Path, o: &PartFileOptions) -> Result<(), CadError> {
    if !(o.flatten_mm.is_finite() && o.flatten_mm > 0.0 && o.flatten_mm <= 10.0) {
        return Err(CadError::Outline {
            path: path.to_path_buf(),
            what: format!(
                "flatten tolerance {} mm: must lie in (0, 10] mm",
                o.flatten_mm
            ),
        });
    }
    Ok(())
}

/// One piece of an outline: a straight segment or a circular arc (signed sweep, CCW positive).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Seg {
    Line(Vec2, Vec2),
    Arc {
        centre: Vec2,
        radius: f64,
        start: f64,
        sweep: f64,
    },
}

impl Seg {
    fn start(&self) -> Vec2 {
        match *self {
            Seg::Line(a, _) => a,
            Seg::Arc {
                centre,
                radius,
                start,
                ..
            } => centre + Vec2::from_angle(start) * radius,
        }
    }
    fn end(&self) -> Vec2 {
        match *self {
            Seg::Line(_, b) => b,
            Seg::Arc {
                centre,
                radius,
                start,
                sweep,
            } => centre + Vec2::from_angle(start + sweep) * radius,
        }
    }
    fn reversed(&self) -> Seg {
        match *self {
            Seg::Line(a, b) => Seg::Line(b, a),
            Seg::Arc {
                centre,
                radius,
                start,
                sweep,
            } => Seg::Arc {
                centre,
                radius,
                start: start + sweep,
                sweep: -sweep,
            },
        }
    }
    /// The segment from `a` to `b` with a DXF bulge (tan of a quarter of the included angle,
    /// positive counter-clockwise).
    fn bulged(a: Vec2, b: Vec2, bulge: f64) -> Seg {
        let chord = b - a;
        let len = chord.norm();
        if bulge == 0.0 || len == 0.0 {
            return Seg::Line(a, b);
        }
        let sweep = 4.0 * bulge.atan();
        let mid = (a + b) * 0.5;
        let left = chord.perp() * (1.0 / len);
        let centre = mid + left * (0.5 * len / (0.5 * sweep).tan());
        let radius = (a - centre).norm();
        Seg::Arc {
            centre,
            radius,
            start: (a - centre).angle(),
            sweep,
        }
    }
    /// The points after the start up to and including the end, the arc's chords at most `tol`
    /// from it (`None` when that takes more than [`MAX_CHORDS_PER_ARC`] chords).
    fn flatten(&self, tol: f64, out: &mut Vec<Vec2>) -> Option<()> {
        match *self {
            Seg::Line(_, b) => out.push(b),
            Seg::Arc {
                centre,
                radius,
                start,
                sweep,
            } => {
                // A chord of angle Δ is at most r(1 − cos(Δ/2)) from its arc.
                let max_step = if tol >= radius {
                    std::f64::consts::PI
                } else {
                    2.0 * (1.0 - tol / radius).acos()
                };
                // At most 120° per chord, so that a circle (or two half circles) gets at least
                // three chords and encloses an area.
                let max_step = max_step.min(std::f64::consts::TAU / 3.0);
                let n = (sweep.abs() / max_step).ceil().max(1.0);
                if n.is_nan() || n > MAX_CHORDS_PER_ARC {
                    return None;
                }
                let n = n as usize;
                for k in 1..=n {
                    let t = start + sweep * (k as f64 / n as f64);
                    out.push(centre + Vec2::from_angle(t) * radius);
                }
            }
        }
        Some(())
    }
}

/// A run of connected segments from one entity, closed or not.
#[derive(Debug, Clone)]
struct Piece {
    entity: EntityRef,
    segs: Vec<Seg>,
    closed: bool,
}

impl Piece {
    fn start(&self) -> Vec2 {
        self.segs[0].start()
    }
    fn end(&self) -> Vec2 {
        self.segs[self.segs.len() - 1].end()
    }
    fn reversed(&self) -> Piece {
        Piece {
            entity: self.entity.clone(),
            segs: self.segs.iter().rev().map(Seg::reversed).collect(),
            closed: self.closed,
        }
    }
}

/// A closed loop: its segments and, per segment, the entity it came from.
#[derive(Debug, Clone)]
struct Loop {
    segs: Vec<(Seg, usize)>,
    entities: Vec<EntityRef>,
}

impl Loop {
    fn names(&self) -> String {
        let names: Vec<String> = self.entities.iter().map(|e| e.to_string()).collect();
        if names.len() <= 4 {
            names.join(", ")
        } else {
            format!("{}, ... ({} entities)", names[..3].join(", "), names.len())
        }
    }
}

fn outline_err(path: &Path, what: String) -> CadError {
    CadError::Outline {
        path: path.to_path_buf(),
        what,
    }
}

/// The DXF library may panic on malformed input; a panic is reported as an unreadable drawing.
fn load_drawing(path: &Path, bytes: &[u8]) -> Result<dxf::Drawing, CadError> {
    let loaded = std::panic::catch_unwind(|| {
        let mut reader = bytes;
        dxf::Drawing::load(&mut reader)
    });
    match loaded {
        Ok(Ok(d)) => Ok(d),
        Ok(Err(e)) => Err(CadError::Dxf {
            path: path.to_path_buf(),
            reason: e.to_string(),
        }),
        Err(_) => Err(CadError::Dxf {
            path: path.to_path_buf(),
            reason: "the DXF reader failed on this file".into(),
        }),
    }
}

/// The unit of a drawing's `$INSUNITS`, if it states one.
fn drawing_unit(units: dxf::enums::Units) -> Option<Unit> {
    use dxf::enums::Units as U;
    Some(match units {
        U::Millimeters => Unit::named("mm"),
        U::Centimeters => Unit::named("cm"),
        U::Decimeters => Unit::named("dm"),
        U::Meters => Unit::named("m"),
        U::Microns => Unit::named("um"),
        U::Inches | U::USSurveyInch => Unit::named("inch"),
        U::Feet | U::USSurveyFeet => Unit::named("ft"),
        U::Mils => Unit::named("mil"),
        U::Yards | U::USSurveyYard => Unit::named("yd"),
        U::Unitless => return None,
        // Kilometres, miles, light years...: no part is drawn in these.
        _ => Unit {
            name: "unsupported",
            mm: f64::NAN,
        },
    })
}

/// The outline of a DXF drawing's bytes (the file's name is for messages).
pub fn dxf_outline(
    path: &Path,
    bytes: &[u8],
    options: &PartFileOptions,
) -> Result<PartFile, CadError> {
    check_options(path, options)?;
    let drawing = load_drawing(path, bytes)?;
    let (unit, unit_source) = match (drawing_unit(drawing.header.default_drawing_units), options.units) {
        (Some(u), _) if u.mm.is_nan() => {
            return Err(outline_err(
                path,
                format!(
                    "the drawing's $INSUNITS is {:?}, not a unit a part is drawn in; save it in mm or inches",
                    drawing.header.default_drawing_units
                ),
            ))
        }
        (Some(u), Some(given)) if u.name != given.name => {
            return Err(outline_err(
                path,
                format!(
                    "the drawing states its unit ($INSUNITS: {}) and {} was given: leave out the unit option, or fix the drawing's units",
                    u.name, given.name
                ),
            ))
        }
        (Some(u), _) => (u, "$INSUNITS"),
        (None, Some(u)) => (u, "given"),
        (None, None) => {
            return Err(outline_err(
                path,
                "the drawing does not state its unit ($INSUNITS is absent or 0, unitless): give it, e.g. --units mm or --units inch (a scenario: units = \"mm\" in [part])".into(),
            ))
        }
    };
    let mut notes = Vec::new();
    let mut pieces = Vec::new();
    let mut skipped: Vec<EntityRef> = Vec::new();
    for e in drawing.entities() {
        if e.common.is_in_paper_space {
            continue;
        }
        let entity = |kind: &'static str| EntityRef {
            kind,
            handle: format!("{:X}", e.common.handle.0),
            layer: e.common.layer.clone(),
        };
        use dxf::entities::EntityType as T;
        let p2 = |p: &dxf::Point| Vec2::new(p.x, p.y);
        let piece = match &e.specific {
            // A zero-length line joins nothing: it is left out.
            T::Line(l) if l.p1.x == l.p2.x && l.p1.y == l.p2.y => None,
            T::Line(l) => Some(Piece {
                entity: entity("LINE"),
                segs: vec![Seg::Line(p2(&l.p1), p2(&l.p2))],
                closed: false,
            }),
            T::Arc(a) => {
                let (s, mut t) = (a.start_angle, a.end_angle);
                while t <= s {
                    t += 360.0;
                }
                let sweep = (t - s).min(360.0).to_radians();
                Some(Piece {
                    entity: entity("ARC"),
                    segs: vec![Seg::Arc {
                        centre: p2(&a.center),
                        radius: a.radius,
                        start: s.to_radians(),
                        sweep,
                    }],
                    closed: false,
                })
                .map(|p| mirror_piece(p, &a.normal))
            }
            T::Circle(c) => Some(Piece {
                entity: entity("CIRCLE"),
                segs: vec![Seg::Arc {
                    centre: p2(&c.center),
                    radius: c.radius,
                    start: 0.0,
                    sweep: std::f64::consts::TAU,
                }],
                closed: true,
            })
            .map(|p| mirror_piece(p, &c.normal)),
            T::LwPolyline(pl) => {
                let pts: Vec<(Vec2, f64)> = pl
                    .vertices
                    .iter()
                    .map(|v| (Vec2::new(v.x, v.y), v.bulge))
                    .collect();
                polyline_piece(entity("LWPOLYLINE"), &pts, pl.is_closed())
                    .map(|p| mirror_piece(p, &pl.extrusion_direction))
            }
            T::Polyline(pl) => {
                if pl.flags & (8 | 16 | 64) != 0 {
                    skipped.push(entity("POLYLINE (3D or mesh)"));
                    None
                } else {
                    let pts: Vec<(Vec2, f64)> =
                        pl.vertices().map(|v| (p2(&v.location), v.bulge)).collect();
                    polyline_piece(entity("POLYLINE"), &pts, pl.is_closed())
                        .map(|p| mirror_piece(p, &pl.normal))
                }
            }
            T::Spline(_) => {
                skipped.push(entity("SPLINE"));
                None
            }
            T::Ellipse(_) => {
                skipped.push(entity("ELLIPSE"));
                None
            }
            T::Insert(_) => {
                skipped.push(entity("INSERT (block reference)"));
                None
            }
            _ => None,
        };
        if let Some(p) = piece {
            pieces.push(p);
        }
    }
    for p in &pieces {
        for s in &p.segs {
            let finite = match *s {
                Seg::Line(a, b) => a.is_finite() && b.is_finite(),
                Seg::Arc {
                    centre,
                    radius,
                    start,
                    sweep,
                } => {
                    centre.is_finite()
                        && radius.is_finite()
                        && start.is_finite()
                        && sweep.is_finite()
                }
            };
            if !finite {
                return Err(outline_err(
                    path,
                    format!("{} has a coordinate that is not a finite number (NaN or infinite); fix or delete it", p.entity),
                ));
            }
            let far = [s.start(), s.end()]
                .iter()
                .map(|v| v.x.abs().max(v.y.abs()))
                .fold(0.0, f64::max);
            if far * unit.mm > MAX_COORD_MM {
                return Err(outline_err(
                    path,
                    format!("{} lies {} mm from the origin; a part's coordinates must lie within ±1 km (is the unit right?)", p.entity, far * unit.mm),
                ));
            }
            if let Seg::Arc { radius, .. } = *s {
                if radius.is_nan() || radius <= 0.0 {
                    return Err(outline_err(
                        path,
                        format!(
                            "{} has radius {radius}: an arc needs a positive radius",
                            p.entity
                        ),
                    ));
                }
            }
        }
    }
    if !skipped.is_empty() {
        let names: Vec<String> = skipped.iter().map(|e| e.to_string()).collect();
        notes.push(format!(
            "not read (only LWPOLYLINE, POLYLINE, LINE, ARC and CIRCLE are): {}; explode blocks and convert splines and ellipses to polylines if they are part of the outline",
            names.join(", ")
        ));
    }
    if pieces.is_empty() {
        return Err(outline_err(
            path,
            format!(
                "no outline: the drawing has no LWPOLYLINE, POLYLINE, LINE, ARC or CIRCLE in model space{}",
                if skipped.is_empty() { String::new() } else { format!(" ({})", notes[0]) }
            ),
        ));
    }
    let loops = chain(path, pieces)?;
    let tol = options.flatten_mm / unit.mm;
    let mut polys = Vec::new();
    for lp in &loops {
        polys.push(flatten_loop(path, lp, tol)?);
    }
    // The outer loop: the one of largest area; every other must lie inside it (a hole).
    let outer = (0..polys.len())
        .max_by(|&i, &j| polys[i].1.abs().total_cmp(&polys[j].1.abs()))
        .unwrap_or(0);
    let mut holes = Vec::new();
    for (i, lp) in loops.iter().enumerate() {
        if i == outer {
            continue;
        }
        if !inside(polys[i].0[0], &polys[outer].0) {
            return Err(outline_err(
                path,
                format!(
                    "several closed loops that are not nested: {} and {}; a part file holds one part: delete the other outlines (or move them out of model space)",
                    loops[outer].names(),
                    lp.names()
                ),
            ));
        }
        holes.push(lp.names());
    }
    if !holes.is_empty() {
        notes.push(format!(
            "{} hole{} ignored (the planar model has no holes): {}",
            holes.len(),
            if holes.len() == 1 { "" } else { "s" },
            holes.join("; ")
        ));
    }
    let (pts, _, owner) = &polys[outer];
    let vertices: Vec<Vec2> = pts.iter().map(|&v| v * unit.mm).collect();
    let lp = &loops[outer];
    if let Err(e) = Polygon::new(&vertices) {
        // The entity of the chord that ends at vertex v.
        let who = |v: usize| lp.entities[owner[v % owner.len()]].to_string();
        let what = match e {
            PolygonError::SelfIntersecting { a1, b1, .. } => format!(
                "the outline crosses itself: {} crosses {}; redraw the outline so that it does not cross",
                who(a1),
                who(b1)
            ),
            PolygonError::ZeroArea => format!(
                "the outline {} has zero area (its points are collinear or it folds back on itself)",
                lp.names()
            ),
            PolygonError::RepeatedVertex { index, .. } => format!(
                "{} has a zero-length edge (two points closer than the unit's precision); delete the short segment",
                who(index)
            ),
            other => format!("the outline {} is not a valid part: {other}", lp.names()),
        };
        return Err(outline_err(path, what));
    }
    Ok(PartFile {
        vertices,
        unit,
        unit_source,
        notes,
    })
}

/// Mirror a piece in x when its entity's extrusion is −Z (arcs and polylines drawn from below).
fn mirror_piece(p: Piece, normal: &dxf::Vector) -> Piece {
    if normal.z >= 0.0 {
        return p;
    }
    let flip = |v: Vec2| Vec2::new(-v.x, v.y);
    let segs = p
        .segs
        .iter()
        .map(|s| match *s {
            Seg::Line(a, b) => Seg::Line(flip(a), flip(b)),
            Seg::Arc {
                centre,
                radius,
                start,
                sweep,
            } => Seg::Arc {
                centre: flip(centre),
                radius,
                start: std::f64::consts::PI - start,
                sweep: -sweep,
            },
        })
        .collect();
    Piece { segs, ..p }
}

/// The piece of a polyline's vertices (with bulges); `None` for fewer than two vertices.
fn polyline_piece(entity: EntityRef, pts: &[(Vec2, f64)], closed: bool) -> Option<Piece> {
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let mut segs: Vec<Seg> = (0..n - 1)
        .map(|i| Seg::bulged(pts[i].0, pts[i + 1].0, pts[i].1))
        .collect();
    if closed {
        segs.push(Seg::bulged(pts[n - 1].0, pts[0].0, pts[n - 1].1));
    }
    // A zero-length closing segment (the last vertex repeating the first) is dropped.
    segs.retain(|s| !matches!(s, Seg::Line(a, b) if a == b));
    if segs.is_empty() {
        return None;
    }
    Some(Piece {
        entity,
        segs,
        closed,
    })
}

/// Chain the pieces into closed loops; open chains and branches are errors.
fn chain(path: &Path, pieces: Vec<Piece>) -> Result<Vec<Loop>, CadError> {
    let (mut lo, mut hi) = (Vec2::new(f64::MAX, f64::MAX), Vec2::new(f64::MIN, f64::MIN));
    for p in &pieces {
        for v in [p.start(), p.end()] {
            lo = Vec2::new(lo.x.min(v.x), lo.y.min(v.y));
            hi = Vec2::new(hi.x.max(v.x), hi.y.max(v.y));
        }
    }
    let size = (hi - lo).norm().max(f64::MIN_POSITIVE);
    let tol = JOIN_TOLERANCE * size;
    let near = |a: Vec2, b: Vec2| (a - b).norm() <= tol;
    let mut loops = Vec::new();
    let mut open: Vec<Piece> = Vec::new();
    for p in pieces {
        if p.closed || (p.segs.len() > 1 && near(p.start(), p.end())) {
            loops.push(Loop {
                segs: p.segs.iter().map(|&s| (s, 0)).collect(),
                entities: vec![p.entity],
            });
        } else if p.segs.len() == 1
            && matches!(p.segs[0], Seg::Arc { sweep, .. } if sweep.abs() >= std::f64::consts::TAU - 1e-12)
        {
            // A full-circle ARC closes on itself.
            loops.push(Loop {
                segs: vec![(p.segs[0], 0)],
                entities: vec![p.entity],
            });
        } else {
            open.push(p);
        }
    }
    let mut used = vec![false; open.len()];
    for first in 0..open.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let start = open[first].start();
        let mut lp = Loop {
            segs: open[first].segs.iter().map(|&s| (s, 0)).collect(),
            entities: vec![open[first].entity.clone()],
        };
        let mut end = open[first].end();
        loop {
            if near(end, start) && lp.entities.len() > 1 {
                break;
            }
            let candidates: Vec<(usize, bool)> = (0..open.len())
                .filter(|&j| !used[j])
                .filter_map(|j| {
                    if near(open[j].start(), end) {
                        Some((j, false))
                    } else if near(open[j].end(), end) {
                        Some((j, true))
                    } else {
                        None
                    }
                })
                .collect();
            let last = lp.entities.last().cloned().expect("a loop has an entity");
            match candidates.as_slice() {
                [] => {
                    return Err(outline_err(
                        path,
                        format!(
                            "open outline: {last} ends at ({}, {}) and no other entity starts within {tol:.3e} drawing units of it (the chain began at {}); close the gap, or join the entities into one closed polyline (PEDIT Join)",
                            fmt_num(end.x), fmt_num(end.y), lp.entities[0]
                        ),
                    ))
                }
                [(j, rev)] => {
                    let piece = if *rev { open[*j].reversed() } else { open[*j].clone() };
                    used[*j] = true;
                    let k = lp.entities.len();
                    lp.entities.push(piece.entity.clone());
                    lp.segs.extend(piece.segs.iter().map(|&s| (s, k)));
                    end = piece.end();
                }
                many => {
                    let names: Vec<String> = std::iter::once(last.to_string())
                        .chain(many.iter().map(|(j, _)| open[*j].entity.to_string()))
                        .collect();
                    return Err(outline_err(
                        path,
                        format!(
                            "the outline branches at ({}, {}): {} meet there; an outline is one loop: delete the extra entities",
                            fmt_num(end.x), fmt_num(end.y), names.join(", ")
                        ),
                    ));
                }
            }
        }
        loops.push(lp);
    }
    Ok(loops)
}

fn fmt_num(x: f64) -> String {
    format!("{}", (x * 1e6).round() / 1e6)
}

/// A loop's polygon (drawing units), its signed area, and per vertex the index of its entity in
/// the loop. Each segment contributes its points after its start.
#[allow(clippy::type_complexity)]
fn flatten_loop(
    path: &Path,
    lp: &Loop,
    tol: f64,
) -> Result<(Vec<Vec2>, f64, Vec<usize>), CadError> {
    let mut pts = Vec::new();
    let mut owner = Vec::new();
    for (s, k) in &lp.segs {
        let before = pts.len();
        if s.flatten(tol, &mut pts).is_none() {
            return Err(outline_err(
                path,
                format!(
                    "{}: flattening its arc to {} drawing units would take more than {MAX_CHORDS_PER_ARC} chords; give a larger flatten tolerance",
                    lp.entities[*k], tol
                ),
            ));
        }
        owner.extend(std::iter::repeat_n(*k, pts.len() - before));
        if pts.len() > MAX_VERTICES {
            return Err(outline_err(
                path,
                format!(
                    "the outline {} flattens to more than {MAX_VERTICES} vertices; give a larger flatten tolerance (--flatten MM), or simplify the drawing",
                    lp.names()
                ),
            ));
        }
    }
    // Vertex i ends a chord of entity owner[i]; the last one is the loop's start.
    let mut area = 0.0;
    for i in 0..pts.len() {
        let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
        area += a.cross(b);
    }
    Ok((pts, area / 2.0, owner))
}

/// Is `p` inside the polygon (even-odd rule)?
fn inside(p: Vec2, poly: &[Vec2]) -> bool {
    let mut c = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            c = !c;
        }
    }
    c
}

/// The outline of a CSV part's bytes: one `x,y` row per vertex.
pub fn csv_outline(
    path: &Path,
    bytes: &[u8],
    options: &PartFileOptions,
) -> Result<PartFile, CadError> {
    let text = std::str::from_utf8(bytes).map_err(|e| CadError::Read {
        path: path.to_path_buf(),
        reason: format!("not UTF-8 text: {e}"),
    })?;
    let (unit, unit_source) = match options.units {
        Some(u) => (u, "given"),
        None => (Unit::named("mm"), "default"),
    };
    let mut vertices = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = l.split([',', ';', '\t']).map(str::trim).collect();
        let nums: Vec<Option<f64>> = cells.iter().map(|c| c.parse::<f64>().ok()).collect();
        match nums.as_slice() {
            [Some(x), Some(y)] => {
                if !(x.is_finite() && y.is_finite()) {
                    return Err(outline_err(path, format!("line {}: '{l}' is not finite; every coordinate must be a finite number", i + 1)));
                }
                if x.abs().max(y.abs()) * unit.mm > MAX_COORD_MM {
                    return Err(outline_err(
                        path,
                        format!(
                            "line {}: '{l}' lies beyond ±1 km (is the unit right?)",
                            i + 1
                        ),
                    ));
                }
                vertices.push(Vec2::new(x * unit.mm, y * unit.mm));
                if vertices.len() > MAX_VERTICES {
                    return Err(outline_err(path, format!("line {}: more than {MAX_VERTICES} vertices; a part file holds at most that many", i + 1)));
                }
            }
            [None, None] if vertices.is_empty() => {} // a header row
            _ => {
                return Err(outline_err(
                    path,
                    format!("line {}: '{l}' is not an x,y row of two numbers", i + 1),
                ))
            }
        }
    }
    // A closed ring repeating its first vertex at the end.
    if vertices.len() > 3 && vertices.first() == vertices.last() {
        vertices.pop();
    }
    Polygon::new(&vertices).map_err(|e| {
        outline_err(
            path,
            format!(
                "the vertices do not make a part: {e} (rows are vertex 0, 1, ... in file order)"
            ),
        )
    })?;
    Ok(PartFile {
        vertices,
        unit,
        unit_source,
        notes: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_bulge_of_one_is_a_counter_clockwise_semicircle() {
        let s = Seg::bulged(Vec2::new(0.0, 0.0), Vec2::new(2.0, 0.0), 1.0);
        let Seg::Arc {
            centre,
            radius,
            sweep,
            ..
        } = s
        else {
            panic!("{s:?}")
        };
        assert!((centre - Vec2::new(1.0, 0.0)).norm() < 1e-12);
        assert!((radius - 1.0).abs() < 1e-12 && (sweep - PI).abs() < 1e-12);
        // Counter-clockwise from (0, 0) to (2, 0) about (1, 0) passes below the chord.
        let mut pts = Vec::new();
        s.flatten(0.01, &mut pts).unwrap();
        assert!(pts.iter().all(|p| p.y <= 1e-12));
        assert!((pts[pts.len() - 1] - Vec2::new(2.0, 0.0)).norm() < 1e-12);
        // A negative bulge is the mirror image, and a reversed arc runs back to the start.
        let m = Seg::bulged(Vec2::new(0.0, 0.0), Vec2::new(2.0, 0.0), -1.0);
        assert!((m.start() - s.start()).norm() < 1e-12 && (m.end() - s.end()).norm() < 1e-12);
        assert!((s.reversed().end() - s.start()).norm() < 1e-12);
    }

    #[test]
    fn flattened_chords_stay_within_the_tolerance() {
        for (r, tol) in [(1.0, 0.05), (10.0, 0.001), (0.01, 0.05), (100.0, 1e-5)] {
            let s = Seg::Arc {
                centre: Vec2::new(0.0, 0.0),
                radius: r,
                start: 0.3,
                sweep: -2.5,
            };
            let mut pts = vec![s.start()];
            s.flatten(tol, &mut pts).unwrap();
            for w in pts.windows(2) {
                // The chord's midpoint is its farthest point from the arc.
                let mid = (w[0] + w[1]) * 0.5;
                assert!(r - mid.norm() <= tol * (1.0 + 1e-9), "r {r} tol {tol}");
                assert!(((w[0]).norm() - r).abs() < 1e-9 * r.max(1.0));
            }
        }
        let fine = Seg::Arc {
            centre: Vec2::new(0.0, 0.0),
            radius: 1e6,
            start: 0.0,
            sweep: 6.0,
        };
        assert!(fine.flatten(1e-9, &mut Vec::new()).is_none());
    }

    #[test]
    fn units_parse_by_name_and_alias() {
        assert_eq!(Unit::parse("Inch").unwrap().mm, 25.4);
        assert_eq!(Unit::parse("in").unwrap().name, "inch");
        assert_eq!(Unit::parse("metres").unwrap().mm, 1000.0);
        assert!(Unit::parse("furlong").is_err());
        assert!(is_part_file("a/B.DXF") && is_part_file(" p.csv ") && !is_part_file("tripoly2"));
    }
}
