"""Scenes, rendering, the dynamic octree, collisions, planning and codes."""

import numpy as np
import pytest

import tesseral as t

RNG = np.random.default_rng(15)


def test_scene_errors_carry_the_line_and_column():
    with pytest.raises(t.SceneError) as e:
        t.Scene.parse("depth 5\nbounds [0, 0, 0] [8, 8, 8]\nsphere(r = ) at [1, 2, 3]\n")
    assert e.value.line == 3 and e.value.column == 12
    assert "expected a value" in str(e.value)


def test_scene_build_at_another_depth():
    s = t.Scene.parse("depth 6\nbounds [0, 0, 0] [64, 64, 64]\nbox(size = 32) at [32, 32, 32]\n")
    assert s.build().voxel_count == 32 ** 3
    coarse = s.build(depth=4)
    assert coarse.depth == 4 and coarse.voxel_count == 8 ** 3
    assert coarse.frame["voxel_size"] == 4.0


def test_render_gives_pixels_and_png():
    s = t.Scene.parse('depth 5\nbounds [0, 0, 0] [32, 32, 32]\nsphere(r = 10) at [16, 16, 16] colour "red"\n')
    img = t.render(s, size=(64, 48), view="front")
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    centre = img[24, 32].astype(int)
    assert centre[0] > centre[1] + 40, centre  # red
    assert (img[0, 0] == 255).all()  # white background
    o = s.build()
    assert np.array_equal(t.render(o, size=(64, 48), view="front")[24, 32] > 0, [True] * 3)
    assert o._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"
    assert s._repr_png_()[:4] == b"\x89PNG"
    with pytest.raises(ValueError, match="view"):
        t.render(o, view="diagonal")


def test_dynamic_octree_matches_a_set():
    d = t.DynamicOctree()
    model = set()
    for _ in range(20):
        add = RNG.integers(-50, 50, size=(300, 3))
        rem = RNG.integers(-50, 50, size=(300, 3))
        new = len({tuple(r) for r in add.tolist()} - model)
        assert d.insert(add) == new
        model |= {tuple(r) for r in add.tolist()}
        gone = len({tuple(r) for r in rem.tolist()} & model)
        assert d.remove(rem) == gone
        model -= {tuple(r) for r in rem.tolist()}
        assert len(d) == len(model)
        probe = RNG.integers(-50, 50, size=(200, 3))
        assert list(d.contains(probe)) == [tuple(p) in model for p in probe.tolist()]
    assert {tuple(v) for v in d.voxels().tolist()} == model
    # Faces: each voxel's faces not shared with a neighbour.
    faces = sum(
        (tuple(np.add(v, s)) not in model)
        for v in model
        for s in [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    )
    assert d.face_count == faces
    assert d.stats()["voxels"] == len(model)


def test_collide_follows_brute_force():
    a = t.Octree.from_voxels(np.array([[x, 0, 0] for x in range(4)]))
    b = t.Octree.from_voxels(np.array([[0, 0, 0], [0, 1, 0]]))
    r = t.collide(a, b, offset=(3, 0, 0))
    assert r["intersects"] and r["overlap_voxels"] == 1
    r = t.collide(a, b, offset=(6, 0, 0))
    assert not r["intersects"] and r["clearance"] == 2.0
    r = t.collide(a, b, offset=(2, 0, 0), turns="z90")
    assert r["overlap_voxels"] == 2


def test_plan_finds_a_path_or_says_why():
    wall = np.array([[4, y, z] for y in range(8) for z in range(8) if (y, z) != (5, 5)])
    env = t.Octree.from_voxels(wall)
    dot = t.Octree.from_voxels(np.array([[0, 0, 0]]))
    p = t.plan(env, dot, (0, 0, 0), (7, 0, 0))
    assert p["found"] and p["steps"] == 7 + 2 * 5 + 2 * 5
    assert t.plan(env, dot, (0, 0, 0), (4, 0, 0))["reason"].startswith("no path")


def test_plan_with_turns():
    import pathlib

    scenes = pathlib.Path(__file__).resolve().parents[2] / "scenes"
    env = t.Octree.read(scenes / "l-corridor.xyz")
    bar = t.Octree.read(scenes / "bar.xyz")
    assert not t.plan(env, bar, (-12, 0, 0), (6, 20, 0))["found"]
    p = t.plan(env, bar, (-12, 0, 0), (6, 20, 0), rotations=True)
    assert p["found"] and p["turns"] >= 1


def test_simulate_a_world_file(tmp_path):
    (tmp_path / "wall.xyz").write_text("".join(f"6 {y} 0\n" for y in range(4)))
    (tmp_path / "dot.xyz").write_text("0 0 0\n")
    (tmp_path / "w.json").write_text(
        '{"environment": "wall.xyz", "steps": 8, "objects": '
        '[{"name": "dot", "octree": "dot.xyz", "start": [0, 0, 0], "velocity": [1, 0, 0]}]}'
    )
    r = t.simulate(tmp_path / "w.json")
    assert r["objects"] == ["dot"] and r["contacts"][0]["time"] == 5.0


def test_codes_match_bit_interleaving():
    c = RNG.integers(0, 2 ** 21, size=(1000, 3))
    codes = t.calc.encode(c)
    want = []
    for x, y, z in c.tolist():
        k = 0
        for i in range(21):
            k |= ((x >> i) & 1) << (3 * i) | ((y >> i) & 1) << (3 * i + 1) | ((z >> i) & 1) << (3 * i + 2)
        want.append(k)
    assert codes.tolist() == want
    assert np.array_equal(t.calc.decode(codes), c)
    # Addition is translation, per axis modulo 2**21.
    d = RNG.integers(0, 2 ** 21, size=(1000, 3))
    s = t.calc.add(codes, t.calc.encode(d))
    assert np.array_equal(t.calc.decode(s), (c + d) % 2 ** 21)
    assert np.array_equal(t.calc.decode(t.calc.sub(s, t.calc.encode(d))), c)
    with pytest.raises(ValueError):
        t.calc.encode(np.array([[-1, 0, 0]]))


def test_reprs_count_with_the_right_nouns():
    one = t.Octree.from_voxels(np.array([[0, 0, 0]]))
    assert repr(one).startswith("Octree(1 voxel, 1 leaf, depth ")
    two = t.Octree.from_voxels(np.array([[0, 0, 0], [5, 5, 5]]))
    assert repr(two).startswith("Octree(2 voxels, 2 leaves, depth ")
    d = t.DynamicOctree()
    assert repr(d) == "DynamicOctree(0 voxels, 0 faces)"
    d.insert(np.array([[0, 0, 0]]))
    assert repr(d) == "DynamicOctree(1 voxel, 6 faces)"
    s = t.Scene.parse("depth 5\nbounds [0, 0, 0] [32, 32, 32]\nsphere(r = 10) at [16, 16, 16]\n")
    assert repr(s).startswith("Scene(1 object, depth 5, ")
