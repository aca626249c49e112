"""Partitioned octrees on Dask: builds, set operations and translations cut by
code range, run as Dask tasks on any `dask.distributed` cluster (or Dask's local
schedulers).

A linear octree is a list of leaves sorted in tesseral (Morton) order; cut into code
ranges [lo, hi) it becomes independent parts whose union is the whole. `Parts` holds
such a cut as Dask tasks: ``parts.octrees[i]`` (a ``dask.delayed`` object) computes
to part i, an `Octree` in the whole space holding the leaves of the code range
``parts.ranges[i]``.

- `build(scene, depth, parts=K)`: one task per range, ranges balanced by sampling
  the scene's classifier (those of ``tesseral build --parts K``);
- `op(a, b, "union")` (also "intersection", "difference", "xor"): part by part,
  after cutting ``b`` to ``a``'s ranges;
- `translate(parts, offset)`: a shuffle between ranges: each part is moved into the
  result's space and cut by the result's ranges, and the pieces of each range are
  joined;
- `write(parts, dir)` / `read(dir)`: a dataset directory (``manifest.json`` and one
  ``.tess`` per part), the one ``tesseral build --parts`` writes and every
  ``tesseral`` command reads.

The Dask scheduler places, moves and retries the tasks; parts travel between
workers pickled as ``.tess`` bytes. Datasets are read and written by the workers,
so on a cluster the directory must be on a file system that they all see.
"""

from __future__ import annotations

import os
from typing import Any, Iterable, List, Sequence, Tuple, Union

try:
    import dask
    from dask.delayed import Delayed
    from dask.sizeof import sizeof as _sizeof
except ImportError as _e:  # pragma: no cover - exercised only without Dask
    raise ImportError(
        "tesseral.dask needs Dask: pip install 'tesseral[dask]' "
        "(or pip install 'dask[distributed]')"
    ) from _e

from . import _tesseral as _ext
from ._tesseral import Octree, Scene

__all__ = ["Parts", "build", "op", "translate", "write", "read", "OPERATIONS"]

#: The set operations `op` accepts.
OPERATIONS = ("union", "intersection", "difference", "xor")

#: Leaves sampled per part to balance the ranges of a translation.
SAMPLE_PER_PART = 4096

Range = Tuple[int, int]


@_sizeof.register(Octree)
def _sizeof_octree(tree: Octree) -> int:
    # Dask's memory accounting: 8 bytes a leaf plus the object.
    return 8 * tree.leaf_count + 256


class Parts:
    """A partitioned octree as Dask tasks.

    ``octrees``: one ``dask.delayed`` per part, each computing to an `Octree` in
    the whole space whose leaves lie in its range. ``ranges``: the code ranges
    [lo, hi) of the parts, tiling the space in order: a list of ``(lo, hi)`` pairs,
    or, after `translate` (whose ranges depend on where the leaves land), a
    ``dask.delayed`` computing to one.
    """

    def __init__(self, ranges: Union[List[Range], Delayed], octrees: Iterable[Delayed]):
        self.octrees: List[Delayed] = list(octrees)
        if not self.octrees:
            raise ValueError("Parts needs at least one part")
        if isinstance(ranges, Delayed):
            self.ranges: Union[List[Range], Delayed] = ranges
        else:
            self.ranges = [(int(lo), int(hi)) for lo, hi in ranges]
            if len(self.ranges) != len(self.octrees):
                raise ValueError(
                    f"{len(self.ranges)} ranges for {len(self.octrees)} parts"
                )

    def __len__(self) -> int:
        return len(self.octrees)

    def __repr__(self) -> str:
        known = "known" if isinstance(self.ranges, list) else "computed by a task"
        return f"Parts({len(self)} parts, ranges {known})"

    def to_delayed(self) -> List[Delayed]:
        """The per-part tasks."""
        return list(self.octrees)

    def concat(self) -> Delayed:
        """A task joining the parts into one `Octree` (on one worker: for results
        that fit one machine)."""
        return dask.delayed(_join, pure=True)(*self.octrees)

    def compute(self, **kwargs: Any) -> Octree:
        """The whole octree: `concat` computed (keyword arguments go to
        ``dask.compute``)."""
        (tree,) = dask.compute(self.concat(), **kwargs)
        return tree

    def persist(self, **kwargs: Any) -> "Parts":
        """The same parts with their tasks computed and kept in (cluster) memory."""
        ranges = self.ranges
        if isinstance(ranges, Delayed):
            ranges, *octrees = dask.persist(ranges, *self.octrees, **kwargs)
        else:
            octrees = dask.persist(*self.octrees, **kwargs)
        return Parts(ranges, octrees)


# Task functions: module-level, so that workers import them by name.


def _build_part(scene: Scene, depth: int, lo: int, hi: int) -> Octree:
    return _ext.partition_build_range(scene, depth, lo, hi)


def _join(*pieces: Octree) -> Octree:
    return _ext.partition_join(list(pieces))


def _op_pieces(a: Octree, kind: str, *pieces: Octree) -> Octree:
    for p in pieces:
        _same_space(p, (a.depth, a.origin))
    return _ext.partition_set_op(a, _ext.partition_join(list(pieces)), kind)


def _same_space(tree: Octree, space) -> None:
    depth, origin = space
    if (tree.depth, tuple(tree.origin)) != (depth, tuple(origin)):
        raise _ext.OctreeError(
            f"the operands are in different spaces (depth {depth} origin {tuple(origin)}, "
            f"depth {tree.depth} origin {tuple(tree.origin)}): combine them whole, or "
            "build both in one space"
        )


def _clip(tree: Octree, lo: int, hi: int, space) -> Octree:
    _same_space(tree, space)
    end = 1 << (3 * tree.depth)
    if hi > end:
        raise _ext.OctreeError(
            f"the operands are in different spaces: the code range [{lo}, {hi}) of the "
            f"first lies outside the second's space (depth {tree.depth})"
        )
    cuts = sorted({0, lo, hi, end})
    ranges = list(zip(cuts, cuts[1:]))
    return _ext.partition_split(tree, ranges)[ranges.index((lo, hi))]


def _split(tree: Octree, ranges: Sequence[Range], space=None) -> List[Octree]:
    if space is not None:
        _same_space(tree, space)
    return _ext.partition_split(tree, list(ranges))


def _bbox(tree: Octree):
    return tree.bbox


def _space(tree: Octree):
    return tree.depth, tree.origin


def _translated_space(space, offset, *bboxes):
    depth, origin = space
    return _ext.partition_translated_space(depth, origin, list(bboxes), offset)


def _sample(tree: Octree, offset, space):
    depth, origin = space
    return _ext.partition_translated_sample(tree, offset, depth, origin, SAMPLE_PER_PART)


def _balanced(space, k: int, *samples):
    import numpy as np

    depth, _ = space
    codes = np.sort(np.concatenate(samples)) if samples else np.zeros(0, np.uint64)
    ranges = _ext.partition_balanced_ranges(depth, k, codes.astype(np.uint64))
    if len(ranges) != k:
        raise ValueError(f"the space of depth {depth} has fewer than {k} codes")
    return ranges


def _translate_split(tree: Octree, offset, space, ranges) -> List[Octree]:
    depth, origin = space
    return _ext.partition_translate_split(tree, offset, depth, origin, list(ranges))


def _write_part(path: str, i: int, ranges, tree: Octree) -> dict:
    lo, hi = ranges[i]
    entry = _ext.partition_write_part(path, i, lo, hi, tree)
    frame = tree.frame
    entry.update(
        depth=tree.depth,
        origin=tree.origin,
        voxel_size=frame["voxel_size"],
        translate=frame["translate"],
    )
    return entry


def _write_manifest(path: str, *entries: dict) -> dict:
    first = entries[0]
    for e in entries[1:]:
        for key in ("depth", "origin", "voxel_size", "translate"):
            if e[key] != first[key]:
                raise ValueError(
                    f"part {e['file']} has {key} {e[key]!r}, part {first['file']} {first[key]!r}"
                )
    _ext.partition_write_manifest(
        path,
        first["depth"],
        first["origin"],
        first["voxel_size"],
        first["translate"],
        list(entries),
    )
    return _ext.partition_read_manifest(path)


def _read_part(path: str, i: int) -> Octree:
    return _ext.partition_read_part(path, i)


# The public API.


def build(scene: Union[Scene, str, "os.PathLike[str]"], depth: Union[int, None] = None, parts: int = 8) -> Parts:
    """The scene (a `Scene` or a ``.tss`` path) built at ``depth`` (default: the
    scene's) as ``parts`` Dask tasks, one per code range; the ranges, of about
    equal work, are those of ``tesseral build --parts``. Nothing runs until the
    parts are computed or written. The parts carry the scene's frame, not its
    colours (as streamed builds)."""
    if not isinstance(scene, Scene):
        scene = Scene.read(os.fspath(scene))
    if not isinstance(parts, int) or parts < 1:
        raise ValueError(f"parts={parts!r}: expected a positive integer")
    ranges = _ext.partition_scene_ranges(scene, depth, parts)
    s = dask.delayed(scene)
    octrees = [dask.delayed(_build_part)(s, depth, lo, hi) for lo, hi in ranges]
    return Parts(ranges, octrees)


def _overlaps(a: Range, b: Range) -> bool:
    return a[0] < b[1] and b[0] < a[1]


def op(a: Parts, b: Parts, operation: str = "union") -> Parts:
    """The set operation ``operation`` ("union", "intersection", "difference" or
    "xor") of two partitioned octrees of one space and frame, part by part on
    ``a``'s ranges: ``b`` is first cut to them (each piece of ``b`` goes to the
    part of ``a`` that it meets)."""
    if operation not in OPERATIONS:
        raise ValueError(f"operation {operation!r}: expected one of {', '.join(OPERATIONS)}")
    known = isinstance(a.ranges, list) and isinstance(b.ranges, list)
    space = dask.delayed(_space)(a.octrees[0])
    if known and a.ranges == b.ranges:
        out = [
            dask.delayed(_op_pieces)(x, operation, y)
            for x, y in zip(a.octrees, b.octrees)
        ]
        return Parts(a.ranges, out)
    out = []
    if known:
        # Cut only the parts of b that meet each range of a.
        for j, r in enumerate(a.ranges):
            pieces = [
                dask.delayed(_clip)(bt, r[0], r[1], space)
                for q, bt in zip(b.ranges, b.octrees)
                if _overlaps(q, r)
            ]
            out.append(dask.delayed(_op_pieces)(a.octrees[j], operation, *pieces))
    else:
        # a's ranges are a task: a full shuffle of b to them.
        k = len(a)
        cut = [dask.delayed(_split, nout=k)(bt, a.ranges, space) for bt in b.octrees]
        for j in range(k):
            pieces = [c[j] for c in cut]
            out.append(dask.delayed(_op_pieces)(a.octrees[j], operation, *pieces))
    return Parts(a.ranges, out)


def translate(parts: Parts, offset: Tuple[int, int, int]) -> Parts:
    """The partitioned octree moved by ``offset`` voxels (x, y, z), as a shuffle
    between ranges, in as many parts. The result's space is the one
    `Octree.translate` gives the whole tree (grown when the moved voxels leave it);
    its ranges are balanced on a sample of where the leaves land, so they come from
    a task. Each part is moved and cut by the new ranges, and each new part joins
    the pieces that land in its range."""
    by = tuple(int(c) for c in offset)
    if len(by) != 3:
        raise ValueError(f"offset {offset!r}: expected three integers (x, y, z)")
    k = len(parts)
    bboxes = [dask.delayed(_bbox)(t) for t in parts.octrees]
    space0 = dask.delayed(_space)(parts.octrees[0])
    space = dask.delayed(_translated_space)(space0, by, *bboxes)
    samples = [dask.delayed(_sample)(t, by, space) for t in parts.octrees]
    ranges = dask.delayed(_balanced)(space, k, *samples)
    cut = [
        dask.delayed(_translate_split, nout=k)(t, by, space, ranges)
        for t in parts.octrees
    ]
    out = [dask.delayed(_join)(*[c[j] for c in cut]) for j in range(k)]
    return Parts(ranges, out)


def write(parts: Parts, path: Union[str, "os.PathLike[str]"], overwrite: bool = False, compute: bool = True, **compute_kwargs: Any):
    """Writes the parts as a dataset in the directory ``path`` (created if
    missing): one ``.tess`` per part, written by the worker that holds it, each
    atomically, then ``manifest.json`` (space, frame, ranges, counts, CRC-32s),
    last. Refuses a directory that already holds a manifest unless ``overwrite``.
    Returns the manifest as a dict, or with ``compute=False`` the task that writes
    it (keyword arguments go to ``dask.compute``)."""
    path = os.path.abspath(os.fspath(path))
    if not overwrite and os.path.exists(os.path.join(path, "manifest.json")):
        raise FileExistsError(f"{path} already holds a dataset (manifest.json); pass overwrite=True")
    entries = [
        dask.delayed(_write_part)(path, i, parts.ranges, t)
        for i, t in enumerate(parts.octrees)
    ]
    task = dask.delayed(_write_manifest)(path, *entries)
    if not compute:
        return task
    (manifest,) = dask.compute(task, **compute_kwargs)
    return manifest


def read(path: Union[str, "os.PathLike[str]"]) -> Parts:
    """A dataset directory (as `write` or ``tesseral build --parts`` write it) as
    parts: the manifest is read and checked at once, each part by a task, checked
    against the manifest (CRC-32, space, range, counts)."""
    path = os.path.abspath(os.fspath(path))
    manifest = _ext.partition_read_manifest(path)
    ranges = [(p["lo"], p["hi"]) for p in manifest["parts"]]
    octrees = [dask.delayed(_read_part)(path, i) for i in range(len(ranges))]
    return Parts(ranges, octrees)
