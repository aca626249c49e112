"""Partitioned octrees on Dask: builds, set operations and translations cut by
code range, run as Dask tasks on any `dask.distributed` cluster (or Dask's local
schedulers).

A linear octree is a list of leaves sorted in tesseral (Morton) order; cut into code
ranges [lo, hi) it becomes independent parts whose union is the whole. `Parts` holds
such a cut as Dask tasks: ``parts.octrees[i]`` (a ``dask.delayed`` object) computes
to part i, an `Octree` in the whole space ``parts.space`` holding the leaves of the
code range ``parts.ranges[i]``, with their colours.

- `build(scene, depth, parts=K)`: one task per range, ranges balanced by sampling
  the scene's classifier (those of ``tesseral build --parts K``), each part with the
  scene's frame and colours;
- `op(a, b, "union")` (also "intersection", "difference", "xor"): part by part on
  ``a``'s ranges, after cutting ``b`` to them (first operand's colour wins); operands
  in different spaces are brought into the space the whole-tree operators use;
- `translate(parts, offset)`: a shuffle between ranges: each part is moved into the
  result's space and cut by the result's ranges that its own range can reach, and
  the pieces of each range are joined;
- `write(parts, dir)` / `read(dir)`: a dataset directory (``manifest.json`` and one
  ``.tess`` per part), the one ``tesseral build --parts`` writes and every
  ``tesseral`` command (and `tesseral.Octree.read`) reads.

The Dask scheduler places, moves and retries the tasks; parts travel between
workers pickled as ``.tess`` bytes. Datasets are read and written by the workers,
so on a cluster the directory must be on a file system that they all see.
"""

from __future__ import annotations

import os
import shutil
import time
from typing import Any, Iterable, List, Optional, Sequence, Tuple, Union

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
#: A space: (depth, origin).
Space = Tuple[int, Tuple[int, int, int]]


@_sizeof.register(Octree)
def _sizeof_octree(tree: Octree) -> int:
    # Dask's memory accounting: 8 bytes a leaf plus the object.
    return 8 * tree.leaf_count + 256


def _space_of(space) -> Optional[Space]:
    if space is None:
        return None
    depth, origin = space
    return int(depth), tuple(int(c) for c in origin)


class Parts:
    """A partitioned octree as Dask tasks.

    ``octrees``: one ``dask.delayed`` per part, each computing to an `Octree` (with
    its frame and colours) in the whole space whose leaves lie in its range.
    ``ranges``: the code ranges [lo, hi) of the parts, tiling the space in order, a
    list of ``(lo, hi)`` pairs (or a ``dask.delayed`` computing to one, for parts
    made by hand). ``space``: ``(depth, origin)`` of that space, or None when not
    known before the parts are computed (then `op` and `translate` compute it).
    """

    def __init__(
        self,
        ranges: Union[List[Range], Delayed],
        octrees: Iterable[Delayed],
        space: Optional[Space] = None,
    ):
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
        self.space: Optional[Space] = _space_of(space)

    def __len__(self) -> int:
        return len(self.octrees)

    def __repr__(self) -> str:
        known = "known" if isinstance(self.ranges, list) else "computed by a task"
        return f"Parts({len(self)} parts, ranges {known}, space {self.space})"

    def to_delayed(self) -> List[Delayed]:
        """The per-part tasks."""
        return list(self.octrees)

    def concat(self) -> Delayed:
        """A task joining the parts into one `Octree` (on one worker: for results
        that fit one machine)."""
        return dask.delayed(_concat, pure=True)(*self.octrees)

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
        return Parts(ranges, octrees, self.space)


# Task functions: module-level, so that workers import them by name.


def _build_part(scene: Scene, depth: int, lo: int, hi: int) -> Octree:
    return _ext.partition_build_range(scene, depth, lo, hi)


def _frame_of(tree: Octree):
    f = tree.frame
    return f["voxel_size"], tuple(f["translate"])


def _join(space: Space, frame, *pieces: Octree) -> Octree:
    depth, origin = space
    voxel_size, translate = frame
    return _ext.partition_join(depth, origin, voxel_size, translate, list(pieces))


def _concat(*parts: Octree) -> Octree:
    first = parts[0]
    return _join((first.depth, first.origin), _frame_of(first), *parts)


def _op_pieces(a: Octree, kind: str, *pieces: Octree) -> Octree:
    if len(pieces) == 1 and (pieces[0].depth, pieces[0].origin) == (a.depth, a.origin):
        b = pieces[0]
    else:
        # The pieces of b that meet a's range (none: b is empty there).
        b = _join((a.depth, a.origin), _frame_of(a), *pieces)
    return _ext.partition_set_op(a, b, kind)


def _move_split(tree: Octree, by, space: Space, ranges, drop: bool) -> List[Octree]:
    depth, origin = space
    return _ext.partition_move_split(tree, by, depth, origin, list(ranges), drop)


def _bbox(tree: Octree):
    return tree.bbox


def _space(tree: Octree) -> Space:
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


def _write_part(path: str, i: int, ranges, tree: Octree) -> dict:
    lo, hi = ranges[i]
    entry = _ext.partition_write_part(path, i, lo, hi, tree)
    voxel_size, translate = _frame_of(tree)
    entry.update(
        depth=tree.depth,
        origin=tree.origin,
        voxel_size=voxel_size,
        translate=translate,
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


def _replaceable(path: str) -> None:
    """Refuses to replace anything but a dataset directory or an empty one."""
    if not os.path.isdir(path) or os.path.islink(path):
        raise FileExistsError(f"{path} exists and is not a dataset directory")
    foreign = [
        n for n in os.listdir(path) if n != "manifest.json" and not n.endswith(".tess")
    ]
    if foreign:
        raise FileExistsError(
            f"{path} holds files that are not a dataset's ({', '.join(sorted(foreign)[:3])}): "
            "not replacing it"
        )


def _check_target(path: str, overwrite: bool) -> None:
    if not os.path.lexists(path):
        return
    if os.path.isdir(path) and not os.path.islink(path) and not os.listdir(path):
        return  # an empty directory
    if not overwrite:
        raise FileExistsError(
            f"{path} already exists (a dataset holds manifest.json); pass overwrite=True"
        )
    _replaceable(path)


def _commit(tmp: str, path: str, overwrite: bool, manifest: dict) -> dict:
    """Moves the dataset written in ``tmp`` to ``path``: renamed into place, an old
    dataset there renamed aside first and removed after, so no part of it stays
    (the library's ``io::commit_staged``, which ``tesseral build --parts`` uses)."""
    if not os.path.exists(tmp) and os.path.exists(os.path.join(path, "manifest.json")):
        # A rerun of this task after its first run committed.
        if _ext.partition_read_manifest(path) == manifest:
            return manifest
    _check_target(path, overwrite)
    if os.path.isdir(path) and not os.listdir(path):
        os.rmdir(path)
    _ext.staged_commit(tmp, path)
    return manifest


def _read_part(path: str, space: Space, frame, entry: dict) -> Octree:
    depth, origin = space
    voxel_size, translate = frame
    return _ext.partition_read_part(path, depth, origin, voxel_size, translate, entry)


# Graph helpers (on the client).


def _settled(parts: Parts, **compute_kwargs: Any) -> Parts:
    """``parts`` with known ranges and space: as they are when known, else
    persisted and the two computed."""
    if isinstance(parts.ranges, list) and parts.space is not None:
        return parts
    kept = parts.persist(**compute_kwargs)
    ranges, space = dask.compute(
        kept.ranges, dask.delayed(_space)(kept.octrees[0]), **compute_kwargs
    )
    return Parts(ranges, kept.octrees, space)


def _shuffle(parts: Parts, by, space: Space, ranges: List[Range], drop: bool) -> List[List[Delayed]]:
    """The pieces of ``parts`` (known ranges and space) moved by ``by`` into
    ``space`` and cut by its ``ranges``, gathered per range. Each part goes only to
    the ranges that its own range can reach (`partition_reach`, from the ranges
    alone), so the graph holds O(K · overlap) pieces, not K²."""
    src_depth, src_origin = parts.space
    dst_depth, dst_origin = space
    reach = _ext.partition_reach(
        src_depth, src_origin, parts.ranges, by, dst_depth, dst_origin, ranges
    )
    same = tuple(by) == (0, 0, 0) and parts.space == space
    incoming: List[List[Delayed]] = [[] for _ in ranges]
    for t, (lo, hi), js in zip(parts.octrees, parts.ranges, reach):
        if not js:
            continue
        if same and len(js) == 1 and ranges[js[0]][0] <= lo and hi <= ranges[js[0]][1]:
            incoming[js[0]].append(t)  # the whole part lies in one range
            continue
        cut = dask.delayed(_move_split, nout=len(js))(
            t, by, space, [ranges[j] for j in js], drop
        )
        for n, j in enumerate(js):
            incoming[j].append(cut[n])
    return incoming


# The public API.


def build(scene: Union[Scene, str, "os.PathLike[str]"], depth: Union[int, None] = None, parts: int = 8) -> Parts:
    """The scene (a `Scene` or a ``.tss`` path) built at ``depth`` (default: the
    scene's) as ``parts`` Dask tasks, one per code range; the ranges, of about
    equal work, are those of ``tesseral build --parts``. Nothing runs until the
    parts are computed or written. Each part carries the scene's frame and its
    colours on the part's voxels (those the CLI's dataset parts hold)."""
    if not isinstance(scene, Scene):
        scene = Scene.read(os.fspath(scene))
    if not isinstance(parts, int) or not 1 <= parts <= 65536:
        raise ValueError(f"parts={parts!r}: expected a number of parts from 1 to 65536")
    ranges = _ext.partition_scene_ranges(scene, depth, parts)
    s = dask.delayed(scene)
    octrees = [dask.delayed(_build_part)(s, depth, lo, hi) for lo, hi in ranges]
    return Parts(ranges, octrees, (scene.depth if depth is None else depth, (0, 0, 0)))


def op(a: Parts, b: Parts, operation: str = "union", **compute_kwargs: Any) -> Parts:
    """The set operation ``operation`` ("union", "intersection", "difference" or
    "xor") of two partitioned octrees of one frame, part by part on ``a``'s ranges:
    each part of ``b`` is cut to the ranges of ``a`` that it meets. Colours: the
    first operand's where it has one, else the second's (as the whole-tree
    operators).

    Operands in different spaces are brought into the space the whole-tree
    operators use: ``a``'s, grown (root expansion) to hold ``b``'s voxels for
    "union" and "xor" (``b``'s voxels outside it are dropped for the other two).
    Learning how far ``b`` reaches then computes ``b`` (persisted, so it is not
    computed twice); so do parts whose ranges or space are not known. Keyword
    arguments go to ``dask.persist``/``dask.compute`` there."""
    if operation not in OPERATIONS:
        raise ValueError(f"operation {operation!r}: expected one of {', '.join(OPERATIONS)}")
    a, b = _settled(a, **compute_kwargs), _settled(b, **compute_kwargs)
    target = a.space
    if b.space != a.space and operation in ("union", "xor"):
        b = b.persist(**compute_kwargs)
        bboxes = dask.compute(*[dask.delayed(_bbox)(t) for t in b.octrees], **compute_kwargs)
        depth, origin = a.space
        target = _space_of(
            _ext.partition_translated_space(depth, origin, list(bboxes), (0, 0, 0))
        )
    if target != a.space:
        # a's space is one aligned cell of the grown one: each part keeps its
        # leaves' order, so it is re-expressed where it is.
        depth, origin = a.space
        ranges = _ext.partition_embedded_ranges(depth, origin, a.ranges, target[0], target[1])
        octrees = [
            dask.delayed(_move_split, nout=1)(t, (0, 0, 0), target, [r], False)[0]
            for t, r in zip(a.octrees, ranges)
        ]
        a = Parts(ranges, octrees, target)
    if b.space == a.space and b.ranges == a.ranges:
        out = [
            dask.delayed(_op_pieces)(x, operation, y)
            for x, y in zip(a.octrees, b.octrees)
        ]
    else:
        incoming = _shuffle(b, (0, 0, 0), a.space, a.ranges, drop=True)
        out = [
            dask.delayed(_op_pieces)(x, operation, *pieces)
            for x, pieces in zip(a.octrees, incoming)
        ]
    return Parts(a.ranges, out, a.space)


def translate(parts: Parts, offset: Tuple[int, int, int], **compute_kwargs: Any) -> Parts:
    """The partitioned octree moved by ``offset`` voxels (x, y, z), colours with
    it, as a shuffle between ranges, in as many parts. The result's space is the
    one `Octree.translate` gives the whole tree (grown when the moved voxels leave
    it); its ranges are balanced on a sample of where the leaves land.

    Finding those ranges computes the parts first (persisted: kept in cluster
    memory for the shuffle, not computed twice; keyword arguments go to
    ``dask.persist``/``dask.compute``), so `translate` returns once the input is
    computed, with the result's ranges known. Each part is then moved and cut only
    by the new ranges that its own range can reach (found from the ranges, not the
    leaves), and each new part joins the pieces that land in its range."""
    by = tuple(int(c) for c in offset)
    if len(by) != 3:
        raise ValueError(f"offset {offset!r}: expected three integers (x, y, z)")
    if not all(-(2**63) <= c < 2**63 for c in by):
        raise ValueError(f"offset {offset!r}: each of x, y, z must lie in int64 "
                         "(-2**63 to 2**63 - 1)")
    kept = parts.persist(**compute_kwargs)
    k = len(kept)
    first = kept.octrees[0]
    space0 = kept.space if kept.space is not None else dask.delayed(_space)(first)
    bboxes = [dask.delayed(_bbox)(t) for t in kept.octrees]
    space = dask.delayed(_translated_space)(space0, by, *bboxes)
    samples = [dask.delayed(_sample)(t, by, space) for t in kept.octrees]
    ranges = dask.delayed(_balanced)(space, k, *samples)
    src_ranges, src_space, space, ranges, frame = dask.compute(
        kept.ranges, space0, space, ranges, dask.delayed(_frame_of)(first), **compute_kwargs
    )
    src = Parts(src_ranges, kept.octrees, src_space)
    space = _space_of(space)
    ranges = [(int(lo), int(hi)) for lo, hi in ranges]
    incoming = _shuffle(src, by, space, ranges, drop=False)
    out = [dask.delayed(_join)(space, frame, *pieces) for pieces in incoming]
    return Parts(ranges, out, space)


def write(parts: Parts, path: Union[str, "os.PathLike[str]"], overwrite: bool = False, compute: bool = True, **compute_kwargs: Any):
    """Writes the parts as a dataset in the directory ``path``: one ``.tess`` per
    part (with its colours), written by the worker that holds it, then
    ``manifest.json`` (space, frame, ranges, counts, CRC-32s), all in a new
    directory beside ``path`` (``.NAME.XXXXXX.tmp``, with a marker naming this
    client, made and renamed by the same library code as ``tesseral build
    --parts``) that is then renamed into place. So a reader sees the
    old dataset or the new one, never a mixture, and no part of an old dataset
    stays. Refuses an existing ``path`` (other than an empty directory) unless
    ``overwrite``, and even then anything but a dataset directory. The workers
    write, so on a cluster ``path`` must be on a file system that they all see. A
    client killed mid-write leaves its directory; the next ``write`` to ``path``
    from the same host removes it (a writer on another host, or still running, is
    left alone).
    Returns the manifest as a dict, or with ``compute=False`` the task that writes
    it (keyword arguments go to ``dask.compute``)."""
    path = os.path.abspath(os.fspath(path))
    _check_target(path, overwrite)
    # Staged as the CLI stages: first the staged directories of clients of this
    # path that were killed mid-write are removed (only those whose marker names
    # a process that is provably gone), then a new one is made, whose marker
    # names this client.
    _ext.staged_sweep(path)
    tmp = os.fspath(_ext.staged_create(path))
    entries = [
        dask.delayed(_write_part)(tmp, i, parts.ranges, t)
        for i, t in enumerate(parts.octrees)
    ]
    manifest = dask.delayed(_write_manifest)(tmp, *entries)
    task = dask.delayed(_commit)(tmp, path, overwrite, manifest)
    if not compute:
        return task
    try:
        (out,) = dask.compute(task, **compute_kwargs)
    except BaseException:
        _remove_staged(tmp)
        raise
    return out


def _remove_staged(tmp: str) -> None:
    """Removes the staged folder of a failed write. Tasks of the failed graph may
    still be writing their parts into it (``dask.compute`` raises at the first
    error): a file they add makes one removal fail, so it is tried again until the
    folder is gone. Gone, it stays gone: a part task refuses to write without it.
    """
    for _ in range(100):
        shutil.rmtree(tmp, ignore_errors=True)
        if not os.path.exists(tmp):
            return
        time.sleep(0.05)


def read(path: Union[str, "os.PathLike[str]"]) -> Parts:
    """A dataset directory (as `write` or ``tesseral build --parts`` write it) as
    parts: the manifest is read and checked at once; each part is read by a task,
    which checks it against this manifest (CRC-32, space, range, leaf and voxel
    counts), so a part damaged or replaced since is an error naming it."""
    path = os.path.abspath(os.fspath(path))
    manifest = _ext.partition_read_manifest(path)
    space = (manifest["depth"], tuple(manifest["origin"]))
    frame = (manifest["voxel_size"], tuple(manifest["translate"]))
    ranges = [(p["lo"], p["hi"]) for p in manifest["parts"]]
    octrees = [
        dask.delayed(_read_part)(path, space, frame, entry) for entry in manifest["parts"]
    ]
    return Parts(ranges, octrees, space)
