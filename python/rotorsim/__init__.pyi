# Type stubs of the rotorsim package (docstrings in __init__.py and docs/python.md).
from os import PathLike
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike]
_Frame = Any  # pandas.DataFrame when pandas is installed, else Dict[str, np.ndarray]

__version__: str

class Damper:
    def __init__(
        self, deck: _Path, model: str = ..., substeps: int = ..., scheme: str = ...
    ) -> None: ...
    @property
    def model(self) -> str: ...
    @property
    def deck(self) -> str: ...
    @property
    def substeps(self) -> int: ...
    @property
    def scheme(self) -> str: ...
    @property
    def channel_names(self) -> List[str]: ...
    def force(
        self, time_s: npt.ArrayLike, stroke_m: npt.ArrayLike
    ) -> npt.NDArray[np.float64]: ...
    def states(self, time_s: npt.ArrayLike, stroke_m: npt.ArrayLike) -> _Frame: ...

class RunResult:
    folder: Path
    summary: Dict[str, Any]
    @property
    def models(self) -> List[str]: ...
    def last_rev(self, model: Optional[str] = ..., blade: Optional[int] = ...) -> _Frame: ...
    def periodic(self, model: Optional[str] = ...) -> Dict[str, Any]: ...
    def loads(self, model: Optional[str] = ...) -> Dict[str, Any]: ...
    def floquet(self, model: Optional[str] = ...) -> Optional[List[Dict[str, Any]]]: ...

def run(
    rotor: Optional[_Path] = ...,
    flight: Optional[_Path] = ...,
    models: Union[None, str, Iterable[str]] = ...,
    set: Optional[Mapping[str, Any]] = ...,
    all_blades: bool = ...,
    airloads: str = ...,
    out: Optional[_Path] = ...,
    revs: Optional[int] = ...,
    steps_per_rev: Optional[int] = ...,
    substeps: Optional[int] = ...,
    progress: Union[bool, Callable[[Dict[str, Any]], None]] = ...,
) -> RunResult: ...
