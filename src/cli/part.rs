//! `pinfeed part`: describe a part (area, centroid, a, convexity, stable states) and plot it.

use anyhow::{bail, Context, Result};
use clap::Args;
use pinfeed::geometry::cad::{is_part_file, read_part_file, PartFileOptions, Unit};
use pinfeed::geometry::{named, Polygon};
use pinfeed::report::part_report::PartReport;
use std::path::PathBuf;

/// Arguments of `pinfeed part`.
#[derive(Debug, Args)]
pub struct PartArgs {
    /// The part, as every command takes it: tripoly1, tripoly2, square, rect:W:H, ngon:N,
    /// lshape, random:SEED[:N], vertices:"x1,y1 x2,y2 ..." (any orientation, any unit), or a
    /// part file FILE.dxf or FILE.csv (in mm; docs/cad.md).
    #[arg(
        long,
        value_name = "PART",
        conflicts_with = "name",
        allow_hyphen_values = true
    )]
    pub part: Option<String>,
    /// The same as --part (positional).
    #[arg(value_name = "PART")]
    pub name: Option<String>,
    /// Deprecated: `--vertices "x1,y1 ..."` is `--part vertices:"x1,y1 ..."`.
    // allow_hyphen_values: a list that starts with a negative coordinate ("-1.5,-0.5 ...") is a
    // value, not an unknown flag.
    #[arg(long, hide = true, conflicts_with_all = ["name", "part"], allow_hyphen_values = true)]
    pub vertices: Option<String>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Draw the part and its radius function into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub file: PartFileArgs,
}

/// How a part file (`--part FILE.dxf` or `FILE.csv`) is read (docs/cad.md).
#[derive(Debug, Clone, Args)]
pub struct PartFileArgs {
    /// A part file's unit when the file does not state it (a DXF without $INSUNITS, a CSV): mm,
    /// cm, m, inch, ft, ... [default: a DXF without units is refused; a CSV is in mm].
    #[arg(long, value_name = "UNIT")]
    pub units: Option<String>,
    /// A part file's chordal tolerance: arcs and bulges become chords at most MM from the arc.
    #[arg(long, value_name = "MM", default_value_t = pinfeed::geometry::cad::DEFAULT_FLATTEN_MM)]
    pub flatten: f64,
}

impl PartFileArgs {
    /// The reading options of the flags.
    pub fn options(&self) -> Result<PartFileOptions> {
        Ok(PartFileOptions {
            flatten_mm: self.flatten,
            units: self
                .units
                .as_deref()
                .map(Unit::parse)
                .transpose()
                .context("--units")?,
        })
    }
}

/// Read a part file as the flags say, printing what the reader dropped or assumed to stderr
/// (`warning: ...`); `None` when `spec` is not a part file.
pub fn read_file_part(spec: &str, file: &PartFileArgs) -> Result<Option<Polygon>> {
    if !is_part_file(spec) {
        return Ok(None);
    }
    let part = read_part_file(std::path::Path::new(spec.trim()), &file.options()?)
        .with_context(|| format!("--part '{spec}'"))?;
    for note in &part.notes {
        eprintln!("warning: {spec}: {note}");
    }
    let poly = part.polygon().with_context(|| format!("--part '{spec}'"))?;
    Ok(Some(poly))
}

/// Resolve a part spec (`--part`, or the positional name) or `--vertices` to a validated polygon
/// and a display name (`vertices` for a vertex list).
pub fn resolve_part(
    name: Option<&str>,
    vertices: Option<&str>,
    file: &PartFileArgs,
) -> Result<(Polygon, String)> {
    match (name, vertices) {
        (Some(n), None) if is_part_file(n) => Ok((
            read_file_part(n, file)?.expect("a part file"),
            n.trim().to_string(),
        )),
        (Some(n), None) => Ok((
            named::part_from_spec(n).with_context(|| format!("--part '{n}'"))?,
            if n.to_lowercase().starts_with("vertices:") {
                "vertices".to_string()
            } else {
                n.to_string()
            },
        )),
        (None, Some(v)) => {
            let pts = named::parse_vertex_list(v)?;
            Ok((
                Polygon::new(&pts).context("invalid polygon given with --vertices")?,
                "vertices".to_string(),
            ))
        }
        _ => bail!("give a part: --part tripoly2, or --part vertices:\"x1,y1 x2,y2 ...\""),
    }
}

pub fn run(args: &PartArgs) -> Result<()> {
    if args.vertices.is_some() {
        eprintln!("warning: --vertices is deprecated; use --part vertices:\"x1,y1 x2,y2 ...\"");
    }
    let spec = args.part.as_deref().or(args.name.as_deref());
    let (poly, name) = resolve_part(spec, args.vertices.as_deref(), &args.file)?;
    let report = PartReport::of(&poly, &name);
    if let Some(path) = &args.plot {
        pinfeed::report::plot_part::plot_part(&poly, &name, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if args.json {
        crate::out!("{}", pinfeed::report::versioned::pretty(&report)?);
    } else {
        crate::out!("{}", report.text());
        if let Some(p) = &args.plot {
            crate::outln!("plot            {}", p.display());
        }
    }
    Ok(())
}
