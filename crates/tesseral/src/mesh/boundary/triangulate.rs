//! Step 4: each rectangle, with every vertex on its sides, fanned into triangles.

use super::lattice::{corners, perimeter, Lattice};
use super::rects::{rectangles, Rect};
use super::squares::boundary_squares;
use super::vertices::Vertices;
use crate::linear::LinearOctree;
use crate::mesh::TriMesh;
use crate::Voxel;

/// A mesh with, per vertex, its lattice point and group, and the groups of the 12
/// faces at its point.
pub(super) type Built = (TriMesh, Vec<(Voxel, i8)>, Vec<[i8; 12]>);

pub(super) fn build(tree: &LinearOctree, merge: bool) -> Built {
    let squares = boundary_squares(tree);
    let rects = rectangles(&squares, merge);
    // The squares are larger than the rectangles they became: freed before the
    // lattice is made.
    drop(squares);
    let lattice = Lattice::new(tree, &rects);
    let mut verts = Vertices::new(&lattice);
    // Corners first: they are the vertices every side must include. Each
    // rectangle's four corner ids are kept for its polygon below.
    let mut corner_ids: Vec<[u32; 4]> = Vec::with_capacity(rects.len());
    for (r, &start) in rects.iter().zip(&lattice.starts) {
        let mut ids = [0u32; 4];
        for (k, (at, p)) in corners(r).into_iter().enumerate() {
            let at = lattice.point[start + at];
            ids[k] = verts.id(at, p, verts.group(r, p, at));
            verts.mark_corner(at);
        }
        corner_ids.push(ids);
    }
    let mut fans = Fans::with_capacity(rects.len());
    let mut poly: Vec<u32> = Vec::new();
    for ((r, ids), &start) in rects.iter().zip(&corner_ids).zip(&lattice.starts) {
        poly.clear();
        // Counter-clockwise seen from +a: each side its first corner, then the
        // points inside it that are vertices (pinch points, and other rectangles'
        // corners of the same group).
        let at_corner = corners(r).map(|(at, _)| at);
        let mut next = 0;
        for (j, p) in perimeter(r).enumerate() {
            if next < 4 && j == at_corner[next] {
                poly.push(ids[next]);
                next += 1;
                continue;
            }
            let at = lattice.point[start + j];
            if verts.is_pinch_point(at) {
                let g = verts.group(r, p, at);
                poly.push(verts.id(at, p, g));
            } else if verts.is_corner(at) {
                if let Some(id) = verts.existing(at, verts.group(r, p, at)) {
                    poly.push(id);
                }
            }
        }
        fans.add(r, &mut poly);
    }
    // Only the keys and groups are given back: the rest goes before the positions
    // are made.
    drop(corner_ids);
    let Vertices { keys, rows, .. } = verts;
    drop(lattice);
    (fans.into_mesh(&keys), keys, rows)
}

/// The triangles of the rectangles' polygons, and the centres of those fanned.
pub(super) struct Fans {
    triangles: Vec<[u32; 3]>,
    centres: Vec<[f64; 3]>,
}

impl Fans {
    pub(super) fn with_capacity(rects: usize) -> Self {
        Self {
            triangles: Vec::with_capacity(2 * rects),
            centres: Vec::new(),
        }
    }

    /// The triangles of `r`'s polygon `poly` (its vertex ids counter-clockwise seen
    /// from +a; reversed here when `r` faces −a): two for a plain rectangle, else a
    /// fan from its centre.
    pub(super) fn add(&mut self, r: &Rect, poly: &mut [u32]) {
        if !r.pos {
            poly.reverse();
        }
        if poly.len() == 4 {
            self.triangles.push([poly[0], poly[1], poly[2]]);
            self.triangles.push([poly[0], poly[2], poly[3]]);
        } else {
            let mut c = [0.0; 3];
            c[r.a] = r.c as f64;
            c[(r.a + 1) % 3] = (r.u0 + r.u1) as f64 / 2.0;
            c[(r.a + 2) % 3] = (r.v0 + r.v1) as f64 / 2.0;
            // Centre ids are placed after the shared vertices; fixed up below.
            let cid = u32::MAX - self.centres.len() as u32;
            self.centres.push(c);
            for i in 0..poly.len() {
                self.triangles
                    .push([cid, poly[i], poly[(i + 1) % poly.len()]]);
            }
        }
    }

    /// The mesh: the vertices `keys` (their lattice points), then the centres.
    pub(super) fn into_mesh(self, keys: &[(Voxel, i8)]) -> TriMesh {
        let Self {
            mut triangles,
            centres,
        } = self;
        let shared = keys.len() as u32;
        let mut positions: Vec<[f64; 3]> = keys.iter().map(|(p, _)| p.map(|x| x as f64)).collect();
        positions.extend_from_slice(&centres);
        for t in &mut triangles {
            for i in t.iter_mut() {
                if *i > u32::MAX - centres.len() as u32 {
                    *i = shared + (u32::MAX - *i);
                }
            }
        }
        TriMesh {
            positions,
            triangles,
            colors: Vec::new(),
        }
    }
}
