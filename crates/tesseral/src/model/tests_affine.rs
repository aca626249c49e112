//! Per-axis scaling and affine maps of models against the map of world cubes.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::tests::{check, key, moved, random_frame, random_model, world};
use crate::linear::rotation_matrix;

#[test]
fn scaling_per_axis_follows_the_world_model() {
    for seed in 0..200 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let (h, t) = random_frame(&mut rng);
        let m = random_model(&mut rng, h, t);
        let hk = key([h, 0.0, 0.0])[0];
        let k: [i64; 3] = [0; 3].map(|_| [-2, -1, 1, 2, 3][rng.random_range(0..5)]);
        let r = m.scale_axes(k).unwrap();
        assert_eq!(r.frame.voxel_size, h);
        // The world cube [K, K + h) scales to [kK, k(K + h)), |k| cubes along the axis.
        let expect = moved(&world(&m), |c| {
            let starts = |a: usize| -> Vec<i64> {
                let lo = (k[a] * c[a]).min(k[a] * (c[a] + hk));
                (0..k[a].abs()).map(|i| lo + i * hk).collect()
            };
            let mut out = Vec::new();
            for x in starts(0) {
                for y in starts(1) {
                    for z in starts(2) {
                        out.push([x, y, z]);
                    }
                }
            }
            out
        });
        check(&r, &expect, &format!("scale_axes {k:?}"), seed);
    }
}

#[test]
fn quarter_turns_by_matrix_follow_the_world_model() {
    for seed in 0..100 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let (h, t) = random_frame(&mut rng);
        let m = random_model(&mut rng, h, t);
        let hk = key([h, 0.0, 0.0])[0];
        // A quarter turn about z through a world point on the lattice's corners.
        let about = [t[0] + h * 3.0, t[1] - h * 2.0, 0.0];
        let r = m
            .rotate_about(rotation_matrix([0.0, 0.0, 1.0], 90.0), about)
            .unwrap();
        assert_eq!(r.frame, m.frame);
        let a = key(about);
        let expect = moved(&world(&m), |c| {
            // (x, y) -> (a0 - (y - a1), a1 + (x - a0)); the cube's lowest corner
            // moves to the image of its (x, y + h) corner.
            vec![[a[0] - (c[1] + hk - a[1]), a[1] + (c[0] - a[0]), c[2]]]
        });
        check(&r, &expect, "rotate_about 90° z", seed);
    }
}

#[test]
fn values_follow_their_voxels_under_any_rotation() {
    for seed in 0..100 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let (h, t) = random_frame(&mut rng);
        let m = random_model(&mut rng, h, t);
        let axis: [f64; 3] = [0; 3].map(|_| rng.random_range(-1.0..1.0));
        let rot = rotation_matrix(axis, rng.random_range(-180.0..180.0));
        let about = m.bbox_centre();
        let r = m.rotate_about(rot, about).unwrap();
        r.assert_valid();
        // Each output voxel carries the values of the voxel its centre came from.
        for w in r
            .tree
            .voxels()
            .chain(r.free.iter().flat_map(|f| f.voxels()))
        {
            let c = r.frame.to_world(w.map(|x| x as f64 + 0.5));
            let d = [0, 1, 2].map(|i| c[i] - about[i]);
            // The inverse of a rotation is its transpose.
            let p: [f64; 3] =
                std::array::from_fn(|i| about[i] + (0..3).map(|j| rot[j][i] * d[j]).sum::<f64>());
            let v = m.frame.voxel_of_point(p);
            assert_eq!(r.tree.contains(w), m.tree.contains(v), "seed {seed}");
            let colour = |mm: &super::Model, x| mm.colors.as_ref().and_then(|l| l.get(x));
            assert_eq!(colour(&r, w), colour(&m, v), "seed {seed}");
        }
    }
}

/// The identity matrix with a whole-voxel offset is a translation: the voxels the
/// point sampling gives, in the space the translation keeps (the sampling took a
/// wider one), and with no offset the model itself.
#[test]
fn the_identity_moves_as_a_translation() {
    let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for seed in 0..100 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let (h, t) = random_frame(&mut rng);
        let m = random_model(&mut rng, h, t);
        let by: [i64; 3] = [0; 3].map(|_| rng.random_range(-5..5));
        let r = m.affine_world(id, by.map(|c| c as f64 * h)).unwrap();
        let hk = key([h, 0.0, 0.0])[0];
        let expect = moved(&world(&m), |c| vec![[0, 1, 2].map(|a| c[a] + by[a] * hk)]);
        check(&r, &expect, "identity moving by whole voxels", seed);
        let sampled = m.tree.affine(id, by.map(|c| c as f64)).unwrap();
        let sorted = |t: &crate::linear::LinearOctree| {
            let mut v: Vec<_> = t.voxels().collect();
            v.sort_unstable();
            v
        };
        assert_eq!(
            sorted(&r.tree),
            sorted(&sampled),
            "seed {seed}: the voxels of the sampling"
        );
        let same = m.affine_world(id, [0.0; 3]).unwrap();
        assert_eq!(
            (same.tree.depth(), same.tree.origin()),
            (m.tree.depth(), m.tree.origin()),
            "seed {seed}: the space"
        );
        assert!(same.tree.voxels().eq(m.tree.voxels()), "seed {seed}");
    }
}
