"""What the array-taking calls accept (any numeric dtype, lists of rows), what they
refuse and how they say so; argument checks, signatures, file errors and threads."""

import errno
import inspect
import os
import threading

import numpy as np
import pytest

import tesseral as t

O = (0.05, 0.05, 0.05)
END = [[1.05, 0.05, 0.05]]
WANT = {"points": 1, "rays": 1, "skipped": 0, "hits": 1, "misses": 10}


@pytest.mark.parametrize(
    "points",
    [
        np.array(END, dtype=np.float32),
        np.array(END, dtype=">f8"),  # big-endian
        np.array(END, dtype=np.float64)[:, ::1],
        np.asfortranarray(np.array(END * 2)),
        [tuple(END[0])],  # a list of tuples
        END,
    ],
    ids=["float32", "big-endian", "float64", "fortran", "tuples", "lists"],
)
def test_insert_scan_takes_any_float_layout_and_dtype(points):
    m = t.OccupancyMap(0.1)
    s = m.insert_scan(O, points)
    assert (s["hits"], s["misses"]) == (1, 10)
    assert m.state(np.array([[10, 0, 0]])).tolist() == [2]


def test_int_points_are_converted_to_floats():
    for dtype in (np.int64, np.int32, np.uint8):
        m = t.OccupancyMap(1.0)
        s = m.insert_scan((0, 0, 0), np.array([[3, 0, 0]], dtype=dtype))
        assert s["hits"] == 1
        assert m.cells_of(np.array([[3, 0, 0]], dtype=dtype)).tolist() == [[3, 0, 0]]
    o = t.Octree.from_points(np.array([[0.1, 0.2, 0.3]], dtype=np.float32), 0.5)
    assert o.voxels().tolist() == [[0, 0, 0]]
    assert t.Octree.from_points([[1, 1, 1]], 0.5).voxels().tolist() == [[2, 2, 2]]


def test_cells_take_any_integer_dtype_and_whole_floats_only():
    m = t.OccupancyMap(0.1)
    m.insert_scan(O, END)
    for cells in ([[10, 0, 0]], np.array([[10, 0, 0]], dtype=np.int32),
                  np.array([[10, 0, 0]], dtype=np.uint16), np.array([[10, 0, 0]], dtype=">i8"),
                  np.array([[10.0, 0.0, 0.0]])):
        assert m.state(cells).tolist() == [2]
        assert m.log_odds(cells)[0] == pytest.approx(0.847, abs=1e-3)
    with pytest.raises(ValueError, match=r"cells: expected integers, got 10.5 in row 1"):
        m.state(np.array([[0.0, 0, 0], [10.5, 0, 0]]))
    with pytest.raises(ValueError, match="expected integers, got NaN"):
        m.log_odds(np.array([[np.nan, 0, 0]]))
    with pytest.raises(ValueError, match="past the range of int64"):
        m.state(np.array([[2 ** 64 - 1, 0, 0]], dtype=np.uint64))
    with pytest.raises(TypeError, match="cells: expected an N×3 array of numbers, got an array of dtype bool"):
        m.state(np.array([[True, False, False]]))
    v = t.Octree.from_voxels(np.array([[1, 2, 3]], dtype=np.int16))
    assert v.voxels().tolist() == [[1, 2, 3]]
    assert v.contains([[1, 2, 3], [0, 0, 0]]).tolist() == [True, False]
    d = t.DynamicOctree()
    assert d.insert(np.array([[1, 2, 3]], dtype=np.int32)) == 1
    assert d.contains([(1.0, 2.0, 3.0)]).tolist() == [True]
    assert t.calc.encode([[1, 2, 3]]).tolist() == t.calc.encode(np.array([[1, 2, 3]])).tolist()


def test_bad_arrays_say_what_was_expected_and_what_came():
    m = t.OccupancyMap(0.1)
    with pytest.raises(ValueError, match=r"points: expected an N×3 array, got an array of shape \(1, 2\)"):
        m.insert_scan(O, np.zeros((1, 2)))
    with pytest.raises(ValueError, match=r"points: expected an N×3 array, got an int of shape \(\)"):
        m.insert_scan(O, 5)
    with pytest.raises(TypeError, match="points: expected an N×3 array of numbers, got a list of dtype <U1"):
        m.insert_scan(O, [["a", "b", "c"]])
    with pytest.raises(ValueError, match="points: expected an N×3 array of numbers, got a list that numpy"):
        m.insert_scan(O, [[1, 2], [1, 2, 3]])
    with pytest.raises(TypeError, match="points: .* of dtype complex128"):
        m.cells_of(np.zeros((2, 3), dtype=complex))
    with pytest.raises(TypeError, match="voxels: .* of dtype object"):
        t.Octree.from_voxels([[1, 2, None]])
    assert m.insert_scan(O, [])["points"] == 0  # an empty list: no rows
    assert m.insert_scan(O, np.zeros((0, 3), dtype=np.float32))["points"] == 0


def test_insert_scans_takes_any_iterable_of_pairs_and_names_the_bad_scan():
    pts = np.array(END)
    want = [WANT, WANT]
    assert t.OccupancyMap(0.1).insert_scans([[O, pts], [O, pts.astype(np.float32)]]) == want
    assert t.OccupancyMap(0.1).insert_scans((O, p) for p in [pts, pts.tolist()]) == want
    assert t.OccupancyMap(0.1).insert_scans(((np.array(O), pts), (list(O), pts))) == want
    m = t.OccupancyMap(0.1)
    good = (O, pts)
    with pytest.raises(ValueError, match=r"scan 3: points: expected an N×3 array, got an array of shape \(4, 2\)"):
        m.insert_scans([good, good, good, (O, np.zeros((4, 2)))])
    with pytest.raises(TypeError, match="scan 2: points: expected an N×3 array of numbers"):
        m.insert_scans([good, good, (O, [["x", "y", "z"]])])
    with pytest.raises(TypeError, match=r"scan 1: expected an \(origin, points\) pair, got int"):
        m.insert_scans([good, 5])
    with pytest.raises(TypeError, match=r"scan 1: expected an \(origin, points\) pair, got tuple"):
        m.insert_scans([good, (O, pts, 1.0)])
    with pytest.raises(TypeError, match="scan 0: origin: expected 3 numbers"):
        m.insert_scans([((0, 0), pts)])
    with pytest.raises(ValueError, match="scan 1: origin: .* not finite"):
        m.insert_scans([good, ((0.0, np.nan, 0.0), pts)])
    with pytest.raises(TypeError, match="scans: expected an iterable"):
        m.insert_scans(5)
    assert m.stats()["occupied"] == 0  # nothing was cast


@pytest.mark.parametrize("bad", [-1.0, 0.0, float("nan"), float("inf")])
def test_max_range_is_none_or_positive_as_the_cli_wants(bad):
    m = t.OccupancyMap(0.1)
    for call in (lambda: m.insert_scan(O, END, max_range=bad),
                 lambda: m.insert_scans([(O, END)], max_range=bad),
                 lambda: t.DynamicOctree().insert_scan((0.5, 0.5, 0.5), [[3.5, 0.5, 0.5]], max_range=bad)):
        with pytest.raises(ValueError, match="max_range .*: expected a positive finite number, or None"):
            call()
    assert m.stats()["free"] == 0


def test_origins_and_poses_must_be_finite(tmp_path):
    m = t.OccupancyMap(0.1)
    with pytest.raises(ValueError, match=r"origin: \[NaN, 0.0, 0.0\] is not finite"):
        m.insert_scan((np.nan, 0.0, 0.0), END)
    with pytest.raises(ValueError, match="origin: .* not finite"):
        t.DynamicOctree().insert_scan((0.0, np.inf, 0.0), END)
    np.savetxt(tmp_path / "c.xyz", END)
    with pytest.raises(ValueError, match="origin: .* not finite"):
        t.read_scans(tmp_path / "c.xyz", origin=(np.nan, 0, 0))
    with pytest.raises(ValueError, match="pose: .* not finite"):
        t.read_scans(tmp_path / "c.xyz", pose=(0, 0, 0, 0, np.nan, 0))
    with pytest.raises(TypeError, match="pose: expected 6 numbers"):
        t.read_scans(tmp_path / "c.xyz", pose=(0, 0, 0))
    [(o, p)] = t.read_scans(tmp_path / "c.xyz", origin=np.array(O, dtype=np.float32))
    assert o == pytest.approx(O)


def test_signatures_show_the_real_defaults():
    sig = inspect.signature(t.OccupancyMap)
    assert sig.parameters["clamp"].default == (0.1192, 0.971)
    assert sig.parameters["prob_hit"].default == 0.7
    assert inspect.signature(t.OccupancyMap.from_octree).parameters["clamp"].default == (0.1192, 0.971)
    for f in (t.OccupancyMap.insert_scan, t.OccupancyMap.insert_scans, t.DynamicOctree.insert_scan):
        assert inspect.signature(f).parameters["max_cells"].default == 10 ** 10
        assert inspect.signature(f).parameters["max_range"].default is None
    r = inspect.signature(t.render).parameters
    assert r["size"].default == (800, 600) and r["background"].default == (255, 255, 255)


def test_the_stub_lists_every_method():
    import ast
    import pathlib

    stub = pathlib.Path(t.__file__).with_name("_tesseral.pyi")
    tree = ast.parse(stub.read_text())
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and node.name in ("Octree", "Scene", "DynamicOctree", "OccupancyMap"):
            listed = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
            cls = getattr(t, node.name)
            public = {k for k in vars(cls) if not k.startswith("__")}
            assert public <= listed, (node.name, public - listed)


def test_file_errors_are_the_oserror_of_their_errno(tmp_path):
    missing = tmp_path / "missing.tess"
    for call, path in [(t.Octree.read, missing), (t.read_scans, tmp_path / "missing.xyz"),
                       (t.Scene.read, tmp_path / "missing.tss")]:
        with pytest.raises(FileNotFoundError) as e:
            call(path)
        assert e.value.errno == errno.ENOENT and e.value.filename == str(path)
    (tmp_path / "dir.tess").mkdir()
    with pytest.raises(IsADirectoryError) as e:
        t.Octree.read(tmp_path / "dir.tess")
    assert e.value.errno == errno.EISDIR and e.value.filename == str(tmp_path / "dir.tess")
    m = t.OccupancyMap(0.1)
    with pytest.raises(FileNotFoundError) as e:
        m.write(tmp_path / "no" / "map.bt")
    assert e.value.errno == errno.ENOENT and e.value.filename == str(tmp_path / "no" / "map.bt")
    if os.geteuid() != 0:  # root reads anything
        locked = tmp_path / "locked.xyz"
        locked.write_text("1 2 3\n")
        locked.chmod(0)
        with pytest.raises(PermissionError) as e:
            t.Octree.read(locked)
        assert e.value.filename == str(locked)


def test_render_takes_a_map_and_checks_the_object_first():
    m = t.OccupancyMap(0.1)
    m.insert_scan(O, END)
    img = t.render(m, size=(32, 24))
    assert img.shape == (24, 32, 3)
    assert np.array_equal(img, t.render(m.to_octree(), size=(32, 24)))
    with pytest.raises(TypeError, match="render takes an Octree, a Scene or an OccupancyMap, got int"):
        t.render(5, size=(16, 12))  # the object first, then the size


def test_a_map_busy_on_another_thread_says_so():
    # A scan of about a third of a second, during which the GIL is released.
    m = t.OccupancyMap(0.05)
    pts = np.random.default_rng(3).uniform(-20.0, 20.0, (20_000, 3))
    done = threading.Event()
    worker = threading.Thread(target=lambda: (m.insert_scan((0.0, 0.0, 0.0), pts), done.set()))
    errors = []
    worker.start()
    while not done.is_set():
        try:
            m.stats()
        except RuntimeError as e:
            errors.append(str(e))
    worker.join()
    assert errors, "the scan ended before the other thread called (make it longer)"
    assert all("in use by a call on another thread" in e for e in errors)
    assert m.stats()["occupied"] > 0


SOME = [0, 1, 7, 8, 100, 127]


@pytest.mark.parametrize(
    "dtype",
    [np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32, np.uint64,
     ">i8", ">u8", ">i4", ">u2", np.float32, np.float64, ">f8"],
)
def test_calc_takes_codes_of_any_integer_dtype_and_whole_floats(dtype):
    codes = np.array(SOME, dtype=dtype)
    want = np.array(SOME, dtype=np.uint64)
    assert np.array_equal(t.calc.decode(codes), t.calc.decode(want))
    assert np.array_equal(t.calc.add(codes, codes), t.calc.add(want, want))
    assert np.array_equal(t.calc.sub(codes, want[::-1]), t.calc.sub(want, want[::-1]))


def test_calc_takes_lists_of_ints_and_strided_or_readonly_uint64():
    big = 2 ** 63 - 1  # the largest code: 21 octal digits of 7
    assert t.calc.decode([0, 1, big]).tolist() == [[0, 0, 0], [1, 0, 0], [2 ** 21 - 1] * 3]
    assert t.calc.add([1, 2], (3, 4)).tolist() == t.calc.add(np.array([1, 2], np.uint64),
                                                             np.array([3, 4], np.uint64)).tolist()
    assert t.calc.decode([]).shape == (0, 3)
    codes = np.arange(10, dtype=np.uint64)
    assert t.calc.decode(codes[::3]).tolist() == t.calc.decode([0, 3, 6, 9]).tolist()
    codes.flags.writeable = False
    assert t.calc.sub(codes, codes).tolist() == [0] * 10


def test_calc_refuses_what_cannot_be_a_code_and_names_it():
    with pytest.raises(ValueError, match=r"^codes\[3\] is -1: codes are unsigned"):
        t.calc.decode(np.array([0, 1, 2, -1], dtype=np.int8))
    with pytest.raises(ValueError, match=r"^b\[1\] is -5: codes are unsigned"):
        t.calc.add([1, 2], [0, -5])
    with pytest.raises(ValueError, match=r"^a\[0\] is -2: codes are unsigned"):
        t.calc.sub(np.array([-2.0]), [0])
    past = r"past the largest code, 2\*\*63 - 1"
    with pytest.raises(ValueError, match=rf"^codes\[1\] is 9223372036854775808: {past}"):
        t.calc.decode(np.array([0, 2 ** 63], dtype=np.uint64))
    with pytest.raises(ValueError, match=rf"^codes\[0\] is 18446744073709551615: {past}"):
        t.calc.decode(np.array([2 ** 64 - 1], dtype=">u8"))
    with pytest.raises(ValueError, match=rf"^codes\[2\] is 18446744073709551616: {past}"):
        t.calc.decode([0, 1, 2 ** 64])  # numpy makes an object array of it
    with pytest.raises(ValueError, match=r"^codes\[0\] is -1: codes are unsigned"):
        t.calc.decode([-1, 2 ** 63])
    with pytest.raises(ValueError, match=rf"^codes\[0\] is 9223372036854776000: {past}"):
        t.calc.decode(np.array([2.0 ** 63]))
    with pytest.raises(ValueError, match=r"^codes\[1\] is 1.5: not a whole number"):
        t.calc.decode(np.array([1.0, 1.5]))
    with pytest.raises(ValueError, match=r"^codes\[0\] is NaN: not a whole number"):
        t.calc.decode(np.array([np.nan], dtype=np.float32))
    with pytest.raises(TypeError, match="codes: expected a 1-D array of codes .* of dtype bool"):
        t.calc.decode(np.array([True, False]))
    with pytest.raises(TypeError, match="codes: expected a 1-D array of codes .* of dtype <U1"):
        t.calc.decode(["a"])
    with pytest.raises(TypeError, match=r"^codes\[1\] is None, not an integer"):
        t.calc.decode([1, None, 2 ** 64])
    with pytest.raises(ValueError, match=r"codes: expected a 1-D array of codes, got an array of shape \(2, 3\)"):
        t.calc.decode(np.zeros((2, 3), dtype=np.uint64))
    with pytest.raises(ValueError, match=r"codes: expected a 1-D array of codes, got an int of shape \(\)"):
        t.calc.decode(5)
    with pytest.raises(ValueError, match="arrays of 2 and 1 codes"):
        t.calc.add([1, 2], [1])


def test_calc_reads_mixed_lists_exactly_and_lets_interrupts_through():
    # numpy makes floats of a list mixing ints past 2**53 with floats: read exactly.
    assert t.calc.decode([2 ** 60 + 1, 1.0]).tolist() == t.calc.decode(
        np.array([2 ** 60 + 1, 1], dtype=np.uint64)).tolist()
    past = r"past the largest code, 2\*\*63 - 1"
    with pytest.raises(ValueError, match=rf"^codes\[0\] is 9223372036854775808: {past}"):
        t.calc.decode([2 ** 63, 0.0])
    # Whole floats beside a huge int (an object array): the huge one is named.
    with pytest.raises(ValueError, match=rf"^codes\[1\] is 18446744073709551616: {past}"):
        t.calc.decode([1.0, 2 ** 64])
    assert t.calc.decode([2.0, 2 ** 62]).tolist()[0] == [0, 1, 0]

    class Interrupting:
        def __index__(self):
            raise KeyboardInterrupt

    class Exhausting:
        def __array__(self, dtype=None, copy=None):
            raise MemoryError

    with pytest.raises(KeyboardInterrupt):
        t.calc.decode([Interrupting(), 2 ** 64])
    with pytest.raises(MemoryError):
        t.calc.decode(Exhausting())


def test_cells_of_mixed_rows_are_read_exactly():
    # numpy makes floats of rows mixing ints past 2**53 with floats: read exactly.
    big = 2 ** 60 + 1
    d = t.DynamicOctree()
    d.insert([[big, 0, 1.0]])
    assert d.voxels().tolist() == [[big, 0, 1]]
    with pytest.raises(ValueError, match=r"voxels: expected integers, got 0.5 in row 1"):
        d.insert([[big, 0, 1.0], [1, 2, 0.5]])
    with pytest.raises(ValueError, match=r"got 9223372036854775808 in row 0"):
        d.insert([[2 ** 63, 0, 1.0]])


def test_calc_releases_the_gil_while_it_computes(ticks_during):
    # Another thread keeps running while add, sub and decode work on a native
    # uint64 array (read in place, so the whole call is the computation).
    codes = np.arange(1 << 22, dtype=np.uint64)
    for call in (lambda: t.calc.add(codes, codes), lambda: t.calc.sub(codes, codes),
                 lambda: t.calc.decode(codes)):
        _, during = ticks_during(call, period=0.0005)
        assert during >= 2, during
