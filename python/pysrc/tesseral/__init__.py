"""tesseral: octrees of 3-D solids from Python.

The classes and functions come from the Rust library through a compiled extension
(`tesseral._tesseral`); arrays go in and out as numpy arrays, and long calls release
the GIL. See docs/python.md in the repository for every function with an example.
"""

from ._tesseral import (
    DynamicOctree,
    FormatError,
    OccupancyMap,
    Octree,
    OctreeError,
    Scene,
    SceneError,
    __version__,
    collide,
    plan,
    read_scans,
    render,
    rsmc,
    simulate,
)
from . import _tesseral as _ext


class calc:
    """Tesseral codes, vectorised: `encode`, `decode`, `add`, `sub` on numpy arrays."""

    encode = staticmethod(_ext.encode)
    decode = staticmethod(_ext.decode)
    add = staticmethod(_ext.add)
    sub = staticmethod(_ext.sub)


__all__ = [
    "DynamicOctree",
    "FormatError",
    "OccupancyMap",
    "Octree",
    "OctreeError",
    "Scene",
    "SceneError",
    "calc",
    "collide",
    "plan",
    "read_scans",
    "render",
    "rsmc",
    "simulate",
    "__version__",
]
