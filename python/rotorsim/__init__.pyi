# Type stubs of the rotorsim package (docstrings in __init__.py and docs/python.md).
from os import PathLike
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike]
_Frame = Any  # pandas.DataFrame when pandas is installed, else Dict[str, np.ndarray]

__version__: str

RUN_OPTIONS: Dict[str, Any]
BENCH_OPTIONS: Dict[str, Any]
STABILITY_OPTIONS: Dict[str, Any]
MODES_OPTIONS: Dict[str, Any]
DIAGNOSE_OPTIONS: Dict[str, Any]

class Damper:
    def __init__(
        self,
        deck: _Path,
        damper: Optional[str] = ...,
        substeps: int = ...,
        scheme: str = ...,
        model: Optional[str] = ...,
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
    @classmethod
    def open(cls, folder: _Path) -> "RunResult": ...
    @property
    def models(self) -> List[str]: ...
    def last_rev(self, model: Optional[str] = ..., blade: Optional[int] = ...) -> _Frame: ...
    def periodic(self, model: Optional[str] = ...) -> Dict[str, Any]: ...
    def loads(self, model: Optional[str] = ...) -> Dict[str, Any]: ...
    def floquet(self, model: Optional[str] = ...) -> Optional[List[Dict[str, Any]]]: ...

def run(
    out: Optional[_Path] = ...,
    progress: Union[bool, Callable[[Dict[str, Any]], None]] = ...,
    models: Union[None, str, Iterable[str]] = ...,
    rotor_model: Optional[str] = ...,
    *,
    # the options of `rotorsim run` (rotorsim.RUN_OPTIONS; checked against the library by
    # tests/run_options.rs)
    rotor: Optional[_Path] = ...,
    flight: Optional[_Path] = ...,
    damper: Union[None, str, Iterable[str]] = ...,
    damper_deck: Optional[_Path] = ...,
    revs: Optional[int] = ...,
    periodic: Optional[str] = ...,
    periodic_tol: Optional[float] = ...,
    initial_state: Optional[_Path] = ...,
    require_periodic: Optional[bool] = ...,
    write_all_revs: Optional[bool] = ...,
    steps_per_rev: Optional[int] = ...,
    substeps: Optional[int] = ...,
    scheme: Optional[str] = ...,
    model: Optional[str] = ...,
    newton: Optional[str] = ...,
    set: Optional[Mapping[str, Any]] = ...,
    all_blades: Optional[bool] = ...,
    airloads: Optional[str] = ...,
) -> RunResult: ...

class BenchResult:
    folder: Path
    replay: bool
    summary: _Frame
    def history(self, peak_velocity_m_s: float, model: Optional[str] = ...) -> _Frame: ...

def bench(
    damper_deck: Optional[_Path] = ...,
    *,
    out: Optional[_Path] = ...,
    deck: Optional[_Path] = ...,
    # the other options of `rotorsim bench` (rotorsim.BENCH_OPTIONS; checked against the
    # library by tests/job_options.rs)
    damper: Optional[str] = ...,
    omega: Optional[float] = ...,
    peak_velocity: Union[None, float, Iterable[float]] = ...,
    velocity_unit: Optional[str] = ...,
    cycles: Optional[int] = ...,
    steps_per_cycle: Optional[int] = ...,
    substeps: Optional[int] = ...,
    scheme: Optional[str] = ...,
    output_rate: Optional[float] = ...,
    measured: Union[None, _Path, Iterable[_Path]] = ...,
    skip_cycles: Optional[int] = ...,
) -> BenchResult: ...

class StabilityResult:
    folder: Path
    summary: Dict[str, Any]
    modes: _Frame
    amplitude: Optional[_Frame]
    @property
    def stable(self) -> bool: ...

_Numbers = Union[str, float, Iterable[float]]

def stability(
    rotor: _Path,
    speeds: _Numbers,
    *,
    out: Optional[_Path] = ...,
    # the other options of `rotorsim stability` (rotorsim.STABILITY_OPTIONS; checked against
    # the library by tests/job_options.rs)
    damper: Optional[str] = ...,
    time: Optional[_Numbers] = ...,
    kick_m_s: Optional[float] = ...,
    time_duration_s: Optional[float] = ...,
    steps_per_rev: Optional[int] = ...,
    amplitudes_m: Optional[_Numbers] = ...,
    amplitude_at_rad_s: Optional[float] = ...,
    hover: Optional[bool] = ...,
    collective_deg: Optional[float] = ...,
    density_kg_m3: Optional[float] = ...,
    speed_of_sound_m_s: Optional[float] = ...,
    strips: Optional[int] = ...,
    set: Optional[Mapping[str, Any]] = ...,
) -> StabilityResult: ...

class ModesResult:
    folder: Path
    modes: _Frame
    shapes: Optional[_Frame]
    fan: Optional[_Frame]
    comparison: Optional[_Frame]
    fan_plot: Optional[Path]

def modes(
    deck: Optional[_Path] = ...,
    rotor: Optional[_Path] = ...,
    *,
    out: Optional[_Path] = ...,
    # the other options of `rotorsim modes` (rotorsim.MODES_OPTIONS; checked against the
    # library by tests/job_options.rs)
    speeds: Optional[_Numbers] = ...,
    speed_fractions: Optional[_Numbers] = ...,
    reference: Optional[_Path] = ...,
    count: Optional[int] = ...,
) -> ModesResult: ...

class DiagnoseResult:
    folder: Path
    deck: Optional[Path]
    diagnosis: Dict[str, Any]
    @property
    def cause(self) -> str: ...
    @property
    def parameters(self) -> Dict[str, float]: ...
    @property
    def gain(self) -> float: ...
    @property
    def candidates(self) -> List[Dict[str, Any]]: ...

def diagnose(
    damper_deck: Optional[_Path] = ...,
    measured: Union[None, _Path, Iterable[_Path]] = ...,
    *,
    out: Optional[_Path] = ...,
    progress: Optional[Callable[[str], None]] = ...,
    deck: Optional[_Path] = ...,
    # the options of `rotorsim diagnose` (rotorsim.DIAGNOSE_OPTIONS; checked against the library
    # by tests/job_options.rs)
    rotor: Optional[_Path] = ...,
    flight: Optional[_Path] = ...,
    write_deck: Optional[_Path] = ...,
    fit_cycles: Optional[int] = ...,
    max_substep: Optional[float] = ...,
    revs: Optional[int] = ...,
    steps_per_rev: Optional[int] = ...,
    substeps: Optional[int] = ...,
    rotor_check: Optional[bool] = ...,
    check_revs: Optional[int] = ...,
    model: Optional[str] = ...,
) -> DiagnoseResult: ...

class SweepResult:
    folder: Path
    failed: List[Tuple[str, str]]
    table: Optional[_Frame]
    def case(self, case_id: str) -> RunResult: ...

def sweep(
    plan: _Path,
    out: _Path,
    jobs: Optional[int] = ...,
    shard: Optional[str] = ...,
    retry_failed: bool = ...,
    warm_start: Optional[bool] = ...,
    progress: Union[bool, Callable[[Dict[str, Any]], None]] = ...,
) -> SweepResult: ...
