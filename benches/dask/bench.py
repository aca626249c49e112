"""Depth-13 build on a Dask LocalCluster of 2 workers against one process.

    target/venv/bin/python benches/dask/bench.py [--scene scenes/fig4c-spheroid.tss]
        [--depth 13] [--parts 8] [--workers 2]

Both sides run the same tasks (`tesseral.dask.write(tesseral.dask.build(scene,
depth, parts=K), dir)`: build each code range, write its .tess, then the
manifest) and must write the same dataset (the manifests, CRC-32s included, are
compared). One process: Dask's synchronous scheduler in this process, each part
built with all cores (rayon). Cluster: a LocalCluster of 1, then N, worker
processes with one thread each and RAYON_NUM_THREADS=1, started before the clock.
Also times the CLI's `tesseral build --parts K` (the same dataset, streamed, one
process) when target/release/tesseral is built. Prints the times, the speed-ups
and the load average (the machine may be shared).
"""

import argparse
import json
import os
import pathlib
import shutil
import subprocess
import tempfile
import time

import dask
import distributed

import tesseral
import tesseral.dask as tdask

ROOT = pathlib.Path(__file__).resolve().parents[2]


def run(scene, depth, parts, out, **kw):
    t0 = time.perf_counter()
    manifest = tdask.write(tdask.build(scene, depth, parts=parts), out, **kw)
    return time.perf_counter() - t0, manifest


def shuffle(tmp, leaves, workers):
    """Reads the one-process dataset back and times, in one process and on the
    LocalCluster: translate by an offset aligned to nothing (every leaf moves to
    another range) then write; union of the dataset with that translation then
    write."""
    by = (1001, -7, 333)
    for label, kw, cluster in [
        ("one process", {"scheduler": "sync"}, None),
        (f"LocalCluster of {workers}", {}, workers),
    ]:
        ctx = (
            distributed.LocalCluster(
                n_workers=cluster,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                env={"RAYON_NUM_THREADS": "1"},
            )
            if cluster
            else None
        )
        client = distributed.Client(ctx) if ctx else None
        try:
            src = tdask.read(tmp / "one")
            t0 = time.perf_counter()
            m = tdask.write(tdask.translate(src, by, **kw), tmp / f"moved-{cluster}", **kw)
            t1 = time.perf_counter()
            n = sum(p["leaves"] for p in m["parts"])
            print(f"{label}: translate {leaves:,} leaves by {by} -> {n:,}: {t1 - t0:.2f} s ({leaves / (t1 - t0) / 1e6:.2f} M leaves/s in)")
            moved = tdask.read(tmp / f"moved-{cluster}")
            src = tdask.read(tmp / "one")
            t0 = time.perf_counter()
            m = tdask.write(tdask.op(src, moved, "union", **kw), tmp / f"union-{cluster}", **kw)
            t1 = time.perf_counter()
            u = sum(p["leaves"] for p in m["parts"])
            print(f"{label}: union of {leaves:,} and {n:,} leaves -> {u:,}: {t1 - t0:.2f} s ({(leaves + n) / (t1 - t0) / 1e6:.2f} M leaves/s in)")
            print(f"load average: {os.getloadavg()}")
        finally:
            if client:
                client.close()
                ctx.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default=str(ROOT / "scenes" / "fig4c-spheroid.tss"))
    ap.add_argument("--depth", type=int, default=13)
    ap.add_argument("--parts", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument(
        "--shuffle",
        action="store_true",
        help="also time translate (a shuffle) and union of the dataset, for the per-part rates",
    )
    a = ap.parse_args()
    scene = tesseral.Scene.read(a.scene)
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="tesseral-dask-bench-"))
    try:
        print(f"scene {a.scene}, depth {a.depth}, {a.parts} parts, cores {os.cpu_count()}")
        print(f"load average before: {os.getloadavg()}")
        one, m1 = run(scene, a.depth, a.parts, tmp / "one", scheduler="sync")
        leaves = sum(p["leaves"] for p in m1["parts"])
        print(f"one process:  {one:8.2f} s  ({leaves:,} leaves, {leaves / one / 1e6:.2f} M leaves/s)")
        print(f"load average: {os.getloadavg()}")
        exe = ROOT / "target" / "release" / "tesseral"
        if exe.exists():
            # The peer: the CLI's streamed `build --parts`, which writes the same
            # dataset (colours included), in one process with all cores.
            t0 = time.perf_counter()
            subprocess.run(
                [str(exe), "build", a.scene, "--depth", str(a.depth), "--parts", str(a.parts),
                 "-o", str(tmp / "cli")],
                check=True,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
            cli = time.perf_counter() - t0
            same = json.loads((tmp / "cli" / "manifest.json").read_text())["parts"] == m1["parts"]
            print(f"CLI build --parts {a.parts}: {cli:8.2f} s  (same dataset: {same})")
            print(f"load average: {os.getloadavg()}")
        if a.shuffle:
            shuffle(tmp, leaves, a.workers)
        times = {}
        for n in sorted({1, a.workers}):
            with distributed.LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                env={"RAYON_NUM_THREADS": "1"},
            ) as cluster, distributed.Client(cluster):
                t, m = run(scene, a.depth, a.parts, tmp / f"cluster{n}")
            assert m == m1, "the runs wrote different datasets"
            times[n] = t
            print(f"LocalCluster ({n} worker(s) x 1 thread): {t:8.2f} s  ({leaves / t / 1e6:.2f} M leaves/s)")
            print(f"load average: {os.getloadavg()}")
        per_part = [p["leaves"] for p in m1["parts"]]
        print(f"leaves per part: min {min(per_part):,}, max {max(per_part):,}")
        two = times[a.workers]
        print(f"speed-up, one process / LocalCluster of {a.workers}: {one / two:.2f}x")
        if a.workers != 1:
            print(f"speed-up, LocalCluster of 1 / of {a.workers}: {times[1] / two:.2f}x")
    finally:
        shutil.rmtree(tmp)


if __name__ == "__main__":
    main()
