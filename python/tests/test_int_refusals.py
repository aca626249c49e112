"""Integer arguments outside their range: a ValueError naming the argument, its
value and the range, however large the value (not pyo3's OverflowError, which names
neither); the private partition steps' depths and frames likewise."""

import numpy as np
import pytest

import tesseral as t
from tesseral import _tesseral as ext

BIG = 2**70
I64 = r"each of x, y, z must lie in int64 \(-2\*\*63 to 2\*\*63 - 1\)"


@pytest.fixture(scope="module")
def dot():
    return t.Octree.from_voxels([[0, 0, 0]])


@pytest.fixture(scope="module")
def scene():
    return t.Scene.parse("depth 5\nbounds [0, 0, 0] [8, 8, 8]\nsphere(r = 2) at [4, 4, 4]\n")


@pytest.mark.parametrize("name, low", [("steps", 0), ("seed", 0), ("sample_every", 1)])
def test_rsmc_names_counts_out_of_range(name, low):
    for bad in (low - 1, -(2**64), 2**64, BIG):
        with pytest.raises(ValueError, match=rf"^{name} {bad}: expected {low} to 2\*\*64 - 1$"):
            t.rsmc(**{name: bad})
    with pytest.raises(ValueError, match=r"^max_area -1: expected None or 6 to 2\*\*64 - 1 faces"):
        t.rsmc(steps=10, max_area=-1)
    with pytest.raises(ValueError, match="max_area = 5 is below 6"):
        t.rsmc(steps=10, max_area=5)
    # The ends of the range are taken.
    r = t.rsmc(steps=10, seed=2**64 - 1, sample_every=2**64 - 1, max_area=2**64 - 1)
    assert r["step"].tolist() == [0, 10]


@pytest.mark.parametrize("bad", [-1, 2**64, BIG])
def test_scans_name_max_cells_out_of_range(bad):
    said = rf"^max_cells {bad}: expected 0 to 2\*\*64 - 1 cells$"
    m = t.OccupancyMap(0.1)
    with pytest.raises(ValueError, match=said):
        m.insert_scan((0, 0, 0), [[1, 0, 0]], max_cells=bad)
    with pytest.raises(ValueError, match=said):
        m.insert_scans([((0, 0, 0), [[1, 0, 0]])], max_cells=bad)
    with pytest.raises(ValueError, match=said):
        t.DynamicOctree().insert_scan((0, 0, 0), [[1, 0, 0]], max_cells=bad)
    assert m.stats()["free"] == 0 == m.stats()["occupied"]
    assert m.insert_scan((0, 0, 0), [[1, 0, 0]], max_cells=2**64 - 1)["rays"] == 1


def test_rotate_takes_any_turn_count_modulo_4():
    bar = t.Octree.from_voxels([[0, 0, 0], [1, 0, 0], [1, 1, 0]])
    for turns in (1, 2, 3):
        want = bar.rotate("z", turns)
        for n in (turns + 4 * 2**40, turns - 4 * BIG, turns + 2**31 + 1 - (2**31 + 1) % 4,
                  np.int64(turns + 8)):
            assert bar.rotate("z", n) == want, n
    assert bar.rotate("z", -BIG) == bar and bar.rotate("z", 4) == bar
    with pytest.raises(TypeError, match="turns: expected an integer, got 1.5"):
        bar.rotate("z", 1.5)


def test_octree_names_coordinates_past_int64(dot):
    for v in ((BIG, 0, 0), (0, -(2**63) - 1, 0), (0, 0, 2**63)):
        with pytest.raises(ValueError, match=rf"^v \({v[0]}, {v[1]}, {v[2]}\): {I64}"):
            dot.translate(v)
        with pytest.raises(ValueError, match=rf"^origin \(.*\): {I64}"):
            t.Octree.from_dense(np.ones((1, 1, 1), bool), origin=v)
        with pytest.raises(ValueError, match=rf"^k \(.*\): {I64}"):
            dot.scale(v)
    with pytest.raises(ValueError, match=r"^k 1180591620717411303424: the factor must lie in int64"):
        dot.scale(BIG)
    # In int64 but too far: the library's error, as before.
    with pytest.raises(t.OctreeError, match="exceeds the maximum of 21"):
        dot.translate((2**63 - 1, 0, 0))
    # from_dense refuses a voxel past int64 rather than wrap it round to -2**63.
    mask = np.array([[[False]], [[True]]])
    with pytest.raises(ValueError, match=r"origin \(9223372036854775807, 0, 0\): the true element "
                                         r"\[1, 0, 0\] lies past int64"):
        t.Octree.from_dense(mask, origin=(2**63 - 1, 0, 0))
    assert t.Octree.from_dense(mask, origin=(-5, 0, 0)).voxels().tolist() == [[-4, 0, 0]]


def test_motion_names_offsets_past_int64(dot):
    for v in ((BIG, 0, 0), (0, 0, -(2**63) - 1)):
        with pytest.raises(ValueError, match=rf"^offset \({v[0]}, {v[1]}, {v[2]}\): {I64}"):
            t.collide(dot, dot, v)
        with pytest.raises(ValueError, match=rf"^start \(.*\): {I64}"):
            t.plan(dot, dot, v, (5, 0, 0))
        with pytest.raises(ValueError, match=rf"^goal \(.*\): {I64}"):
            t.plan(dot, dot, (2, 0, 0), v)
    for bad in (-1, BIG):
        with pytest.raises(ValueError, match=rf"^margin {bad}: expected 0 to 2\*\*63 - 1 voxels"):
            t.plan(dot, dot, (2, 0, 0), (5, 0, 0), margin=bad)
    assert t.collide(dot, dot, (2**63 - 1, 0, 0))["intersects"] is False
    assert t.collide(dot, dot)["intersects"] is True


def test_partition_steps_name_depths_out_of_range(dot, scene):
    for bad in (-1, 22, 300, BIG):
        said = rf"^depth {bad}: expected 0 to 21$"
        with pytest.raises(ValueError, match=said):
            ext.partition_join(bad, (0, 0, 0), 1.0, (0.0, 0.0, 0.0), [])
        with pytest.raises(ValueError, match=said):
            ext.partition_translated_space(bad, (0, 0, 0), [], (0, 0, 0))
        with pytest.raises(ValueError, match=said):
            ext.partition_translated_sample(dot, (0, 0, 0), bad, (0, 0, 0), 4)
        with pytest.raises(ValueError, match=said):
            ext.partition_balanced_ranges(bad, 2, np.zeros(0, np.uint64))
        with pytest.raises(ValueError, match=said):
            ext.partition_move_split(dot, (0, 0, 0), bad, (0, 0, 0), [(0, 8)], False)
        with pytest.raises(ValueError, match=said):
            ext.partition_embedded_ranges(bad, (0, 0, 0), [(0, 8)], 3, (0, 0, 0))
        with pytest.raises(ValueError, match=rf"^new_depth {bad}: expected 0 to 21$"):
            ext.partition_embedded_ranges(1, (0, 0, 0), [(0, 8)], bad, (0, 0, 0))
        with pytest.raises(ValueError, match=rf"^dst_depth {bad}: expected 0 to 21$"):
            ext.partition_reach(1, (0, 0, 0), [(0, 8)], (0, 0, 0), bad, (0, 0, 0), [(0, 8)])
        with pytest.raises(ValueError, match=rf"^depth {bad}: expected 1 to 16$"):
            ext.partition_scene_ranges(scene, bad, 2)
        with pytest.raises(ValueError, match=rf"^depth {bad}: expected 1 to 16$"):
            ext.partition_build_range(scene, bad, 0, 8)
    with pytest.raises(ValueError, match=r"^k -1: expected 0 to 2\*\*64 - 1$"):
        ext.partition_balanced_ranges(1, -1, np.zeros(0, np.uint64))
    assert ext.partition_translated_space(21, (0, 0, 0), [], (0, 0, 0)) == (21, (0, 0, 0))


def test_partition_steps_name_translates_not_finite(tmp_path):
    entry = dict(file="a.tess", lo=0, hi=8, leaves=1, voxels=1, crc32=0)
    for tr in ((np.nan, 0.0, 0.0), (0.0, np.inf, 0.0), (0.0, 0.0, -np.inf)):
        said = r"^translate \(.*\): each of x, y, z must be finite$"
        with pytest.raises(ValueError, match=said):
            ext.partition_join(1, (0, 0, 0), 1.0, tr, [])
        with pytest.raises(ValueError, match=said):
            ext.partition_write_manifest(str(tmp_path), 1, (0, 0, 0), 1.0, tr, [])
        with pytest.raises(ValueError, match=said):
            ext.partition_read_part(str(tmp_path), 1, (0, 0, 0), 1.0, tr, entry)
    assert not (tmp_path / "manifest.json").exists()


def test_dask_names_its_arguments_out_of_range(scene):
    td = pytest.importorskip("tesseral.dask")
    with pytest.raises(ValueError, match=rf"^depth {BIG}: expected 1 to 16$"):
        td.build(scene, depth=BIG, parts=2)
    with pytest.raises(ValueError, match=rf"^parts={BIG}: expected a number of parts from 1 to 65536"):
        td.build(scene, parts=BIG)
    parts = td.build(scene, parts=2)
    with pytest.raises(ValueError, match=rf"^offset \({BIG}, 0, 0\): {I64}"):
        td.translate(parts, (BIG, 0, 0))
