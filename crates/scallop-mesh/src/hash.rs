//! One fast hash map for keys made of integer words (cell numbers, indices,
//! float bit patterns), shared by the mesh's welding and the readers' merging
//! of identical vertices.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A multiply-rotate hasher per 64-bit word (the Fx hash of rustc), then a full
/// avalanche (the SplitMix64 finaliser), so that float bit patterns with zero low
/// bits spread well. Not DoS-resistant, which a local batch computation on its own
/// keys does not need; no output depends on the iteration order of its maps.
#[derive(Default, Clone, Copy, Debug)]
pub struct WordHasher(u64);

impl Hasher for WordHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u64(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn write_u32(&mut self, word: u32) {
        self.write_u64(u64::from(word));
    }

    fn write_i64(&mut self, word: i64) {
        self.write_u64(word.cast_unsigned());
    }

    fn write_usize(&mut self, word: usize) {
        self.write_u64(word as u64);
    }

    fn finish(&self) -> u64 {
        // SplitMix64 finaliser.
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// A `HashMap` with [`WordHasher`].
///
/// ```
/// let mut first = scallop_mesh::FastMap::<[u64; 3], usize>::default();
/// first.insert([1, 2, 3], 0);
/// assert_eq!(first.get(&[1, 2, 3]), Some(&0));
/// ```
pub type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<WordHasher>>;
