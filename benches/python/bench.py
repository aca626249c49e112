"""Python against Rust on the same work, in one run (issue 14 §4).

    python benches/python/bench.py            # after `pip install ./python`

Writes the voxels to temporary files, runs the Rust example `python_baseline` on them
(built with cargo), then times the Python calls on the same arrays, best of 5 each,
and prints the ratios. Single-threaded parts are compared as they run; the
rayon-parallel ones (from_voxels) run with the same thread count on both sides.
"""

import os
import pathlib
import subprocess
import tempfile
import time

import numpy as np

import tesseral as t

ROOT = pathlib.Path(__file__).resolve().parents[2]


def best(f):
    out = []
    for _ in range(5):
        s = time.perf_counter()
        f()
        out.append((time.perf_counter() - s) * 1e3)
    return min(out)


def main():
    rng = np.random.default_rng(14)
    dynamic = rng.integers(-2000, 2000, size=(1_000_000, 3), dtype=np.int64)
    # A solid ball of about 4 M voxels.
    r = 99
    g = np.mgrid[-r - 1 : r + 1, -r - 1 : r + 1, -r - 1 : r + 1].reshape(3, -1).T.astype(np.int64)
    solid = np.ascontiguousarray(g[((2 * g + 1) ** 2).sum(axis=1) <= 4 * r * r])
    with tempfile.TemporaryDirectory() as d:
        a, b = os.path.join(d, "dynamic.bin"), os.path.join(d, "solid.bin")
        dynamic.tofile(a)
        solid.tofile(b)
        subprocess.run(
            ["cargo", "build", "--release", "-q", "-p", "tesseral", "--example", "python_baseline"],
            cwd=ROOT, check=True)
        out = subprocess.run(
            [str(ROOT / "target/release/examples/python_baseline"), a, b],
            check=True, capture_output=True, text=True).stdout
    rust = {k: float(v) for k, v in (line.split() for line in out.splitlines())}

    def insert():
        d = t.DynamicOctree()
        d.insert(dynamic)

    tree = t.Octree.from_voxels(solid)
    other = tree.translate((7, 3, 1))
    py = {
        "dynamic_insert": best(insert),
        "from_voxels": best(lambda: t.Octree.from_voxels(solid)),
        "voxels": best(tree.voxels),
        "union": best(lambda: tree | other),
    }
    copy = best(lambda: solid.copy())
    print(f"{len(dynamic):,} dynamic voxels, a ball of {len(solid):,} voxels ({tree.leaf_count:,} leaves)")
    print(f"{'measure':<16} {'rust ms':>9} {'python ms':>10} {'python/rust':>12}")
    for k in py:
        print(f"{k:<16} {rust[k]:>9.2f} {py[k]:>10.2f} {py[k] / rust[k]:>12.2f}")
    print(f"{'numpy copy':<16} {'':>9} {copy:>10.2f}   voxels() / numpy copy: {py['voxels'] / copy:.2f}")


if __name__ == "__main__":
    main()
