//! Minkowski sums, configuration obstacles and plans against brute force.

use super::*;

#[test]
fn minkowski_sum_matches_brute_force() {
    for seed in 0..150u64 {
        let mut rng = seeded("minkowski_sum_matches_brute_force", seed);
        let (da, db) = (rng.random_range(0..=3), rng.random_range(0..=2));
        let oa = [rng.random_range(-4..4), 0, rng.random_range(-4..4)];
        let ob = [0, rng.random_range(-4..4), 0];
        let (a, va) = random_solid(&mut rng, da, oa);
        let (b, vb) = random_solid(&mut rng, db, ob);
        let sum = minkowski_sum(&a, &b).unwrap();
        sum.assert_valid();
        let brute: HashSet<Voxel> = va
            .iter()
            .flat_map(|p| {
                vb.iter()
                    .map(move |q| [p[0] + q[0], p[1] + q[1], p[2] + q[2]])
            })
            .collect();
        let got: HashSet<Voxel> = sum.voxels().collect();
        assert_eq!(got, brute, "seed {seed}");
    }
}

#[test]
fn rotated_and_reflected_trees_match_their_voxels() {
    for seed in 0..100u64 {
        let mut rng = seeded("rotated_and_reflected_trees_match_their_voxels", seed);
        let o = [
            rng.random_range(-9..9),
            rng.random_range(-9..9),
            rng.random_range(-9..9),
        ];
        let (t, vs) = random_solid(&mut rng, 3, o);
        let r = Rotation::all()[rng.random_range(0..24)];
        let rt = rotated(&t, r);
        rt.assert_valid();
        let want: HashSet<Voxel> = vs.iter().map(|&v| r.apply_voxel(v)).collect();
        assert_eq!(rt.voxels().collect::<HashSet<_>>(), want, "seed {seed}");
        let ft = reflected(&t);
        ft.assert_valid();
        let want: HashSet<Voxel> = vs.iter().map(|v| v.map(|c| -c)).collect();
        assert_eq!(ft.voxels().collect::<HashSet<_>>(), want, "seed {seed}");
    }
}

#[test]
fn config_obstacles_match_brute_force_interference() {
    for seed in 0..60u64 {
        let mut rng = seeded("config_obstacles_match_brute_force_interference", seed);
        let (env, venv) = random_solid(&mut rng, 3, [0, 0, 0]);
        let d = rng.random_range(0..=2);
        let (obj, vobj) = random_solid(&mut rng, d, [0, 0, 0]);
        let r = Rotation::all()[rng.random_range(0..24)];
        let cobs = config_obstacles(&env, &obj, r).unwrap();
        cobs.assert_valid();
        let senv: HashSet<Voxel> = venv.iter().copied().collect();
        for x in -12..12 {
            for y in -12..12 {
                for z in -12..12 {
                    let place = Placement {
                        rotation: r,
                        offset: [x, y, z],
                    };
                    let brute = vobj.iter().any(|&v| senv.contains(&place.apply_voxel(v)));
                    assert_eq!(
                        cobs.contains([x, y, z]),
                        brute,
                        "seed {seed} at {x},{y},{z}"
                    );
                }
            }
        }
    }
}

/// Every lattice position of the raw path, step by step, is free and in bounds; every
/// smoothed segment is free by the brute-force swept test and by sampling.
fn check_path(
    plan: &Plan,
    venv: &HashSet<Voxel>,
    vobj: &[Voxel],
    r: Rotation,
    bounds: (Voxel, Voxel),
    seed: u64,
) {
    let free = |p: Voxel| {
        let place = Placement {
            rotation: r,
            offset: p,
        };
        (0..3).all(|a| bounds.0[a] <= p[a] && p[a] <= bounds.1[a])
            && vobj.iter().all(|&v| !venv.contains(&place.apply_voxel(v)))
    };
    let mut steps = 0u64;
    for w in plan.raw.windows(2) {
        // Axis by axis, staying in the box spanned by the two points.
        let mut p = w[0];
        assert!(free(p), "seed {seed}: raw point {p:?} blocked");
        for a in 0..3 {
            while p[a] != w[1][a] {
                p[a] += (w[1][a] - p[a]).signum();
                steps += 1;
                assert!(free(p), "seed {seed}: raw path blocked at {p:?}");
            }
        }
    }
    assert_eq!(steps, plan.steps, "seed {seed}: raw length");
    let venv_list: Vec<Voxel> = venv.iter().copied().collect();
    let moved = |p: Voxel| -> Vec<Voxel> {
        let place = Placement {
            rotation: r,
            offset: p,
        };
        vobj.iter().map(|&v| place.apply_voxel(v)).collect()
    };
    for w in plan.waypoints.windows(2) {
        assert!(free(w[0]) && free(w[1]), "seed {seed}");
        let mv = [0, 1, 2].map(|a| w[1][a] - w[0][a]);
        assert_eq!(
            first_contact_brute(&venv_list, &moved(w[0]), mv),
            None,
            "seed {seed}: segment {w:?}"
        );
        let start = moved(w[0]);
        for k in 0..=40 {
            let t = f64::from(k) / 40.0;
            let hit = start.iter().any(|q| {
                venv.iter().any(|e| {
                    (0..3).all(|a| (q[a] as f64 + t * mv[a] as f64 - e[a] as f64).abs() < 1.0)
                })
            });
            assert!(!hit, "seed {seed}: segment {w:?} blocked at t = {t}");
        }
    }
    assert_eq!(plan.waypoints.first(), plan.raw.first());
    assert_eq!(plan.waypoints.last(), plan.raw.last());
    assert!(plan.length <= plan.steps as f64 + 1e-9);
}

/// BFS on the dense grid of positions (unit costs: Dijkstra).
fn dense_shortest(free: &dyn Fn(Voxel) -> bool, from: Voxel, to: Voxel) -> Option<u64> {
    let mut dist = std::collections::HashMap::new();
    let mut queue = std::collections::VecDeque::new();
    dist.insert(from, 0u64);
    queue.push_back(from);
    while let Some(p) = queue.pop_front() {
        let d = dist[&p];
        if p == to {
            return Some(d);
        }
        for a in 0..3 {
            for s in [-1, 1] {
                let mut q = p;
                q[a] += s;
                if !dist.contains_key(&q) && free(q) {
                    dist.insert(q, d + 1);
                    queue.push_back(q);
                }
            }
        }
    }
    None
}

#[test]
fn plans_are_optimal_against_dense_dijkstra_and_collision_free() {
    let mut outcomes = [0; 3];
    for seed in 0..120u64 {
        let mut rng = seeded(
            "plans_are_optimal_against_dense_dijkstra_and_collision_free",
            seed,
        );
        // Walls with holes make mazes; plus random blocks.
        let side = 16i64;
        let mut env_set: HashSet<Voxel> = HashSet::new();
        for _ in 0..rng.random_range(1..=3) {
            let axis = rng.random_range(0..3);
            let at = rng.random_range(2..side - 2);
            let hole = [rng.random_range(0..side - 3), rng.random_range(0..side - 3)];
            let hs = rng.random_range(0..=3);
            for u in 0..side {
                for w in 0..side {
                    if (hole[0]..hole[0] + hs).contains(&u) && (hole[1]..hole[1] + hs).contains(&w)
                    {
                        continue;
                    }
                    let mut v = [0; 3];
                    v[axis] = at;
                    v[(axis + 1) % 3] = u;
                    v[(axis + 2) % 3] = w;
                    env_set.insert(v);
                }
            }
        }
        let (_, extra) = random_solid(&mut rng, 4, [0, 0, 0]);
        env_set.extend(extra.into_iter().take(40));
        let env = LinearOctree::from_voxels(4, [0, 0, 0], env_set.iter().copied()).unwrap();
        let d = rng.random_range(0..=1);
        let (obj, vobj) = random_solid(&mut rng, d, [0, 0, 0]);
        if vobj.is_empty() {
            continue;
        }
        let r = Rotation::all()[rng.random_range(0..24)];
        let obj_box = rotated(&obj, r).bbox().unwrap();
        let bounds = (
            [0, 1, 2].map(|a| -obj_box.0[a]),
            [0, 1, 2].map(|a| side - 1 - obj_box.1[a]),
        );
        let free = |p: Voxel| {
            let place = Placement {
                rotation: r,
                offset: p,
            };
            (0..3).all(|a| bounds.0[a] <= p[a] && p[a] <= bounds.1[a])
                && vobj
                    .iter()
                    .all(|&v| !env_set.contains(&place.apply_voxel(v)))
        };
        let pick = |rng: &mut Pcg64| [0, 1, 2].map(|a| rng.random_range(bounds.0[a]..=bounds.1[a]));
        let (from, to) = (pick(&mut rng), pick(&mut rng));
        let options = PlanOptions {
            rotation: r,
            region: Some(Aabb {
                min: [0; 3],
                max: [side - 1; 3],
            }),
            ..PlanOptions::default()
        };
        let got = plan(&env, &obj, from, to, &options);
        match (free(from), free(to)) {
            (false, _) => {
                assert!(
                    matches!(got, Err(NoPath::StartBlocked { .. })),
                    "seed {seed}: {got:?}"
                );
                continue;
            }
            (true, false) => {
                assert!(
                    matches!(got, Err(NoPath::GoalBlocked { .. })),
                    "seed {seed}: {got:?}"
                );
                continue;
            }
            _ => {}
        }
        match dense_shortest(&free, from, to) {
            Some(cost) => {
                let p = got.unwrap_or_else(|e| panic!("seed {seed}: {e}"));
                assert_eq!(p.steps, cost, "seed {seed}: A* cost against dense Dijkstra");
                check_path(&p, &env_set, &vobj, r, bounds, seed);
                outcomes[0] += 1;
                if p.waypoints.len() < p.raw.len() {
                    outcomes[2] += 1;
                }
            }
            None => {
                assert!(
                    matches!(got, Err(NoPath::Unreachable { .. })),
                    "seed {seed}: {got:?}"
                );
                outcomes[1] += 1;
            }
        }
    }
    // Found paths, enclosed goals and actual smoothing all occur.
    assert!(
        outcomes[0] > 30 && outcomes[1] > 3 && outcomes[2] > 10,
        "{outcomes:?}"
    );
}

#[test]
fn no_path_says_why() {
    let mut walls = Vec::new();
    // A closed 8x8x8 box shell (outside 0..8), an object of one voxel inside.
    for x in 0..8 {
        for y in 0..8 {
            for z in 0..8 {
                if [x, y, z].iter().any(|&c| c == 0 || c == 7) {
                    walls.push([x, y, z]);
                }
            }
        }
    }
    let env = LinearOctree::from_voxels(4, [0, 0, 0], walls).unwrap();
    let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
    let o = PlanOptions {
        region: Some(Aabb {
            min: [0; 3],
            max: [15; 3],
        }),
        ..PlanOptions::default()
    };
    let e = plan(&env, &dot, [3, 3, 3], [12, 12, 12], &o).unwrap_err();
    assert!(
        matches!(
            e,
            NoPath::Unreachable {
                cells: _,
                positions: 216
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("no path"));
    assert!(matches!(
        plan(&env, &dot, [0, 3, 3], [4, 4, 4], &o),
        Err(NoPath::StartBlocked { overlap_voxels: 1 })
    ));
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [7, 4, 4], &o),
        Err(NoPath::GoalBlocked { .. })
    ));
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [16, 4, 4], &o),
        Err(NoPath::GoalOutOfBounds { .. })
    ));
    assert!(matches!(
        plan(&env, &dot, [-1, 3, 3], [4, 4, 4], &o),
        Err(NoPath::StartOutOfBounds { .. })
    ));
    let big = LinearOctree::full(5, [0, 0, 0]).unwrap();
    assert!(matches!(
        plan(&env, &big, [0; 3], [0; 3], &o),
        Err(NoPath::ObjectTooLarge)
    ));
    let empty = LinearOctree::empty(1, [0, 0, 0]).unwrap();
    assert!(matches!(
        plan(&env, &empty, [0; 3], [0; 3], &o),
        Err(NoPath::EmptyObject)
    ));
    // Inside the box a path exists, and start = goal is the empty move.
    // The default region is the bounding box: going around the outside needs a margin.
    let d = PlanOptions::default();
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [9, 3, 3], &d),
        Err(NoPath::Unreachable { .. })
    ));
    let around = PlanOptions {
        margin: 1,
        ..PlanOptions::default()
    };
    assert!(matches!(
        plan(&env, &dot, [3, 3, 3], [9, 3, 3], &around),
        Err(NoPath::Unreachable { .. })
    ));
    assert!(matches!(
        plan(&env, &dot, [-1, 3, 3], [9, 3, 3], &d),
        Err(NoPath::Unreachable { .. })
    ));
    let p = plan(&env, &dot, [-1, 3, 3], [9, 3, 3], &around).unwrap();
    assert_eq!(p.steps, 10 + 2 * 4); // around the side: y from 3 to -1 and back
    assert_eq!(p.clearance, Some(0.0));
    let p = plan(&env, &dot, [1, 1, 1], [6, 6, 6], &o).unwrap();
    assert_eq!(p.steps, 15);
    assert_eq!(p.waypoints, vec![[1, 1, 1], [6, 6, 6]]);
    assert!((p.length - 75f64.sqrt()).abs() < 1e-9);
    assert_eq!(p.clearance, Some(0.0));
    let p = plan(&env, &dot, [2, 2, 2], [2, 2, 2], &o).unwrap();
    assert_eq!((p.steps, p.waypoints.len()), (0, 1));
    assert_eq!(p.clearance, Some(1.0));
}
