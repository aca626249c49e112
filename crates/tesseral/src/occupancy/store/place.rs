//! Placing blocks in the arenas: a slot's block emptied, made uniform or given
//! room in the arena its values call for, moved between the arenas, and an arena
//! compacted once a quarter of it is free, or at the end of a batch of scans once
//! an eighth of its bytes hold no block ([`Store::tidy`]).

use super::arena::{Arena, UNIT};
use super::census::Census;
use super::forms::{decode, units_of, wide, SPARSE};
use super::{block_of, Entry, Store, BLOCK_CELLS, OCCUPIED, OPEN};
use crate::occupancy::sensor::Fixed;

impl Store {
    /// Empties slot `s`, freeing its block's storage.
    pub(super) fn clear(&mut self, s: usize) {
        let e = self.tables[s];
        if e != Entry::EMPTY {
            self.blocks -= 1;
        }
        self.set_entry(s, Entry::EMPTY);
        if e.in_arena() {
            let units = units_of(e.tag(), self.words_of(e));
            self.release(e.arena(), e.offset(), units);
        }
    }

    /// Writes slot `s`'s entry, mirrored in the read index.
    #[inline]
    pub(super) fn set_entry(&mut self, s: usize, e: Entry) {
        self.tables[s] = e;
        self.flat.set(block_of(&self.keys, s), e);
    }

    /// Makes slot `s` a uniform block of value `v` (a clamp), freeing its storage.
    pub(super) fn set_uniform(&mut self, s: usize, v: i16) {
        self.clear(s);
        self.set_entry(s, Entry::uniform(v));
        self.blocks += 1;
    }

    /// Gives slot `s` (emptied first) a new block of `units` units with this tag, in
    /// the arena of blocks that list an occupied value when `occupied` (see
    /// [`lists_occupied`](super::forms::lists_occupied)); returns the block's words.
    /// `None`, leaving the slot as it was, when that arena has no room for it (past
    /// its limit): then [`Store::overflowed`] tells.
    pub(super) fn place(
        &mut self,
        s: usize,
        tag: u32,
        units: usize,
        occupied: bool,
    ) -> Option<&mut [u16]> {
        let a = usize::from(occupied);
        let old = self.tables[s];
        let at = if old.in_arena()
            && old.arena() == a
            && units_of(old.tag(), self.words_of(old)) == units
        {
            old.offset()
        } else {
            if !self.arenas[a].has_room(units) {
                self.overflowed = true;
                return None;
            }
            self.clear(s);
            self.blocks += 1;
            // Clearing may compact an arena, which only makes room.
            self.arenas[a].alloc(units).expect("room checked")
        };
        self.set_entry(s, Entry::at(tag, a, at));
        Some(self.arenas[a].get_mut(at, units * UNIT))
    }

    /// Moves the block of slot `s` (entry `e`, in the open arena), which lists an
    /// occupied value now, to the occupied arena. When that arena is full the block
    /// stays (its cells are right, only its place is not): then `crowded`.
    pub(super) fn relocate(&mut self, s: usize, e: Entry) {
        debug_assert_eq!(e.arena(), OPEN, "only open blocks move in place");
        let units = units_of(e.tag(), self.words_of(e));
        let Some(at) = self.arenas[OCCUPIED].alloc(units) else {
            self.crowded = true;
            return;
        };
        let [open, occupied] = &mut self.arenas;
        let len = units * UNIT;
        occupied
            .get_mut(at, len)
            .copy_from_slice(open.get(e.offset(), len));
        self.set_entry(s, Entry::at(e.tag(), OCCUPIED, at));
        self.release(OPEN, e.offset(), units);
    }

    /// Frees the chunk of `units` units at `at` in arena `a`, and compacts that
    /// arena once a quarter of it is free (and more than a few KiB).
    fn release(&mut self, a: usize, at: u32, units: usize) {
        let arena = &mut self.arenas[a];
        arena.release(at, units);
        if arena.free_units * 4 > arena.len_units() && arena.free_units > 256 {
            self.compact(a);
        }
    }

    /// Whether a block was refused for want of room in the arena (so that some
    /// updates were dropped), since the store was made.
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    /// An arena's limit in bytes (each has its own).
    pub fn limit_bytes(&self) -> usize {
        self.arenas[OPEN].limit * UNIT * 2
    }

    /// Lowers each arena's limit to `units` units (a test hook: the real limit,
    /// 4 GiB, is too big for a test).
    #[cfg(test)]
    pub fn set_limit_units(&mut self, units: usize) {
        self.arenas.iter_mut().for_each(|a| a.limit = units);
    }

    /// Ends a batch of scans: [`repatch`](Self::repatch), [`tidy`](Self::tidy),
    /// then [`settle`](Self::settle).
    ///
    /// # Runtime
    /// That of the three.
    pub fn pack(&mut self, fixed: Fixed) {
        self.repatch(fixed);
        self.tidy();
        self.settle();
    }

    /// Compacts each arena in which more than an eighth of the bytes hold no
    /// block (free chunks and room reserved for growth, more than a few KiB), and
    /// trims the tables' room for growth past an eighth: called at the end of a
    /// batch of scans, it leaves the map within an eighth of its blocks' and
    /// tables' bytes. (The arena grows by an eighth at a time, so growth alone
    /// does not set it off.)
    ///
    /// # Runtime
    /// O(s + u) for s table slots and u units of an arena compacted; nothing when
    /// none is.
    pub fn tidy(&mut self) {
        for a in [OPEN, OCCUPIED] {
            let arena = &self.arenas[a];
            let held = arena.words.capacity() / UNIT;
            let idle = held - (arena.len_units() - arena.free_units);
            if idle * 8 > held && idle > 256 {
                self.compact(a);
            }
        }
        if (self.tables.capacity() - self.tables.len()) * 8 > self.tables.len() {
            self.tables.shrink_to_fit();
            self.keys.shrink_to_fit();
        }
    }

    /// Notes slot `s` for [`repatch`](Self::repatch). The notes are kept to one
    /// per slot once they pass the blocks stored, so that a map updated a scan at
    /// a time and never repatched holds at most 4 bytes a block of them.
    pub(super) fn note_pending(&mut self, s: usize) {
        self.pending.push(s as u32);
        if self.pending.len() > self.blocks.max(4096) {
            self.pending.sort_unstable();
            self.pending.dedup();
        }
    }

    /// Stores each block noted by a scan's update (a palette of 4 or 8 bits, a
    /// dense block, a long sparse one) in its smallest form, a patched palette
    /// among them. At the end of a batch of scans, before [`tidy`](Self::tidy).
    ///
    /// # Runtime
    /// O(n log n + 512 n) for n blocks noted.
    pub fn repatch(&mut self, fixed: Fixed) {
        // Taken, not cleared: a batch's notes may be many, and their room goes too.
        let mut pending = std::mem::take(&mut self.pending);
        pending.sort_unstable();
        pending.dedup();
        let mut cells = [0i16; BLOCK_CELLS];
        for s in pending {
            let s = s as usize;
            let e = self.tables[s];
            let tag = e.tag();
            if !(wide(tag) || tag == SPARSE) {
                continue;
            }
            // Stored again in its smallest form, which may be a patched palette or,
            // for a palette updated in place whose values have since dwindled, a
            // narrower palette.
            decode(tag, self.words_of(e), &mut cells);
            self.put_census(s, &cells, &Census::of(&cells), fixed, true);
        }
    }

    /// Moves every block of arena `a` to a new arena, in table order, leaving no
    /// free chunk and no room for growth (the arena's next block grows it).
    fn compact(&mut self, a: usize) {
        let old = std::mem::take(&mut self.arenas[a]);
        let used = old.len_units() - old.free_units;
        let mut words = Vec::with_capacity(used * UNIT);
        for (s, e) in self.tables.iter_mut().enumerate() {
            if e.in_arena() && e.arena() == a {
                let from = e.offset() as usize * UNIT;
                let len = units_of(e.tag(), &old.words[from..]) * UNIT;
                let at = (words.len() / UNIT) as u32;
                words.extend_from_slice(&old.words[from..from + len]);
                *e = Entry::at(e.tag(), a, at);
                self.flat.set(block_of(&self.keys, s), *e);
            }
        }
        self.arenas[a] = Arena {
            words,
            limit: old.limit,
            ..Arena::default()
        };
        self.compactions += 1;
    }
}
