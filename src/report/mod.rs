//! Reports for people and programs: terminal tables, JSON/CSV, and SVG figures.

pub mod map_table;
pub mod plot_accuracy;
pub mod plot_contact;
pub mod plot_map;
pub mod plot_part;
