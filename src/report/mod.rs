//! Reports for people and programs: terminal tables, JSON/CSV, and SVG figures.

pub mod plot_accuracy;
pub mod plot_contact;
pub mod plot_part;
