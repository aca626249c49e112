//! The last two levels at once: 4 × 4 × 4 occupancy masks, cut out of a window and
//! turned back into leaves.

use crate::linear::Leaf;

/// The voxels of the 2 × 2 × 2 octant 0 of a 4 × 4 × 4 block, bit `x + 4y + 16z`.
pub(super) const OCTANT: u64 = 0x0033_0033;

/// The bit offset of octant `d` (label `x + 2y + 4z`) in a 4 × 4 × 4 block; half of
/// it is the offset of voxel `d` within an octant.
#[inline]
pub(super) fn octant_shift(d: usize) -> u32 {
    (2 * (d & 1) + 8 * ((d >> 1) & 1) + 32 * ((d >> 2) & 1)) as u32
}

/// `n` copies of a `width`-bit pattern, every `width` bits of a u64.
const fn repeat(pattern: u64, width: u32) -> u64 {
    let mut out = 0;
    let mut i = 0;
    while i < 64 {
        out |= pattern << i;
        i += width;
    }
    out
}

/// How to cut a 4 × 4 × 4 block at offset `r` (each in 0..4) out of the 8 × 8 × 8
/// region of eight blocks: the shifts and the masks of the bits that come from the
/// lower block on each axis, computed once per resample.
#[derive(Clone, Copy)]
pub(super) struct Cut {
    r: [u32; 3],
    low_x: u64,
    low_y: u64,
}

impl Cut {
    pub(super) fn new(r: [i64; 3]) -> Self {
        let r = r.map(|v| v as u32);
        Self {
            r,
            low_x: repeat((1 << (4 - r[0])) - 1, 4),
            low_y: repeat((1 << (4 * (4 - r[1]))) - 1, 16),
        }
    }

    /// The block, from the eight blocks `m` (index `x + 2y + 4z`), all in layout
    /// `x + 4y + 16z`.
    #[inline]
    pub(super) fn extract(&self, m: [u64; 8]) -> u64 {
        let [rx, ry, rz] = self.r;
        let sx = |a: u64, b: u64| -> u64 {
            if rx == 0 {
                a
            } else {
                ((a >> rx) & self.low_x) | ((b << (4 - rx)) & !self.low_x)
            }
        };
        let sy = |a: u64, b: u64| -> u64 {
            if ry == 0 {
                a
            } else {
                ((a >> (4 * ry)) & self.low_y) | ((b << (4 * (4 - ry))) & !self.low_y)
            }
        };
        let p0 = sy(sx(m[0], m[1]), sx(m[2], m[3]));
        if rz == 0 {
            return p0;
        }
        let p1 = sy(sx(m[4], m[5]), sx(m[6], m[7]));
        (p0 >> (16 * rz)) | (p1 << (16 * (4 - rz)))
    }
}

/// Appends the canonical leaves of a 4 × 4 × 4 block (bit `x + 4y + 16z`) whose
/// lowest voxel has code `code`.
#[inline]
pub(super) fn emit_block(block: u64, code: u64, out: &mut Vec<Leaf>) {
    if block == u64::MAX {
        out.push(Leaf::new(code, 2));
        return;
    }
    if block == 0 {
        return;
    }
    for d in 0..8usize {
        let x = block >> octant_shift(d);
        // The octant's eight voxels as a byte, bit e for voxel label e.
        let byte = (x & 0x3) | ((x >> 2) & 0xc) | ((x >> 12) & 0x30) | ((x >> 14) & 0xc0);
        let c = code + 8 * d as u64;
        if byte == 0xff {
            out.push(Leaf::new(c, 1));
            continue;
        }
        let mut bits = byte;
        while bits != 0 {
            let e = u64::from(bits.trailing_zeros());
            out.push(Leaf::new(c + e, 0));
            bits &= bits - 1;
        }
    }
}
