//! What `pinfeed part` says of a part: its size, mass properties, convexity and stable states
//! (docs/physics.md), as a typed result ([`PartReport`]) printed as text or JSON.

use crate::geometry::Polygon;
use serde::Serialize;

/// A part described: what `pinfeed part --json` prints.
#[derive(Debug, Serialize)]
pub struct PartReport {
    /// The part's name as given (`vertices` for a vertex list).
    pub name: String,
    /// Number of vertices.
    pub vertices: usize,
    /// Area, in the input's units squared.
    pub area: f64,
    /// Centroid of the input vertices, in the input's coordinates.
    pub centroid: [f64; 2],
    /// a: the largest distance from the centroid to a vertex (the unit of pin offsets d).
    pub a: f64,
    /// Polar moment of area about the centroid, in the input's units to the fourth.
    pub polar_moment: f64,
    /// Whether the polygon is convex.
    pub convex: bool,
    /// The stable states' orientations θ in degrees, ascending in [0, 360) (docs/physics.md#stable-states).
    pub stable_states_deg: Vec<f64>,
    /// Vertices in the part frame (counter-clockwise, centroid at the origin).
    pub part_frame_vertices: Vec<[f64; 2]>,
}

impl PartReport {
    /// The description of `poly`, shown under `name`.
    pub fn of(poly: &Polygon, name: &str) -> PartReport {
        PartReport {
            name: name.to_string(),
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
        }
    }

    /// The table `pinfeed part` prints, one property a line.
    pub fn text(&self) -> String {
        let states: Vec<String> = self
            .stable_states_deg
            .iter()
            .map(|d| format!("{d:.3}"))
            .collect();
        format!(
            "part            {}\nvertices        {}\narea            {:.6}\n\
             centroid        ({:.6}, {:.6})\na               {:.6}\npolar moment    {:.6}\n\
             convex          {}\nstable states   {} (deg)\n",
            self.name,
            self.vertices,
            self.area,
            self.centroid[0],
            self.centroid[1],
            self.a,
            self.polar_moment,
            if self.convex { "yes" } else { "no" },
            states.join(", ")
        )
    }
}
