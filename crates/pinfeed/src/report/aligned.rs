//! Aligned plain-text tables for the terminal: each column padded to its widest cell, columns two
//! spaces apart, trailing spaces trimmed.

/// The header and each row as one aligned line (with its newline), in order.
pub fn aligned_lines<R: AsRef<[String]>>(header: &[&str], rows: &[R]) -> Vec<String> {
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in width.iter_mut().zip(r.as_ref()) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: Vec<&str>| -> String {
        let padded: Vec<String> = cells
            .iter()
            .zip(&width)
            .map(|(c, &w)| format!("{c}{}", " ".repeat(w - c.chars().count())))
            .collect();
        padded.join("  ").trim_end().to_string() + "\n"
    };
    let mut out = vec![line(header.to_vec())];
    for r in rows {
        out.push(line(r.as_ref().iter().map(String::as_str).collect()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_line_up() {
        let rows = vec![
            vec!["a".to_string(), "long cell".into()],
            vec!["bbb".into(), "c".into()],
        ];
        let lines = aligned_lines(&["h1", "h2"], &rows);
        assert_eq!(lines, ["h1   h2\n", "a    long cell\n", "bbb  c\n"]);
    }
}
