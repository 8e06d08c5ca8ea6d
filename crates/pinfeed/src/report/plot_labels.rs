//! Labels that never overlap: each label goes into the first row, on its side of a drawing, where
//! no label already placed there overlaps it across (with a gap) while both are shown (an interval
//! of time; a still label is shown throughout). Widths are estimated from the text (sans-serif).

/// The estimated width (px) of `text` at `size` px: a generous average advance per character.
pub fn text_width(text: &str, size: f64, bold: bool) -> f64 {
    let per = if bold { 0.68 } else { 0.62 };
    text.chars().count() as f64 * size * per
}

/// Gap kept between two labels in one row (px).
pub const GAP_PX: f64 = 6.0;

#[derive(Debug, Clone, Copy)]
struct Placed {
    above: bool,
    row: usize,
    x0: f64,
    x1: f64,
    t0: f64,
    t1: f64,
}

/// Rows of labels above and below a drawing.
#[derive(Debug, Clone, Default)]
pub struct LabelRows {
    placed: Vec<Placed>,
}

impl LabelRows {
    /// No labels placed yet.
    pub fn new() -> LabelRows {
        LabelRows::default()
    }

    /// Place a label spanning `x0..x1` (px), shown over `t0..t1`, `above` or below, in the first
    /// free row at or beyond `first_row`; returns the row.
    pub fn place(
        &mut self,
        above: bool,
        x0: f64,
        x1: f64,
        t: (f64, f64),
        first_row: usize,
    ) -> usize {
        let mut row = first_row;
        loop {
            let clash = self.placed.iter().any(|p| {
                p.above == above
                    && p.row == row
                    && p.x0 < x1 + GAP_PX
                    && x0 < p.x1 + GAP_PX
                    && p.t0 < t.1
                    && t.0 < p.t1
            });
            if !clash {
                break;
            }
            row += 1;
        }
        self.placed.push(Placed {
            above,
            row,
            x0,
            x1,
            t0: t.0,
            t1: t.1,
        });
        row
    }

    /// Rows used on a side (0 when none).
    pub fn rows(&self, above: bool) -> usize {
        self.placed
            .iter()
            .filter(|p| p.above == above)
            .map(|p| p.row + 1)
            .max()
            .unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlapping_labels_take_new_rows_unless_shown_apart() {
        let mut r = LabelRows::new();
        assert_eq!(r.place(true, 0.0, 100.0, (0.0, 1.0), 0), 0);
        assert_eq!(r.place(true, 50.0, 150.0, (0.0, 1.0), 0), 1);
        assert_eq!(r.place(true, 200.0, 300.0, (0.0, 1.0), 0), 0);
        assert_eq!(r.place(false, 50.0, 150.0, (0.0, 1.0), 0), 0);
        // Shown at another time: the same row.
        assert_eq!(r.place(true, 0.0, 100.0, (2.0, 3.0), 0), 0);
        assert_eq!(r.rows(true), 2);
        assert_eq!(r.rows(false), 1);
        assert!(text_width("abcd", 10.0, false) > 20.0);
    }
}
