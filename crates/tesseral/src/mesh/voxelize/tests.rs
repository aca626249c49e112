//! The voxelizer against brute force: inside tests at voxel centres, exact overlaps,
//! crossing bounds and budgets.

use super::columns::rasterize;
use super::*;
use rand::{Rng, SeedableRng};

/// A closed axis-aligned box mesh, outward-facing.
fn box_mesh(lo: [f64; 3], hi: [f64; 3]) -> TriMesh {
    let p = |x: usize, y: usize, z: usize| {
        [
            if x == 1 { hi[0] } else { lo[0] },
            if y == 1 { hi[1] } else { lo[1] },
            if z == 1 { hi[2] } else { lo[2] },
        ]
    };
    let positions: Vec<[f64; 3]> = (0..8)
        .map(|i| p(i & 1, (i >> 1) & 1, (i >> 2) & 1))
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    TriMesh {
        positions,
        triangles,
        colors: Vec::new(),
    }
}

fn model_count(lo: [f64; 3], hi: [f64; 3], h: f64) -> u64 {
    (0..3)
        .map(|a| {
            // Centres (i + 0.5) h strictly inside, or on the surface counted by the
            // perturbation rule (not needed for these tests: no centre on a face).
            let first = (lo[a] / h - 0.5).ceil() as i64;
            let last = (hi[a] / h - 0.5).floor() as i64;
            (last - first + 1).max(0) as u64
        })
        .product()
}

#[test]
fn boxes_voxelize_to_the_exact_count() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    for case in 0..60 {
        let lo = [
            rng.random_range(-5.0..5.0),
            rng.random_range(-5.0..5.0),
            rng.random_range(-5.0..5.0),
        ];
        let hi = [
            lo[0] + rng.random_range(0.1..6.0),
            lo[1] + rng.random_range(0.1..6.0),
            lo[2] + rng.random_range(0.1..6.0),
        ];
        let h = rng.random_range(0.2..1.0);
        let opts = VoxelizeOptions {
            resolution: Resolution::VoxelSize(h),
            surface_only: false,
            ..Default::default()
        };
        let m = voxelize(&box_mesh(lo, hi), &opts).unwrap();
        m.tree.assert_valid();
        assert_eq!(
            m.tree.voxel_count(),
            model_count(lo, hi, h),
            "case {case}: {lo:?} {hi:?} h {h}"
        );
    }
}

#[test]
fn centres_on_faces_are_counted_once() {
    // Box [0.5, 4.5]^3 with unit voxels: every face passes through voxel centres.
    // The perturbation moves a column by (+ε, +ε²) in xy and a centre down in z,
    // so x and y keep voxels 0..=3 and z keeps 1..=4: 64 voxels, not 125 or 27.
    let opts = VoxelizeOptions {
        resolution: Resolution::VoxelSize(1.0),
        surface_only: false,
        ..Default::default()
    };
    let whole = voxelize(&box_mesh([0.5; 3], [4.5; 3]), &opts).unwrap();
    assert_eq!(whole.tree.voxel_count(), 64);
    assert!(whole.tree.contains([0, 0, 4]) && !whole.tree.contains([0, 0, 0]));
    // Two boxes meeting in the plane x = 2.5, which holds the centres of column
    // x = 2: the shared top and bottom edges must not count twice.
    let mut a = box_mesh([0.5, 0.5, 0.5], [2.5, 4.5, 4.5]);
    let b = box_mesh([2.5, 0.5, 0.5], [4.5, 4.5, 4.5]);
    let off = a.positions.len() as u32;
    a.positions.extend(b.positions);
    a.triangles
        .extend(b.triangles.iter().map(|t| t.map(|i| i + off)));
    let halves = voxelize(&a, &opts).unwrap();
    assert_eq!(halves.tree, whole.tree);
}

#[test]
fn random_points_agree_with_the_parity_model() {
    // A closed, non-convex mesh: two boxes joined (a union as one surface).
    let m = {
        let obj = "v 0 0 0\nv 6 0 0\nv 6 2 0\nv 2 2 0\nv 2 6 0\nv 0 6 0\n\
                   v 0 0 3\nv 6 0 3\nv 6 2 3\nv 2 2 3\nv 2 6 3\nv 0 6 3\n\
                   f 1 6 5 4 3 2\nf 7 8 9 10 11 12\n\
                   f 1 2 8 7\nf 2 3 9 8\nf 3 4 10 9\nf 4 5 11 10\nf 5 6 12 11\nf 6 1 7 12\n";
        crate::io::mesh::parse_obj(obj.as_bytes()).unwrap()
    };
    assert_eq!(m.edge_defects(), 0);
    let opts = VoxelizeOptions {
        resolution: Resolution::VoxelSize(0.25),
        surface_only: false,
        ..Default::default()
    };
    let v = voxelize(&m, &opts).unwrap();
    // L-shaped prism: area 6*2 + 2*4 = 20, height 3 → 60 units → 60 * 64 voxels.
    assert_eq!(v.tree.voxel_count(), 60 * 64);
    let shell = VoxelizeOptions {
        resolution: Resolution::VoxelSize(0.25),
        surface_only: true,
        ..Default::default()
    };
    let s = voxelize(&m, &shell).unwrap();
    s.tree.assert_valid();
    // Every surface voxel touches the solid's boundary: it is a solid voxel or a
    // neighbour of one.
    for vox in s.tree.voxels() {
        let near = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                (-1..=1).any(|dz| v.tree.contains([vox[0] + dx, vox[1] + dy, vox[2] + dz]))
            })
        });
        assert!(near, "{vox:?}");
    }
}

#[test]
fn the_crossing_bound_holds_and_the_budget_is_checked_first() {
    let side = 1i64 << 8;
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let mut next = |m: i64| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % m as u64) as i64
    };
    for seed in 0..300 {
        let t: Tri =
            std::array::from_fn(|_| [next(side * ONE), next(side * ONE), next(side * ONE)]);
        let mut out = Vec::new();
        rasterize(&t, side, &mut out);
        let bound = crossing_bound(&[t]);
        assert!(
            out.len() as u64 <= bound,
            "seed {seed}: {} > {bound}",
            out.len()
        );
    }
    // A budget below the bound is refused before any work, naming the flag.
    let opts = VoxelizeOptions {
        resolution: Resolution::Depth(6),
        max_crossings: 100,
        ..Default::default()
    };
    let e = voxelize(&box_mesh([0.0; 3], [1.0; 3]), &opts).unwrap_err();
    assert!(
        matches!(e, VoxelizeError::TooLarge(_)) && e.to_string().contains("--memory"),
        "{e}"
    );
}

#[test]
fn open_meshes_are_refused_unless_surface_only() {
    let mut m = box_mesh([0.0; 3], [1.0; 3]);
    m.triangles.pop();
    let opts = VoxelizeOptions::default();
    let err = voxelize(&m, &opts).unwrap_err();
    assert!(
        matches!(err, VoxelizeError::NotWatertight { open_edges: 3, .. }),
        "{err}"
    );
    let ok = voxelize(
        &m,
        &VoxelizeOptions {
            surface_only: true,
            ..opts
        },
    )
    .unwrap();
    assert!(ok.tree.voxel_count() > 0);
}

#[test]
fn tri_box_matches_sampling() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    for _ in 0..2000 {
        let t: Tri = std::array::from_fn(|_| std::array::from_fn(|_| rng.random_range(-20..20)));
        let lo = [
            rng.random_range(-10..5),
            rng.random_range(-10..5),
            rng.random_range(-10..5),
        ];
        let hi = [
            lo[0] + rng.random_range(0..8),
            lo[1] + rng.random_range(0..8),
            lo[2] + rng.random_range(0..8),
        ];
        let overlap = tri_box_overlap(lo, hi, &t);
        // Sampled points of the triangle inside the box imply overlap.
        for i in 0..=20 {
            for j in 0..=(20 - i) {
                let p: [f64; 3] = std::array::from_fn(|a| {
                    (t[0][a] as f64 * (20 - i - j) as f64
                        + t[1][a] as f64 * i as f64
                        + t[2][a] as f64 * j as f64)
                        / 20.0
                });
                if (0..3).all(|a| p[a] >= lo[a] as f64 && p[a] <= hi[a] as f64) {
                    assert!(overlap, "{t:?} {lo:?} {hi:?} {p:?}");
                }
            }
        }
    }
}

#[test]
fn surface_only_matches_brute_force() {
    for seed in 0..40u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let n = rng.random_range(1..12);
        let positions: Vec<[f64; 3]> = (0..3 * n)
            .map(|_| {
                // Some coordinates on voxel boundaries, to exercise touching.
                std::array::from_fn(|_| {
                    if rng.random_bool(0.3) {
                        f64::from(rng.random_range(0..8))
                    } else {
                        rng.random_range(0.0..8.0)
                    }
                })
            })
            .collect();
        let triangles = (0..n as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        let mesh = TriMesh {
            positions,
            triangles,
            colors: Vec::new(),
        };
        let opts = VoxelizeOptions {
            resolution: Resolution::VoxelSize(1.0),
            surface_only: true,
            ..Default::default()
        };
        let got = voxelize(&mesh, &opts).unwrap();
        got.tree.assert_valid();
        let o = got.tree.origin();
        let side = got.tree.side() as i64;
        let q: Vec<[i64; 3]> = mesh
            .positions
            .iter()
            .map(|p| [0, 1, 2].map(|a| ((p[a] - o[a] as f64) * ONE as f64).round() as i64))
            .collect();
        let tris: Vec<Tri> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|i| q[i as usize]))
            .collect();
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    let lo = [x * ONE, y * ONE, z * ONE];
                    let hi = [(x + 1) * ONE, (y + 1) * ONE, (z + 1) * ONE];
                    let want = tris.iter().any(|t| tri_box_overlap(lo, hi, t));
                    let v = [x + o[0], y + o[1], z + o[2]];
                    assert_eq!(got.tree.contains(v), want, "seed {seed}, voxel {v:?}");
                }
            }
        }
    }
}

#[test]
fn solid_matches_brute_force_parity() {
    // A closed but irregular mesh: a jittered sphere, voxelized and compared with
    // a column-by-column parity count over all triangles.
    for seed in 0..6u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let (lat, lon) = (7usize, 9usize);
        let mut positions = vec![[4.0, 4.0, 0.6]];
        for i in 1..lat {
            let th = std::f64::consts::PI * i as f64 / lat as f64;
            for j in 0..lon {
                let ph = 2.0 * std::f64::consts::PI * j as f64 / lon as f64;
                let r = 3.4 + rng.random_range(-0.4..0.4);
                positions.push([
                    4.0 + r * th.sin() * ph.cos(),
                    4.0 + r * th.sin() * ph.sin(),
                    4.0 - r * th.cos(),
                ]);
            }
        }
        positions.push([4.0, 4.0, 7.4]);
        let top = (positions.len() - 1) as u32;
        let at = |i: usize, j: usize| (1 + (i - 1) * lon + j % lon) as u32;
        let mut triangles = Vec::new();
        for j in 0..lon {
            triangles.push([0, at(1, j + 1), at(1, j)]);
            triangles.push([top, at(lat - 1, j), at(lat - 1, j + 1)]);
        }
        for i in 1..lat - 1 {
            for j in 0..lon {
                triangles.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            }
        }
        let mesh = TriMesh {
            positions,
            triangles,
            colors: Vec::new(),
        };
        let h = 0.25;
        let opts = VoxelizeOptions {
            resolution: Resolution::VoxelSize(h),
            surface_only: false,
            ..Default::default()
        };
        let got = voxelize(&mesh, &opts).unwrap();
        got.tree.assert_valid();
        // Brute force in f64 (no centre lies exactly on the jittered surface).
        let o = got.tree.origin();
        let side = got.tree.side() as i64;
        let mut count = 0u64;
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    let c = [
                        (x + o[0]) as f64 + 0.5,
                        (y + o[1]) as f64 + 0.5,
                        (z + o[2]) as f64 + 0.5,
                    ]
                    .map(|v| v * h);
                    let mut crossings = 0;
                    for t in &mesh.triangles {
                        let [a, b, d] = t.map(|i| mesh.positions[i as usize]);
                        let e = |p: [f64; 3], q: [f64; 3]| {
                            (q[0] - p[0]) * (c[1] - p[1]) - (q[1] - p[1]) * (c[0] - p[0])
                        };
                        let (w0, w1, w2) = (e(b, d), e(d, a), e(a, b));
                        let inside = (w0 > 0.0 && w1 > 0.0 && w2 > 0.0)
                            || (w0 < 0.0 && w1 < 0.0 && w2 < 0.0);
                        if inside {
                            let zc = (w0 * a[2] + w1 * b[2] + w2 * d[2]) / (w0 + w1 + w2);
                            if zc < c[2] {
                                crossings += 1;
                            }
                        }
                    }
                    let want = crossings % 2 == 1;
                    let v = [x + o[0], y + o[1], z + o[2]];
                    assert_eq!(got.tree.contains(v), want, "seed {seed}, voxel {v:?}");
                    count += u64::from(want);
                }
            }
        }
        assert!(count > 1000, "seed {seed}: {count}");
    }
}

/// Issue 19 item 8: coincident triangles cost triangles × area. Every triangle of a
/// box three times, plus an even stack of a large triangle cutting through it, give
/// the box's voxels exactly; surface voxelization keeps the large triangle's voxels.
#[test]
fn coincident_triangles_are_folded_exactly() {
    let plain = box_mesh([0.3, 0.2, 0.1], [5.6, 6.1, 4.7]);
    let mut stacked = plain.clone();
    let n = stacked.triangles.len();
    for _ in 0..2 {
        for t in 0..n {
            stacked.triangles.push(stacked.triangles[t]);
        }
    }
    let base = stacked.positions.len() as u32;
    stacked
        .positions
        .extend([[-1.0, -1.0, 2.0], [7.0, -1.0, 2.0], [-1.0, 7.0, 2.0]]);
    for k in 0..1000 {
        let t = [base, base + 1, base + 2];
        stacked
            .triangles
            .push(if k % 2 == 0 { t } else { [t[0], t[2], t[1]] });
    }
    let opts = |surface_only| VoxelizeOptions {
        resolution: Resolution::VoxelSize(0.5),
        surface_only,
        ..Default::default()
    };
    let want = voxelize(&plain, &opts(false)).unwrap();
    let got = voxelize(&stacked, &opts(false)).unwrap();
    got.assert_valid();
    assert!(got.tree.same_voxels(&want.tree).unwrap());
    assert_eq!(got.frame, want.frame);
    // Surface only: the box's surface and the large triangle's plane, once.
    let mut once = plain.clone();
    once.positions
        .extend([[-1.0, -1.0, 2.0], [7.0, -1.0, 2.0], [-1.0, 7.0, 2.0]]);
    once.triangles.push([base, base + 1, base + 2]);
    let want = voxelize(&once, &opts(true)).unwrap();
    let got = voxelize(&stacked, &opts(true)).unwrap();
    got.assert_valid();
    assert!(got.tree.same_voxels(&want.tree).unwrap());
}
