"""tesseral.dask on a real cluster: a dask.distributed LocalCluster (its own
scheduler, two worker processes with one thread each). Every partitioned result
is held against the single-process one, voxel for voxel."""

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
SCENE_A = (
    "depth 7\n" + BOUNDS + "difference { sphere(r = 24) sphere(r = 10) } at [30, 33, 31]\n"
    "box(size = [50, 8, 6]) rotate [10, 20, 30] at [32, 20, 40]\n"
)
SCENE_B = (
    "depth 7\n" + BOUNDS + "cylinder(r = 9, h = 50) rotate [0, 35, 0] at [36, 36, 30]\n"
    "sphere(r = 12) at [14, 50, 18]\n"
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


def same(got, want):
    """Voxel for voxel: the same space, leaves and voxels as the single-process
    result."""
    assert isinstance(got, tesseral.Octree)
    assert (got.depth, got.origin) == (want.depth, want.origin)
    assert got.voxel_count == want.voxel_count
    assert got.leaf_count == want.leaf_count
    assert np.array_equal(got.voxels(), want.voxels())
    assert got == want


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
    trees = dask.compute(*parts.octrees)
    for (lo, hi), t in zip(parts.ranges, trees):
        codes, _ = t.leaves()
        assert ((codes >= lo) & (codes < hi)).all()
    want = scene.build(7)
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
    # A translated operand (ranges from a task) in a set operation.
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
    same(back.compute(), want)
    with pytest.raises(FileExistsError):
        tdask.write(parts, tmp_path / "ds")
    # A translated dataset (ranges from a task) written and read back.
    moved = tdask.translate(back, (5, 0, -3))
    tdask.write(moved, tmp_path / "ds", overwrite=True)
    same(tdask.read(tmp_path / "ds").compute(), want.translate((5, 0, -3)))
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
    # The same ranges, counts and voxels part by part (the CLI's parts also hold the
    # scene's colours, which the Dask build does not carry, so the bytes differ).
    mine = json.loads((ours / "manifest.json").read_text())
    theirs = json.loads((cli / "manifest.json").read_text())
    keys = ("lo", "hi", "leaves", "voxels", "file")
    assert [[p[k] for k in keys] for p in mine["parts"]] == [
        [p[k] for k in keys] for p in theirs["parts"]
    ]
    assert tdask.read(ours).compute() == tdask.read(cli).compute()
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
    pa = tdask.Parts(pa.ranges, pa.octrees[:2] + [victim] + pa.octrees[3:])
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
    other = tdask.build(tesseral.Scene.parse("depth 6\n" + BOUNDS + "sphere(r = 9) at [9, 9, 9]\n"), parts=2)
    with pytest.raises(tesseral.OctreeError, match="different spaces"):
        tdask.op(p, other, "union").compute(scheduler="sync")
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
