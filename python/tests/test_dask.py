"""tesseral.dask on a real cluster: a dask.distributed LocalCluster (its own
scheduler, two worker processes with one thread each). Every partitioned result
is held against the single-process one, voxel for voxel and colour for colour."""

import json
import os
import pathlib
import pickle
import shutil
import signal
import subprocess
import sys

import numpy as np
import pytest

dask = pytest.importorskip("dask")
distributed = pytest.importorskip("distributed")

import tesseral  # noqa: E402
import tesseral.dask as tdask  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]

# Two scenes in one space and frame (same depth and bounds).
BOUNDS = "bounds [0, 0, 0] [64, 64, 64]\n"
# Coloured and uncoloured objects; the two scenes share a colour and overlap, so
# "the first operand's colour wins" shows.
SCENE_A = (
    "depth 7\n" + BOUNDS + "difference { sphere(r = 24) sphere(r = 10) } at [30, 33, 31] colour \"red\"\n"
    "box(size = [50, 8, 6]) rotate [10, 20, 30] at [32, 20, 40]\n"
    "sphere(r = 7) at [12, 12, 50] colour \"green\"\n"
)
SCENE_B = (
    "depth 7\n" + BOUNDS + "cylinder(r = 9, h = 50) rotate [0, 35, 0] at [36, 36, 30] colour \"blue\"\n"
    "sphere(r = 12) at [14, 50, 18] colour \"red\"\n"
    "box(size = 10) at [50, 50, 50]\n"
)


@pytest.fixture(scope="module")
def client():
    # A worker that dies takes its tasks with it: the scheduler reruns them
    # elsewhere, up to allowed-failures times per task.
    with dask.config.set({"distributed.scheduler.allowed-failures": 4}):
        with distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            env={"RAYON_NUM_THREADS": "1"},
        ) as cluster, distributed.Client(cluster) as c:
            yield c


def same(got, want, colours=True):
    """Voxel for voxel: the same space, frame, leaves and voxels as the
    single-process result, and each voxel the same colour (or none)."""
    assert isinstance(got, tesseral.Octree)
    assert (got.depth, got.origin) == (want.depth, want.origin)
    assert got.frame == want.frame
    assert got.voxel_count == want.voxel_count
    assert got.leaf_count == want.leaf_count
    assert np.array_equal(got.voxels(), want.voxels())
    assert got == want
    if colours:
        (gv, gc), (wv, wc) = got.colors(), want.colors()
        assert np.array_equal(gv, wv) and np.array_equal(gc, wc)


def coloured(tree):
    """How many voxels have a colour (so a test shows it had some to keep)."""
    return len(tree.colors()[0])


def test_octrees_and_scenes_pickle():
    a = tesseral.Scene.parse(SCENE_A)
    t = a.build()
    back = pickle.loads(pickle.dumps(t))
    same(back, t)
    assert back.frame == t.frame
    assert tesseral.Octree.from_bytes(t.to_bytes()) == t
    s = pickle.loads(pickle.dumps(a))
    same(s.build(), t)
    with pytest.raises(tesseral.FormatError):
        tesseral.Octree.from_bytes(b"not a tess file")


def test_import_tesseral_does_not_import_dask():
    code = "import sys, tesseral; assert 'dask' not in sys.modules, 'dask imported'"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_build_equals_the_single_process_build(client):
    scene = tesseral.Scene.parse(SCENE_A)
    parts = tdask.build(scene, 7, parts=5)
    assert len(parts) == len(parts.ranges) == 5
    assert parts.ranges[0][0] == 0 and parts.ranges[-1][1] == 8**7
    assert all(a[1] == b[0] for a, b in zip(parts.ranges, parts.ranges[1:]))
    assert parts.space == (7, (0, 0, 0))
    trees = dask.compute(*parts.octrees)
    for (lo, hi), t in zip(parts.ranges, trees):
        codes, _ = t.leaves()
        assert ((codes >= lo) & (codes < hi)).all()
        cv, _ = t.colors()
        assert t.contains(cv).all()  # a part's colours lie on its voxels
    want = scene.build(7)
    assert coloured(want) > 1000
    assert sum(coloured(t) for t in trees) == coloured(want)
    same(parts.compute(), want)
    assert len(client.scheduler_info()["workers"]) == 2
    kept = parts.persist()  # computed once, held by the workers
    assert kept.ranges == parts.ranges
    same(kept.compute(), want)
    # Another depth, from a path.
    coarse = tdask.build(ROOT / "scenes" / "tank.tss", 6, parts=3).compute()
    same(coarse, tesseral.Scene.read(str(ROOT / "scenes" / "tank.tss")).build(6))


@pytest.mark.parametrize("operation", tdask.OPERATIONS)
def test_operations_equal_the_single_process_ones(client, operation):
    a, b = tesseral.Scene.parse(SCENE_A), tesseral.Scene.parse(SCENE_B)
    wa, wb = a.build(), b.build()
    want = {
        "union": wa | wb,
        "intersection": wa & wb,
        "difference": wa - wb,
        "xor": wa ^ wb,
    }[operation]
    assert coloured(want) > 0
    pa, pb = tdask.build(a, parts=4), tdask.build(b, parts=3)
    assert pa.ranges != pb.ranges  # b is cut to a's ranges
    same(tdask.op(pa, pb, operation).compute(), want)
    # Same ranges: part by part without cutting.
    same(tdask.op(pa, tdask.build(b, parts=4), operation).compute(), want)


def test_translate_is_a_shuffle_equal_to_the_single_process_one(client):
    a, b = tesseral.Scene.parse(SCENE_A), tesseral.Scene.parse(SCENE_B)
    wa = a.build()
    pa = tdask.build(a, parts=4)
    for offset in [(3, -2, 5), (100, 0, -7), (-300, 513, 1)]:
        moved = tdask.translate(pa, offset)
        want = wa.translate(offset)
        ranges, trees = dask.compute(moved.ranges, moved.octrees)
        assert len(ranges) == len(trees) == 4
        end = 1 << (3 * want.depth)
        assert ranges[0][0] == 0 and ranges[-1][1] == end
        for (lo, hi), t in zip(ranges, trees):
            codes, _ = t.leaves()
            assert ((codes >= lo) & (codes < hi)).all()
        same(moved.compute(), want)
        kept = moved.persist()
        assert dask.compute(kept.ranges)[0] == ranges
        same(kept.compute(), want)
    # A translated operand in a set operation.
    moved = tdask.translate(pa, (2, 1, -1))
    same(
        tdask.op(moved, tdask.build(b, parts=3), "union").compute(),
        wa.translate((2, 1, -1)) | b.build(),
    )
    same(
        tdask.op(tdask.build(b, parts=3), moved, "difference").compute(),
        b.build() - wa.translate((2, 1, -1)),
    )


def test_write_and_read_round_trip(client, tmp_path):
    scene = tesseral.Scene.parse(SCENE_A)
    parts = tdask.build(scene, parts=4)
    manifest = tdask.write(parts, tmp_path / "ds")
    assert [(p["lo"], p["hi"]) for p in manifest["parts"]] == parts.ranges
    want = scene.build()
    assert sum(p["voxels"] for p in manifest["parts"]) == want.voxel_count
    assert manifest["voxel_size"] == want.frame["voxel_size"]
    back = tdask.read(tmp_path / "ds")
    assert back.ranges == parts.ranges
    assert back.space == (want.depth, want.origin)
    same(back.compute(), want)
    same(tesseral.Octree.read(tmp_path / "ds"), want)  # the dataset as one model
    with pytest.raises(FileExistsError):
        tdask.write(parts, tmp_path / "ds")
    # A translated dataset written over it and read back.
    moved = tdask.translate(back, (5, 0, -3))
    tdask.write(moved, tmp_path / "ds", overwrite=True)
    same(tdask.read(tmp_path / "ds").compute(), want.translate((5, 0, -3)))
    same(tesseral.Octree.read(tmp_path / "ds"), want.translate((5, 0, -3)))
    # Damage is named.
    part = tmp_path / "ds" / "part-00001.tess"
    data = bytearray(part.read_bytes())
    data[len(data) // 2] ^= 1
    part.write_bytes(bytes(data))
    with pytest.raises(tesseral.FormatError, match="part-00001.tess"):
        tdask.read(tmp_path / "ds").compute()


def test_the_dataset_is_the_one_the_cli_writes(client, tmp_path):
    exe = ROOT / "target" / "release" / "tesseral"
    if not exe.exists():
        pytest.skip("the tesseral binary is not built (cargo build --release)")
    scene = ROOT / "scenes" / "tank.tss"
    cli = tmp_path / "cli"
    subprocess.run([str(exe), "build", str(scene), "--parts", "3", "-o", str(cli)], check=True)
    ours = tmp_path / "ours"
    tdask.write(tdask.build(scene, parts=3), ours)
    names = sorted(os.listdir(cli))
    assert names == sorted(os.listdir(ours))
    # The same ranges and counts, and part by part the same voxels and colours.
    mine = json.loads((ours / "manifest.json").read_text())
    theirs = json.loads((cli / "manifest.json").read_text())
    keys = ("lo", "hi", "leaves", "voxels", "file")
    assert [[p[k] for k in keys] for p in mine["parts"]] == [
        [p[k] for k in keys] for p in theirs["parts"]
    ]
    for k in ("depth", "origin", "frame"):
        assert mine[k] == theirs[k]
    # Byte for byte, colours included: the same manifests (CRC-32s too), same files.
    assert mine == theirs
    for name in names:
        assert (ours / name).read_bytes() == (cli / name).read_bytes(), name
    ours_parts = dask.compute(*tdask.read(ours).octrees)
    cli_parts = dask.compute(*tdask.read(cli).octrees)
    for x, y in zip(ours_parts, cli_parts):
        same(x, y)
    assert sum(coloured(t) for t in cli_parts) > 1000
    whole = tesseral.Scene.read(str(scene)).build()
    same(tesseral.Octree.read(cli), whole)
    same(tesseral.Octree.read(ours), whole)
    info = subprocess.run(
        [str(exe), "info", str(ours), "--json"], check=True, capture_output=True, text=True
    )
    assert str(tesseral.Scene.read(str(scene)).build().voxel_count) in info.stdout


def test_a_worker_killed_mid_run_changes_nothing(client, tmp_path):
    marker = str(tmp_path / "killed")

    def kill_once(tree):
        # The first run of this task kills its own worker process (no cleanup,
        # as a crash); the scheduler reruns it on a live worker.
        if not os.path.exists(marker):
            open(marker, "w").close()
            os.kill(os.getpid(), signal.SIGKILL)
        return tree

    a, b = tesseral.Scene.parse(SCENE_A), tesseral.Scene.parse(SCENE_B)
    pa, pb = tdask.build(a, parts=4), tdask.build(b, parts=4)
    victim = dask.delayed(kill_once)(pa.octrees[2])
    pa = tdask.Parts(pa.ranges, pa.octrees[:2] + [victim] + pa.octrees[3:], pa.space)
    workers_before = set(client.scheduler_info()["workers"])
    moved = tdask.translate(tdask.op(pa, pb, "union"), (7, -3, 2))
    got = moved.compute()
    assert os.path.exists(marker)  # the worker was killed
    same(got, (a.build() | b.build()).translate((7, -3, 2)))
    client.wait_for_workers(2)
    assert set(client.scheduler_info()["workers"]) != workers_before


def test_bad_arguments_are_named():
    scene = tesseral.Scene.parse(SCENE_A)
    with pytest.raises(ValueError, match="parts"):
        tdask.build(scene, parts=0)
    p = tdask.build(scene, parts=2)
    with pytest.raises(ValueError, match="operation"):
        tdask.op(p, p, "sum")
    with pytest.raises(ValueError, match="offset"):
        tdask.translate(p, (1, 2))
    # The same bounds at depth 6: voxels twice the size, another frame.
    other = tdask.build(tesseral.Scene.parse("depth 6\n" + BOUNDS + "sphere(r = 9) at [9, 9, 9]\n"), parts=2)
    with pytest.raises(tesseral.OctreeError, match="different frames"):
        tdask.op(p, other, "union", scheduler="sync").compute(scheduler="sync")
    with pytest.raises(OSError, match="manifest.json"):
        tdask.read(ROOT / "scenes")


def test_without_dask_the_error_says_what_to_install():
    code = (
        "import sys; sys.modules['dask'] = None\n"
        "import tesseral\n"
        "try:\n"
        "    import tesseral.dask\n"
        "except ImportError as e:\n"
        "    assert 'pip install' in str(e), e\n"
        "else:\n"
        "    raise SystemExit('imported without dask')\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("operation", tdask.OPERATIONS)
def test_operands_in_different_spaces_meet_in_the_whole_tree_space(client, tmp_path, operation):
    scene = tesseral.Scene.read(str(ROOT / "scenes" / "tank.tss"))
    whole = scene.build(6)
    tdask.write(tdask.build(scene, 6, parts=3), tmp_path / "ds")
    parts = tdask.read(tmp_path / "ds")
    for by in [(70, 0, -9), (-5, 3, 2)]:  # the first grows the space
        moved = tdask.translate(parts, by)
        wmoved = whole.translate(by)
        assert moved.space == (wmoved.depth, wmoved.origin)
        for x, y, wx, wy in [(parts, moved, whole, wmoved), (moved, parts, wmoved, whole)]:
            want = {
                "union": wx | wy,
                "intersection": wx & wy,
                "difference": wx - wy,
                "xor": wx ^ wy,
            }[operation]
            got = tdask.op(x, y, operation)
            assert got.space == (want.depth, want.origin)
            same(got.compute(), want)
    # Parts made by hand, space and ranges unknown: computed first.
    hand = tdask.Parts(dask.delayed(list)(parts.ranges), parts.octrees)
    assert hand.space is None
    grown, wgrown = tdask.translate(parts, (70, 0, -9)), whole.translate((70, 0, -9))
    want = {
        "union": whole | wgrown,
        "intersection": whole & wgrown,
        "difference": whole - wgrown,
        "xor": whole ^ wgrown,
    }[operation]
    same(tdask.op(hand, grown, operation).compute(), want)


def test_a_translation_sends_each_part_only_where_it_can_land(client):
    scene = tesseral.Scene.parse(SCENE_A)
    k = 64
    parts = tdask.build(scene, parts=k)
    assert len(parts) == k
    want = scene.build()
    for by in [(3, -5, 7), (-37, 11, 90)]:
        moved = tdask.translate(parts, by)
        src = tdask._settled(parts)
        reach = tesseral._tesseral.partition_reach(
            src.space[0], src.space[1], src.ranges, by, moved.space[0], moved.space[1], moved.ranges
        )
        pieces = sum(len(r) for r in reach)
        # A full shuffle would make k * k = 4096 pieces; the pieces that hold
        # leaves (found here from the data) are all reached, and few more.
        trees = dask.compute(*src.octrees)
        needed = 0
        for t, r in zip(trees, reach):
            cut = tesseral._tesseral.partition_move_split(
                t, by, moved.space[0], moved.space[1], moved.ranges, False
            )
            full = [j for j, piece in enumerate(cut) if piece.leaf_count]
            assert set(full) <= set(r)
            needed += len(full)
        assert pieces <= 16 * k and pieces <= 1.5 * needed, (pieces, needed)
        graph = {}
        for d in moved.octrees:
            graph.update(dict(d.__dask_graph__()))
        # The persisted sources, one cut and a piece per reached range, the joins.
        assert len(graph) <= 3 * k + pieces, len(graph)
        same(moved.compute(), want.translate(by))


def test_overwriting_replaces_the_whole_dataset(client, tmp_path):
    a, b = tesseral.Scene.parse(SCENE_A), tesseral.Scene.parse(SCENE_B)
    ds = tmp_path / "ds"
    tdask.write(tdask.build(a, parts=6), ds)
    assert len(list(ds.glob("part-*.tess"))) == 6
    stale = tdask.read(ds)  # manifest read now, parts later
    tdask.write(tdask.build(b, parts=2), ds, overwrite=True)
    # No part of the older, larger dataset stays; nothing left beside it.
    assert sorted(os.listdir(ds)) == ["manifest.json", "part-00000.tess", "part-00001.tess"]
    assert sorted(os.listdir(tmp_path)) == ["ds"]
    same(tdask.read(ds).compute(), b.build())
    same(tesseral.Octree.read(ds), b.build())
    # Parts read against the manifest read before the overwrite: the part that
    # changed is named by the worker that loads it.
    with pytest.raises(tesseral.FormatError, match="part-0000[01].tess"):
        dask.compute(stale.octrees[0])
    with pytest.raises(OSError, match="part-00002.tess"):  # gone
        dask.compute(stale.octrees[2])
    # A failed write leaves the dataset there as it was, and no temporary folder.
    def boom(tree):
        raise RuntimeError("boom")

    bad = tdask.build(a, parts=3)
    bad = tdask.Parts(bad.ranges, bad.octrees[:2] + [dask.delayed(boom)(bad.octrees[2])], bad.space)
    with pytest.raises(RuntimeError, match="boom"):
        tdask.write(bad, ds, overwrite=True)
    assert sorted(os.listdir(tmp_path)) == ["ds"]
    same(tdask.read(ds).compute(), b.build())
    # Anything but a dataset directory (or an empty one) is refused.
    other = tmp_path / "notes"
    other.mkdir()
    (other / "readme.txt").write_text("mine")
    with pytest.raises(FileExistsError, match="readme.txt"):
        tdask.write(tdask.build(b, parts=2), other, overwrite=True)
    assert (other / "readme.txt").read_text() == "mine"
    empty = tmp_path / "empty"
    empty.mkdir()
    tdask.write(tdask.build(b, parts=2), empty)
    same(tesseral.Octree.read(empty), b.build())
    # write(compute=False): the task that writes and commits.
    task = tdask.write(tdask.build(a, parts=3), tmp_path / "later", compute=False)
    assert not (tmp_path / "later").exists()
    (manifest,) = dask.compute(task)
    assert len(manifest["parts"]) == 3
    same(tesseral.Octree.read(tmp_path / "later"), a.build())


KILLED_CLIENT = """
import os, signal, sys
import dask
import tesseral, tesseral.dask as tdask
scene = tesseral.Scene.parse(sys.argv[2])
parts = tdask.build(scene, parts=3)
def die(tree):
    os.kill(os.getpid(), signal.SIGKILL)
parts = tdask.Parts(parts.ranges, parts.octrees[:2] + [dask.delayed(die)(parts.octrees[2])], parts.space)
tdask.write(parts, sys.argv[1], scheduler="sync")
"""


def test_a_killed_clients_staged_directory_is_swept_by_the_next_write(client, tmp_path):
    ds = tmp_path / "ds"
    # A client killed (SIGKILL) in the middle of its write: the write's tasks run
    # in the client (the synchronous scheduler), and the last one kills it.
    out = subprocess.run(
        [sys.executable, "-c", KILLED_CLIENT, str(ds), SCENE_A], capture_output=True, text=True
    )
    assert out.returncode == -signal.SIGKILL, out.stderr
    (left,) = [n for n in os.listdir(tmp_path) if n.startswith(".ds.") and n.endswith(".tmp")]
    assert ".tesseral-staged" in os.listdir(tmp_path / left)
    assert not ds.exists()
    # A staged directory of a live writer (this process) is kept.
    live = os.fspath(tesseral._tesseral.staged_create(ds))
    b = tesseral.Scene.parse(SCENE_B)
    tdask.write(tdask.build(b, parts=2), ds)
    staged = sorted(n for n in os.listdir(tmp_path) if n != "ds")
    assert staged == [os.path.basename(live)]
    assert sorted(os.listdir(ds)) == ["manifest.json", "part-00000.tess", "part-00001.tess"]
    same(tdask.read(ds).compute(), b.build())
    shutil.rmtree(live)
