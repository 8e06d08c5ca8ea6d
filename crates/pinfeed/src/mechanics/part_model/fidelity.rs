//! [`Fidelity`]: which model of the support friction a solve uses, with its command-line name.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Which model of the support friction to use (docs/physics.md#fidelity-tiers).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// The thesis's COR-locus tip (Peshkin & Sanderson): slowest possible rotation.
    Tip,
    /// Ellipsoidal limit surface (Lynch et al. 1992).
    Ellipsoid,
    /// The limit surface of the actual pressure distribution.
    #[default]
    Exact,
}

impl Fidelity {
    /// The name on the command line and in reports: `tip`, `ellipsoid` or `exact`.
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Tip => "tip",
            Fidelity::Ellipsoid => "ellipsoid",
            Fidelity::Exact => "exact",
        }
    }

    /// The fidelity named `s` (as [`Fidelity::name`] spells it); `None` for any other string.
    pub fn parse(s: &str) -> Option<Fidelity> {
        match s {
            "tip" => Some(Fidelity::Tip),
            "ellipsoid" => Some(Fidelity::Ellipsoid),
            "exact" => Some(Fidelity::Exact),
            _ => None,
        }
    }
}

impl fmt::Display for Fidelity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back() {
        for fid in [Fidelity::Tip, Fidelity::Ellipsoid, Fidelity::Exact] {
            assert_eq!(Fidelity::parse(fid.name()), Some(fid));
            assert_eq!(fid.to_string(), fid.name());
        }
        assert_eq!(Fidelity::parse("map"), None);
    }
}
