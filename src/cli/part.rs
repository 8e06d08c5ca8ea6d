//! `pinfeed part`: describe a part (area, centroid, a, convexity, stable states) and plot it.

use anyhow::{bail, Context, Result};
use clap::Args;
use pinfeed::geometry::{named, Polygon};
use pinfeed::report::part_report::PartReport;
use std::path::PathBuf;

/// Arguments of `pinfeed part`.
#[derive(Debug, Args)]
pub struct PartArgs {
    /// The part, as every command takes it: tripoly1, tripoly2, square, rect:W:H, ngon:N,
    /// lshape, random:SEED[:N], or vertices:"x1,y1 x2,y2 ..." (any orientation, any unit).
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
}

/// Resolve a part spec (`--part`, or the positional name) or `--vertices` to a validated polygon
/// and a display name (`vertices` for a vertex list).
pub fn resolve_part(name: Option<&str>, vertices: Option<&str>) -> Result<(Polygon, String)> {
    match (name, vertices) {
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
    let (poly, name) = resolve_part(spec, args.vertices.as_deref())?;
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
