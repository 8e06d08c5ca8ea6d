//! What a `pinfeed fuzz` run is asked for: each target's case count (`--counts TARGET=N,...`) and
//! one case re-run and described (`--case N`).

use super::{case_input, run_case, Corpus, Target};

/// Most cases of one target in a run.
pub const MAX_CASES: u64 = 100_000_000;

/// `TARGET=N,...`: the targets' own case counts, each in [0, [`MAX_CASES`]]; an error names the
/// word it could not read and what was expected.
pub fn parse_counts(text: &str) -> Result<Vec<(Target, u64)>, String> {
    text.split(',')
        .filter(|w| !w.trim().is_empty())
        .map(|w| {
            let (name, n) = w
                .split_once('=')
                .ok_or_else(|| format!("--counts: `{w}` is not TARGET=N"))?;
            let t = Target::ALL
                .into_iter()
                .find(|t| t.name() == name.trim())
                .ok_or_else(|| {
                    format!(
                        "--counts: unknown target `{}` (expected one of {})",
                        name.trim(),
                        Target::ALL.map(|t| t.name()).join(", ")
                    )
                })?;
            let n: u64 = n
                .trim()
                .parse()
                .ok()
                .filter(|&n| n <= MAX_CASES)
                .ok_or_else(|| {
                    format!(
                        "--counts: {} must be a count in [0, {MAX_CASES}], got `{n}`",
                        t.name()
                    )
                })?;
            Ok((t, n))
        })
        .collect()
}

/// Case `index` of `target` re-run: its input, then how it ended (class, contact status, detail).
pub fn replay(target: Target, corpus: &Corpus, seed: u64, index: u64) -> String {
    let input = case_input(target, corpus, seed, index);
    let r = run_case(target, corpus, seed, index);
    let status = r
        .status
        .as_ref()
        .map(|s| format!(" (status {s})"))
        .unwrap_or_default();
    let detail = if r.detail.is_empty() {
        String::new()
    } else {
        format!(": {}", r.detail)
    };
    format!(
        "== {} case {index}\n{input}\n-> {:?}{status}{detail}\n",
        target.name(),
        r.class
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_read_per_target_and_bad_words_are_named() {
        assert_eq!(
            parse_counts("plans=5, pairs=20000,").unwrap(),
            [(Target::Plans, 5), (Target::Pairs, 20000)]
        );
        assert!(parse_counts("plans")
            .unwrap_err()
            .contains("`plans` is not TARGET=N"));
        assert!(parse_counts("bogus=1")
            .unwrap_err()
            .contains("unknown target `bogus`"));
        let e = parse_counts("csvs=100000001").unwrap_err();
        assert!(e.contains("[0, 100000000]") && e.contains("csvs"), "{e}");
    }
}
