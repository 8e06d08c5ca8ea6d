//! A stable 64-bit content hash (FNV-1a) that identifies a study: the study file's bytes, the
//! scenario file's bytes and the number of samples per point. Shards of one study carry the same
//! hash; `merge` refuses shards whose hashes differ. Not cryptographic: it guards against mixing
//! up files, not against forgery.

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a over a sequence of byte strings, each followed by a 0xff separator so that moving bytes
/// between parts changes the hash.
pub fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h = OFFSET;
    for p in parts {
        for &b in p.iter().chain(std::iter::once(&0xffu8)) {
            h ^= b as u64;
            h = h.wrapping_mul(PRIME);
        }
    }
    h
}

/// The hash as 16 hex digits.
pub fn hex(h: u64) -> String {
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_value_and_separation() {
        // FNV-1a 64 of "a" is af63dc4c8601ec8c; with the separator byte it differs.
        let mut h = OFFSET;
        h ^= b'a' as u64;
        h = h.wrapping_mul(PRIME);
        assert_eq!(hex(h), "af63dc4c8601ec8c");
        assert_ne!(fnv1a(&[b"ab", b"c"]), fnv1a(&[b"a", b"bc"]));
        assert_eq!(fnv1a(&[b"x"]), fnv1a(&[b"x"]));
    }
}
