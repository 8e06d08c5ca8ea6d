//! Reports for people and programs: terminal tables, JSON/CSV, and SVG figures.

pub mod aligned;
pub mod animate;
pub mod atomic;
pub mod compare_table;
pub mod line_table;
pub mod map_table;
pub mod parts_csv;
pub mod plot_accuracy;
pub mod plot_contact;
pub mod plot_line;
pub mod plot_map;
pub mod plot_orientations;
pub mod plot_part;
pub mod plot_plan;
pub mod plot_sensing;
pub mod plot_sensitivity;
pub mod plot_survey;
pub mod plot_validate;
