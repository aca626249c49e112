//! Step 3: the vertex groups at a lattice point, one table for every colouring of
//! its eight voxels.

use std::sync::OnceLock;

/// The face at a lattice point with normal `a` whose other offsets are the bits of
/// octant `o` along the other two axes: index `4a + du + 2dv`.
fn face_index(a: usize, o: usize) -> usize {
    let (u, v) = ((a + 1) % 3, (a + 2) % 3);
    4 * a + ((o >> u) & 1) + 2 * ((o >> v) & 1)
}

/// The four faces around the edge at a lattice point along axis `e`, towards `+e`
/// when `s == 1`: `(normal axis, face index)` for the faces with normal `others[0]`
/// then `others[1]`.
fn edge_faces(e: usize, s: usize) -> [usize; 4] {
    let others = [(e + 1) % 3, (e + 2) % 3];
    let mut out = [0; 4];
    for (i, &a) in others.iter().enumerate() {
        let w = others[1 - i];
        for wb in 0..2 {
            out[2 * i + wb] = face_index(a, (s << e) | (wb << w));
        }
    }
    out
}

/// The vertex groups at a lattice point: for each of the 256 colourings of its 8
/// voxels and each choice of pairing at its 6 edges (bit `2e + s` set: an edge with
/// four boundary faces pairs the faces of the same *white* voxel instead of the same
/// black voxel), the group of each of the 12 faces (-1 when not boundary).
pub(super) fn group_table() -> &'static Vec<[[i8; 12]; 64]> {
    static TABLE: OnceLock<Vec<[[i8; 12]; 64]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut table = vec![[[-1i8; 12]; 64]; 256];
        for (config, rows) in table.iter_mut().enumerate() {
            for (mask, row) in rows.iter_mut().enumerate() {
                *row = groups_for(config, mask);
            }
        }
        table
    })
}

fn groups_for(config: usize, mask: usize) -> [i8; 12] {
    let black = |o: usize| (config >> o) & 1 == 1;
    let mut boundary = [false; 12];
    for (f, b) in boundary.iter_mut().enumerate() {
        let a = f / 4;
        let (u, v) = ((a + 1) % 3, (a + 2) % 3);
        let o0 = ((f & 1) << u) | (((f >> 1) & 1) << v);
        *b = black(o0) != black(o0 | 1 << a);
    }
    let mut parent: [usize; 12] = std::array::from_fn(|i| i);
    fn find(p: &mut [usize; 12], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let union = |p: &mut [usize; 12], x: usize, y: usize| {
        let (rx, ry) = (find(p, x), find(p, y));
        p[rx] = ry;
    };
    for e in 0..3 {
        for s in 0..2 {
            let others = [(e + 1) % 3, (e + 2) % 3];
            let faces: Vec<usize> = edge_faces(e, s)
                .into_iter()
                .filter(|&f| boundary[f])
                .collect();
            match faces.len() {
                2 => union(&mut parent, faces[0], faces[1]),
                4 => {
                    let want_black = mask & (1 << (2 * e + s)) == 0;
                    for o in 0..8 {
                        if (o >> e) & 1 == s && black(o) == want_black {
                            union(
                                &mut parent,
                                face_index(others[0], o),
                                face_index(others[1], o),
                            );
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let mut label = [-1i8; 12];
    let mut row = [-1i8; 12];
    let mut next = 0i8;
    for f in 0..12 {
        if boundary[f] {
            let r = find(&mut parent, f);
            if label[r] < 0 {
                label[r] = next;
                next += 1;
            }
            row[f] = label[r];
        }
    }
    row
}

/// Whether, pairing by black voxels everywhere, the two sheets through the edge
/// `(e, s)` at a point of colouring `config` are one group there (the edge would be
/// pinched at this end).
pub(super) fn joined_by_black(config: usize, e: usize, s: usize) -> bool {
    let g = &group_table()[config][0];
    let others = [(e + 1) % 3, (e + 2) % 3];
    let mut groups = Vec::with_capacity(2);
    for o in 0..8 {
        if (o >> e) & 1 == s && (config >> o) & 1 == 1 {
            groups.push(g[face_index(others[0], o)]);
        }
    }
    groups.len() == 2 && groups[0] == groups[1]
}

/// Whether the edge `(e, s)` at a point of colouring `config` has four boundary faces.
pub(super) fn is_pinch_edge(config: usize, e: usize, s: usize) -> bool {
    let g = &group_table()[config][0];
    edge_faces(e, s).iter().all(|&f| g[f] >= 0)
}

/// Whether an edge at a point of colouring `config` has four boundary faces (a
/// table of the 256 colourings).
pub(super) fn is_pinch_point(config: u8) -> bool {
    static TABLE: OnceLock<[bool; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|c| (0..3).any(|e| (0..2).any(|s| is_pinch_edge(c, e, s))))
    })[usize::from(config)]
}
