//! An arena of non-uniform blocks (the store keeps two): one `Vec<u16>` cut into
//! units of 16 bytes, with a free list per size (the store compacts it once a
//! quarter is free).

/// `u16` words per unit.
pub(crate) const UNIT: usize = 8;

/// The most units an arena addresses (28 bits of a block entry): 4 GiB.
pub(crate) const MAX_UNITS: usize = 1 << 28;

#[derive(Debug, Clone)]
pub(crate) struct Arena {
    /// The words, `UNIT` per unit; a block starts at a unit.
    pub words: Vec<u16>,
    /// Free chunks by size in units: `free[n]` lists the offsets of free `n`-unit chunks.
    pub free: Vec<Vec<u32>>,
    /// Units in free chunks.
    pub free_units: usize,
    /// The most units the arena may hold ([`MAX_UNITS`], less in tests).
    pub limit: usize,
}

impl Default for Arena {
    fn default() -> Self {
        Self {
            words: Vec::new(),
            free: Vec::new(),
            free_units: 0,
            limit: MAX_UNITS,
        }
    }
}

impl Arena {
    /// Units in use or free (the arena's length).
    pub fn len_units(&self) -> usize {
        self.words.len() / UNIT
    }

    /// Whether [`alloc`](Self::alloc) of `units` units would succeed.
    pub fn has_room(&self, units: usize) -> bool {
        self.free.get(units).is_some_and(|f| !f.is_empty())
            || self.len_units() + units <= self.limit.min(MAX_UNITS)
    }

    /// A chunk of `units` units (contents unspecified), as its offset in units, or
    /// `None` when the arena would pass its limit (at most [`MAX_UNITS`], 4 GiB of
    /// blocks, as far as a block entry's 28 bits of offset reach).
    pub fn alloc(&mut self, units: usize) -> Option<u32> {
        if let Some(at) = self.free.get_mut(units).and_then(Vec::pop) {
            self.free_units -= units;
            return Some(at);
        }
        let at = self.len_units();
        if at + units > self.limit.min(MAX_UNITS) {
            return None;
        }
        let need = self.words.len() + units * UNIT;
        if need > self.words.capacity() {
            // Grow by an eighth, not a doubling: the capacity is counted in `bytes`.
            let extra = (self.words.len() / 8).max(units * UNIT).max(64 * UNIT);
            self.words.reserve_exact(extra);
        }
        self.words.resize(need, 0);
        Some(at as u32)
    }

    /// Frees the chunk of `units` units at `at`.
    pub fn release(&mut self, at: u32, units: usize) {
        if self.free.len() <= units {
            self.free.resize_with(units + 1, Vec::new);
        }
        self.free[units].push(at);
        self.free_units += units;
    }

    /// The words of the chunk at `at` (in units), `len` words long.
    #[inline]
    pub fn get(&self, at: u32, len: usize) -> &[u16] {
        let s = at as usize * UNIT;
        &self.words[s..s + len]
    }

    /// The words of the chunk at `at`, mutably.
    #[inline]
    pub fn get_mut(&mut self, at: u32, len: usize) -> &mut [u16] {
        let s = at as usize * UNIT;
        &mut self.words[s..s + len]
    }

    /// Bytes held: the words' capacity and the free lists.
    pub fn bytes(&self) -> usize {
        self.words.capacity() * 2
            + self.free.capacity() * std::mem::size_of::<Vec<u32>>()
            + self.free.iter().map(|f| f.capacity() * 4).sum::<usize>()
    }
}
