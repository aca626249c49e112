"""Arguments the bindings refuse rather than misread, and how they say so: points in
no cell of the lattice, render's angles and colours, paths, masks, depths, plans."""

import errno

import numpy as np
import pytest

import tesseral as t

# 2**63: the first float past int64.
PAST_I64 = 2.0**63


@pytest.mark.parametrize(
    "x, said",
    [
        (1e30, r"points: row 1 is \[1e30, 0.2, 0.3\], whose x = 1e30 lies in voxel 1e30, "
               r"past the range of int64"),
        (9.3e18, r"whose x = 9.3e18 lies in voxel 9.3e18, past the range of int64"),
        (-PAST_I64 * 2, r"whose x = -1.8446744073709552e19 lies in voxel"),
        (np.nan, r"row 1 is \[NaN, 0.2, 0.3\], whose x is NaN"),
        (np.inf, r"whose x is inf"),
    ],
)
def test_from_points_refuses_points_in_no_voxel(x, said):
    points = np.array([[0.1, 0.2, 0.3], [x, 0.2, 0.3]])
    with pytest.raises(t.OctreeError, match=said):
        t.Octree.from_points(points, 1.0)
    # The same through the voxel size: a fine voxel puts a far point past int64.
    said = r"points: row 0 is \[0.0, 0.0, 10000000000.0\], whose z .* voxel 1e20"
    with pytest.raises(t.OctreeError, match=said):
        t.Octree.from_points([[0.0, 0.0, 1e10]], 1e-10)


def test_from_points_keeps_points_within_int64():
    # The largest floats below 2**63 and from -2**63 have voxels: exactly themselves.
    big = float(np.nextafter(PAST_I64, 0))
    assert t.Octree.from_points([[big, 0, 0]], 1.0).voxels().tolist() == [[int(big), 0, 0]]
    low = t.Octree.from_points([[-PAST_I64, 0, 0]], 1.0).voxels().tolist()
    assert low == [[-(2**63), 0, 0]]


@pytest.mark.parametrize(
    "x, said",
    [
        (np.nan, r"points: row 1 is \[NaN, 0.0, 0.0\], whose x is NaN"),
        (np.inf, r"points: row 1 is \[inf, 0.0, 0.0\], whose x is inf"),
        (-np.inf, r"whose x is -inf"),
        (1e30, r"points: row 1 is \[1e30, 0.0, 0.0\], whose x = 1e30 lies in cell 1e31"),
    ],
)
def test_cells_of_refuses_points_in_no_cell(x, said):
    m = t.OccupancyMap(0.1)
    with pytest.raises(ValueError, match=said):
        m.cells_of(np.array([[0.0, 0.0, 0.0], [x, 0.0, 0.0]]))
    with pytest.raises(ValueError, match=r"row 0 .* whose y"):
        m.cells_of([[0.0, x, 0.0]])


def test_cells_of_keeps_far_points_within_int64():
    m = t.OccupancyMap(1.0)
    big = float(np.nextafter(PAST_I64, 0))
    assert m.cells_of([[big, -PAST_I64, 0.5]]).tolist() == [[int(big), -(2**63), 0]]


def test_insert_scan_still_skips_and_counts_points_in_no_cell():
    m = t.OccupancyMap(0.1)
    s = m.insert_scan((0, 0, 0), [[np.nan, 0, 0], [np.inf, 0, 0], [1e30, 0, 0], [0.5, 0, 0]])
    assert (s["points"], s["skipped"], s["rays"]) == (4, 3, 1)


@pytest.fixture(scope="module")
def dot():
    return t.Octree.from_voxels([[0, 0, 0]])


@pytest.mark.parametrize(
    "kwargs, said",
    [
        ({"perspective": float("nan")}, "perspective NaN: the field of view must lie between 0 "
                                        "and 180 degrees"),
        ({"perspective": 0}, "perspective 0: the field of view must lie between 0 and 180"),
        ({"perspective": 180}, "perspective 180: "),
        ({"perspective": 200}, "perspective 200: "),
        ({"perspective": -40}, "perspective -40: "),
        ({"perspective": float("inf")}, "perspective inf: "),
        ({"azimuth": float("nan")}, "azimuth NaN: must be a finite number of degrees"),
        ({"azimuth": float("-inf")}, "azimuth -inf: must be a finite number of degrees"),
        ({"elevation": float("inf")}, "elevation inf: must be a finite number of degrees"),
        ({"elevation": 90.5}, "elevation 90.5: must lie between -90 and 90 degrees"),
        ({"zoom": float("nan")}, "zoom NaN: must be a positive finite number"),
        ({"zoom": 0}, "zoom 0: must be a positive finite number"),
    ],
)
def test_render_refuses_angles_the_cli_refuses(dot, kwargs, said):
    with pytest.raises(ValueError, match=said):
        t.render(dot, size=(32, 32), **kwargs)


def test_render_takes_angles_within_their_ranges(dot):
    for kwargs in ({"perspective": 1}, {"perspective": 179.9}, {"elevation": -90},
                   {"elevation": 90, "azimuth": -720.0}, {"zoom": 1e-3}):
        assert t.render(dot, size=(32, 32), **kwargs).shape == (32, 32, 3)


def _world(tmp_path, environment="wall.xyz", octree="dot.xyz"):
    (tmp_path / "wall.xyz").write_text("".join(f"6 {y} 0\n" for y in range(4)))
    (tmp_path / "dot.xyz").write_text("0 0 0\n")
    (tmp_path / "w.json").write_text(
        f'{{"environment": "{environment}", "steps": 8, "objects": '
        f'[{{"name": "dot", "octree": "{octree}", "start": [0, 0, 0], '
        f'"velocity": [1, 0, 0]}}]}}'
    )
    return tmp_path / "w.json"


def test_simulate_raises_the_oserror_of_its_errno(tmp_path):
    missing = tmp_path / "nope.json"
    with pytest.raises(FileNotFoundError) as e:
        t.simulate(missing)
    assert e.value.errno == errno.ENOENT and e.value.filename == str(missing)
    for folder in (tmp_path, tmp_path / "d.json"):
        folder.mkdir(exist_ok=True)
        with pytest.raises(IsADirectoryError) as e:
            t.simulate(folder)
        assert e.value.errno == errno.EISDIR and e.value.filename == str(folder)
    # An octree or scene the world names, missing: the same, naming that file.
    for env, obj, gone in (("gone.xyz", "dot.xyz", "gone.xyz"),
                           ("wall.xyz", "gone.tss", "gone.tss")):
        with pytest.raises(FileNotFoundError) as e:
            t.simulate(_world(tmp_path, env, obj))
        assert e.value.filename == str(tmp_path / gone)


def test_simulate_keeps_format_and_scene_errors(tmp_path):
    (tmp_path / "bad.json").write_text('{"environment": 3}')
    with pytest.raises(t.FormatError, match=r"bad.json:1:"):
        t.simulate(tmp_path / "bad.json")
    (tmp_path / "bad.tss").write_text(
        "depth 5\nbounds [0, 0, 0] [8, 8, 8]\nsphere(r = ) at [1, 2, 3]\n")
    with pytest.raises(t.SceneError) as e:
        t.simulate(_world(tmp_path, octree="bad.tss"))
    assert (e.value.line, e.value.column) == (3, 12)
    assert t.simulate(_world(tmp_path))["contacts"][0]["time"] == 5.0


@pytest.mark.parametrize(
    "mask, error, said",
    [
        (np.ones((2, 2, 2), int), TypeError,
         r"mask: expected a 3-D bool array, got an array of dtype int64, 3-D "
         r"\(shape \(2, 2, 2\)\)"),
        (np.ones((2, 2, 2)), TypeError, r"got an array of dtype float64, 3-D"),
        (np.ones((2, 2), bool), ValueError,
         r"mask: expected a 3-D bool array, got an array of dtype bool, 2-D \(shape \(2, 2\)\)"),
        (np.ones((1, 2, 2, 2), bool), ValueError, r"of dtype bool, 4-D"),
        ("abc", TypeError, r"got a str of dtype <U3, 0-D"),
    ],
)
def test_from_dense_says_it_wants_a_3d_bool_array(mask, error, said):
    with pytest.raises(error, match=said):
        t.Octree.from_dense(mask)


def test_from_dense_takes_any_layout_and_nested_lists_of_bools():
    mask = np.zeros((4, 3, 2), bool)
    mask[1, 2, 1] = mask[3, 0, 0] = True
    want = [[1, 2, 1], [3, 0, 0]]
    for m in (mask, np.asfortranarray(mask), mask.tolist()):
        assert sorted(t.Octree.from_dense(m).voxels().tolist()) == want
    flipped = np.zeros((4, 3, 4), bool)[:, :, ::2]
    flipped[1, 2, 1] = flipped[3, 0, 0] = True
    assert sorted(t.Octree.from_dense(flipped).voxels().tolist()) == want


def test_render_and_build_name_integers_out_of_range(dot):
    for bad in ((300, 0, 0), (0, -1, 0), (0, 0, 2**70)):
        with pytest.raises(ValueError, match=r"background \(.*\): each channel \(r, g, b\) must "
                                             r"be 0 to 255"):
            t.render(dot, size=(32, 32), background=bad)
    for bad in ((-1, 20), (20, 10**30), (8193, 20), (15, 16)):
        with pytest.raises(ValueError, match=r"size \(.*\): each side must be 16 to 8192 pixels"):
            t.render(dot, size=bad)
    with pytest.raises(TypeError, match="background: expected 3 integers"):
        t.render(dot, size=(32, 32), background=(1, 2))
    with pytest.raises(TypeError, match="background: expected an integer, got 0.5"):
        t.render(dot, size=(32, 32), background=(0.5, 2, 3))
    img = t.render(dot, size=(32, 16), background=(0, np.uint8(255), 7), shadows=False)
    assert img.shape == (16, 32, 3) and img[0, 0].tolist() == [0, 255, 7]
    s = t.Scene.parse("depth 5\nbounds [0, 0, 0] [8, 8, 8]\nsphere(r = 2) at [4, 4, 4]\n")
    for bad in (-1, 0, 17, 300, 2**70):
        with pytest.raises(ValueError, match=f"depth {bad}: expected 1 to 16"):
            s.build(depth=bad)
    with pytest.raises(TypeError, match="depth: expected an integer, got 2.5"):
        s.build(depth=2.5)
    assert s.build(depth=3).depth == 3 and s.build(None).depth == s.depth


def test_plan_refuses_a_region_too_large_to_search():
    a = t.Octree.from_voxels([[0, 0, 0]])
    with pytest.raises(ValueError, match=r"the planning region is too large to search: depth 31 "
                                         r"exceeds the maximum of 21 .* margin=1000000000 voxels"):
        t.plan(a, a, (2, 0, 0), (5, 0, 0), margin=10**9)
    with pytest.raises(ValueError, match=r"too large to search: .* margin=1000000000"):
        t.plan(a, a, (2, 0, 0), (5, 0, 0), margin=10**9, rotations=True)
    with pytest.raises(ValueError, match=r"too large to search: .* margin=0 voxels"):
        t.plan(a, a, (2, 0, 0), (2**40, 0, 0))
    with pytest.raises(ValueError, match=r"margin -1: expected 0 to 2\*\*63 - 1 voxels"):
        t.plan(a, a, (2, 0, 0), (5, 0, 0), margin=-1)
    # A real "no path" is still a finding, and a wide margin within the limit plans.
    assert t.plan(a, a, (0, 0, 0), (5, 0, 0))["reason"].startswith("no path: at the start")
    assert t.plan(a, a, (2, 0, 0), (5, 0, 0), margin=1000)["found"]


def test_plan_of_start_at_goal_has_length_plus_zero():
    a = t.Octree.from_voxels([[0, 0, 0]])
    p = t.plan(a, a, (2, 0, 0), (2, 0, 0))
    assert p["found"] and p["steps"] == 0 and p["waypoints"] == [[2, 0, 0]]
    assert p["length"] == 0.0 and str(p["length"]) == "0.0"


def test_calc_add_and_sub_wrap_per_axis_and_say_so():
    edge = t.calc.encode([[2**21 - 1, 5, 0]])
    moved = t.calc.add(edge, t.calc.encode([[3, 2**21 - 2, 0]]))
    assert t.calc.decode(moved).tolist() == [[2, 3, 0]]     # the carries dropped
    assert t.calc.decode(t.calc.sub([0], [1])).tolist() == [[2**21 - 1, 0, 0]]
    for f in (t.calc.add, t.calc.sub):
        doc = " ".join(f.__doc__.split())
        assert "wrapping per axis" in doc and "modulo 2**21" in doc
