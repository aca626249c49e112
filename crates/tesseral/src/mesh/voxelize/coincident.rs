//! Coincident triangles, folded before any work. A mesh that repeats a triangle many
//! times (a hostile file, or a careless export) would otherwise cost triangles ×
//! covered area: every copy is rasterized onto the same columns.
//!
//! After snapping, two triangles with the same three vertices are the same set of
//! points. Inside/outside is ray parity, so an even number of copies crosses every
//! column an even number of times and contributes nothing, and an odd number acts as
//! one copy; the watertightness check counts edges mod 2 and agrees. For a surface
//! voxelization one copy marks the same voxels as many.

use super::Tri;

/// The triangles with every group of coincident ones folded: one copy of each group
/// of odd size (or of every group, for `surface_only`), in the order of first
/// appearance, with the first copy's orientation. O(T log T).
pub(super) fn fold_coincident(tris: Vec<Tri>, surface_only: bool) -> Vec<Tri> {
    let key = |t: &Tri| {
        let mut k = *t;
        k.sort_unstable();
        k
    };
    let mut order: Vec<u32> = (0..tris.len() as u32).collect();
    order.sort_unstable_by_key(|&i| (key(&tris[i as usize]), i));
    if order
        .windows(2)
        .all(|w| key(&tris[w[0] as usize]) != key(&tris[w[1] as usize]))
    {
        return tris; // the common case: nothing to fold
    }
    let mut keep = vec![false; tris.len()];
    let mut start = 0;
    while start < order.len() {
        let k = key(&tris[order[start] as usize]);
        let mut end = start + 1;
        while end < order.len() && key(&tris[order[end] as usize]) == k {
            end += 1;
        }
        if surface_only || (end - start) % 2 == 1 {
            keep[order[start] as usize] = true;
        }
        start = end;
    }
    tris.into_iter()
        .zip(keep)
        .filter_map(|(t, k)| k.then_some(t))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(k: i64) -> Tri {
        [[k, 0, 0], [0, k, 0], [0, 0, k]]
    }

    #[test]
    fn even_groups_vanish_and_odd_groups_keep_one_copy() {
        let (a, b, c) = (tri(1), tri(2), tri(3));
        let flipped = [a[0], a[2], a[1]];
        // a three times (one flipped), b twice, c once.
        let tris = vec![a, b, c, flipped, b, a];
        assert_eq!(fold_coincident(tris.clone(), false), vec![a, c]);
        assert_eq!(fold_coincident(tris, true), vec![a, b, c]);
        let distinct = vec![c, a, b];
        assert_eq!(fold_coincident(distinct.clone(), false), distinct);
    }
}
