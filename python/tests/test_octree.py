"""Every Octree operation against a numpy / Python set model, with frames and colours."""

import numpy as np
import pytest

import tesseral as t

RNG = np.random.default_rng(14)


def random_voxels(n=200, lo=-20, hi=20):
    return RNG.integers(lo, hi, size=(n, 3), dtype=np.int64)


def as_set(arr):
    return {tuple(int(c) for c in row) for row in arr}


def test_from_voxels_and_back():
    for _ in range(20):
        v = random_voxels()
        o = t.Octree.from_voxels(v)
        assert as_set(o.voxels()) == as_set(v)
        assert len(o) == o.voxel_count == len(as_set(v))
        lo, hi = o.bbox
        assert lo == tuple(int(c) for c in v.min(axis=0))
        assert hi == tuple(int(c) for c in v.max(axis=0))
        codes, sizes = o.leaves()
        assert codes.dtype == np.uint64 and sizes.dtype == np.uint8
        assert int((8 ** sizes.astype(np.int64)).sum()) == o.voxel_count


def test_voxels_copy_is_contiguous_int64():
    o = t.Octree.from_voxels(random_voxels())
    v = o.voxels()
    assert v.dtype == np.int64 and v.shape[1] == 3 and v.flags["C_CONTIGUOUS"]
    # Non-contiguous input works too.
    w = np.asfortranarray(random_voxels())
    assert as_set(t.Octree.from_voxels(w).voxels()) == as_set(w)


def test_from_points_and_points():
    p = RNG.uniform(-3.0, 3.0, size=(300, 3))
    o = t.Octree.from_points(p, 0.25)
    assert o.frame["voxel_size"] == 0.25
    want = {tuple(int(c) for c in np.floor(q / 0.25)) for q in p}
    assert as_set(o.voxels()) == want
    centres = o.points()
    assert as_set(np.floor(centres / 0.25).astype(np.int64)) == want


def test_from_dense():
    mask = RNG.random((7, 5, 6)) < 0.3
    o = t.Octree.from_dense(mask, origin=(10, -2, 3))
    want = {(x + 10, y - 2, z + 3) for x, y, z in zip(*np.nonzero(mask))}
    assert as_set(o.voxels()) == want


def test_set_operations_match_python_sets():
    for _ in range(20):
        a, b = random_voxels(), random_voxels()
        oa, ob = t.Octree.from_voxels(a), t.Octree.from_voxels(b)
        sa, sb = as_set(a), as_set(b)
        assert as_set((oa | ob).voxels()) == sa | sb
        assert as_set((oa & ob).voxels()) == sa & sb
        assert as_set((oa - ob).voxels()) == sa - sb
        assert as_set((oa ^ ob).voxels()) == sa ^ sb
        assert oa.union(ob) == oa | ob
        assert oa.intersection(ob) == oa & ob
        assert oa.difference(ob) == oa - ob
        assert oa.symmetric_difference(ob) == oa ^ ob


def test_complement_fills_the_space():
    o = t.Octree.from_voxels(random_voxels(50, 0, 8))
    c = o.complement()
    assert o.voxel_count + c.voxel_count == 8 ** o.depth
    assert not (as_set(o.voxels()) & as_set(c.voxels()))


def test_transforms_match_the_model():
    v = random_voxels(100, 0, 16)
    o = t.Octree.from_voxels(v)
    s = as_set(v)
    assert as_set(o.translate((3, -2, 5)).voxels()) == {(x + 3, y - 2, z + 5) for x, y, z in s}
    # Mirror and rotate act within the space [origin, origin + 2**depth).
    ox, oy, oz = o.origin
    n = 2 ** o.depth
    assert as_set(o.mirror("x").voxels()) == {(2 * ox + n - 1 - x, y, z) for x, y, z in s}
    r = o.rotate("z", 1)
    assert as_set(r.voxels()) == {(ox + oy + n - 1 - y, x - ox + oy, z) for x, y, z in s}
    k = o.scale((2, 1, -1))
    want = {(2 * x + i, y, -z - 1) for x, y, z in s for i in range(2)}
    assert as_set(k.voxels()) == want
    assert o.scale(3).voxel_count == 27 * o.voxel_count


def test_contains_and_equality():
    v = random_voxels()
    o = t.Octree.from_voxels(v)
    probe = random_voxels(500)
    got = o.contains(probe)
    assert got.dtype == np.bool_
    s = as_set(v)
    assert list(got) == [tuple(int(c) for c in p) in s for p in probe]
    assert o == t.Octree.from_voxels(v[::-1])
    assert o != o.translate((1, 0, 0))


def test_mesh_is_closed():
    o = t.Octree.from_voxels(random_voxels(60, 0, 6))
    verts, faces = o.mesh()
    assert verts.shape[1] == 3 and faces.shape[1] == 3
    edges = {}
    for f in faces:
        for i in range(3):
            e = tuple(sorted((int(f[i]), int(f[(i + 1) % 3]))))
            edges[e] = edges.get(e, 0) + 1
    assert all(c == 2 for c in edges.values())


@pytest.mark.parametrize("ext", ["tess", "xyz", "bt", "ot", "binvox", "vox"])
def test_round_trips_through_every_format(tmp_path, ext):
    o = t.Octree.from_voxels(random_voxels(80, 0, 30))
    path = tmp_path / f"a.{ext}"
    o.write(path)
    assert t.Octree.read(path) == o


def test_frames_and_colours_survive(tmp_path):
    s = t.Scene.parse(
        'depth 5\nbounds [1, 2, 3] [9, 10, 11]\n'
        'box(size = 4) at [5, 6, 7] colour "red"\nsphere(r = 2) at [3, 4, 5] colour "blue"\n'
    )
    o = s.build()
    assert o.frame["voxel_size"] == 0.25 and o.frame["translate"] == (1.0, 2.0, 3.0)
    assert o.info()["colors"] == 2
    o.write(tmp_path / "c.tess")
    back = t.Octree.read(tmp_path / "c.tess")
    assert back.frame == o.frame and back.info()["colors"] == 2
    moved = back.translate((4, 0, 0))
    assert moved.frame == o.frame and moved.info()["colored_voxels"] == o.info()["colored_voxels"]
    # Points are in world units: voxel centres inside the bounds.
    p = o.points()
    assert p.min() >= 1.0 and p.max() <= 11.0


def test_mismatched_frames_raise():
    a = t.Octree.from_points(np.array([[0.0, 0.0, 0.0]]), 0.5)
    b = t.Octree.from_points(np.array([[0.0, 0.0, 0.0]]), 0.25)
    with pytest.raises(t.OctreeError, match="voxel sizes differ"):
        a | b


def test_errors(tmp_path):
    with pytest.raises(OSError):
        t.Octree.read(tmp_path / "missing.tess")
    bad = tmp_path / "bad.xyz"
    bad.write_text("0 0 0\n1 x 0\n")
    with pytest.raises(t.FormatError, match="bad.xyz"):
        t.Octree.read(bad)
    with pytest.raises(ValueError):
        t.Octree.from_voxels(np.zeros((3, 2), dtype=np.int64))
    with pytest.raises(ValueError):
        t.Octree.from_voxels(np.zeros((1, 3), dtype=np.int64)).rotate("w", 1)


def test_long_calls_release_the_gil(ticks_during):
    s = t.Scene.parse("depth 9\nbounds [0, 0, 0] [512, 512, 512]\nsphere(r = 250) at [256, 256, 256]\n")
    o, during = ticks_during(s.build)
    assert o.voxel_count > 0
    # The other thread kept running while the build held no GIL.
    assert during >= 3, during
