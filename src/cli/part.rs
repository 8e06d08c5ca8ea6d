//! `pinfeed part`: describe a part (area, centroid, a, convexity, stable states) and plot it.

use crate::geometry::{named, Polygon};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
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

/// What `pinfeed part --json` prints.
#[derive(Debug, Serialize)]
pub struct PartReport {
    pub name: String,
    pub vertices: usize,
    pub area: f64,
    /// Centroid of the input vertices, in the input's coordinates.
    pub centroid: [f64; 2],
    pub a: f64,
    pub polar_moment: f64,
    pub convex: bool,
    pub stable_states_deg: Vec<f64>,
    /// Vertices in the part frame (counter-clockwise, centroid at the origin).
    pub part_frame_vertices: Vec<[f64; 2]>,
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
    let report = PartReport {
        name: name.clone(),
        vertices: poly.len(),
        area: poly.area(),
        centroid: [poly.offset().x, poly.offset().y],
        a: poly.radius(),
        polar_moment: poly.polar_moment(),
        convex: poly.is_convex(),
        stable_states_deg: poly
            .stable_states()
            .iter()
            .map(|s| s.theta_rad.to_degrees())
            .collect(),
        part_frame_vertices: poly.vertices().iter().map(|p| [p.x, p.y]).collect(),
    };
    if let Some(path) = &args.plot {
        crate::report::plot_part::plot_part(&poly, &name, path)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if args.json {
        print!("{}", crate::report::versioned::pretty(&report)?);
    } else {
        println!("part            {}", report.name);
        println!("vertices        {}", report.vertices);
        println!("area            {:.6}", report.area);
        println!(
            "centroid        ({:.6}, {:.6})",
            report.centroid[0], report.centroid[1]
        );
        println!("a               {:.6}", report.a);
        println!("polar moment    {:.6}", report.polar_moment);
        println!(
            "convex          {}",
            if report.convex { "yes" } else { "no" }
        );
        let s: Vec<String> = report
            .stable_states_deg
            .iter()
            .map(|d| format!("{d:.3}"))
            .collect();
        println!("stable states   {} (deg)", s.join(", "));
        if let Some(p) = &args.plot {
            println!("plot            {}", p.display());
        }
    }
    Ok(())
}
