//! Every JSON document pinfeed prints or writes starts with `schema_version`
//! ([`crate::SCHEMA_VERSION`]) and `pinfeed_version` ([`crate::PINFEED_VERSION`]), followed by
//! the document's own fields in their order (docs/outputs.md).

use serde::Serialize;

/// `body`'s fields after the two version fields (`body` serialises as a JSON object).
#[derive(Debug, Serialize)]
pub struct Versioned<'a, T: ?Sized + Serialize> {
    /// [`crate::SCHEMA_VERSION`].
    pub schema_version: u32,
    /// [`crate::PINFEED_VERSION`].
    pub pinfeed_version: &'static str,
    /// The document's own fields.
    #[serde(flatten)]
    pub body: &'a T,
}

/// `body` with the two version fields in front.
pub fn versioned<T: ?Sized + Serialize>(body: &T) -> Versioned<'_, T> {
    Versioned {
        schema_version: crate::SCHEMA_VERSION,
        pinfeed_version: crate::PINFEED_VERSION,
        body,
    }
}

/// Pretty JSON of `body` with the version fields, with a final newline.
pub fn pretty<T: ?Sized + Serialize>(body: &T) -> serde_json::Result<String> {
    Ok(serde_json::to_string_pretty(&versioned(body))? + "\n")
}

/// Compact JSON of `body` with the version fields, with a final newline.
pub fn compact<T: ?Sized + Serialize>(body: &T) -> serde_json::Result<String> {
    Ok(serde_json::to_string(&versioned(body))? + "\n")
}

#[cfg(test)]
mod tests {
    #[derive(serde::Serialize)]
    struct Doc {
        b: u32,
        a: &'static str,
    }

    #[test]
    fn versions_come_first_then_the_fields_in_order() {
        let s = super::compact(&Doc { b: 2, a: "x" }).unwrap();
        assert_eq!(
            s,
            format!(
                "{{\"schema_version\":{},\"pinfeed_version\":\"{}\",\"b\":2,\"a\":\"x\"}}\n",
                crate::SCHEMA_VERSION,
                crate::PINFEED_VERSION
            )
        );
    }
}
