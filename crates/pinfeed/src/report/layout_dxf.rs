//! A line as a fabrication drawing (DXF, millimetres; docs/outputs.md#the-layout-drawing): what
//! `run --dxf` and `plan --dxf` write.
//!
//! The drawing's `$INSUNITS` is 4 (millimetres) and its coordinates are the scenario's world
//! frame (x along the belt from its entry, y across it, origin on the belt's centre line) times
//! 1000. Its layers:
//!
//! | layer | entities |
//! |---|---|
//! | `BELT` | the belt's two edges (y = ±width/2) and its entry and exit (x = 0, x = length), LINEs |
//! | `PINS` | each fixed pin: a CIRCLE of its radius at its centre (a POINT for a point pin) |
//! | `SENSORS` | each sensor pin: its CIRCLE, and a cross of two LINEs through its centre, one radius long each way |
//! | `MOVING` | each moving or retractable pin: its CIRCLE at its home, and a moving pin's travel, a LINE across the belt from its centre's least to its greatest y |
//! | `FENCES` | each fence: its straight part, a LINE from its start to its straight end, and its curved tail, an ARC |
//! | `TEXT` | each obstacle's name (with ` (sensor)`, ` (moving)` or ` (retractable)`), a TEXT beside it |

use crate::scenario::{Actuator, Obstacle, Scene};
use dxf::entities::{Arc, Circle, Entity, EntityType, Line, ModelPoint, Text};
use dxf::enums::{AcadVersion, Units};
use dxf::tables::Layer;
use dxf::{Color, Drawing, Point};
use std::path::Path;

/// The layers of a layout drawing, with their colours (AutoCAD colour index).
pub const LAYERS: &[(&str, u8)] = &[
    ("BELT", 8),
    ("PINS", 1),
    ("SENSORS", 3),
    ("MOVING", 5),
    ("FENCES", 6),
    ("TEXT", 7),
];

/// Millimetres per metre: the drawing's unit.
const MM: f64 = 1000.0;

/// Why a layout drawing could not be written.
#[derive(Debug, thiserror::Error)]
pub enum LayoutDxfError {
    /// The DXF library could not produce the drawing.
    #[error("writing the layout drawing {}: {reason}", path.display())]
    Encode {
        /// The file.
        path: std::path::PathBuf,
        /// The library's reason.
        reason: String,
    },
    /// The file could not be written.
    #[error(transparent)]
    Write(#[from] crate::output::WriteError),
}

fn point(x: f64, y: f64) -> Point {
    Point::new(x * MM, y * MM, 0.0)
}

fn add(d: &mut Drawing, layer: &str, specific: EntityType) {
    let mut e = Entity::new(specific);
    e.common.layer = layer.to_string();
    d.add_entity(e);
}

fn label(d: &mut Drawing, text: String, x: f64, y: f64, height_mm: f64) {
    let mut t = Text {
        location: point(x, y),
        text_height: height_mm,
        value: text,
        ..Default::default()
    };
    t.second_alignment_point = t.location.clone();
    add(d, "TEXT", EntityType::Text(t));
}

/// The layout drawing of a scene. A pin is drawn as a sensor when it has its sensor, or when its
/// obstacle index is in `sensor_pins` (a scene drafted but not trained).
pub fn layout_drawing(scene: &Scene, sensor_pins: &[usize]) -> Drawing {
    let mut d = Drawing::new();
    d.header.version = AcadVersion::R2000;
    d.header.default_drawing_units = Units::Millimeters;
    for &(name, colour) in LAYERS {
        d.add_layer(Layer {
            name: name.to_string(),
            color: Color::from_index(colour),
            ..Default::default()
        });
    }
    let (w, len) = (scene.belt.width, scene.belt.length);
    for y in [-w / 2.0, w / 2.0] {
        add(
            &mut d,
            "BELT",
            EntityType::Line(Line::new(point(0.0, y), point(len, y))),
        );
    }
    for x in [0.0, len] {
        add(
            &mut d,
            "BELT",
            EntityType::Line(Line::new(point(x, -w / 2.0), point(x, w / 2.0))),
        );
    }
    // Text height: 1/40 of the belt's width, at least 1 mm.
    let h = (w * MM / 40.0).max(1.0);
    for (i, ob) in scene.obstacles.iter().enumerate() {
        match ob {
            Obstacle::Pin(pin) => {
                let sensor = pin.sensor.is_some() || sensor_pins.contains(&i);
                let (layer, what) = match (&pin.actuator, sensor) {
                    (_, true) => ("SENSORS", " (sensor)"),
                    (Some(Actuator::Moving(_)), _) => ("MOVING", " (moving)"),
                    (Some(Actuator::Retractable(_)), _) => ("MOVING", " (retractable)"),
                    (None, false) => ("PINS", ""),
                };
                let c = pin.centre;
                let shape = if pin.radius > 0.0 {
                    EntityType::Circle(Circle::new(point(c.x, c.y), pin.radius * MM))
                } else {
                    EntityType::ModelPoint(ModelPoint::new(point(c.x, c.y)))
                };
                add(&mut d, layer, shape);
                if sensor {
                    let r = pin.radius.max(0.002);
                    for (dx, dy) in [(r, 0.0), (0.0, r)] {
                        add(
                            &mut d,
                            "SENSORS",
                            EntityType::Line(Line::new(
                                point(c.x - dx, c.y - dy),
                                point(c.x + dx, c.y + dy),
                            )),
                        );
                    }
                }
                if let Some(Actuator::Moving(m)) = &pin.actuator {
                    add(
                        &mut d,
                        "MOVING",
                        EntityType::Line(Line::new(
                            point(c.x, m.travel[0]),
                            point(c.x, m.travel[1]),
                        )),
                    );
                }
                label(
                    &mut d,
                    format!("{}{what}", pin.name),
                    c.x + pin.radius + h / MM,
                    c.y + pin.radius + h / MM,
                    h,
                );
            }
            Obstacle::Fence(f) => {
                let spec = f.spec();
                let end = spec.straight_end();
                add(
                    &mut d,
                    "FENCES",
                    EntityType::Line(Line::new(point(f.start.x, f.start.y), point(end.x, end.y))),
                );
                if let Some((c, r, n, _)) = spec.tail_arc() {
                    // The tail turns from n by −angle: counter-clockwise from the smaller angle.
                    let a0 = n.angle().to_degrees();
                    let a1 = a0 - f.angle_rad.to_degrees();
                    let (s, e) = if a1 < a0 { (a1, a0) } else { (a0, a1) };
                    add(
                        &mut d,
                        "FENCES",
                        EntityType::Arc(Arc::new(point(c.x, c.y), r * MM, s, e)),
                    );
                }
                let m = (f.start + end) * 0.5;
                label(&mut d, f.name.clone(), m.x, m.y + h / MM, h);
            }
        }
    }
    d
}

/// Write the layout drawing of `scene` to `path`, whole or not at all (see [`layout_drawing`]).
pub fn write_layout_dxf(
    scene: &Scene,
    sensor_pins: &[usize],
    path: &Path,
) -> Result<(), LayoutDxfError> {
    let d = layout_drawing(scene, sensor_pins);
    let mut bytes = Vec::new();
    d.save(&mut bytes).map_err(|e| LayoutDxfError::Encode {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    crate::output::write_file(path, bytes)?;
    Ok(())
}
