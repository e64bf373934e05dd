import os
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

from . import fleet as fleet
from ._families import FAMILIES as FAMILIES
from ._families import FamilyName as FamilyName
from ._hysid import CallbackError as CallbackError
from ._hysid import ConfigError as ConfigError
from ._hysid import DataError as DataError
from ._hysid import HysidError as HysidError
from ._hysid import InternalError as InternalError
from ._hysid import ModelFileError as ModelFileError
from ._hysid import NumericalError as NumericalError

__version__: str
BOUC_WEN_FS: float
ACTUATOR_GEAR_RATIO: float
ACTUATOR_SADDLE_MASS: float
_ArrayLike = Any

class Parameter:
    name: str
    value: float
    lower: float
    upper: float
    fixed: bool
    unit: str
    std: Optional[float]
    def __init__(
        self,
        name: str,
        value: float,
        *,
        lower: float = ...,
        upper: float = ...,
        fixed: bool = ...,
        unit: str = ...,
        std: Optional[float] = ...,
    ) -> None: ...

class GreyBoxModel:
    states: List[str]
    parameters: List[Parameter]
    inputs: int
    outputs: int
    x0: npt.NDArray[np.float64]
    equations: Optional[str]
    def __init__(
        self,
        states: Any,
        parameters: Sequence[Parameter],
        rhs: Callable[..., Any],
        output: Callable[..., Any],
        *,
        inputs: int = ...,
        x0: Optional[_ArrayLike] = ...,
    ) -> None: ...
    @classmethod
    def from_equations(cls, text: str, *, origin: str = ...) -> "GreyBoxModel": ...
    @classmethod
    def from_equations_file(cls, path: "os.PathLike[str] | str") -> "GreyBoxModel": ...
    def to_model(self, *, integrator: str = ..., substeps: int = ..., interpolation: str = ...) -> "Model": ...
    def simulate(
        self, u: _ArrayLike, *, ts: float, integrator: str = ..., substeps: int = ..., interpolation: str = ...
    ) -> npt.NDArray[np.float64]: ...

class Model:
    file: Dict[str, Any]
    @property
    def kind(self) -> str: ...
    @property
    def parameters(self) -> Dict[str, Parameter]: ...
    def simulate(self, u: _ArrayLike, *, ts: float, y0: Optional[float] = ...) -> npt.NDArray[np.float64]: ...
    def save(self, path: "os.PathLike[str] | str") -> None: ...
    def export(
        self,
        target: str,
        name: str,
        out: "os.PathLike[str] | str",
        *,
        inverse: bool = ...,
        ts: Optional[float] = ...,
        binary: bool = ...,
    ) -> List[str]: ...

class Result:
    parameters: Dict[str, Parameter]
    fit_percent: Optional[float]
    rmse: Optional[float]
    termination: str
    converged: bool
    elapsed_s: Optional[float]
    validation: List[Dict[str, Any]]
    model: Optional[Model]
    def report(self) -> Dict[str, Any]: ...
    def to_json(self) -> str: ...
    def to_dataframe(self) -> Any: ...

def load_model(path: "os.PathLike[str] | str") -> Model: ...
def identify_cascade(
    x: Any,
    y: Any = ...,
    *,
    hysteresis: str = ...,
    na: int,
    nb: int,
    delay: int,
    ts: float = ...,
    uncertainty: str = ...,
    seed: int = ...,
    replicates: int = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def identify_operator(
    u: Any,
    y: Any = ...,
    *,
    family: FamilyName,
    ts: float = ...,
    thresholds: "int | Sequence[float]" = ...,
    grid: int = ...,
    lambda_: float = ...,
    dead_zones: int = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def identify_hysteresis(
    x: Any,
    y: Any = ...,
    *,
    hysteresis: str = ...,
    ts: float = ...,
    initial_output: str = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def greybox_fit(
    model: "str | GreyBoxModel",
    u: Any,
    y: Any = ...,
    *,
    ts: Optional[float] = ...,
    init: Optional[Dict[str, float]] = ...,
    fix: Iterable[str] = ...,
    bounds: Optional[Dict[str, Tuple[float, float]]] = ...,
    starts: int = ...,
    seed: int = ...,
    integrator: str = ...,
    substeps: int = ...,
    interpolation: str = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def benchmark_bouc_wen(
    u_train: Any,
    y_train: Any = ...,
    *,
    tests: Sequence[Any] = ...,
    steady_state: bool = ...,
    ts: Optional[float] = ...,
    starts: int = ...,
    seed: int = ...,
    substeps: int = ...,
    start_factor: float = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def rigid_body_ls(
    q: Any,
    u: Any,
    *,
    ts: float,
    gain: float = ...,
    offset: bool = ...,
    cutoff_hz: float = ...,
    order: int = ...,
    decimation: int = ...,
    border: int = ...,
    inertia_name: str = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def set_num_threads(n: Optional[int]) -> None: ...
def get_num_threads() -> int: ...

class ActuatorRecord:
    set: int
    saddle_free: bool
    u: npt.NDArray[np.float64]
    y: npt.NDArray[np.float64]
    sampling_time: float
    def __init__(
        self, set: int, saddle_free: bool, u: npt.NDArray[np.float64], y: npt.NDArray[np.float64], sampling_time: float
    ) -> None: ...

def actuator_three_steps(
    records: Any,
    *,
    ts: Optional[float] = ...,
    truth: Optional[Dict[str, float]] = ...,
    gear_ratio: float = ...,
    saddle_mass: float = ...,
    cutoff_hz: float = ...,
    remove_mean: bool = ...,
    reversal_margin: float = ...,
    unfiltered_step3: bool = ...,
    max_iterations: int = ...,
    tolerance: float = ...,
    threads: Optional[int] = ...,
) -> Result: ...
def actuator_rig(
    *,
    truth: Optional[Dict[str, float]] = ...,
    backlash: float = ...,
    noise: float = ...,
    seed: int = ...,
    gear_ratio: float = ...,
    saddle_mass: float = ...,
) -> List[ActuatorRecord]: ...
