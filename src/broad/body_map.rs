//! Body id maps of the stateful broad phases, with a hash fit for `u32` ids.
//!
//! The standard library's SipHash guards against adversarial keys and costs about 20 ns a
//! look-up; body ids are chosen by the scene, not by an adversary, and every moved body is
//! looked up once per frame. One multiply by the golden-ratio constant spreads an id over
//! the high bits, and folding the high half down reaches the low bits the table indexes by.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Body id → a value (by default its slot).
pub(crate) type BodyMap<V = u32> = HashMap<u32, V, BuildHasherDefault<IdHasher>>;

/// Multiplicative hash of one `u32` id.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct IdHasher {
    state: u64,
}

impl Hasher for IdHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    #[inline]
    fn write_u32(&mut self, id: u32) {
        self.write_u64(u64::from(id));
    }

    #[inline]
    fn write_u64(&mut self, word: u64) {
        self.state = (self.state ^ word).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.state ^ (self.state >> 32)
    }
}
