# Type stubs of the package dispex (python/dispex): checked against the module by
# python/tests/test_api.py (mypy's stubtest) and used by type checkers and IDEs.
import os
from typing import Any, Callable, Dict, Iterable, Optional, Union

from ._errors import (CancelledError as CancelledError, Error as Error,
                      InputError as InputError, MemoryBudgetError as MemoryBudgetError,
                      MismatchError as MismatchError, OutputError as OutputError,
                      VerifyError as VerifyError)

from ._dispex import Map as Map, Mesh as Mesh, UvMap as UvMap, __version__ as __version__

_PathLike = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]
_Progress = Callable[[int, int], Any]
_Report = Dict[str, Any]
_MeshArrays = Dict[str, Any]
_MeshInput = Union[_PathLike, Mesh, _MeshArrays]


def option_names() -> Dict[str, Dict[str, Any]]: ...
def read_mesh(path: _PathLike) -> Mesh: ...
def extract(base: _MeshInput, sculpt: _MeshInput, output: Optional[_PathLike] = ..., *,
            out_dir: Optional[_PathLike] = ..., shapes: Optional[Iterable[str]] = ...,
            progress: Optional[_Progress] = ..., **options: Any) -> _Report: ...
def extract_manifest(manifest: _PathLike, out_dir: Optional[_PathLike] = ..., *,
                     shapes: Optional[Iterable[str]] = ..., progress: Optional[_Progress] = ...,
                     **options: Any) -> _Report: ...
def merge(parts: Iterable[_PathLike], output: _PathLike, *, progress: Optional[_Progress] = ...,
          threads: int = ..., max_memory: Union[int, str] = ...) -> _Report: ...
def verify(base: _PathLike, sculpt: Optional[_PathLike], map: _PathLike, *, check: bool = ...,
           **options: Any) -> _Report: ...
def make_sculpt(cage: _PathLike, output: _PathLike, **options: Any) -> _Report: ...
def info(path: _PathLike, *, faces: bool = ..., strict: bool = ...) -> _Report: ...
