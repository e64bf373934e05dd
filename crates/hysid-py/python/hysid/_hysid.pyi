"""Type stubs of the extension module hysid._hysid (the low-level layer; use the functions
of the hysid package). Every fit returns the hysid.report/1 report as JSON text."""

from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class HysidError(Exception): ...
class NumericalError(HysidError): ...
class ModelFileError(HysidError): ...
class CallbackError(HysidError): ...
class InternalError(HysidError): ...
class DataError(HysidError, ValueError): ...
class ConfigError(HysidError, ValueError): ...

_Array = npt.NDArray[np.float64]
_Param = Tuple[str, float, float, float, bool, str]
#: (stage, done, total, iteration, cost, elapsed_s), called on the calling thread.
_Progress = Callable[[str, int, int, Optional[int], Optional[float], float], None]
_Spec = Tuple[object, object, List[str], int, int, List[_Param], List[float]]

def identify_cascade(
    x: _Array,
    y: _Array,
    hysteresis: str,
    na: int,
    nb: int,
    delay: int,
    ts: float,
    uncertainty: str,
    replicates: int,
    seed: int,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...
def families() -> List[Tuple[str, str]]: ...
def identify_operator(
    u: _Array,
    y: _Array,
    family: str,
    ts: float,
    thresholds: Optional[int],
    threshold_grid: Sequence[float],
    grid: Optional[int],
    lambda_: float,
    dead_zones: Optional[int],
    threads: int = 0,
    orientation: Optional[str] = None,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
    initial_state: Optional[str] = None,
    envelope: Optional[str] = None,
) -> str: ...
def identify_operator_cascade(
    x: _Array,
    y: _Array,
    family: str,
    na: int,
    nb: int,
    delay: int,
    ts: float,
    thresholds: int,
    grid: int,
    threads: int = 0,
    orientation: Optional[str] = None,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...
def compare(
    u: _Array,
    y: _Array,
    u_val: Optional[_Array],
    y_val: Optional[_Array],
    families: Sequence[str],
    ts: float,
    thresholds: Optional[int],
    threshold_grid: Sequence[float],
    grid: Optional[int],
    lambda_: float,
    dead_zones: Optional[int],
    threads: int = 0,
    orientation: Optional[str] = None,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
    initial_state: Optional[str] = None,
    envelope: Optional[str] = None,
) -> Tuple[str, List[Tuple[str, Optional[str]]], _Array, _Array, List[_Array]]: ...
def compensate(
    model_json: str,
    reference: _Array,
    ts: float,
    model_source: str,
    limits: Optional[Tuple[float, float]] = None,
) -> Tuple[str, _Array, _Array]: ...
def residual_analysis(u: _Array, y: _Array, yhat: _Array, ts: float, max_lag: int) -> str: ...
def identify_hysteresis(
    x: _Array,
    y: _Array,
    hysteresis: str,
    ts: float,
    initial_output: str,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...
def model_parameters(kind: str) -> Tuple[List[_Param], List[str], int]: ...
def greybox_fit(
    kind: str,
    u: Sequence[_Array],
    y: Sequence[_Array],
    ts: float,
    params: Sequence[_Param],
    starts: int,
    seed: int,
    integrator: str,
    substeps: int,
    interpolation: str,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...
def greybox_fit_user(
    spec: _Spec,
    u: Sequence[_Array],
    y: Sequence[_Array],
    ts: float,
    starts: int,
    seed: int,
    integrator: str,
    substeps: int,
    interpolation: str,
) -> str: ...
def benchmark_bouc_wen(
    u: _Array,
    y: _Array,
    ts: float,
    params: Sequence[_Param],
    tests: Sequence[Tuple[_Array, _Array, float, str]],
    steady_state: bool,
    starts: int,
    seed: int,
    substeps: int,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...
def rigid_body_ls(
    q: _Array,
    u: _Array,
    ts: float,
    gain: float,
    offset: bool,
    cutoff_hz: float,
    order: int,
    decimation: int,
    border: int,
    inertia_name: str,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...
def simulate_model(
    model_json: str,
    inputs: Sequence[_Array],
    ts: float,
    y0: Optional[float] = None,
    evaluator: Optional[str] = None,
) -> List[_Array]: ...
def simulate_user(
    spec: _Spec, inputs: Sequence[_Array], ts: float, integrator: str, substeps: int, interpolation: str
) -> List[_Array]: ...
def load_model(path: str) -> str: ...
def check_model(model_json: str) -> str: ...
def set_num_threads(n: int) -> None: ...
def get_num_threads() -> int: ...
def equation_info(
    text: str, origin: str
) -> Tuple[str, List[_Param], List[str], List[str], List[str], List[float], List[bool]]: ...
def equation_model_file(
    text: str, params: Sequence[_Param], x0: Sequence[float], integrator: str, substeps: int, interpolation: str
) -> str: ...
def greybox_fit_equations(
    text: str,
    u: Sequence[_Array],
    y: Sequence[_Array],
    ts: float,
    params: Sequence[_Param],
    starts: int,
    seed: int,
    integrator: str,
    substeps: int,
    interpolation: str,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
    evaluator: Optional[str] = None,
) -> str: ...
def actuator_parameter_names() -> List[str]: ...
def actuator_rig_truth() -> List[float]: ...
def actuator_read_data_sets(dir: str) -> List[Tuple[_Array, _Array, float]]: ...
def actuator_rig(
    truth: Optional[Sequence[float]], backlash: float, noise: float, seed: int, gear_ratio: float, saddle_mass: float
) -> List[Tuple[int, bool, float, _Array, _Array]]: ...
def actuator_three_steps(
    sets: Sequence[Tuple[_Array, _Array, float]],
    source: str,
    truth: Optional[Sequence[float]],
    gear_ratio: float,
    saddle_mass: float,
    cutoff_hz: float,
    remove_mean: bool,
    reversal_margin: float,
    unfiltered_step3: bool,
    max_iterations: int,
    tolerance: float,
    threads: int = 0,
    time_limit: Optional[float] = None,
    progress: Optional[_Progress] = None,
) -> str: ...

class Stepper:
    n_inputs: int
    n_outputs: int
    faults: int
    error: bool
    def reset(self) -> None: ...
    def step(self, u: Sequence[float]) -> List[float]: ...
    def run(self, inputs: Sequence[_Array]) -> List[_Array]: ...

class Compensator:
    preview: int
    clipped: int
    faults: int
    error: bool
    limits: Optional[Tuple[float, float]]
    def reset(self) -> None: ...
    def step(self, r: float) -> Tuple[float, float, bool]: ...
    def run(self, r: _Array) -> Tuple[_Array, _Array]: ...

def model_stepper(model_json: str, ts: float, y0: Optional[float] = None) -> Stepper: ...
def model_compensator(model_json: str, ts: float, limits: Optional[Tuple[float, float]] = None) -> Compensator: ...
def export_model(
    model_json: str,
    target: str,
    name: str,
    out: str,
    inverse: bool,
    ts: Optional[float],
    binary: bool,
    y0: Optional[float] = None,
    limits: Optional[Tuple[float, float]] = None,
    precision: str = "double",
) -> List[str]: ...
def fmu_of_c_code(header: str, source: str, interface_json: str, binary: bool) -> bytes: ...
