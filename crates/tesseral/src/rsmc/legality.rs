//! The local legality test of one move (Libes §6, step 3, made exact).
//!
//! # The condition
//! Let `B` be the black set, a PL 3-ball (the union of its closed unit cubes), and
//! let `p` be the voxel that a move toggles. Let `X` be the colour that `p` joins:
//! black for growth, white for shrinking. The move is legal exactly when
//! `K = X ∩ ∂p`, the part of the surface of the cube `p` touched by closed cubes of
//! colour `X`, is a closed 2-disc.
//!
//! *Sufficient*: the union of two 3-balls that meet in a 2-disc on both boundaries is
//! a 3-ball, so growth keeps `B` a ball. For shrinking, run the same argument on the
//! white side in the 3-sphere `R³ ∪ {∞}`, where the complement of a PL ball is a ball
//! (Alexander): the white ball grows, so the black side stays a ball.
//!
//! *Necessary*: if both `B` and `B ∪ p` are balls, Mayer–Vietoris gives that `K` is
//! connected, non-empty and acyclic; and `K` must be pure (every edge and vertex of
//! `K` lies on a face of `K`), else the cubes of `X` around `p` would meet `p` along
//! an edge only or a vertex only, and `B ∪ p` would not be a manifold.
//!
//! # The test in bits
//! `K` is pure and a disc iff
//! 1. the set `F` of faces of `p` whose neighbour has colour `X` is a disc on the
//!    cube: 1 to 5 faces, but not two opposite faces (two discs) and not four faces
//!    missing an opposite pair (an annulus). Libes's rule (ii) is the case "only the
//!    top and bottom neighbours exist".
//! 2. every edge neighbour of colour `X` has one of its two face neighbours in `X`
//!    (Libes's rule (i): no two voxels share only an edge), and
//! 3. every corner neighbour of colour `X` has one of its three face neighbours in
//!    `X` (no two voxels share only a vertex).
//!
//! Conditions 2 and 3 are read for both colours, since shrinking applies them to
//! white: this is "the same holds for empty cells". The whole test is two table
//! look-ups and a mask, O(1).
//!
//! ```
//! use tesseral::lattice::Neighbourhood;
//! use tesseral::rsmc::legality::legal_grow;
//! // Growing next to a lone voxel at -x: legal.
//! let lone = Neighbourhood::EMPTY.with([-1, 0, 0]);
//! assert!(legal_grow(lone));
//! // Only the top and bottom neighbours: would close a tunnel (Libes Fig. 4).
//! let top_bottom = Neighbourhood::EMPTY.with([0, 0, -1]).with([0, 0, 1]);
//! assert!(!legal_grow(top_bottom));
//! ```

use crate::lattice::{Directions, Neighbourhood};

/// The 20 edge and corner neighbours (two or three non-zero offsets), as bits.
const NON_FACE: u32 = Neighbourhood::EDGES_AND_CORNERS.bits();

/// Whether the face set `f` is a disc on the cube.
#[must_use]
pub const fn face_set_is_disc(f: Directions) -> bool {
    let f = f.bits();
    let n = f.count_ones();
    if n == 0 || n == 6 {
        return false;
    }
    let opposite_pairs = [0b11u8, 0b1100, 0b11_0000];
    let mut i = 0;
    while i < 3 {
        if n == 2 && f == opposite_pairs[i] {
            return false;
        }
        if n == 4 && (!f & 0x3f) == opposite_pairs[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// `DISC[f]`: [`face_set_is_disc`] for all 64 face sets.
pub const DISC: [bool; 64] = {
    let mut t = [false; 64];
    let mut f = 0;
    while f < 64 {
        t[f] = face_set_is_disc(Directions::from_bits(f as u8));
        f += 1;
    }
    t
};

/// `COVERED[f]`: the edge and corner neighbours that touch at least one face
/// neighbour in the face set `f` (an edge neighbour touches its two face neighbours,
/// a corner neighbour its three).
pub const COVERED: [u32; 64] = {
    let mut t = [0u32; 64];
    let mut f = 0;
    while f < 64 {
        let mut m = 0u32;
        let mut b = 0;
        while b < 27 {
            let d = [b % 3, (b / 3) % 3, b / 9];
            let nz = (d[0] != 1) as u32 + (d[1] != 1) as u32 + (d[2] != 1) as u32;
            if nz >= 2 {
                // Face neighbours of this cell's contact with p: one per non-zero axis.
                let mut covered = false;
                let mut axis = 0;
                while axis < 3 {
                    if d[axis] != 1 {
                        let dir = 2 * axis + (d[axis] == 2) as usize;
                        if f & (1 << dir) != 0 {
                            covered = true;
                        }
                    }
                    axis += 1;
                }
                if covered {
                    m |= 1 << b;
                }
            }
            b += 1;
        }
        t[f] = m;
        f += 1;
    }
    t
};

/// Whether toggling the centre cell into colour `X` keeps the black set a ball,
/// where `x` holds the cells of colour `X` in the 26-neighbourhood (the centre bit
/// is ignored). O(1).
#[inline]
#[must_use]
pub const fn legal_join(x: Neighbourhood) -> bool {
    let f = x.faces().bits() as usize;
    DISC[f] && (x.bits() & NON_FACE & !COVERED[f]) == 0
}

/// Whether creating the (white) centre voxel is legal, given the black occupancy
/// `n` of its neighbourhood. O(1).
#[inline]
#[must_use]
pub const fn legal_grow(n: Neighbourhood) -> bool {
    legal_join(n)
}

/// Whether deleting the (black) centre voxel is legal, given the black occupancy
/// `n` of its neighbourhood. O(1).
#[inline]
#[must_use]
pub const fn legal_shrink(n: Neighbourhood) -> bool {
    legal_join(n.complement())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::collections::{BTreeSet, HashMap};

    fn nb(bits: u32) -> Neighbourhood {
        Neighbourhood::from_bits(bits)
    }

    /// Brute force, from the definition: build the sub-complex K of the cube surface
    /// ∂p touched by closed cubes of colour X, and decide whether K is a closed disc
    /// (connected pure 2-complex, a 2-manifold with boundary, Euler characteristic 1).
    fn brute_is_disc(x: Neighbourhood) -> bool {
        let x = x.bits();
        // Cube p = [0,1]^3 with lattice points in {0,1}^3. A neighbour cell with
        // offset d occupies [d, d+1]; it touches the point q of p iff q_i ∈ {d_i, d_i+1}.
        let cells: Vec<[i64; 3]> = (0..27)
            .filter(|&b| b != 13 && x & (1 << b) != 0)
            .map(|b| [b % 3 - 1, (b / 3) % 3 - 1, b / 9 - 1])
            .collect();
        let touches = |c: &[i64; 3], q: [i64; 3]| (0..3).all(|i| q[i] == c[i] || q[i] == c[i] + 1);
        let pts: Vec<[i64; 3]> = (0..8).map(|i| [i & 1, (i >> 1) & 1, i >> 2]).collect();
        // A closed cell of ∂p (vertex, edge or face) is a set of cube corners; it is in K
        // iff one closed neighbour cube contains all its corners.
        let in_k =
            |corners: &[[i64; 3]]| cells.iter().any(|c| corners.iter().all(|&q| touches(c, q)));
        let vertices: Vec<usize> = (0..8).filter(|&i| in_k(&[pts[i]])).collect();
        let mut edges = Vec::new();
        for i in 0..8usize {
            for j in i + 1..8 {
                if (i ^ j).count_ones() == 1 && in_k(&[pts[i], pts[j]]) {
                    edges.push((i, j));
                }
            }
        }
        let mut faces = Vec::new();
        for axis in 0..3 {
            for side in 0..2 {
                let f: Vec<usize> = (0..8).filter(|&i| (i >> axis) & 1 == side).collect();
                let corners: Vec<[i64; 3]> = f.iter().map(|&i| pts[i]).collect();
                if in_k(&corners) {
                    faces.push(f);
                }
            }
        }
        if faces.is_empty() {
            return false;
        }
        // Pure: every vertex and edge of K lies on a face of K.
        for &v in &vertices {
            if !faces.iter().any(|f| f.contains(&v)) {
                return false;
            }
        }
        for &(i, j) in &edges {
            if !faces.iter().any(|f| f.contains(&i) && f.contains(&j)) {
                return false;
            }
        }
        // Manifold with boundary: the faces around each vertex form one fan (a path or
        // a cycle). Faces at a vertex of a cube are at most 3, pairwise adjacent
        // through edges of K; the link is a path or cycle iff the faces at the vertex
        // are connected through shared edges.
        for &v in &vertices {
            let at: Vec<&Vec<usize>> = faces.iter().filter(|f| f.contains(&v)).collect();
            let mut comp: Vec<usize> = (0..at.len()).collect();
            for a in 0..at.len() {
                for b in 0..at.len() {
                    let shared = at[a].iter().filter(|q| at[b].contains(q)).count();
                    if a != b && shared == 2 {
                        let (ca, cb) = (comp[a], comp[b]);
                        for c in comp.iter_mut() {
                            if *c == cb {
                                *c = ca;
                            }
                        }
                    }
                }
            }
            if comp.iter().collect::<BTreeSet<_>>().len() != 1 {
                return false;
            }
        }
        // Connected through shared edges.
        let mut comp: Vec<usize> = (0..faces.len()).collect();
        for _ in 0..faces.len() {
            for a in 0..faces.len() {
                for b in 0..faces.len() {
                    if faces[a].iter().filter(|q| faces[b].contains(q)).count() == 2 {
                        let m = comp[a].min(comp[b]);
                        comp[a] = m;
                        comp[b] = m;
                    }
                }
            }
        }
        if comp.iter().collect::<BTreeSet<_>>().len() != 1 {
            return false;
        }
        let chi = vertices.len() as i64 - edges.len() as i64 + faces.len() as i64;
        chi == 1
    }

    #[test]
    fn tables_match_brute_force_on_all_face_sets() {
        // Every face set, with no edge or corner neighbours, and with all edge and
        // corner neighbours: 128 cases, exhaustive.
        for f in 0..64u32 {
            let mut x = 0;
            for d in Directions::from_bits(f as u8).iter() {
                x |= 1 << Neighbourhood::face_bit(d);
            }
            assert_eq!(
                legal_join(nb(x)),
                brute_is_disc(nb(x)),
                "faces only {f:06b}"
            );
            let y = x | NON_FACE;
            assert_eq!(
                legal_join(nb(y)),
                brute_is_disc(nb(y)),
                "faces {f:06b} + all others"
            );
        }
    }

    #[test]
    fn tables_match_brute_force_on_all_small_extras() {
        // Every face set with every choice of up to two of the 20 edge and corner
        // neighbours: 64 × (1 + 20 + 190) cases, exhaustive at that size.
        let others: Vec<u32> = (0..27).filter(|b| NON_FACE & (1 << b) != 0).collect();
        assert_eq!(others.len(), 20);
        for f in 0..64u32 {
            let mut x = 0;
            for d in Directions::from_bits(f as u8).iter() {
                x |= 1 << Neighbourhood::face_bit(d);
            }
            for i in 0..=others.len() {
                for j in i..=others.len() {
                    let mut y = x;
                    if i < others.len() {
                        y |= 1 << others[i];
                    }
                    if j < others.len() {
                        y |= 1 << others[j];
                    }
                    assert_eq!(legal_join(nb(y)), brute_is_disc(nb(y)), "x = {y:#029b}");
                }
            }
        }
    }

    #[test]
    fn tables_match_brute_force_on_random_neighbourhoods() {
        let seed = 0x5eed_1e6a;
        println!("seed {seed:#x}");
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        let mut agree: HashMap<bool, u64> = HashMap::new();
        for i in 0..60_000 {
            // Vary the density so both sparse and dense neighbourhoods appear.
            let p = [0.1, 0.3, 0.5, 0.7, 0.9][i % 5];
            let mut x = 0u32;
            for b in 0..27 {
                if b != 13 && rng.random_bool(p) {
                    x |= 1 << b;
                }
            }
            let fast = legal_join(nb(x));
            assert_eq!(
                fast,
                brute_is_disc(nb(x)),
                "x = {x:#029b} (seed {seed:#x}, case {i})"
            );
            *agree.entry(fast).or_default() += 1;
        }
        // Both outcomes must be well represented, or the test proves little.
        assert!(agree[&true] > 1000 && agree[&false] > 1000, "{agree:?}");
    }

    #[test]
    fn libes_rules_examples() {
        // Rule (i), Fig. 3: deleting a voxel that leaves two voxels sharing only an edge.
        // Black: centre, +x, +y, and the diagonal (+x,+y)... deleting the centre leaves
        // +x, +y, diag: still connected through the diagonal, legal. Instead take black
        // centre, +x and +y only: deleting the centre leaves +x and +y sharing an edge.
        let e = Neighbourhood::EMPTY;
        let n = e.with([0, 0, 0]).with([1, 0, 0]).with([0, 1, 0]);
        assert!(!legal_shrink(n));
        // Growing next to a lone edge-diagonal voxel only: rule (i).
        assert!(!legal_grow(e.with([1, 1, 0]).with([-1, 0, 0])));
        // Rule (ii), Fig. 4: top and bottom only.
        assert!(!legal_grow(e.with([0, 0, -1]).with([0, 0, 1])));
        // The last voxel can never be deleted.
        assert!(!legal_shrink(e.with([0, 0, 0])));
    }
}
