//! The slots of a scan's scratch for blocks beyond its dense index
//! ([`Scratch`](super::ray::Scratch)).

use rustc_hash::FxHashMap;

/// The slots of blocks beyond the dense index, in bricks of 8³ blocks (a
/// brick's 512 entries, 0 or a slot plus one, side by side) found through a hash
/// map by the brick's packed offset. Consecutive rays of a scan, sorted by
/// direction, cross neighbouring blocks: these share a brick, whose entries stay
/// cached, where a hash map by block would scatter them (each probe a cache miss).
/// The last brick found is kept, as a ray crosses several blocks of one brick.
#[derive(Debug)]
pub(super) struct Far {
    bricks: FxHashMap<u64, u32>,
    entries: Vec<u32>,
    /// The key and index of the last brick found.
    last: (u64, u32),
}

impl Default for Far {
    fn default() -> Self {
        Self {
            bricks: FxHashMap::default(),
            entries: Vec::new(),
            // No brick has this key (keys take 54 bits).
            last: (u64::MAX, 0),
        }
    }
}

impl Far {
    /// The slot of the block at offset `p` (each axis in `0..2^21`), or `n`
    /// (entered as its slot) when it has none.
    #[inline]
    pub fn slot(&mut self, p: [u64; 3], n: u32) -> u32 {
        let key = p[0] >> 3 | (p[1] >> 3) << 18 | (p[2] >> 3) << 36;
        let brick = if key == self.last.0 {
            self.last.1
        } else {
            let next = (self.entries.len() / 512) as u32;
            let brick = *self.bricks.entry(key).or_insert(next);
            if brick == next {
                self.entries.resize(self.entries.len() + 512, 0);
            }
            self.last = (key, brick);
            brick
        };
        let at = brick as usize * 512 + (p[0] & 7 | (p[1] & 7) << 3 | (p[2] & 7) << 6) as usize;
        match self.entries[at] {
            0 => {
                self.entries[at] = n + 1;
                n
            }
            s => s - 1,
        }
    }
}
