//! Step 4: each rectangle, with every vertex on its sides, fanned into triangles.

use rustc_hash::{FxHashMap, FxHashSet};

use super::rects::rectangles;
use super::squares::boundary_squares;
use super::vertices::{point, Vertices};
use crate::linear::LinearOctree;
use crate::mesh::TriMesh;
use crate::Voxel;

/// A mesh with, per vertex, its lattice point and group, and the groups per point.
pub(super) type Built = (TriMesh, Vec<(Voxel, i8)>, FxHashMap<Voxel, [i8; 12]>);

pub(super) fn build(tree: &LinearOctree, merge: bool) -> Built {
    let squares = boundary_squares(tree);
    let rects = rectangles(&squares, merge);
    // The squares are larger than the rectangles they became: freed before the
    // vertices' maps grow.
    drop(squares);
    let mut verts = Vertices {
        tree,
        config: FxHashMap::default(),
        groups: FxHashMap::default(),
        ids: FxHashMap::default(),
        keys: Vec::new(),
    };
    // Corners first: they are the vertices every side must include. Each
    // rectangle's four corner ids are kept for its polygon below.
    let mut corners: FxHashSet<Voxel> = FxHashSet::default();
    let mut corner_ids: Vec<[u32; 4]> = Vec::with_capacity(rects.len());
    for r in &rects {
        let mut ids = [0u32; 4];
        for (k, (pu, pv)) in [(r.u0, r.v0), (r.u1, r.v0), (r.u1, r.v1), (r.u0, r.v1)]
            .into_iter()
            .enumerate()
        {
            let p = point(r, pu, pv);
            let g = verts.group(r, p);
            ids[k] = verts.id((p, g));
            corners.insert(p);
        }
        corner_ids.push(ids);
    }
    let mut triangles = Vec::with_capacity(2 * rects.len());
    let mut centres: Vec<[f64; 3]> = Vec::new();
    let mut poly: Vec<u32> = Vec::new();
    for (r, ids) in rects.iter().zip(&corner_ids) {
        poly.clear();
        // Counter-clockwise seen from +a: along v0, up u1, back along v1, down u0;
        // each side its first corner, then the points inside it that are vertices
        // (pinch points, and other rectangles' corners of the same group).
        let mut side =
            |corner: u32, inside: &mut dyn Iterator<Item = (i64, i64)>, verts: &mut Vertices| {
                poly.push(corner);
                for (pu, pv) in inside {
                    let p = point(r, pu, pv);
                    if verts.is_pinch_point(p) {
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
        side(ids[0], &mut (r.u0 + 1..r.u1).map(|u| (u, r.v0)), &mut verts);
        side(ids[1], &mut (r.v0 + 1..r.v1).map(|v| (r.u1, v)), &mut verts);
        side(
            ids[2],
            &mut (r.u0 + 1..r.u1).rev().map(|u| (u, r.v1)),
            &mut verts,
        );
        side(
            ids[3],
            &mut (r.v0 + 1..r.v1).rev().map(|v| (r.u0, v)),
            &mut verts,
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
    // Only the keys and groups are given back: the rest goes before the positions
    // are made.
    drop((corners, corner_ids));
    let Vertices { keys, groups, .. } = verts;
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
    (
        TriMesh {
            positions,
            triangles,
            colors: Vec::new(),
        },
        keys,
        groups,
    )
}
