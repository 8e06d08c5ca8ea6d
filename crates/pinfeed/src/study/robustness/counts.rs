//! What a `pinfeed fuzz` run is asked for: each target's case count (`--counts TARGET=N,...`) and
//! one case re-run and described (`--case N`).

use super::{case_input, run_case, Corpus, Target};

/// Most cases of one target in a run.
pub const MAX_CASES: u64 = 100_000_000;

/// Why a `--counts` list could not be read ([`parse_counts`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CountsError {
    /// A word without `=`.
    #[error("--counts: `{0}` is not TARGET=N")]
    NotPair(String),
    /// A name that is no fuzz target.
    #[error(
        "--counts: unknown target `{name}` (expected one of {})",
        Target::ALL.map(|t| t.name()).join(", ")
    )]
    Target {
        /// The name given.
        name: String,
    },
    /// A count that is not a whole number in [0, [`MAX_CASES`]].
    #[error("--counts: {} must be a count in [0, {MAX_CASES}], got `{value}`", .target.name())]
    Count {
        /// The target the count is for.
        target: Target,
        /// The text given as its count.
        value: String,
    },
}

/// `TARGET=N,...`: the targets' own case counts, each in [0, [`MAX_CASES`]]; an error names the
/// word it could not read and what was expected.
pub fn parse_counts(text: &str) -> Result<Vec<(Target, u64)>, CountsError> {
    text.split(',')
        .filter(|w| !w.trim().is_empty())
        .map(|w| {
            let (name, n) = w
                .split_once('=')
                .ok_or_else(|| CountsError::NotPair(w.to_string()))?;
            let t = Target::ALL
                .into_iter()
                .find(|t| t.name() == name.trim())
                .ok_or_else(|| CountsError::Target {
                    name: name.trim().to_string(),
                })?;
            let n: u64 = n
                .trim()
                .parse()
                .ok()
                .filter(|&n| n <= MAX_CASES)
                .ok_or_else(|| CountsError::Count {
                    target: t,
                    value: n.to_string(),
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
        assert_eq!(
            parse_counts("plans").unwrap_err(),
            CountsError::NotPair("plans".into())
        );
        assert!(parse_counts("plans")
            .unwrap_err()
            .to_string()
            .contains("`plans` is not TARGET=N"));
        assert_eq!(
            parse_counts("bogus=1").unwrap_err(),
            CountsError::Target {
                name: "bogus".into()
            }
        );
        assert!(parse_counts("bogus=1")
            .unwrap_err()
            .to_string()
            .contains("unknown target `bogus`"));
        let e = parse_counts("csvs=100000001").unwrap_err();
        assert!(
            matches!(
                e,
                CountsError::Count {
                    target: Target::Csvs,
                    ..
                }
            ),
            "{e:?}"
        );
        let e = e.to_string();
        assert!(e.contains("[0, 100000000]") && e.contains("csvs"), "{e}");
    }
}
