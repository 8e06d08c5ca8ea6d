//! Reports for people and programs: terminal tables, JSON/CSV, and SVG figures.

pub mod aligned;
pub mod animate;
pub mod calibrate_report;
pub mod compare_table;
pub mod ensemble_report;
pub mod error;
pub mod layout_dxf;
pub mod line_table;
pub mod map_report;
pub mod map_table;
pub mod part_report;
pub mod parts_csv;
pub mod plan_summary;
pub mod plot_accuracy;
pub mod plot_contact;
pub(crate) mod plot_labels;
pub mod plot_line;
pub mod plot_loop;
pub mod plot_map;
pub mod plot_orientations;
pub mod plot_part;
pub mod plot_plan;
pub mod plot_sensing;
pub mod plot_sensitivity;
pub mod plot_survey;
pub mod plot_validate;
pub(crate) mod plot_zoom;
pub mod run_folder;
pub mod sense;
pub mod stale;
pub mod study_files;
pub mod validate_report;
pub mod versioned;

pub use error::{ReportError, ReportResult};

/// `x` with `decimals` decimals (`plus`: with its sign always), never as a negative zero: a value
/// that rounds to zero is printed as 0 (`-0.000` from a −0.0 or a −1e-17 says nothing).
pub fn fixed(x: f64, decimals: usize, plus: bool) -> String {
    let s = if plus {
        format!("{x:+.decimals$}")
    } else {
        format!("{x:.decimals$}")
    };
    let digits = s.trim_start_matches(['-', '+']);
    if digits.chars().all(|c| c == '0' || c == '.') {
        if plus {
            format!("+{digits}")
        } else {
            digits.to_string()
        }
    } else {
        s
    }
}

#[cfg(test)]
mod fixed_tests {
    #[test]
    fn no_negative_zero() {
        use super::fixed;
        assert_eq!(fixed(-0.0, 3, false), "0.000");
        assert_eq!(fixed(-1e-17, 3, false), "0.000");
        assert_eq!(fixed(-1e-17, 1, true), "+0.0");
        assert_eq!(fixed(-0.25, 2, false), "-0.25");
        assert_eq!(fixed(1.5, 1, true), "+1.5");
    }
}
