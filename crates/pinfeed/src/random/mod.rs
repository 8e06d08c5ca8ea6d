//! Reproducible random streams. Every consumer draws from its own ChaCha8 stream derived from
//! (seed, stream index), so results never depend on thread count, sharding or evaluation order.
//! (`StdRng` is not used: its algorithm may change between rand releases.)

pub mod distribution;

pub use rand::rngs::ChaCha8Rng;
use rand::SeedableRng;

/// The random stream number `index` of a run seeded with `seed`.
pub fn stream(seed: u64, index: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    rng
}

/// The random stream number `index` of purpose `purpose` in a run seeded with `seed`: a family
/// of streams apart from [`stream`]'s (which the parts' draws use), one per purpose (a closed
/// loop's gate, return transit, merge, re-entries), so that adding a purpose never changes the
/// draws of another. The key is mixed by SplitMix64 (Steele, Lea & Flood 2014).
pub fn substream(seed: u64, purpose: u64, index: u64) -> ChaCha8Rng {
    let mut z = seed ^ purpose.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(17);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let mut rng = ChaCha8Rng::seed_from_u64(z ^ 0x6A09_E667_F3BC_C909);
    rng.set_stream(index);
    rng
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4)
            .map(|_| 0)
            .scan(stream(7, 3), |r, _| Some(r.random::<u64>()))
            .collect();
        let b: Vec<u64> = (0..4)
            .map(|_| 0)
            .scan(stream(7, 3), |r, _| Some(r.random::<u64>()))
            .collect();
        let c: Vec<u64> = (0..4)
            .map(|_| 0)
            .scan(stream(7, 4), |r, _| Some(r.random::<u64>()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
