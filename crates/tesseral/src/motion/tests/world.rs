//! Worlds in motion, step by step, against brute force.

use super::*;

fn cube(side: i64) -> LinearOctree {
    LinearOctree::from_voxels_fitted(
        &(0..side * side * side)
            .map(|i| [i % side, i / side % side, i / side / side])
            .collect::<Vec<_>>(),
    )
    .unwrap()
}

/// Two runs agree on every contact and overlap; block decompositions may differ
/// (a translated tree has other blocks, Ahuja & Nash §1), so contact boxes are
/// compared as voxel sets.
fn assert_same_run(x: &Simulation, y: &Simulation, seed: u64) {
    let key = |s: &Simulation| -> Vec<_> {
        s.contacts
            .iter()
            .map(|c| {
                (
                    c.step,
                    c.fraction,
                    c.a.clone(),
                    c.b.clone(),
                    c.between_steps,
                    c.time.to_bits(),
                )
            })
            .collect()
    };
    assert_eq!(key(x), key(y), "seed {seed}");
    assert_eq!(x.frames.len(), y.frames.len());
    let voxels = |boxes: &[Aabb]| -> HashSet<Voxel> {
        let mut out = HashSet::new();
        for b in boxes {
            for i in b.min[0]..=b.max[0] {
                for j in b.min[1]..=b.max[1] {
                    for k in b.min[2]..=b.max[2] {
                        out.insert([i, j, k]);
                    }
                }
            }
        }
        out
    };
    for (f, g) in x.frames.iter().zip(&y.frames) {
        assert_eq!(
            (f.step, &f.offsets, &f.overlaps),
            (g.step, &g.offsets, &g.overlaps),
            "seed {seed}"
        );
        assert_eq!(
            voxels(&f.contact_boxes),
            voxels(&g.contact_boxes),
            "seed {seed}"
        );
    }
}

#[test]
fn world_catches_a_fast_object_tunnelling_through_a_thin_wall() {
    let wall = thin_wall(30);
    let mut world = World::new(wall);
    world.objects.push(MovingObject {
        name: "bullet".into(),
        tree: cube(2),
        rotation: Rotation::IDENTITY,
        trajectory: Trajectory::Constant {
            start: [0.0, 4.0, 4.0],
            velocity: [25.0, 0.0, 0.0],
        },
    });
    let sim = world.simulate(1.0, 3).unwrap();
    for method in [TranslationMethod::Linear, TranslationMethod::Labels] {
        world.method = method;
        assert_same_run(&world.simulate(1.0, 3).unwrap(), &sim, 0);
    }
    // No step samples the bullet inside the wall (x = 0, 25, 50, 75).
    assert!(sim.frames.iter().all(|f| f.overlaps.is_empty()));
    assert_eq!(sim.contacts.len(), 1);
    let c = &sim.contacts[0];
    assert!(c.between_steps);
    assert_eq!((c.step, c.fraction), (1, Fraction::new(3, 25)));
    assert_eq!(c.time, 1.12); // x = 25 + 3 puts the front face x = 30 on the wall
    assert_eq!(c.a, Body::Environment);
}

#[test]
fn world_matches_brute_force_step_by_step() {
    let (mut swept, mut at_start) = (0, 0);
    for seed in 0..150u64 {
        let mut rng = seeded("world_matches_brute_force_step_by_step", seed);
        let (env, venv) = random_solid(&mut rng, 4, [0, 0, 0]);
        let mut world = World::new(env);
        let mut voxels = Vec::new();
        for k in 0..3 {
            let d = rng.random_range(0..=2);
            let (tree, vs) = random_solid(&mut rng, d, [0, 0, 0]);
            let rotation = Rotation::all()[rng.random_range(0..24)];
            let start = [0, 1, 2].map(|_| f64::from(rng.random_range(-4..16)));
            let velocity = [0, 1, 2].map(|_| f64::from(rng.random_range(-30..30)) / 4.0);
            world.objects.push(MovingObject {
                name: format!("o{k}"),
                tree,
                rotation,
                trajectory: Trajectory::Constant { start, velocity },
            });
            voxels.push(vs);
        }
        let steps = 8;
        let sim = world.simulate(0.5, steps).unwrap();
        // Keeping each object's tree current by linear translation gives the same run.
        for method in [TranslationMethod::Linear, TranslationMethod::Labels] {
            world.method = method;
            assert_same_run(&world.simulate(0.5, steps).unwrap(), &sim, seed);
        }
        assert_eq!(sim.frames.len(), steps as usize + 1);
        let placed = |k: usize, off: Voxel| -> Vec<Voxel> {
            let place = Placement {
                rotation: world.objects[k].rotation,
                offset: off,
            };
            voxels[k].iter().map(|&v| place.apply_voxel(v)).collect()
        };
        let shared = |a: &[Voxel], b: &[Voxel]| {
            let s: HashSet<Voxel> = a.iter().copied().collect();
            b.iter().filter(|v| s.contains(*v)).count() as u64
        };
        let mut expected_contacts = Vec::new();
        for f in &sim.frames {
            let n = f.step;
            let off: Vec<Voxel> = (0..3)
                .map(|k| world.objects[k].trajectory.offset_at(n as f64 * 0.5))
                .collect();
            assert_eq!(f.offsets, off, "seed {seed}");
            let mut overlaps = Vec::new();
            let bodies: Vec<(Option<usize>, usize)> = vec![
                (None, 0),
                (None, 1),
                (None, 2),
                (Some(0), 1),
                (Some(0), 2),
                (Some(1), 2),
            ];
            for &(i, j) in &bodies {
                let va = i.map_or(venv.clone(), |i| placed(i, off[i]));
                let vb = placed(j, off[j]);
                let s = shared(&va, &vb);
                if s > 0 {
                    overlaps.push((i, j, s));
                    if n == 0 {
                        expected_contacts.push((0, Fraction::ZERO, i, j));
                    }
                } else if n < steps {
                    let next: Vec<Voxel> = (0..3)
                        .map(|k| world.objects[k].trajectory.offset_at((n + 1) as f64 * 0.5))
                        .collect();
                    let mv = |k: usize| [0, 1, 2].map(|a| next[k][a] - off[k][a]);
                    let rel = {
                        let (mb, ma) = (mv(j), i.map_or([0; 3], mv));
                        [0, 1, 2].map(|a| mb[a] - ma[a])
                    };
                    if let Some(t) = first_contact_brute(&va, &vb, rel) {
                        expected_contacts.push((n, t, i, j));
                    }
                }
            }
            assert_eq!(f.overlaps, overlaps, "seed {seed} step {n}");
        }
        let got: Vec<_> = sim
            .contacts
            .iter()
            .map(|c| {
                let idx = |b: &Body| match b {
                    Body::Environment => None,
                    Body::Object { index, .. } => Some(*index),
                };
                (c.step, c.fraction, idx(&c.a), idx(&c.b).unwrap())
            })
            .collect();
        let mut want = expected_contacts.clone();
        let mut got_sorted = got.clone();
        want.sort();
        got_sorted.sort();
        assert_eq!(got_sorted, want, "seed {seed}");
        swept += want.iter().filter(|c| c.1 > Fraction::ZERO).count();
        at_start += want.iter().filter(|c| c.1 == Fraction::ZERO).count();
    }
    assert!(swept > 10 && at_start > 10, "{swept} {at_start}");
}
