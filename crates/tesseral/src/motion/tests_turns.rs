//! Planning with quarter turns: paths are free at every sampled step of every move
//! and turn, and a bar passes an L-shaped corridor only by turning.

use std::path::Path;

use super::*;
use crate::linear::LinearOctree;
use crate::Voxel;

fn scene(name: &str) -> LinearOctree {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    crate::io::read_octree(&path).unwrap()
}

/// Checks a path step by step: each state free, each move a unit step, and each
/// turn free at 64 sampled angles (every object voxel's centre and corners turned
/// about the pivot, looked up in the environment).
fn assert_free_everywhere(env: &LinearOctree, obj: &LinearOctree, plan: &TurnPlan) {
    let s = &plan.states;
    for (p, r) in s {
        assert!(
            !interference(
                env,
                obj,
                Placement {
                    rotation: *r,
                    offset: *p
                },
                false
            )
            .intersects,
            "state {p:?} {r}"
        );
    }
    for w in s.windows(2) {
        let ((p, r), (q, r2)) = (w[0], w[1]);
        if r == r2 {
            let d: u64 = (0..3).map(|a| p[a].abs_diff(q[a])).sum();
            assert_eq!(d, 1, "a move is one unit step: {p:?} -> {q:?}");
            continue;
        }
        assert_eq!(p, q, "a turn stays in place");
        // Which quarter turn: the one taking r to r2.
        let (axis, dir) = (0..3)
            .flat_map(|a| [(a, -1), (a, 1)])
            .find(|&(a, d)| Rotation::about_axis(a, d).compose(r) == r2)
            .expect("neighbouring orientations");
        let turned = rotated(obj, r);
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for i in 0..=64 {
            let theta = f64::from(dir) * std::f64::consts::FRAC_PI_2 * f64::from(i) / 64.0;
            let (sn, cs) = theta.sin_cos();
            for vox in turned.voxels() {
                for c in 0..9 {
                    let pt: [f64; 3] = std::array::from_fn(|a| {
                        vox[a] as f64
                            + if c == 8 {
                                0.5
                            } else {
                                ((c >> a) & 1) as f64 * 0.999 + 0.0005
                            }
                    });
                    let mut t = pt;
                    t[u] = cs * pt[u] - sn * pt[v];
                    t[v] = sn * pt[u] + cs * pt[v];
                    let hit: Voxel = std::array::from_fn(|a| p[a] + t[a].floor() as i64);
                    assert!(
                        !env.contains(hit),
                        "turn at {p:?} {r} -> {r2}: {hit:?} at {theta}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_bar_passes_an_l_shaped_corridor_only_by_turning() {
    let env = scene("l-corridor.xyz");
    let bar = scene("bar.xyz");
    let opts = PlanOptions::default();
    let fixed = plan(&env, &bar, [-12, 0, 0], [6, 20, 0], &opts);
    assert!(
        matches!(fixed, Err(NoPath::GoalBlocked { .. })),
        "{fixed:?}"
    );
    let p = plan_with_turns(
        &env,
        &bar,
        [-12, 0, 0],
        [6, 20, 0],
        Rotation::IDENTITY,
        &opts,
    )
    .unwrap();
    assert!(p.turns >= 1, "{p:?}");
    assert_eq!(p.states.first().unwrap().0, [-12, 0, 0]);
    assert_eq!(p.states.last().unwrap().0, [6, 20, 0]);
    assert_free_everywhere(&env, &bar, &p);
    // In place and already there: no motion.
    let still = plan_with_turns(
        &env,
        &bar,
        [-12, 0, 0],
        [-12, 0, 0],
        Rotation::IDENTITY,
        &opts,
    )
    .unwrap();
    assert_eq!((still.moves, still.turns), (0, 0));
}

#[test]
fn a_room_too_small_to_turn_in_gives_the_reason() {
    // The same corridors with a room only 5 across: the bar can reach the corner but
    // cannot turn there.
    let mut voxels = Vec::new();
    for x in -21..8 {
        for y in -7..28 {
            for z in -1..=1 {
                let open = z == 0
                    && ((-20..0).contains(&x) && (-1..2).contains(&y)
                        || (0..5).contains(&x) && (-2..3).contains(&y)
                        || (1..4).contains(&x) && (3..27).contains(&y));
                if !open {
                    voxels.push([x, y, z]);
                }
            }
        }
    }
    let env = LinearOctree::from_voxels_fitted(&voxels).unwrap();
    let bar = scene("bar.xyz");
    let r = plan_with_turns(
        &env,
        &bar,
        [-12, 0, 0],
        [2, 20, 0],
        Rotation::IDENTITY,
        &PlanOptions::default(),
    );
    match r {
        Err(NoPath::Unreachable { cells, .. }) => assert!(cells > 0),
        other => panic!("expected an enclosed start, got {other:?}"),
    }
}

#[test]
fn sweeps_cover_the_turning_object() {
    let bar = scene("bar.xyz");
    for axis in 0..3 {
        for dir in [-1, 1] {
            let s = quarter_turn_sweep(&bar, axis, dir);
            // Both end orientations lie within the sweep.
            for v in bar.voxels() {
                assert!(s.contains(&v));
                let end = Rotation::about_axis(axis, dir).apply_voxel(v);
                assert!(s.contains(&end), "axis {axis} dir {dir}: {end:?}");
            }
        }
    }
}

#[test]
fn random_rooms_give_paths_free_everywhere_or_a_reason() {
    use rand::{Rng, SeedableRng};
    // Walled rooms 10 × 10 × 4 with random pillars, a small random object (a bar of
    // three or an L), random start and goal: every path found is checked at every
    // sampled step of every move and turn; every failure names its reason.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(160);
    let (mut found, mut failed) = (0, 0);
    for case in 0..24 {
        let mut voxels = Vec::new();
        for x in -1..=10 {
            for y in -1..=10 {
                for z in -1..=4 {
                    let wall =
                        !(0..=9).contains(&x) || !(0..=9).contains(&y) || !(0..=3).contains(&z);
                    if wall || rng.random_bool(0.06) {
                        voxels.push([x, y, z]);
                    }
                }
            }
        }
        let env = LinearOctree::from_voxels_fitted(&voxels).unwrap();
        let shape: Vec<Voxel> = if rng.random_bool(0.5) {
            vec![[-1, 0, 0], [0, 0, 0], [1, 0, 0]]
        } else {
            vec![[0, 0, 0], [1, 0, 0], [0, 1, 0]]
        };
        let obj = LinearOctree::from_voxels_fitted(&shape).unwrap();
        let mut pick = || -> Voxel {
            [
                rng.random_range(1..9),
                rng.random_range(1..9),
                rng.random_range(1..3),
            ]
        };
        let (from, to) = (pick(), pick());
        match plan_with_turns(
            &env,
            &obj,
            from,
            to,
            Rotation::IDENTITY,
            &PlanOptions::default(),
        ) {
            Ok(p) => {
                found += 1;
                assert_eq!(
                    p.states.first().unwrap(),
                    &(from, Rotation::IDENTITY),
                    "case {case}"
                );
                assert_eq!(p.states.last().unwrap().0, to, "case {case}");
                assert_free_everywhere(&env, &obj, &p);
            }
            Err(e) => {
                failed += 1;
                let reason = e.to_string();
                assert!(
                    reason.starts_with("no path: ") && reason.len() > 20,
                    "case {case}: {reason}"
                );
            }
        }
    }
    // Both outcomes occur, so both halves of the test ran.
    assert!(found > 0 && failed > 0, "{found} found, {failed} failed");
}
