import os
from typing import Any, Iterable, List, Optional, Tuple, Union

from dask.delayed import Delayed

from ._tesseral import Octree, Scene

Range = Tuple[int, int]
Space = Tuple[int, Tuple[int, int, int]]
PathLike = Union[str, os.PathLike[str]]

OPERATIONS: Tuple[str, ...]
SAMPLE_PER_PART: int

class Parts:
    octrees: List[Delayed]
    ranges: Union[List[Range], Delayed]
    space: Optional[Space]
    def __init__(
        self,
        ranges: Union[List[Range], Delayed],
        octrees: Iterable[Delayed],
        space: Optional[Space] = None,
    ) -> None: ...
    def __len__(self) -> int: ...
    def to_delayed(self) -> List[Delayed]: ...
    def concat(self) -> Delayed: ...
    def compute(self, **kwargs: Any) -> Octree: ...
    def persist(self, **kwargs: Any) -> Parts: ...

def build(scene: Union[Scene, PathLike], depth: Optional[int] = None, parts: int = 8) -> Parts: ...
def op(a: Parts, b: Parts, operation: str = "union", **compute_kwargs: Any) -> Parts: ...
def translate(parts: Parts, offset: Tuple[int, int, int], **compute_kwargs: Any) -> Parts: ...
def write(
    parts: Parts,
    path: PathLike,
    overwrite: bool = False,
    compute: bool = True,
    **compute_kwargs: Any,
) -> Any: ...
def read(path: PathLike) -> Parts: ...
