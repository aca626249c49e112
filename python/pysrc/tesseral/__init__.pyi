from ._tesseral import (
    DynamicOctree as DynamicOctree,
    FormatError as FormatError,
    OccupancyMap as OccupancyMap,
    Octree as Octree,
    OctreeError as OctreeError,
    Scene as Scene,
    SceneError as SceneError,
    __version__ as __version__,
    collide as collide,
    plan as plan,
    read_scans as read_scans,
    render as render,
    rsmc as rsmc,
    simulate as simulate,
)
from . import _tesseral

class calc:
    encode = _tesseral.encode
    decode = _tesseral.decode
    add = _tesseral.add
    sub = _tesseral.sub
