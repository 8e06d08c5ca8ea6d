//! The key of a map: a canonical little-endian encoding of every input that changes its answer
//! (format version, the contact model's version, normalised polygon, support, pin radius in units of a, μc, tolerance, travel
//! limit, budgets, grid), hashed with two FNV-1a 64-bit streams (a 128-bit key; not
//! cryptographic — it names cache files and detects stale ones).

use super::{TierInputs, TierSpec};
use crate::mechanics::{Support, MODEL_VERSION};
use std::fmt;

/// Bumped whenever the tier's sampling, certification or file layout changes meaning.
pub const FORMAT_VERSION: u32 = 2;

/// A 128-bit map key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TierKey(pub [u8; 16]);

impl fmt::Display for TierKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for b in self.0 {
            write!(f, "{b:02x}")?;
        }
        Ok(())
    }
}

/// FNV-1a over `bytes`, from offset basis `basis`.
pub fn fnv1a64(bytes: &[u8], basis: u64) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h = basis;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(PRIME);
    }
    h
}

/// The standard FNV-1a 64 offset basis, and a second one for the other half of the key.
pub const BASIS: u64 = 0xcbf2_9ce4_8422_2325;
const BASIS_2: u64 = 0x6c62_272e_07bb_0142;

/// Canonical bytes of a map's inputs, for the current contact model.
pub fn encode(inputs: &TierInputs) -> Vec<u8> {
    encode_for_model(inputs, MODEL_VERSION)
}

/// Canonical bytes of a map's inputs as a contact model of version `model_version` would key them.
fn encode_for_model(inputs: &TierInputs, model_version: u32) -> Vec<u8> {
    let mut b = Vec::with_capacity(512);
    b.extend_from_slice(b"pinfeed-map-tier");
    b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    b.extend_from_slice(&model_version.to_le_bytes());
    let model = inputs.model;
    let k = model.scale();
    let verts = model.polygon().vertices();
    b.extend_from_slice(&(verts.len() as u64).to_le_bytes());
    for v in verts {
        put_f64(&mut b, v.x);
        put_f64(&mut b, v.y);
    }
    match inputs.support {
        Support::Uniform => b.push(0),
        Support::Points { points, weights } => {
            b.push(1);
            b.extend_from_slice(&(points.len() as u64).to_le_bytes());
            for (p, w) in points.iter().zip(weights) {
                put_f64(&mut b, p.x / k);
                put_f64(&mut b, p.y / k);
                put_f64(&mut b, *w);
            }
        }
    }
    put_f64(&mut b, inputs.radius / k);
    let s = &inputs.settings;
    put_f64(&mut b, s.mu_c);
    put_f64(&mut b, s.tol);
    put_f64(&mut b, s.max_travel);
    b.extend_from_slice(&s.max_evaluations.to_le_bytes());
    b.extend_from_slice(&s.max_events.to_le_bytes());
    encode_spec(&mut b, &inputs.spec);
    b
}

fn encode_spec(b: &mut Vec<u8>, spec: &TierSpec) {
    b.extend_from_slice(&spec.theta_cells.to_le_bytes());
    b.extend_from_slice(&spec.d_cells.to_le_bytes());
    b.extend_from_slice(&spec.max_depth.to_le_bytes());
    put_f64(b, spec.check_deg);
    put_f64(b, spec.check_pos);
}

/// An f64 by its bits, with −0 folded onto +0 (the same input).
fn put_f64(b: &mut Vec<u8>, x: f64) {
    let x = if x == 0.0 { 0.0 } else { x };
    b.extend_from_slice(&x.to_bits().to_le_bytes());
}

impl TierKey {
    /// The key of a map's inputs.
    pub fn of(inputs: &TierInputs) -> TierKey {
        TierKey::of_bytes(&encode(inputs))
    }

    fn of_bytes(bytes: &[u8]) -> TierKey {
        let mut key = [0u8; 16];
        key[..8].copy_from_slice(&fnv1a64(bytes, BASIS).to_le_bytes());
        key[8..].copy_from_slice(&fnv1a64(bytes, BASIS_2).to_le_bytes());
        TierKey(key)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::{ContactSettings, PartModel};

    /// A map cached by an older contact model is keyed apart from the current one's (so it is
    /// rebuilt, not reused), and the key of the current model is the one `TierKey::of` gives.
    #[test]
    fn the_key_carries_the_contact_models_version() {
        let model =
            PartModel::new(&part_from_spec("tripoly2").unwrap(), &Support::Uniform).unwrap();
        let inputs = TierInputs {
            model: &model,
            support: &Support::Uniform,
            radius: 0.002,
            settings: ContactSettings::default(),
            spec: TierSpec::default(),
        };
        let now = TierKey::of(&inputs);
        assert_eq!(
            now,
            TierKey::of_bytes(&encode_for_model(&inputs, MODEL_VERSION))
        );
        assert_ne!(
            now,
            TierKey::of_bytes(&encode_for_model(&inputs, MODEL_VERSION - 1))
        );
        assert_ne!(
            now,
            TierKey::of_bytes(&encode_for_model(&inputs, MODEL_VERSION + 1))
        );
    }
}
