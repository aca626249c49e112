//! Tests of the chain: global topology along trajectories, a naive lattice as a
//! third implementation, checkpoints, Libes's worked examples (detailed balance is in
//! `tests_balance.rs`).

use std::collections::{HashMap, HashSet};

use super::*;

/// The obviously-right lattice: a `HashSet` of voxels, a `Vec` of faces and a
/// `HashMap` from face to index, following the same order rule.
#[derive(Default)]
pub(crate) struct NaiveLattice {
    set: HashSet<Voxel>,
    faces: Vec<Face>,
    at: HashMap<Face, usize>,
}

impl NaiveLattice {
    fn push(&mut self, f: Face) {
        self.at.insert(f, self.faces.len());
        self.faces.push(f);
    }
    fn take(&mut self, f: Face) {
        let i = self.at.remove(&f).expect("listed face");
        self.faces.swap_remove(i);
        if i < self.faces.len() {
            self.at.insert(self.faces[i], i);
        }
    }
}

impl Lattice for NaiveLattice {
    fn empty() -> Self {
        Self::default()
    }
    fn insert(&mut self, v: Voxel) -> bool {
        if !self.set.insert(v) {
            return false;
        }
        for d in Direction::ALL {
            let n = d.step(v);
            if self.set.contains(&n) {
                self.take(Face {
                    voxel: n,
                    dir: d.opposite(),
                });
            } else {
                self.push(Face { voxel: v, dir: d });
            }
        }
        true
    }
    fn remove(&mut self, v: Voxel) -> bool {
        if !self.set.remove(&v) {
            return false;
        }
        for d in Direction::ALL {
            let n = d.step(v);
            if self.set.contains(&n) {
                self.push(Face {
                    voxel: n,
                    dir: d.opposite(),
                });
            } else {
                self.take(Face { voxel: v, dir: d });
            }
        }
        true
    }
    fn contains(&self, v: Voxel) -> bool {
        self.set.contains(&v)
    }
    fn voxel_count(&self) -> u64 {
        self.set.len() as u64
    }
    fn face_count(&self) -> usize {
        self.faces.len()
    }
    fn face(&self, i: usize) -> Face {
        self.faces[i]
    }
    fn neighbourhood(&self, v: Voxel) -> Neighbourhood {
        let mut bits = 0;
        for b in 0..27i64 {
            let w = [v[0] + b % 3 - 1, v[1] + (b / 3) % 3 - 1, v[2] + b / 9 - 1];
            bits |= u32::from(self.set.contains(&w)) << b;
        }
        Neighbourhood::from_bits(bits)
    }
}

fn params(beta: f64) -> Params {
    Params {
        beta,
        ..Params::default()
    }
}

#[test]
fn trajectories_keep_sphere_topology() {
    // Growing (β < 0), neutral, shrinking-biased and Libes's rule; global checks
    // every 1000 steps.
    for (i, p) in [
        params(-0.3),
        params(0.0),
        Params {
            beta: 0.4,
            mu: -0.5,
            ..Params::default()
        },
        Params {
            hastings: false,
            ..Params::default()
        },
    ]
    .into_iter()
    .enumerate()
    {
        let seed = 1000 + i as u64;
        let mut chain = Chain::new(DenseLattice::new(), p, seed, &[[0, 0, 0]]).unwrap();
        for round in 0..20 {
            chain.run(1000);
            let voxels = chain.voxels();
            let report = topology::check_sphere(&voxels)
                .unwrap_or_else(|e| panic!("seed {seed} params {p:?} round {round}: {e}"));
            assert_eq!(report.faces, chain.area(), "seed {seed}");
            assert_eq!(report.volume, chain.volume(), "seed {seed}");
            assert_eq!(report.euler(), 2);
            chain.lattice().assert_valid();
            if round % 5 == 4 {
                chain.assert_valid();
            }
        }
        let c = chain.counters();
        assert_eq!(c.steps, 20_000);
        assert_eq!(c.steps, c.accepted + c.illegal + c.capped + c.refused);
        assert!(c.accepted > 1000, "seed {seed}: {c:?}");
        assert!(c.illegal > 0, "seed {seed}: the rules never fired: {c:?}");
    }
}

#[test]
fn dense_and_naive_lattices_give_identical_trajectories() {
    for seed in [1u64, 2, 3] {
        let p = params(-0.2);
        let mut a = Chain::new(DenseLattice::new(), p, seed, &[[0, 0, 0]]).unwrap();
        let mut b = Chain::new(NaiveLattice::default(), p, seed, &[[0, 0, 0]]).unwrap();
        for step in 0..30_000 {
            assert_eq!(a.step(), b.step(), "seed {seed} step {step}");
            if step % 1000 == 0 {
                assert_eq!(a.faces(), b.faces(), "seed {seed} step {step}");
            }
        }
        assert_eq!(a.counters(), b.counters());
        assert_eq!(a.voxels(), b.voxels());
        assert_eq!(a.faces(), b.faces());
        assert!(a.area() > 200, "grew to {}", a.area());
    }
}

#[test]
fn area_cap_holds() {
    let p = Params {
        beta: -1.0,
        max_area: Some(40),
        ..Params::default()
    };
    let mut chain = Chain::new(DenseLattice::new(), p, 9, &[[0, 0, 0]]).unwrap();
    for _ in 0..20_000 {
        chain.step();
        assert!(chain.area() <= 40);
    }
    assert!(chain.counters().capped > 0);
}

#[test]
fn bad_start_and_parameters_are_errors() {
    let bad = Chain::new(DenseLattice::new(), params(0.0), 1, &[[0, 0, 0], [1, 1, 0]]);
    assert!(matches!(bad, Err(RsmcError::BadStart(_))));
    let bad = Chain::new(DenseLattice::new(), params(f64::NAN), 1, &[[0, 0, 0]]);
    assert!(matches!(bad, Err(RsmcError::InvalidParameter(_))));
    let cap = Params {
        max_area: Some(5),
        ..Params::default()
    };
    assert!(Chain::new(DenseLattice::new(), cap, 1, &[[0, 0, 0]]).is_err());
}

#[test]
fn checkpoint_resume_is_bit_exact() {
    let p = Params {
        beta: -0.1,
        mu: 0.05,
        ..Params::default()
    };
    let seed = 77;
    // Uninterrupted: 20k steps, checkpoint (which canonicalizes), 20k more.
    let mut a = Chain::new(DenseLattice::new(), p, seed, &[[0, 0, 0]]).unwrap();
    a.run(20_000);
    let cp = a.checkpoint();
    a.run(20_000);
    // Interrupted: serialize, read back, continue on a fresh lattice.
    let json = serde_json::to_string(&cp).unwrap();
    let back: Checkpoint = serde_json::from_str(&json).unwrap();
    assert_eq!(back, cp);
    let mut b = Chain::from_checkpoint(DenseLattice::new(), back).unwrap();
    b.run(20_000);
    assert_eq!(a.counters(), b.counters());
    assert_eq!(a.faces(), b.faces());
    assert_eq!(a.voxels(), b.voxels());
    assert_eq!(
        a.radius_of_gyration().to_bits(),
        b.radius_of_gyration().to_bits()
    );
    // A damaged checkpoint is an error, not a panic.
    let mut broken = cp.clone();
    broken.voxels.push([100, 100, 100]);
    assert!(Chain::from_checkpoint(DenseLattice::new(), broken).is_err());
    let mut broken = cp;
    broken.format = 99;
    assert!(Chain::from_checkpoint(DenseLattice::new(), broken).is_err());
}

#[test]
fn radius_of_gyration_of_a_domino() {
    let chain = Chain::new(DenseLattice::new(), params(0.0), 1, &[[0, 0, 0], [1, 0, 0]]).unwrap();
    assert!((chain.radius_of_gyration() - 0.5).abs() < 1e-12);
    assert_eq!((chain.area(), chain.volume()), (10, 2));
}

/// Detailed balance with a volume weight: the joint (area, volume) histogram against
/// The dynamic octree and the dense baseline give the same trajectory, step for
/// step, for the same seed: same accept/reject decisions, same face lists.
#[test]
fn octree_and_dense_give_identical_trajectories() {
    use crate::dynamic::DynamicOctree;
    for (seed, p) in [
        (
            1u64,
            Params {
                hastings: false,
                ..Params::default()
            },
        ),
        (2, params(-0.2)),
        (
            3,
            Params {
                beta: 0.3,
                mu: -0.2,
                ..Params::default()
            },
        ),
    ] {
        let mut a = Chain::new(DenseLattice::new(), p, seed, &[[0, 0, 0]]).unwrap();
        let mut b = Chain::new(DynamicOctree::with_faces(), p, seed, &[[0, 0, 0]]).unwrap();
        for step in 0..60_000u32 {
            assert_eq!(a.step(), b.step(), "seed {seed} step {step}");
            if step % 5000 == 0 {
                assert_eq!(a.faces(), b.faces(), "seed {seed} step {step}");
                b.lattice().assert_valid();
            }
        }
        assert_eq!(a.counters(), b.counters(), "seed {seed}");
        assert_eq!(a.faces(), b.faces(), "seed {seed}");
        assert_eq!(a.voxels(), b.voxels(), "seed {seed}");
        assert_eq!(
            a.radius_of_gyration().to_bits(),
            b.radius_of_gyration().to_bits()
        );
        b.lattice().assert_valid();
        b.assert_valid();
        // And after a checkpoint round trip on the other backend.
        let cp = a.checkpoint();
        let mut c = Chain::from_checkpoint(DynamicOctree::with_faces(), cp).unwrap();
        let _ = b.checkpoint();
        for step in 0..20_000u32 {
            assert_eq!(b.step(), c.step(), "seed {seed} resumed step {step}");
        }
        assert_eq!(b.faces(), c.faces());
        println!("seed {seed}: area {} volume {}", b.area(), b.volume());
    }
}

/// Libes §6, rule (i) as worded in the paper: "if the east and south neighbors do
/// not exist, the east-south neighbor is retrieved from the octree. If it exists, the
/// operation is rejected". Rule (ii), Fig. 4: creating a voxel whose only neighbours
/// are its top and bottom ones would make a hole.
#[test]
fn libes_worked_examples_on_the_octree() {
    use crate::dynamic::DynamicOctree;
    use legality::{legal_grow, legal_shrink};
    let p = [0, 0, 0];
    // East = +x, south = −y, up = +z (docs/conventions.md axes).
    let mut t = DynamicOctree::with_faces();
    t.insert([0, 0, -1]); // below p: p is proposed from this voxel's top face
    t.insert([0, -1, -1]);
    t.insert([1, -1, -1]);
    t.insert([1, -1, 0]); // east-south of p, joined to the rest below
    assert!(topology::check_sphere(&t.voxels()).is_ok());
    assert!(!t.contains([1, 0, 0]) && !t.contains([0, -1, 0]));
    assert!(
        !legal_grow(t.neighbourhood(p)),
        "rule (i): east and south empty, east-south black"
    );
    // Fill the east neighbour: now p and the east-south voxel share a face neighbour.
    t.insert([1, 0, -1]);
    t.insert([1, 0, 0]);
    assert!(topology::check_sphere(&t.voxels()).is_ok());
    assert!(legal_grow(t.neighbourhood(p)));
    // Fig. 4: a column with a gap of one; only the top and bottom neighbours exist.
    let mut c = DynamicOctree::with_faces();
    for v in [
        [0, 0, -1],
        [0, 1, -1],
        [0, 2, -1],
        [0, 2, 0],
        [0, 2, 1],
        [0, 1, 1],
        [0, 0, 1],
    ] {
        c.insert(v);
    }
    assert!(topology::check_sphere(&c.voxels()).is_ok());
    assert!(
        !legal_grow(c.neighbourhood(p)),
        "rule (ii): would close a ring"
    );
    // Fig. 3 (deletion, rule (i)): deleting a voxel that would leave two voxels
    // sharing only an edge.
    let mut s = DynamicOctree::with_faces();
    for v in [
        [1, 0, 0],
        [0, 0, 0],
        [0, 1, 0],
        [-1, 1, 0],
        [1, 1, -1],
        [1, 1, 0],
    ] {
        s.insert(v);
    }
    // (0,0,0) joins (1,0,0) and (0,1,0); with (1,1,0) black too, removing (0,0,0)
    // leaves the square's other three: legal.
    assert!(topology::check_sphere(&s.voxels()).is_ok());
    assert!(legal_shrink(s.neighbourhood([0, 0, 0])));
    // Removing (1,1,0) instead leaves (1,0,0) and (0,1,0) joined through (0,0,0):
    // still legal; but without (0,0,0), removing (1,1,0) would leave (1,0,0) and
    // (0,1,0) sharing only an edge.
    s.remove([0, 0, 0]);
    assert!(topology::check_sphere(&s.voxels()).is_ok());
    assert!(
        !legal_shrink(s.neighbourhood([1, 1, 0])),
        "rule (i) on deletion"
    );
}

#[test]
fn samples_report_the_acceptance_since_the_previous_one() {
    let mut c = Chain::new(DenseLattice::new(), params(0.2), 11, &[[0, 0, 0]]).unwrap();
    let start = c.sample(Counters::default());
    assert_eq!((start.step, start.area, start.volume), (0, 6, 1));
    assert_eq!((start.radius_of_gyration, start.acceptance), (0.0, 0.0));
    c.run(500);
    let first = c.counters();
    c.run(700);
    let s = c.sample(first);
    let k = c.counters();
    assert_eq!(s.step, 1200);
    assert_eq!((s.area, s.volume), (c.area(), c.volume()));
    assert_eq!(s.radius_of_gyration, c.radius_of_gyration());
    let expected = (k.accepted - first.accepted) as f64 / 700.0;
    assert!(expected > 0.0 && (s.acceptance - expected).abs() < 1e-15);
    // A sample taken where the previous one was has no steps to rate.
    assert_eq!(c.sample(k).acceptance, 0.0);
    c.assert_valid();
}
