//! Tests of the dynamic octree against naive models: a `HashSet` of voxels for
//! occupancy, and a dense `Vec<Face>` with linear search that applies the face-list
//! order rule literally.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

mod convert;
mod faces;
mod growth;
mod sequences;
mod tess_dyn;

/// The face-list rule of the contract, applied to a plain `Vec` with linear search.
#[derive(Default)]
struct Model {
    set: HashSet<Voxel>,
    faces: Vec<Face>,
}

impl Model {
    fn remove_face(&mut self, f: Face) {
        let i = self.faces.iter().position(|&g| g == f).expect("model face");
        self.faces.swap_remove(i);
    }
    fn insert(&mut self, v: Voxel) -> bool {
        if !self.set.insert(v) {
            return false;
        }
        for dir in Direction::ALL {
            let n = dir.step(v);
            if self.set.contains(&n) {
                self.remove_face(Face {
                    voxel: n,
                    dir: dir.opposite(),
                });
            } else {
                self.faces.push(Face { voxel: v, dir });
            }
        }
        true
    }
    fn remove(&mut self, v: Voxel) -> bool {
        if !self.set.remove(&v) {
            return false;
        }
        for dir in Direction::ALL {
            let n = dir.step(v);
            if self.set.contains(&n) {
                self.faces.push(Face {
                    voxel: n,
                    dir: dir.opposite(),
                });
            } else {
                self.remove_face(Face { voxel: v, dir });
            }
        }
        true
    }
    fn neighbourhood(&self, v: Voxel) -> Neighbourhood {
        let mut r = 0;
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let n = [
                        v[0].wrapping_add(dx),
                        v[1].wrapping_add(dy),
                        v[2].wrapping_add(dz),
                    ];
                    if self.set.contains(&n) {
                        r |= 1 << ((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1));
                    }
                }
            }
        }
        Neighbourhood::from_bits(r)
    }
}

fn check_against(t: &DynamicOctree, m: &Model, probes: &[Voxel]) {
    assert_eq!(t.voxel_count(), m.set.len() as u64);
    for &p in probes {
        assert_eq!(t.contains(p), m.set.contains(&p), "contains {p:?}");
        assert_eq!(
            t.neighbourhood(p),
            m.neighbourhood(p),
            "neighbourhood {p:?}"
        );
    }
    if t.tracks_faces() {
        assert_eq!(t.faces(), m.faces, "face list order");
    }
}

/// Random create/delete sequences in a box `[lo, lo + side)³`, checked after every
/// operation.
fn random_ops(seed: u64, lo: Voxel, side: i64, steps: usize, p_insert: f64, faces: bool) {
    random_ops_in(seed, lo, side, steps, p_insert, faces, !faces);
}

/// [`random_ops`] with the block form chosen: `small` makes new blocks start small
/// (the default without faces), otherwise they are bitmaps (the default with faces).
fn random_ops_in(
    seed: u64,
    lo: Voxel,
    side: i64,
    steps: usize,
    p_insert: f64,
    faces: bool,
    small: bool,
) {
    eprintln!("random_ops seed {seed} lo {lo:?} side {side} faces {faces} small {small}");
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = if faces {
        DynamicOctree::with_faces()
    } else {
        DynamicOctree::new()
    };
    t.set_small_blocks(small);
    let mut m = Model::default();
    let pick = |rng: &mut Pcg64| -> Voxel {
        std::array::from_fn(|a| lo[a].wrapping_add(rng.random_range(0..side)))
    };
    for step_no in 0..steps {
        let v = if !m.set.is_empty() && rng.random_bool(0.3) {
            // hit an existing voxel or its neighbour so deletions and contacts happen
            let i = rng.random_range(0..m.set.len());
            let w = *m.set.iter().nth(i).unwrap();
            Direction::ALL[rng.random_range(0..6)].step(w)
        } else {
            pick(&mut rng)
        };
        // Every other step goes through the variants that take the neighbourhood
        // from the caller (as the RS/MC chain does).
        let known = step_no % 2 == 1;
        let nb = t.neighbourhood(v);
        if rng.random_bool(p_insert) {
            let got = if known {
                t.insert_with_neighbourhood(v, nb)
            } else {
                t.insert(v)
            };
            assert_eq!(got, m.insert(v), "insert {v:?} at step {step_no}");
        } else {
            let got = if known {
                t.remove_with_neighbourhood(v, nb)
            } else {
                t.remove(v)
            };
            assert_eq!(got, m.remove(v), "remove {v:?} at step {step_no}");
        }
        t.assert_valid();
        let probes: Vec<Voxel> = (0..4)
            .map(|_| pick(&mut rng))
            .chain([v, Direction::NegX.step(v), Direction::PosZ.step(v)])
            .collect();
        check_against(&t, &m, &probes);
    }
    let mut got = t.voxels();
    let mut want: Vec<Voxel> = m.set.iter().copied().collect();
    got.sort_unstable();
    want.sort_unstable();
    assert_eq!(got, want);
}
