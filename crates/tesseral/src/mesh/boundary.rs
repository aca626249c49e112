//! The boundary of a linear octree as a watertight, manifold triangle mesh.
//!
//! 1. **Boundary squares.** For each face of each black block, the aligned cube across
//!    it is classified against the tree (one binary search): black, white, or mixed;
//!    mixed cubes are split into the four quarters touching the face. White squares
//!    are boundary. The cost follows the boundary, not the volume.
//! 2. **Greedy merging.** Squares are cut into rows per plane and orientation, runs
//!    in a row are joined, and identical runs in consecutive rows are stacked into
//!    rectangles, so a flat side of any size costs two triangles.
//! 3. **Split vertices.** At a lattice point, the (up to 12) boundary unit faces are
//!    grouped by which faces continue into which across the 6 edges at the point: an
//!    edge with two boundary faces joins them; an edge with four (voxels touching only
//!    along that edge) joins the two faces of the same black voxel. Each group is one
//!    vertex, so voxels meeting at an edge or a corner get separate vertices and the
//!    surface is a manifold (black is 6-connected).
//! 4. **No T-junctions.** A rectangle includes, along its sides, every vertex that is
//!    a corner of another rectangle in the same group, and is then fanned from its
//!    centre, so the two sides of every edge are cut at the same points and every
//!    edge has exactly two triangles.

use std::collections::{HashMap, HashSet};
use std::sync::OnceLock;

use super::TriMesh;
use crate::code;
use crate::linear::LinearOctree;
use crate::Voxel;

#[derive(Clone, Copy)]
struct Square {
    a: usize,
    pos: bool,
    c: i64,
    u: i64,
    v: i64,
    s: i64,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Region {
    Full,
    Empty,
    Mixed,
}

/// Classifies the cube of side `2^k` at `min` (aligned in the tree's space, or wholly
/// outside it) against the tree.
fn classify_cube(tree: &LinearOctree, min: Voxel, k: u8) -> Region {
    let side = tree.side() as i64;
    let o = tree.origin();
    let mut rel = [0u32; 3];
    for a in 0..3 {
        let r = min[a] - o[a];
        if r < 0 || r >= side {
            return Region::Empty;
        }
        rel[a] = r as u32;
    }
    let c = code::encode(rel[0], rel[1], rel[2]);
    let len = 1u64 << (3 * u32::from(k));
    let leaves = tree.leaves();
    let i = leaves.partition_point(|l| l.code() <= c);
    if i > 0 && leaves[i - 1].end() > c {
        return if leaves[i - 1].size_log2() >= k {
            Region::Full
        } else {
            Region::Mixed
        };
    }
    if i < leaves.len() && leaves[i].code() < c + len {
        Region::Mixed
    } else {
        Region::Empty
    }
}

fn boundary_squares(tree: &LinearOctree) -> Vec<Square> {
    let mut out = Vec::new();
    for b in tree.blocks() {
        let s = b.size();
        for a in 0..3 {
            for pos in [false, true] {
                let mut n = b.min;
                n[a] += if pos { s } else { -s };
                let plane = if pos { b.min[a] + s } else { b.min[a] };
                descend(tree, n, b.size_log2, a, pos, plane, &mut out);
            }
        }
    }
    out
}

fn descend(
    tree: &LinearOctree,
    cube: Voxel,
    k: u8,
    a: usize,
    pos: bool,
    plane: i64,
    out: &mut Vec<Square>,
) {
    let (u, v) = ((a + 1) % 3, (a + 2) % 3);
    match classify_cube(tree, cube, k) {
        Region::Full => {}
        Region::Empty => out.push(Square {
            a,
            pos,
            c: plane,
            u: cube[u],
            v: cube[v],
            s: 1 << k,
        }),
        Region::Mixed => {
            let h = 1i64 << (k - 1);
            for du in 0..2 {
                for dv in 0..2 {
                    let mut m = cube;
                    m[u] += du * h;
                    m[v] += dv * h;
                    if !pos {
                        m[a] += h;
                    }
                    descend(tree, m, k - 1, a, pos, plane, out);
                }
            }
        }
    }
}

/// A rectangle of boundary in plane `x_a = c`, facing +a when `pos`, spanning
/// `[u0, u1] × [v0, v1]` in the axes `(a+1) % 3`, `(a+2) % 3`.
#[derive(Clone, Copy, Debug)]
struct Rect {
    a: usize,
    pos: bool,
    c: i64,
    u0: i64,
    u1: i64,
    v0: i64,
    v1: i64,
}

fn rectangles(squares: &[Square], merge: bool) -> Vec<Rect> {
    if !merge {
        let mut out = Vec::new();
        for q in squares {
            for du in 0..q.s {
                for dv in 0..q.s {
                    out.push(Rect {
                        a: q.a,
                        pos: q.pos,
                        c: q.c,
                        u0: q.u + du,
                        u1: q.u + du + 1,
                        v0: q.v + dv,
                        v1: q.v + dv + 1,
                    });
                }
            }
        }
        return out;
    }
    // Rows: (axis, orientation, plane, v, u0, u1).
    let mut rows: Vec<(usize, bool, i64, i64, i64, i64)> = Vec::new();
    for q in squares {
        for v in q.v..q.v + q.s {
            rows.push((q.a, q.pos, q.c, v, q.u, q.u + q.s));
        }
    }
    rows.sort_unstable();
    // Join touching runs in each row.
    let mut runs: Vec<(usize, bool, i64, i64, i64, i64)> = Vec::with_capacity(rows.len());
    for r in rows {
        if let Some(last) = runs.last_mut() {
            if (last.0, last.1, last.2, last.3) == (r.0, r.1, r.2, r.3) && last.5 == r.4 {
                last.5 = r.5;
                continue;
            }
        }
        runs.push(r);
    }
    // Stack identical runs of consecutive rows.
    // (axis, orientation, plane, u0, u1) -> (first row, last row)
    type RunKey = (usize, bool, i64, i64, i64);
    let mut open: HashMap<RunKey, (i64, i64)> = HashMap::new();
    let mut out = Vec::new();
    let emit = |key: RunKey, span: (i64, i64), out: &mut Vec<Rect>| {
        out.push(Rect {
            a: key.0,
            pos: key.1,
            c: key.2,
            u0: key.3,
            u1: key.4,
            v0: span.0,
            v1: span.1 + 1,
        });
    };
    for (a, pos, c, v, u0, u1) in runs {
        let key = (a, pos, c, u0, u1);
        match open.get_mut(&key) {
            Some(span) if span.1 == v - 1 => span.1 = v,
            Some(span) => {
                let old = *span;
                *span = (v, v);
                emit(key, old, &mut out);
            }
            None => {
                open.insert(key, (v, v));
            }
        }
    }
    let mut rest: Vec<_> = open.into_iter().collect();
    rest.sort_unstable_by_key(|e| e.0);
    for (key, span) in rest {
        emit(key, span, &mut out);
    }
    out
}

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
fn group_table() -> &'static Vec<[[i8; 12]; 64]> {
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
fn joined_by_black(config: usize, e: usize, s: usize) -> bool {
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
fn is_pinch_edge(config: usize, e: usize, s: usize) -> bool {
    let g = &group_table()[config][0];
    edge_faces(e, s).iter().all(|&f| g[f] >= 0)
}

struct Vertices<'t> {
    tree: &'t LinearOctree,
    config: HashMap<Voxel, u8>,
    groups: HashMap<Voxel, [i8; 12]>,
    ids: HashMap<(Voxel, i8), u32>,
    keys: Vec<(Voxel, i8)>,
}

impl Vertices<'_> {
    fn config(&mut self, p: Voxel) -> u8 {
        let tree = self.tree;
        *self.config.entry(p).or_insert_with(|| {
            let mut c = 0u8;
            for o in 0..8 {
                let v = [
                    p[0] - 1 + (o & 1),
                    p[1] - 1 + ((o >> 1) & 1),
                    p[2] - 1 + ((o >> 2) & 1),
                ];
                if tree.contains(v) {
                    c |= 1 << o;
                }
            }
            c
        })
    }

    /// The vertex groups of the 12 faces at `p`. An edge with four boundary faces
    /// pairs them by black voxel, unless that pinches the edge at both of its ends,
    /// in which case it pairs them by white voxel (which then cannot pinch at either
    /// end), so that no two triangles' edges share both vertices twice.
    fn groups(&mut self, p: Voxel) -> [i8; 12] {
        if let Some(g) = self.groups.get(&p) {
            return *g;
        }
        let cfg = usize::from(self.config(p));
        let mut mask = 0usize;
        for e in 0..3 {
            for s in 0..2 {
                if is_pinch_edge(cfg, e, s) && joined_by_black(cfg, e, s) {
                    let mut q = p;
                    q[e] += if s == 1 { 1 } else { -1 };
                    let qcfg = usize::from(self.config(q));
                    if joined_by_black(qcfg, e, 1 - s) {
                        mask |= 1 << (2 * e + s);
                    }
                }
            }
        }
        let g = group_table()[cfg][mask];
        self.groups.insert(p, g);
        g
    }

    /// Whether an edge at `p` has four boundary faces: such points must be vertices
    /// of every rectangle whose side passes through them.
    fn is_pinch_point(&mut self, p: Voxel) -> bool {
        let cfg = usize::from(self.config(p));
        (0..3).any(|e| (0..2).any(|s| is_pinch_edge(cfg, e, s)))
    }

    /// The vertex group at `p` of the face of `r` that touches `p`.
    fn group(&mut self, r: &Rect, p: Voxel) -> i8 {
        let (u, v) = ((r.a + 1) % 3, (r.a + 2) % 3);
        let du = usize::from(p[u] < r.u1);
        let dv = usize::from(p[v] < r.v1);
        let g = self.groups(p)[4 * r.a + du + 2 * dv];
        debug_assert!(g >= 0, "rectangle face at {p:?} is not boundary");
        g
    }

    fn id(&mut self, key: (Voxel, i8)) -> u32 {
        let next = self.keys.len() as u32;
        *self.ids.entry(key).or_insert_with(|| {
            self.keys.push(key);
            next
        })
    }
}

fn point(r: &Rect, pu: i64, pv: i64) -> Voxel {
    let mut p = [0i64; 3];
    p[r.a] = r.c;
    p[(r.a + 1) % 3] = pu;
    p[(r.a + 2) % 3] = pv;
    p
}

/// A mesh with, per vertex, its lattice point and group, and the groups per point.
type Built = (TriMesh, Vec<(Voxel, i8)>, HashMap<Voxel, [i8; 12]>);

fn build(tree: &LinearOctree, merge: bool) -> Built {
    let squares = boundary_squares(tree);
    let rects = rectangles(&squares, merge);
    let mut verts = Vertices {
        tree,
        config: HashMap::new(),
        groups: HashMap::new(),
        ids: HashMap::new(),
        keys: Vec::new(),
    };
    // Corners first: they are the vertices every side must include.
    let mut corners: HashSet<Voxel> = HashSet::new();
    for r in &rects {
        for (pu, pv) in [(r.u0, r.v0), (r.u1, r.v0), (r.u1, r.v1), (r.u0, r.v1)] {
            let p = point(r, pu, pv);
            let g = verts.group(r, p);
            verts.id((p, g));
            corners.insert(p);
        }
    }
    let mut triangles = Vec::with_capacity(2 * rects.len());
    let mut centres: Vec<[f64; 3]> = Vec::new();
    let mut poly: Vec<u32> = Vec::new();
    for r in &rects {
        poly.clear();
        // Counter-clockwise seen from +a: along v0, up u1, back along v1, down u0.
        let mut side =
            |pts: &mut dyn Iterator<Item = (i64, i64)>, verts: &mut Vertices, first: bool| {
                for (i, (pu, pv)) in pts.enumerate() {
                    let p = point(r, pu, pv);
                    if i == 0 && !first {
                        continue;
                    }
                    let is_corner = (pu == r.u0 || pu == r.u1) && (pv == r.v0 || pv == r.v1);
                    if is_corner || verts.is_pinch_point(p) {
                        let g = verts.group(r, p);
                        poly.push(verts.id((p, g)));
                    } else if corners.contains(&p) {
                        let g = verts.group(r, p);
                        if let Some(&id) = verts.ids.get(&(p, g)) {
                            poly.push(id);
                        }
                    }
                }
            };
        side(&mut (r.u0..r.u1).map(|u| (u, r.v0)), &mut verts, true);
        side(&mut (r.v0..r.v1).map(|v| (r.u1, v)), &mut verts, true);
        side(
            &mut ((r.u0 + 1)..=r.u1).rev().map(|u| (u, r.v1)),
            &mut verts,
            true,
        );
        side(
            &mut ((r.v0 + 1)..=r.v1).rev().map(|v| (r.u0, v)),
            &mut verts,
            true,
        );
        if !r.pos {
            poly.reverse();
        }
        if poly.len() == 4 {
            triangles.push([poly[0], poly[1], poly[2]]);
            triangles.push([poly[0], poly[2], poly[3]]);
        } else {
            let mut c = [0.0; 3];
            c[r.a] = r.c as f64;
            c[(r.a + 1) % 3] = (r.u0 + r.u1) as f64 / 2.0;
            c[(r.a + 2) % 3] = (r.v0 + r.v1) as f64 / 2.0;
            // Centre ids are placed after the shared vertices; fixed up below.
            let cid = u32::MAX - centres.len() as u32;
            centres.push(c);
            for i in 0..poly.len() {
                triangles.push([cid, poly[i], poly[(i + 1) % poly.len()]]);
            }
        }
    }
    let shared = verts.keys.len() as u32;
    let mut positions: Vec<[f64; 3]> = verts
        .keys
        .iter()
        .map(|(p, _)| p.map(|x| x as f64))
        .collect();
    positions.extend_from_slice(&centres);
    for t in &mut triangles {
        for i in t.iter_mut() {
            if *i > u32::MAX - centres.len() as u32 {
                *i = shared + (u32::MAX - *i);
            }
        }
    }
    (
        TriMesh {
            positions,
            triangles,
            colors: Vec::new(),
        },
        verts.keys,
        verts.groups,
    )
}

/// The boundary of `tree` as a watertight, manifold mesh in voxel coordinates
/// (voxel `(i, j, k)` is the unit cube at that corner), with coplanar faces merged.
///
/// Every edge is shared by exactly two triangles, in opposite directions, and the
/// enclosed volume equals the voxel count. Voxels that touch only along an edge or at
/// a corner get separate vertices there.
///
/// # Runtime
/// O(B log n) for B boundary squares found top-down and n leaves, plus hashing per
/// output vertex.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::mesh::boundary_mesh;
/// let cube = LinearOctree::full(5, [0, 0, 0]).unwrap(); // 32³ voxels
/// let mesh = boundary_mesh(&cube);
/// assert_eq!(mesh.triangles.len(), 12); // six sides, two triangles each
/// assert!((mesh.volume() - 32.0 * 32.0 * 32.0).abs() < 1e-6);
/// assert_eq!(mesh.edge_defects(), 0);
/// ```
#[must_use]
pub fn boundary_mesh(tree: &LinearOctree) -> TriMesh {
    build(tree, true).0
}

/// A smooth surface: the unit-face boundary with each vertex moved to the mean of the
/// centres of its faces (surface nets over the voxel centres). The topology is that of
/// the blocky boundary (watertight, manifold, split at edge and corner contacts).
///
/// # Runtime
/// O(unit boundary faces · log n).
///
/// ```
/// use tesseral::linear::LinearOctree;
/// let cube = LinearOctree::full(2, [0, 0, 0]).unwrap();
/// let mesh = tesseral::mesh::smooth_mesh(&cube);
/// assert_eq!(mesh.edge_defects(), 0);
/// assert!(mesh.volume() > 0.0 && mesh.volume() < 64.0);
/// ```
#[must_use]
pub fn smooth_mesh(tree: &LinearOctree) -> TriMesh {
    let (mut mesh, keys, groups) = build(tree, false);
    for (i, (p, g)) in keys.iter().enumerate() {
        let row = groups[p];
        let mut sum = [0.0f64; 3];
        let mut n = 0.0;
        for (f, _) in row.iter().enumerate().filter(|e| e.1 == g) {
            {
                let a = f / 4;
                let mut c = p.map(|x| x as f64);
                c[(a + 1) % 3] += (f & 1) as f64 - 0.5;
                c[(a + 2) % 3] += ((f >> 1) & 1) as f64 - 0.5;
                for (s, c) in sum.iter_mut().zip(c) {
                    *s += c;
                }
                n += 1.0;
            }
        }
        mesh.positions[i] = sum.map(|s| s / n);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn check(tree: &LinearOctree, label: &str) -> TriMesh {
        let m = boundary_mesh(tree);
        assert_eq!(m.edge_defects(), 0, "{label}: open or non-manifold edges");
        assert!(
            (m.volume() - tree.voxel_count() as f64).abs() < 1e-6,
            "{label}: volume {} != voxels {}",
            m.volume(),
            tree.voxel_count()
        );
        let s = smooth_mesh(tree);
        assert_eq!(s.edge_defects(), 0, "{label}: smooth mesh has bad edges");
        m
    }

    #[test]
    fn edge_and_corner_contacts_split_vertices() {
        // Two voxels touching along an edge, and two touching at a corner.
        let edge = LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 1, 0]]).unwrap();
        let m = check(&edge, "edge");
        assert_eq!(m.positions.len(), 16, "two separate cubes: 8 + 8 vertices");
        let corner = LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 1, 1]]).unwrap();
        let m = check(&corner, "corner");
        assert_eq!(m.positions.len(), 16);
        // The complement case: a block with one voxel missing at a corner and an
        // edge-diagonal pair missing.
        let mut vox: Vec<Voxel> = Vec::new();
        for x in 0..4 {
            for y in 0..4 {
                for z in 0..4 {
                    let hole = z < 2 && ((x, y) == (1, 1) || (x, y) == (2, 2));
                    if !hole {
                        vox.push([x, y, z]);
                    }
                }
            }
        }
        check(&LinearOctree::from_voxels(2, [0; 3], vox).unwrap(), "holes");
    }

    #[test]
    fn random_solids_are_watertight_with_exact_volume() {
        for seed in 0..120u64 {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let depth = rng.random_range(1..=4u8);
            let side = 1i64 << depth;
            let origin = [
                rng.random_range(-3..3),
                rng.random_range(-3..3),
                rng.random_range(-3..3),
            ];
            let density = rng.random_range(0.05..0.95);
            let voxels: Vec<Voxel> = (0..side)
                .flat_map(|x| (0..side).flat_map(move |y| (0..side).map(move |z| [x, y, z])))
                .filter(|_| rng.random_bool(density))
                .map(|v| [v[0] + origin[0], v[1] + origin[1], v[2] + origin[2]])
                .collect();
            let tree = LinearOctree::from_voxels(depth, origin, voxels).unwrap();
            check(&tree, &format!("seed {seed}"));
        }
    }

    #[test]
    fn big_blocks_cost_few_triangles() {
        // A 16³ block beside a single voxel: the block's shared side is cut where
        // the voxel's square sits, everything else stays one rectangle.
        let mut vox: Vec<Voxel> = Vec::new();
        for x in 0..16 {
            for y in 0..16 {
                for z in 0..16 {
                    vox.push([x, y, z]);
                }
            }
        }
        vox.push([16, 3, 5]);
        let tree = LinearOctree::from_voxels(5, [0; 3], vox).unwrap();
        let m = check(&tree, "block and voxel");
        assert!(m.triangles.len() < 60, "{} triangles", m.triangles.len());
    }

    #[test]
    fn dense_random_blocks_of_4_cubed_are_manifold() {
        // Every pinch (two voxels, or two holes, meeting along an edge) in dense
        // random 4×4×4 solids, blocky and smooth.
        for seed in 0..1500u64 {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let d = rng.random_range(0.3..0.95);
            let mut voxels: Vec<Voxel> = Vec::new();
            for x in 0..4 {
                for y in 0..4 {
                    for z in 0..4 {
                        if rng.random_bool(d) {
                            voxels.push([x, y, z]);
                        }
                    }
                }
            }
            let tree = LinearOctree::from_voxels(2, [0; 3], voxels).unwrap();
            check(&tree, &format!("dense seed {seed}"));
        }
    }
}
