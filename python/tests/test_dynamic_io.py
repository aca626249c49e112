"""DynamicOctree.write and DynamicOctree.read: a model's file when the octree fits
one, the octree's own .tess when it is wider; the errors of a bad or missing file."""

import errno
import inspect

import numpy as np
import pytest

import tesseral as t

MODEL_MAGIC = b"\x89TESSRL\n"
DYN_MAGIC = b"\x89TESSDY\n"


def voxel_set(d):
    return set(map(tuple, d.voxels().tolist()))


def octree(voxels):
    d = t.DynamicOctree()
    d.insert(np.array(voxels, dtype=np.int64))
    return d


def wide():
    # 4,000,000 apart on x: past a model's 2^21 voxels on an axis.
    return octree([[0, 0, 0], [1, 0, 0], [-3, 2, 1], [4_000_000, 0, 0], [4_000_001, -7, 5]])


def test_a_small_octree_round_trips_as_a_model(tmp_path):
    d = octree([[0, 0, 0], [1, 0, 0], [-5, 7, 3], [100, -20, 9]] + [[x, 4, 4] for x in range(20)])
    p = tmp_path / "small.tess"
    d.write(p)
    assert p.read_bytes()[:8] == MODEL_MAGIC  # any model reader takes it
    assert len(t.Octree.read(p)) == len(d)
    back = t.DynamicOctree.read(p)
    assert voxel_set(back) == voxel_set(d) and len(back) == len(d)
    # The face list is rebuilt, and kept up to date by later edits.
    assert back.face_count == d.face_count
    for tree in (d, back):
        tree.insert([[2, 0, 0], [0, 1, 0]])
        tree.remove([[5, 4, 4]])
    assert back.face_count == d.face_count and voxel_set(back) == voxel_set(d)
    assert back.stats()["faces"] == back.face_count


def test_an_octree_wider_than_a_model_keeps_its_own_tess(tmp_path):
    d = wide()
    p = tmp_path / "wide.tess"
    d.write(str(p))  # a str or a path
    assert p.read_bytes()[:8] == DYN_MAGIC
    back = t.DynamicOctree.read(str(p))
    assert voxel_set(back) == voxel_set(d) and len(back) == 5
    assert back.face_count == d.face_count == 5 * 6 - 2
    # Model readers refuse it, and say what reads it.
    with pytest.raises(t.FormatError, match="read it as a dynamic octree") as e:
        t.Octree.read(p)
    assert str(p) in str(e.value)


def test_an_empty_octree_round_trips(tmp_path):
    p = tmp_path / "empty.tess"
    t.DynamicOctree().write(p)
    back = t.DynamicOctree.read(p)
    assert len(back) == 0 and back.face_count == 0


def test_a_wide_octree_in_another_format_is_refused_and_the_old_file_kept(tmp_path):
    p = tmp_path / "wide.xyz"
    p.write_text("kept\n")
    with pytest.raises(t.FormatError, match=r"only \.tess keeps it") as e:
        wide().write(p)
    assert str(p) in str(e.value)
    assert p.read_text() == "kept\n"
    # A write that succeeds replaces the file whole.
    q = tmp_path / "wide.tess"
    q.write_bytes(b"old" * 1000)
    wide().write(q)
    assert voxel_set(t.DynamicOctree.read(q)) == voxel_set(wide())
    assert sorted(f.name for f in tmp_path.iterdir()) == ["wide.tess", "wide.xyz"]


def test_file_errors_are_the_oserror_of_their_errno(tmp_path):
    missing = tmp_path / "missing.tess"
    with pytest.raises(FileNotFoundError) as e:
        t.DynamicOctree.read(missing)
    assert e.value.errno == errno.ENOENT and e.value.filename == str(missing)
    target = tmp_path / "no" / "d.tess"
    for d in (octree([[0, 0, 0]]), wide()):
        with pytest.raises(FileNotFoundError) as e:
            d.write(target)
        assert e.value.errno == errno.ENOENT and e.value.filename == str(target)
    (tmp_path / "dir.tess").mkdir()
    with pytest.raises(IsADirectoryError) as e:
        t.DynamicOctree.read(tmp_path / "dir.tess")
    assert e.value.errno == errno.EISDIR and e.value.filename == str(tmp_path / "dir.tess")


def test_a_corrupt_file_is_a_format_error_naming_it(tmp_path):
    p = tmp_path / "wide.tess"
    wide().write(p)
    good = p.read_bytes()
    bad = bytearray(good)
    bad[40] ^= 0xFF
    p.write_bytes(bytes(bad))
    with pytest.raises(t.FormatError, match="checksum mismatch") as e:
        t.DynamicOctree.read(p)
    assert str(e.value).startswith(str(p))
    p.write_bytes(good[:20])
    with pytest.raises(t.FormatError, match="truncated") as e:
        t.DynamicOctree.read(p)
    assert str(p) in str(e.value)
    p.write_bytes(b"not an octree at all")
    with pytest.raises(t.FormatError, match="bad magic number") as e:
        t.DynamicOctree.read(p)
    assert str(p) in str(e.value)


def test_a_solid_model_reads_whole_and_its_faces_are_counted(tmp_path):
    p = tmp_path / "box.tess"
    t.Scene.parse("depth 7\nbox(size = [128, 128, 128])\n").build().write(p)  # 2^21 voxels
    back = t.DynamicOctree.read(p)
    assert len(back) == 128**3 and back.face_count == 6 * 128**2
    back.remove([[0, 0, 0]])  # a corner: three faces gone, three inner ones exposed
    assert back.face_count == 6 * 128**2
    back.remove([[1, 1, 1]])  # inside, its six neighbours there: six faces exposed
    assert back.face_count == 6 * 128**2 + 6


def test_a_solid_whose_faces_would_take_too_long_to_count_is_refused(tmp_path):
    p = tmp_path / "big.tess"
    # A cube of 2^15 a side, one leaf in a few bytes: 3 * 2^30 lookups on its
    # faces, past read's 2^28.
    box = t.Scene.parse("depth 9\nbox(size = [512, 512, 512])\n").build().scale(64)
    box.write(p)
    with pytest.raises(t.FormatError, match=r"lookups to count, past the 2\^28") as e:
        t.DynamicOctree.read(p)
    assert str(e.value).startswith(str(p))


def naive_faces(cells):
    steps = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    return sum((x + a, y + b, z + c) not in cells for (x, y, z) in cells for (a, b, c) in steps)


def test_the_face_count_follows_edits_as_a_set_model_counts_them():
    rng = np.random.default_rng(13)
    d, model = t.DynamicOctree(), set()
    for step in range(60):
        v = rng.integers(-3, 4, size=(rng.integers(1, 20), 3))
        if step % 3 == 2:
            assert d.remove(v) == len(model & set(map(tuple, v.tolist())))
            model -= set(map(tuple, v.tolist()))
        else:
            assert d.insert(v) == len(set(map(tuple, v.tolist())) - model)
            model |= set(map(tuple, v.tolist()))
        assert len(d) == len(model) and d.face_count == naive_faces(model), step
    # A scan's cells too.
    d.insert_scan((0.5, 0.5, 0.5), np.array([[6.5, 0.5, 0.5], [0.5, 6.5, 0.5]]))
    assert d.face_count == naive_faces(set(map(tuple, d.voxels().tolist())))


def test_a_map_file_and_a_dynamic_octree_file_are_told_apart(tmp_path):
    m = t.OccupancyMap(0.1)
    m.insert_scan((0.05, 0.05, 0.05), np.array([[1.05, 0.05, 0.05]]))
    m.insert_scan((1e6, 0.5, 0.5), np.array([[1e6 + 1.0, 0.5, 0.5]]))
    maps = tmp_path / "map.tess"
    m.write(maps)
    with pytest.raises(t.FormatError, match="occupancy map .* read it as a map") as e:
        t.DynamicOctree.read(maps)
    assert str(maps) in str(e.value)
    dyn = tmp_path / "dyn.tess"
    wide().write(dyn)
    with pytest.raises(t.FormatError, match=r"read it as a dynamic octree .*tesseral\.DynamicOctree\.read") as e:
        t.OccupancyMap.read(dyn)
    assert str(dyn) in str(e.value)


def test_read_is_a_static_method_with_real_signatures():
    assert isinstance(inspect.getattr_static(t.DynamicOctree, "read"), staticmethod)
    assert list(inspect.signature(t.DynamicOctree.read).parameters) == ["path"]
    assert list(inspect.signature(t.DynamicOctree.write).parameters) == ["self", "path"]
