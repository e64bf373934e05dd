"""hysid — identification of dynamic systems with hysteresis, from numpy arrays.

The Rust library hysid behind a Python API: numpy arrays (float64, 1-D; 2-D ``(samples,
channels)`` for several inputs) in and out, fits that release the GIL, results and models
that pickle exactly.

Models and methods
------------------
* Coleman–Hodgdon hysteresis (forms ``ch1``…``ch4``) followed by a linear block
  A(q⁻¹)y = q⁻ᵏB(q⁻¹)v: the cascade of J. Vörös, "Modeling and Identification of
  Discrete-Time Nonlinear Dynamic Cascade Systems with Input Hysteresis", Mathematical
  Problems in Engineering 2015, 393572 (key-term separation, then output error).
* Continuous-time grey-box models ẋ = f(t, x, u, θ), y = h(x, u, θ) fitted by output error
  (Levenberg–Marquardt, multi-start): built-in (Bouc–Wen oscillator, rigid body with
  friction, the actuator of J. Gunnar et al., ICRA 2006) or written as Python functions
  (:class:`GreyBoxModel`).
* The Bouc–Wen hysteretic benchmark of J.-P. Noël and M. Schoukens (2016), scored by
  e_RMS, the RMS of the simulation error.

Quick start::

    import numpy as np, hysid
    r = hysid.identify_cascade(x, y, hysteresis="ch4", na=2, nb=2, delay=1)
    print(r.parameters["a1"].value, r.fit_percent)
    yhat = r.model.simulate(x, ts=1.0)

Threads: every fit releases the GIL. ``threads=None`` (the default) runs a call's parallel
work on all cores, the fastest for one fit at a time; ``threads=1`` runs it on a worker of
its own, the best throughput when several fits run at once (Python threads, a thread
pool, Dask workers with several threads): n such calls use n cores.
:func:`set_num_threads` changes the default for the whole process.

Errors are :class:`HysidError` subclasses; bad data and bad settings are also
``ValueError`` (:class:`DataError`, :class:`ConfigError`), wrong types ``TypeError``.
"""

from __future__ import annotations

import copy
import json
import math
import os
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from . import _hysid
from ._families import FAMILIES, FamilyName
from ._hysid import (
    CallbackError,
    ConfigError,
    DataError,
    HysidError,
    InternalError,
    ModelFileError,
    NumericalError,
)

__version__ = _hysid.__version__

__all__ = [
    "FAMILIES",
    "FamilyName",
    "identify_operator",
    "identify_cascade",
    "identify_hysteresis",
    "greybox_fit",
    "benchmark_bouc_wen",
    "rigid_body_ls",
    "actuator_three_steps",
    "actuator_rig",
    "ActuatorRecord",
    "set_num_threads",
    "get_num_threads",
    "load_model",
    "Parameter",
    "GreyBoxModel",
    "Result",
    "Model",
    "HysidError",
    "DataError",
    "ConfigError",
    "NumericalError",
    "ModelFileError",
    "CallbackError",
    "InternalError",
]

for _cls in (HysidError, NumericalError, ModelFileError, CallbackError, InternalError):
    _cls.__module__ = "hysid"


# --------------------------------------------------------------------------- input checks


def _array(a: Any, name: str, *, ndim: Tuple[int, ...] = (1,)) -> np.ndarray:
    """``a`` as a C-contiguous float64 array of one of the dimensions ``ndim``, finite and
    not empty; TypeError for something that is not numeric, DataError otherwise."""
    if isinstance(a, (str, bytes, dict)) or a is None:
        raise TypeError(f"{name}: expected a numeric array, got {type(a).__name__}")
    try:
        arr = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: expected a numeric array, got {type(a).__name__} ({e})") from None
    if arr.ndim not in ndim:
        want = " or ".join(f"{d}-D" for d in ndim)
        raise DataError(f"{name}: expected a {want} array, got shape {arr.shape}")
    if arr.size == 0:
        raise DataError(f"{name}: the array is empty; give at least one sample")
    bad = np.flatnonzero(~np.isfinite(arr.ravel()))
    if bad.size:
        k = int(bad[0])
        idx = np.unravel_index(k, arr.shape)
        where = idx[0] if arr.ndim == 1 else tuple(int(i) for i in idx)
        raise DataError(f"{name}: sample {where} is {arr.ravel()[k]}, not finite; remove or interpolate it")
    return arr


def _channels(a: Any, name: str) -> List[np.ndarray]:
    """1-D → one channel; 2-D (samples, channels) → one contiguous array per column."""
    arr = _array(a, name, ndim=(1, 2))
    if arr.ndim == 1:
        return [arr]
    return [np.ascontiguousarray(arr[:, j]) for j in range(arr.shape[1])]


def _pair(x: Any, y: Any, names: Tuple[str, str], ts: Optional[float]):
    """(x, y, ts) from two arrays, or from a record with ``.u``, ``.y``,
    ``.sampling_time`` (``nonlinear_benchmarks.Input_output_data``) passed as ``x``."""
    if y is None and hasattr(x, "u") and hasattr(x, "y"):
        rec_ts = getattr(x, "sampling_time", None)
        x, y = x.u, x.y
        if ts is None and rec_ts is not None:
            ts = float(rec_ts)
    if y is None:
        raise TypeError(f"give {names[1]}, or pass a record with .u and .y as {names[0]}")
    xa, ya = _array(x, names[0]), _array(y, names[1])
    if xa.shape != ya.shape:
        raise DataError(f"{names[0]} has {xa.shape[0]} samples and {names[1]} {ya.shape[0]}; give equal lengths")
    return xa, ya, ts


def _ts(ts: Any, default: Optional[float] = None) -> float:
    if ts is None:
        if default is None:
            raise TypeError("give the sample time ts (seconds)")
        ts = default
    if isinstance(ts, bool) or not isinstance(ts, (int, float, np.floating, np.integer)):
        raise TypeError(f"ts: expected a number, got {type(ts).__name__}")
    ts = float(ts)
    if not (math.isfinite(ts) and ts > 0):
        raise ConfigError(f"ts = {ts}: give a positive, finite sample time")
    return ts


def _count(v: Any, name: str) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {type(v).__name__}")
    if v < 0:
        raise ConfigError(f"{name} = {v}: give a non-negative integer")
    return int(v)


def _choice(v: Any, name: str) -> str:
    if not isinstance(v, str):
        raise TypeError(f"{name}: expected a string, got {type(v).__name__}")
    return v


def _threads(v: Any) -> int:
    """``threads`` as the extension takes it: 0 for the process default."""
    return 0 if v is None else _count(v, "threads")


def set_num_threads(n: Optional[int]) -> None:
    """Sets the worker threads of every later call that does not pass ``threads``.

    ``None`` or 0: all cores (rayon's global pool; the default, fastest for one fit at a
    time). 1: each call on a worker of its own, for the best throughput when several calls
    run at once from Python threads or a Dask worker's threads. Pools are built once per
    calling thread and count, then reused."""
    _hysid.set_num_threads(_threads(n))


def get_num_threads() -> int:
    """The worker threads of a call that does not pass ``threads`` (0: all cores)."""
    return int(_hysid.get_num_threads())


# --------------------------------------------------------------------------- parameters


class Parameter:
    """A model parameter: name, value, bounds [lower, upper], fixed flag, unit, and — in a
    :class:`Result` — the standard deviation ``std`` of the estimate (None when fixed or not
    estimated)."""

    __slots__ = ("name", "value", "lower", "upper", "fixed", "unit", "std")

    def __init__(
        self,
        name: str,
        value: float,
        *,
        lower: float = -math.inf,
        upper: float = math.inf,
        fixed: bool = False,
        unit: str = "",
        std: Optional[float] = None,
    ) -> None:
        if not isinstance(name, str) or not name:
            raise TypeError("Parameter name: expected a non-empty string")
        for label, v in (("value", value), ("lower", lower), ("upper", upper)):
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
                raise TypeError(f"parameter {name}: {label} must be a number, got {type(v).__name__}")
        self.name, self.value = name, float(value)
        self.lower, self.upper = float(lower), float(upper)
        self.fixed, self.unit = bool(fixed), str(unit)
        self.std = None if std is None else float(std)
        if not math.isfinite(self.value):
            raise ConfigError(f"parameter {name}: value {self.value} is not finite; give a finite start value")
        if math.isnan(self.lower) or math.isnan(self.upper) or self.lower > self.upper:
            raise ConfigError(f"parameter {name}: bounds [{self.lower}, {self.upper}] are not an interval")

    def _tuple(self):
        return (self.name, self.value, self.lower, self.upper, self.fixed, self.unit)

    def __repr__(self) -> str:
        std = "" if self.std is None else f" ± {self.std:.3e}"
        unit = f" {self.unit}" if self.unit else ""
        fixed = " (fixed)" if self.fixed else ""
        return f"Parameter({self.name} = {self.value!r}{std}{unit}{fixed})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Parameter) and all(getattr(self, s) == getattr(other, s) for s in self.__slots__)

    def __getstate__(self):
        return {s: getattr(self, s) for s in self.__slots__}

    def __setstate__(self, state):
        for s in self.__slots__:
            object.__setattr__(self, s, state[s])


def _from_record(rec: Dict[str, Any]) -> Parameter:
    lo, hi = rec.get("lower"), rec.get("upper")
    return Parameter(
        rec["name"],
        rec["value"],
        lower=-math.inf if lo is None else lo,
        upper=math.inf if hi is None else hi,
        fixed=rec.get("fixed", False),
        unit=rec.get("unit", ""),
        std=rec.get("std"),
    )


# --------------------------------------------------------------------------- user models


class GreyBoxModel:
    """A continuous-time grey-box model written as Python functions:

    ẋ = f(t, x, u, p) = ``rhs(t, x, u, p)``,   y = h(x, u, p) = ``output(t, x, u, p)``

    ``x`` (states), ``u`` (inputs) and ``p`` (parameter values in the order of
    ``parameters``) are float64 numpy arrays; each function returns a 1-D array (n_states
    values for ``rhs``, n_outputs for ``output``). ``output`` is called with ``t = nan``:
    the library's output map is time-invariant.

    ``states``: the state names (or their number); ``parameters``: a list of
    :class:`Parameter`; ``inputs``: the number of inputs; ``x0``: the initial state
    (default zeros), held fixed in a fit.

    Speed: the model is integrated by RK4, one ``rhs`` call per stage; each call costs
    about 3 µs of overhead (three small numpy arrays in, one read back) plus the function's
    own time, against nanoseconds for a built-in model, and the finite-difference sensitivities
    (one extra simulation per free parameter) run one after the other since a Python
    callback holds the GIL; a built-in model has analytic sensitivities and runs them in
    parallel. Measured: a Bouc–Wen oscillator in Python fits ~80× slower than the built-in one.
    The functions must be picklable (module-level) for the model to pickle.

    An equation model (:meth:`from_equations`, :meth:`from_equations_file`) has no Python
    callback: its equations are compiled and differentiated symbolically, so it fits with
    exact sensitivities at the speed of a built-in model, on all cores, and its fitted
    model saves to a model file the CLI reads. Its ``equations`` attribute holds the text
    (None for a model written as Python functions).
    """

    #: The equation-file text of an equation model; None for Python callbacks.
    equations: Optional[str] = None

    def __init__(
        self,
        states: Any,
        parameters: Sequence[Parameter],
        rhs: Callable,
        output: Callable,
        *,
        inputs: int = 1,
        x0: Any = None,
    ) -> None:
        if isinstance(states, (int, np.integer)) and not isinstance(states, bool):
            states = [f"x{i + 1}" for i in range(int(states))]
        if isinstance(states, str) or not all(isinstance(s, str) for s in states):
            raise TypeError("states: give a list of state names or their number")
        self.states = list(states)
        if not self.states:
            raise ConfigError("states: a model needs at least one state")
        if not all(isinstance(p, Parameter) for p in parameters):
            raise TypeError("parameters: give a list of hysid.Parameter")
        self.parameters = [copy.copy(p) for p in parameters]
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise ConfigError(f"parameters: names must be unique, got {names}")
        if not callable(rhs) or not callable(output):
            raise TypeError("rhs and output must be callables f(t, x, u, p)")
        self.rhs, self.output = rhs, output
        self.inputs = _count(inputs, "inputs")
        if x0 is None:
            self.x0 = np.zeros(len(self.states))
        else:
            self.x0 = _array(x0, "x0")
            if self.x0.shape != (len(self.states),):
                raise DataError(f"x0 has {self.x0.size} values for {len(self.states)} states")
        self.outputs = self._probe()

    def _probe(self) -> int:
        """Calls rhs and output once at x0 to check their shapes; returns the output count."""
        x, u = self.x0.copy(), np.zeros(self.inputs)
        p = np.array([q.value for q in self.parameters])
        dx = _call_checked(self.rhs, "rhs", (0.0, x, u, p))
        if dx.shape != (len(self.states),):
            raise CallbackError(f"rhs(t, x, u, p) returned shape {dx.shape}; it must return ({len(self.states)},)")
        y = _call_checked(self.output, "output", (math.nan, x, u, p))
        if y.ndim != 1 or y.size == 0:
            raise CallbackError(f"output(t, x, u, p) returned shape {y.shape}; return a 1-D array")
        return int(y.size)

    @classmethod
    def from_equations(cls, text: str, *, origin: str = "equation text") -> "GreyBoxModel":
        """A grey-box model from the text of an equation file (TOML)::

            [model]        name, states, inputs, outputs (and their units)
            [parameters]   name = { value, lower, upper, unit, fixed }
            [initial]      state = { value, fixed }   (fixed = false: estimated)
            [let]          named intermediate quantities, evaluated in order
            [equations]    state = "dstate/dt as an expression"
            [output]       output = "expression"

        Expressions: ``+ - * / ^``, parentheses, numbers, the functions sin, cos, tan, exp,
        ln, sqrt, abs, sign, tanh, atan, min, max, pow and ``if(cond, a, b)``. The
        equations are differentiated symbolically and compiled, so the model fits with exact
        forward sensitivities like a built-in model (no Python callback, GIL released).
        A malformed text raises :class:`ConfigError` (a ``ValueError``) naming ``origin``,
        the line and the column. Usable wherever a :class:`GreyBoxModel` goes:
        :func:`greybox_fit`, :meth:`simulate`, pickle; the fitted ``Result.model`` saves
        to a model file (kind ``equations``, the text embedded) that the CLI simulates.
        """
        if not isinstance(text, str):
            raise TypeError(f"text: expected the equation file's text (str), got {type(text).__name__}")
        name, params, states, inputs, outputs, x0, x0_estimated = _hysid.equation_info(text, str(origin))
        self = cls.__new__(cls)
        self.name = name
        self.states = list(states)
        self.parameters = [
            Parameter(n, v, lower=lo, upper=hi, fixed=f, unit=unit) for (n, v, lo, hi, f, unit) in params
        ]
        self.rhs = self.output = None
        self.inputs, self.outputs = len(inputs), len(outputs)
        self.input_names, self.output_names = list(inputs), list(outputs)
        self.x0 = np.asarray(x0, dtype=np.float64)
        self.x0_estimated = list(x0_estimated)
        self.equations = text
        return self

    @classmethod
    def from_equations_file(cls, path: "os.PathLike[str] | str") -> "GreyBoxModel":
        """:meth:`from_equations` on the text of the file at ``path`` (errors name the file)."""
        if not isinstance(path, (str, os.PathLike)):
            raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise ModelFileError(f"cannot read equation file {os.fspath(path)}: {e.strerror}") from None
        return cls.from_equations(text, origin=os.fspath(path))

    def to_model(self, *, integrator: str = "rk4", substeps: int = 10, interpolation: str = "zoh") -> "Model":
        """The model with its current parameter values as a :class:`Model` (simulate, save;
        an equation model's file is the ``equations`` kind the CLI reads)."""
        sim = (_choice(integrator, "integrator"), _count(substeps, "substeps"), _choice(interpolation, "interpolation"))
        if self.equations is not None:
            params = [p._tuple() for p in self.parameters]
            x0 = [float(v) for v in self.x0]
            return Model(json.loads(_hysid.equation_model_file(self.equations, params, x0, *sim)))
        records = [
            {
                "name": p.name,
                "value": p.value,
                "std": None,
                "unit": p.unit,
                "fixed": p.fixed,
                "lower": None if math.isinf(p.lower) else p.lower,
                "upper": None if math.isinf(p.upper) else p.upper,
            }
            for p in self.parameters
        ]
        interp = {"zoh": "zero_order_hold", "band-limited": "band_limited"}.get(sim[2], sim[2])
        file = {
            "schema": "hysid.model/1",
            "kind": "python",
            "parameters": records,
            "hysteresis": None,
            "delay": None,
            "initial_output": None,
            "simulation": {"integrator": sim[0], "substeps": sim[1], "interpolation": interp},
            "initial_state": [float(v) for v in self.x0],
        }
        return Model(file, self)

    def simulate(
        self, u: Any, *, ts: float, integrator: str = "rk4", substeps: int = 10, interpolation: str = "zoh"
    ) -> np.ndarray:
        """The output for input ``u`` (1-D, or 2-D (samples, inputs)) sampled every ``ts``
        seconds, from ``x0`` with the current parameter values (RK4 with ``substeps`` per
        sample; inputs ``zoh``, ``linear`` or ``band-limited`` between samples)."""
        model = self.to_model(integrator=integrator, substeps=substeps, interpolation=interpolation)
        return model.simulate(u, ts=ts)

    def _spec(self, values: Optional[Sequence[float]] = None):
        params = [p._tuple() for p in self.parameters]
        if values is not None:
            params = [(n, float(v), lo, hi, f, unit) for (n, _, lo, hi, f, unit), v in zip(params, values)]
        return (self.rhs, self.output, self.states, self.inputs, self.outputs, params, [float(v) for v in self.x0])

    def __repr__(self) -> str:
        kind = f"equations '{self.name}', " if self.equations is not None else ""
        return f"GreyBoxModel({kind}states={self.states}, parameters={[p.name for p in self.parameters]}, inputs={self.inputs}, outputs={self.outputs})"


def _call_checked(f: Callable, which: str, args) -> np.ndarray:
    try:
        out = f(*args)
    except Exception as e:  # noqa: BLE001 — re-raised with the callback's name
        raise CallbackError(f"{which}(t, x, u, p) raised {type(e).__name__}: {e}") from e
    try:
        return np.asarray(out, dtype=np.float64)
    except (TypeError, ValueError):
        raise CallbackError(f"{which}(t, x, u, p) returned {out!r}; return a 1-D float array") from None


# --------------------------------------------------------------------------- models and results


class Model:
    """A fitted model (the ``hysid.model/1`` model file the CLI reads and writes).

    ``simulate(u, *, ts, y0=None)`` returns the simulated output (1-D for one output,
    ``(samples, outputs)`` otherwise); ``save(path)`` writes the model file;
    ``.file`` is its content as a dict.
    """

    def __init__(self, file: Dict[str, Any], user: Optional[GreyBoxModel] = None) -> None:
        self.file = file
        self._user = user

    @property
    def kind(self) -> str:
        return self.file["kind"]

    @property
    def parameters(self) -> Dict[str, Parameter]:
        return {r["name"]: _from_record(r) for r in self.file["parameters"]}

    def simulate(self, u: Any, *, ts: float, y0: Optional[float] = None) -> np.ndarray:
        """The model's output for input ``u`` (1-D, or 2-D (samples, inputs)) sampled every
        ``ts`` seconds; ``y0`` is the measured initial output, for a hysteresis that starts
        from it."""
        ts = _ts(ts)
        channels = _channels(u, "u")
        if y0 is not None:
            y0 = float(y0)
        if self._user is not None:
            sim = self.file.get("simulation") or {}
            outs = _hysid.simulate_user(
                self._user._spec([r["value"] for r in self.file["parameters"]]),
                channels,
                ts,
                _integrator_name(sim),
                int(sim.get("substeps") or 1),
                _interp_name(sim),
            )
        else:
            outs = _hysid.simulate_model(json.dumps(self.file), channels, ts, y0)
        return outs[0] if len(outs) == 1 else np.column_stack(outs)

    def save(self, path: "os.PathLike[str] | str") -> None:
        """Writes the model file (``hysid.model/1``) that ``hysid simulate --model`` reads."""
        if self._user is not None:
            raise ModelFileError(
                "a model written as Python functions cannot be saved as a model file (the CLI "
                "cannot run Python); pickle the Result instead"
            )
        with open(path, "w", encoding="utf-8") as f:
            f.write(_hysid.check_model(json.dumps(self.file)))
            f.write("\n")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Model) and self.file == other.file

    def __repr__(self) -> str:
        values = ", ".join(f"{r['name']}={r['value']:.6g}" for r in self.file["parameters"])
        return f"Model({self.kind}: {values})"

    def __reduce__(self):
        return (_model_from_json, (json.dumps(self.file), self._user))


def _integrator_name(sim: Dict[str, Any]) -> str:
    name = str(sim.get("integrator", "rk4")).lower()
    return "newmark" if "newmark" in name else "rk4"


def _interp_name(sim: Dict[str, Any]) -> str:
    name = str(sim.get("interpolation", "zoh")).lower().replace("_", "-")
    if "band" in name:
        return "band-limited"
    return "linear" if "linear" in name else "zoh"


def _model_from_json(text: str, user: Optional[GreyBoxModel]) -> Model:
    return Model(json.loads(text), user)


def load_model(path: "os.PathLike[str] | str") -> Model:
    """Reads a model file written by the CLI (``--model``) or by :meth:`Model.save`."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    return Model(json.loads(_hysid.load_model(os.fspath(path))))


class Result:
    """The result of a fit, built on its ``hysid.report/1`` report.

    Attributes: ``parameters`` (dict name → :class:`Parameter` with ``.value``, ``.std``,
    ``.unit``, ``.fixed``), ``fit_percent`` (100 (1 − ‖y − ŷ‖/‖y − ȳ‖)), ``rmse``,
    ``termination`` (why the search stopped), ``converged``, ``validation`` (one dict per
    test record: source, samples, fit_percent, rmse, e_rms), ``model`` (:class:`Model`),
    ``elapsed_s``. ``report()`` returns the report as a dict; ``to_dataframe()`` the
    parameter table as a pandas DataFrame.
    """

    def __init__(self, report: Dict[str, Any], user: Optional[GreyBoxModel] = None) -> None:
        self._report = report
        self._user = user
        self.model = Model(report["model"], user) if report.get("model") else None
        self.parameters: Dict[str, Parameter] = self.model.parameters if self.model is not None else {}
        fit = report.get("fit") or {}
        self.fit_percent: Optional[float] = fit.get("fit_percent")
        self.rmse: Optional[float] = fit.get("rmse")
        search = report.get("search") or {}
        term = search.get("termination") or {}
        self.termination: str = term.get("message", "")
        self.converged: bool = bool(term.get("converged", False))
        self.elapsed_s: Optional[float] = search.get("elapsed_s")
        self.validation: List[Dict[str, Any]] = list(report.get("validation") or [])

    def report(self) -> Dict[str, Any]:
        """The ``hysid.report/1`` report as a dict (a copy)."""
        return copy.deepcopy(self._report)

    def to_json(self) -> str:
        return json.dumps(self._report, indent=2)

    def to_dataframe(self):
        """The parameters as a pandas DataFrame (columns value, std, unit, fixed, lower,
        upper; index the names). Needs pandas."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_dataframe() needs pandas: pip install pandas") from e
        rows = [
            {
                "name": p.name,
                "value": p.value,
                "std": p.std,
                "unit": p.unit,
                "fixed": p.fixed,
                "lower": p.lower,
                "upper": p.upper,
            }
            for p in self.parameters.values()
        ]
        return pd.DataFrame(rows).set_index("name")

    def _timeless(self) -> Dict[str, Any]:
        """The report without its wall-clock figures (equal fits compare equal)."""
        rep = copy.deepcopy(self._report)
        if isinstance(rep.get("search"), dict):
            rep["search"].pop("elapsed_s", None)
        return rep

    def __eq__(self, other: object) -> bool:
        """Equal estimates, figures and models; the wall-clock time is not compared."""
        return isinstance(other, Result) and self._timeless() == other._timeless()

    def __repr__(self) -> str:
        values = ", ".join(f"{n}={p.value:.6g}" for n, p in self.parameters.items())
        fit = "n/a" if self.fit_percent is None else f"{self.fit_percent:.2f} %"
        return f"Result({self._report.get('command')}: {values}; fit {fit})"

    def __reduce__(self):
        return (_result_from_json, (json.dumps(self._report), self._user))


def _result_from_json(text: str, user: Optional[GreyBoxModel] = None) -> Result:
    return Result(json.loads(text), user)


# --------------------------------------------------------------------------- recipes


def identify_cascade(
    x: Any,
    y: Any = None,
    *,
    hysteresis: str = "ch4",
    na: int,
    nb: int,
    delay: int,
    ts: float = 1.0,
    uncertainty: str = "asymptotic",
    seed: int = 0,
    replicates: int = 30,
    threads: Optional[int] = None,
) -> Result:
    """Identifies a Coleman–Hodgdon hysteresis + linear-block cascade (Vörös 2015).

    v(k) = H[x](k) is a Coleman–Hodgdon hysteresis of form ``hysteresis`` (``ch1``…``ch4``);
    A(q⁻¹) y(k) = q⁻ᵈᵉˡᵃʸ B(q⁻¹) v(k) with ``na`` denominator and ``nb`` numerator
    coefficients. Estimation: a grid over the switching threshold, the paper's key-term
    separation iteration, then output error (Levenberg–Marquardt) from the best candidates.
    ``uncertainty``: ``"asymptotic"`` (σ²(JᵀJ)⁻¹) or ``"bootstrap"`` (parametric bootstrap,
    ``replicates`` re-identifications seeded by ``seed``). ``x`` may be a record with
    ``.u``, ``.y`` (then ``y`` is omitted). Runs with the GIL released; ``threads``: worker
    threads (None: the process default, all cores; 1 for concurrent fits).
    The report is the CLI's ``identify cascade`` report.
    """
    x, y, ts = _pair(x, y, ("x", "y"), ts)
    text = _hysid.identify_cascade(
        x,
        y,
        _choice(hysteresis, "hysteresis"),
        _count(na, "na"),
        _count(nb, "nb"),
        _count(delay, "delay"),
        _ts(ts, 1.0),
        _choice(uncertainty, "uncertainty"),
        _count(replicates, "replicates"),
        _count(seed, "seed"),
        _threads(threads),
    )
    return Result(json.loads(text))


def identify_operator(
    u: Any,
    y: Any = None,
    *,
    family: FamilyName,
    ts: float = 1.0,
    thresholds: "int | Sequence[float]" = 10,
    grid: int = 20,
    lambda_: float = 1e-6,
    dead_zones: int = 4,
    threads: Optional[int] = None,
) -> Result:
    """Fits one hysteresis family y = Γ[u] to a measured input ``u`` and output ``y`` from
    the data alone (no initial guess): the CLI's ``hysid identify operator``, the same
    estimates and report.

    ``family``: one of :data:`FAMILIES` (``"pi"``, ``"preisach"``, ``"bouc-wen"``, …; see
    ``docs/zoo.md``). ``thresholds``: PI/GPI thresholds and Maxwell-slip elements, a count
    (a uniform grid over the input range) or the thresholds themselves (strictly increasing,
    > 0). ``grid``: Preisach intervals; ``lambda_``: Preisach smoothness; ``dead_zones``: GPI
    dead zones per side. ``u`` may be a record with ``.u``, ``.y`` (then ``y`` is omitted).
    """
    u, y, ts = _pair(u, y, ("u", "y"), ts)
    name = _choice(family, "family")
    if name not in FAMILIES:
        raise ConfigError(f"family={family!r}: unknown hysteresis family; use one of {', '.join(FAMILIES)}")
    if isinstance(thresholds, (int, np.integer)) and not isinstance(thresholds, bool):
        count, grid_values = _count(thresholds, "thresholds"), []
    else:
        grid_values = [float(r) for r in _array(thresholds, "thresholds")]
        count = len(grid_values)
    lam = float(lambda_)
    if not (math.isfinite(lam) and lam >= 0.0):
        raise ConfigError(f"lambda_={lambda_!r}: the Preisach smoothness must be finite and >= 0")
    text = _hysid.identify_operator(
        u,
        y,
        name,
        _ts(ts, 1.0),
        count,
        grid_values,
        _count(grid, "grid"),
        lam,
        _count(dead_zones, "dead_zones"),
        _threads(threads),
    )
    return Result(json.loads(text))


def identify_hysteresis(
    x: Any,
    y: Any = None,
    *,
    hysteresis: str = "ch4",
    ts: float = 1.0,
    initial_output: str = "measured",
    threads: Optional[int] = None,
) -> Result:
    """Identifies a Coleman–Hodgdon hysteresis y = H[x] alone: separated linear regression
    with the switching threshold re-estimated, then output error. ``initial_output``:
    ``"measured"`` (the model starts from y[0]) or ``"zero"``. ``threads``: as for
    :func:`identify_cascade`."""
    x, y, ts = _pair(x, y, ("x", "y"), ts)
    text = _hysid.identify_hysteresis(
        x,
        y,
        _choice(hysteresis, "hysteresis"),
        _ts(ts, 1.0),
        _choice(initial_output, "initial_output"),
        _threads(threads),
    )
    return Result(json.loads(text))


def _configure(params: List[Parameter], init, fix, bounds) -> List[Parameter]:
    by_name = {p.name: p for p in params}

    def get(name: str, what: str) -> Parameter:
        if name not in by_name:
            raise ConfigError(f"{what}: no parameter '{name}'; the model's are {', '.join(by_name)}")
        return by_name[name]

    if init is not None:
        if not isinstance(init, dict):
            raise TypeError("init: give a dict name → start value")
        for name, v in init.items():
            get(name, "init").value = float(v)
    if isinstance(fix, str):
        fix = (fix,)
    for name in fix:
        get(name, "fix").fixed = True
    if bounds is not None:
        if not isinstance(bounds, dict):
            raise TypeError("bounds: give a dict name → (lower, upper)")
        for name, (lo, hi) in bounds.items():
            p = get(name, "bounds")
            p.lower, p.upper = float(lo), float(hi)
    for p in params:
        if not math.isfinite(p.value):
            raise ConfigError(f"parameter {p.name}: start value {p.value} is not finite")
    return params


def greybox_fit(
    model: Any,
    u: Any,
    y: Any = None,
    *,
    ts: Optional[float] = None,
    init: Optional[Dict[str, float]] = None,
    fix: Iterable[str] = (),
    bounds: Optional[Dict[str, Tuple[float, float]]] = None,
    starts: int = 1,
    seed: int = 0,
    integrator: str = "rk4",
    substeps: int = 10,
    interpolation: str = "zoh",
    threads: Optional[int] = None,
) -> Result:
    """Output-error fit of a continuous-time grey-box model ẋ = f(t, x, u, θ), y = h(x, u, θ).

    ``model``: a built-in name (``"bouc-wen"``, ``"rigid-body"``, ``"actuator-fixed"``,
    ``"actuator-free"``) or a :class:`GreyBoxModel`. ``u``: 1-D or (samples, inputs);
    ``y``: 1-D or (samples, outputs). ``init`` (name → start value), ``fix`` (names held
    fixed), ``bounds`` (name → (lower, upper)) change the model's parameters; ``starts``
    > 1 screens that many random starts (seeded by ``seed``) before the full fit.
    Integration: RK4 (or Newmark) with ``substeps`` per sample, inputs held (``zoh``),
    interpolated (``linear``) or band-limited between samples. Built-in models and
    equation models (:meth:`GreyBoxModel.from_equations`) use exact sensitivities and
    ``threads`` workers (None: the process default, all cores); a :class:`GreyBoxModel`
    written as Python functions uses finite differences, on one thread. The report is the
    CLI's ``greybox fit`` report (``--model-file`` for an equation model).
    """
    u, y, ts = _pair_channels(u, y, ts)
    ts = _ts(ts)
    args = (
        _count(starts, "starts"),
        _count(seed, "seed"),
        _choice(integrator, "integrator"),
        _count(substeps, "substeps"),
        _choice(interpolation, "interpolation"),
    )
    if isinstance(model, GreyBoxModel):
        user = copy.copy(model)
        user.parameters = _configure([copy.copy(p) for p in model.parameters], init, fix, bounds)
        if len(u) != user.inputs:
            raise DataError(f"u has {len(u)} channel(s); the model has {user.inputs} input(s)")
        if len(y) != user.outputs:
            raise DataError(f"y has {len(y)} channel(s); the model has {user.outputs} output(s)")
        if user.equations is not None:
            params = [p._tuple() for p in user.parameters]
            text = _hysid.greybox_fit_equations(user.equations, u, y, ts, params, *args, _threads(threads))
            return Result(json.loads(text))
        text = _hysid.greybox_fit_user(user._spec(), u, y, ts, *args)
        return Result(json.loads(text), user)
    if not isinstance(model, str):
        raise TypeError(f"model: give a built-in model name or a hysid.GreyBoxModel, got {type(model).__name__}")
    defaults, _, _ = _hysid.model_parameters(model)
    params = [Parameter(n, v, lower=lo, upper=hi, fixed=f, unit=unit) for (n, v, lo, hi, f, unit) in defaults]
    params = _configure(params, init, fix, bounds)
    text = _hysid.greybox_fit(model, u, y, ts, [p._tuple() for p in params], *args, _threads(threads))
    return Result(json.loads(text))


def _pair_channels(u: Any, y: Any, ts: Optional[float]):
    if y is None and hasattr(u, "u") and hasattr(u, "y"):
        rec_ts = getattr(u, "sampling_time", None)
        u, y = u.u, u.y
        if ts is None and rec_ts is not None:
            ts = float(rec_ts)
    if y is None:
        raise TypeError("give y, or pass a record with .u and .y as u")
    uc, yc = _channels(u, "u"), _channels(y, "y")
    if uc[0].shape[0] != yc[0].shape[0]:
        raise DataError(f"u has {uc[0].shape[0]} samples and y {yc[0].shape[0]}; give equal lengths")
    return uc, yc, ts


#: Sampling frequency of the Bouc–Wen benchmark records [Hz].
BOUC_WEN_FS = 750.0


def benchmark_bouc_wen(
    u_train: Any,
    y_train: Any = None,
    *,
    tests: Sequence[Any] = (),
    steady_state: bool = False,
    ts: Optional[float] = None,
    starts: int = 8,
    seed: int = 1,
    substeps: int = 4,
    start_factor: float = 1.0,
    threads: Optional[int] = None,
) -> Result:
    """The Bouc–Wen hysteretic benchmark (Noël & Schoukens 2016): fits the Bouc–Wen
    oscillator m ÿ + c ẏ + k y + z = u, ż = α ẏ − β(γ|ẏ||z|^(ν−1) z − δ ẏ|z|^ν)
    (RK4 with ``substeps`` per sample, band-limited input) on the training record from the
    nominal parameters times ``start_factor`` with ``starts`` screened starts, then scores
    each test record by e_RMS = RMS(y − ŷ) in simulation mode (from rest, or with
    ``steady_state`` in the periodic steady state: the input applied twice). ``tests``:
    (u, y) pairs or records with ``.u``, ``.y``; ``Result.validation`` holds one entry per
    test with ``e_rms``. Records default to 750 Hz. ``threads``: as for
    :func:`identify_cascade`. The report is the CLI's ``benchmark bouc-wen`` report.
    """
    u, y, ts = _pair(u_train, y_train, ("u_train", "y_train"), ts)
    ts = _ts(ts, 1.0 / BOUC_WEN_FS)
    records = []
    for i, t in enumerate(tests):
        if hasattr(t, "u") and hasattr(t, "y"):
            tu, ty, tts = t.u, t.y, getattr(t, "sampling_time", None)
            name = str(getattr(t, "name", None) or f"test {i + 1}")
        else:
            try:
                tu, ty = t
            except (TypeError, ValueError):
                raise TypeError(f"tests[{i}]: give a (u, y) pair or a record with .u and .y") from None
            tts, name = None, f"test {i + 1}"
        tu, ty, _ = _pair(tu, ty, (f"tests[{i}].u", f"tests[{i}].y"), None)
        records.append((tu, ty, _ts(tts, ts), name))
    defaults, _, _ = _hysid.model_parameters("bouc-wen")
    params = [(n, v * float(start_factor) if not f else v, lo, hi, f, unit) for (n, v, lo, hi, f, unit) in defaults]
    text = _hysid.benchmark_bouc_wen(
        u,
        y,
        ts,
        params,
        records,
        bool(steady_state),
        _count(starts, "starts"),
        _count(seed, "seed"),
        _count(substeps, "substeps"),
        _threads(threads),
    )
    return Result(json.loads(text))


def rigid_body_ls(
    q: Any,
    u: Any,
    *,
    ts: float,
    gain: float = 1.0,
    offset: bool = False,
    cutoff_hz: float = 100.0,
    order: int = 4,
    decimation: int = 10,
    border: int = 50,
    inertia_name: str = "M",
    threads: Optional[int] = None,
) -> Result:
    """Rigid-body least squares (step 1 of Gunnar et al., ICRA 2006): position ``q``
    filtered by a zero-phase Butterworth low-pass (``order``, ``cutoff_hz``), velocity and
    acceleration by central differences, and g·u = M q̈ + Fv q̇ + Fc sgn(q̇) (+ offset)
    solved by linear least squares; ``decimation`` keeps every n-th equation, ``border``
    drops samples at each end (defaults: the CLI's, 10 and 50). ``Result.parameters`` holds the estimates and their std;
    the report's details hold the relative error and condition numbers (the CLI's
    ``rigid-body ls`` report); the model is the built-in ``rigid_body`` model."""
    qa, ua, _ = _pair(q, u, ("q", "u"), None)
    text = _hysid.rigid_body_ls(
        qa,
        ua,
        _ts(ts),
        float(gain),
        bool(offset),
        float(cutoff_hz),
        _count(order, "order"),
        _count(decimation, "decimation"),
        _count(border, "border"),
        str(inertia_name),
        _threads(threads),
    )
    return Result(json.loads(text))


#: Gear ratio r [m/rad] and saddle mass m [kg] of the actuator of Gunnar et al. (2006).
ACTUATOR_GEAR_RATIO, ACTUATOR_SADDLE_MASS = 1.867e-3, 1.2


def _actuator_sets(records: Any, ts: Optional[float]):
    """(sets [(torque, angle, ts)] for data sets 1–8, source, truth from rig.json or None)."""
    if isinstance(records, (str, os.PathLike)):
        folder = os.fspath(records)
        sets = _hysid.actuator_read_data_sets(folder)
        truth = None
        rig = os.path.join(folder, "rig.json")
        if os.path.isfile(rig):
            with open(rig, encoding="utf-8") as f:
                given = json.load(f).get("truth") or {}
            names = _hysid.actuator_parameter_names()
            missing = [n for n in names if n not in given]
            if missing:
                raise ModelFileError(
                    f"{rig}: truth.{missing[0]} is missing (remove the file or rewrite it with hysid.actuator_rig)"
                )
            truth = {n: float(given[n]) for n in names}
        return sets, folder, truth
    if isinstance(records, dict):
        keys = sorted(records)
        if keys != list(range(1, 9)):
            raise DataError(f"records: the keys must be the data sets 1 to 8, got {keys}")
        records = [records[k] for k in keys]
    try:
        records = list(records)
    except TypeError:
        raise TypeError("records: give a directory, a list of 8 records or a dict {1: …, 8: …}") from None
    if len(records) != 8:
        raise DataError(f"records: {len(records)} data sets given; the procedure needs data sets 1 to 8 in order")
    sets = []
    for i, rec in enumerate(records):
        name = f"data set {i + 1}"
        if hasattr(rec, "u") and hasattr(rec, "y"):
            tau, theta, rts = rec.u, rec.y, getattr(rec, "sampling_time", None)
        elif isinstance(rec, (tuple, list)) and len(rec) in (2, 3):
            tau, theta, rts = rec[0], rec[1], (rec[2] if len(rec) == 3 else None)
        else:
            raise TypeError(f"records[{i}]: give (torque, angle), (torque, angle, ts) or a record with .u, .y")
        tau, theta, _ = _pair(tau, theta, (f"{name} torque", f"{name} angle"), None)
        sets.append((tau, theta, _ts(rts if rts is not None else ts)))
    return sets, "python (numpy arrays)", None


def actuator_three_steps(
    records: Any,
    *,
    ts: Optional[float] = None,
    truth: Optional[Dict[str, float]] = None,
    gear_ratio: float = ACTUATOR_GEAR_RATIO,
    saddle_mass: float = ACTUATOR_SADDLE_MASS,
    cutoff_hz: float = 100.0,
    remove_mean: bool = False,
    reversal_margin: float = 0.05,
    unfiltered_step3: bool = False,
    max_iterations: int = 30,
    tolerance: float = 1e-4,
    threads: Optional[int] = None,
) -> Result:
    """The three-step identification of a linear actuator with hysteresis (J. Gunnar,
    E. Wernholt, G. Hovland, T. Brogårdh, "Nonlinear Grey-Box Identification of Linear
    Actuators Containing Hysteresis", ICRA 2006), as ``hysid actuator identify`` runs it.

    ``records``: data sets 1–8 (motor torque τ [N·m] in, motor angle θ [rad] out), as a
    directory holding ``dataset1.csv`` … ``dataset8.csv`` (columns t_s, tau_Nm, theta_rad;
    a ``rig.json`` beside them gives the true parameters), a list of 8 records — each
    ``(torque, angle)``, ``(torque, angle, ts)`` or an object with ``.u`` (torque), ``.y``
    (angle) and ``.sampling_time`` — or a dict ``{1: …, 8: …}``. ``ts`` is the sample time
    of records that do not carry one.

    1. Rigid body (set 1, saddle free): Jt θ̈ + Fv θ̇ + Fc sgn(θ̇) = τ by least squares on the
       filtered, differentiated angle; J = Jt − r² m (``gear_ratio`` r, ``saddle_mass`` m).
    2. Steady-state loops (sets 2–5, saddle fixed): τn = k1 x1 + k2 x1³ + Cu/d(x1) with the
       Dhaouadi-type hysteresis branches, α by a profile search, k1, k2, A by least
       squares; samples within ``reversal_margin`` of a reversal are left out.
    3. Output error of the saddle-fixed model from m0 on set 6 with 7 (m67) and with 8
       (m68), all seven parameters free or J, Fv, Fc fixed (m67f, m68f); at most
       ``max_iterations`` iterations, stopped when the expected improvement falls below
       ``tolerance``.

    Preprocessing: 4th-order zero-phase Butterworth at ``cutoff_hz`` on every signal
    (``unfiltered_step3`` fits step 3 on the raw records), optional mean removal.

    Returns a :class:`Result` whose ``parameters`` and ``model`` are m67's (J, Fv, Fc, k1,
    k2, alpha, A), ``validation`` lists m67 on sets 6–8, and ``report()`` is the CLI's JSON
    report: ``details.steps`` holds one report per step (step 1, step 2, step 3 m67, m68,
    m67f, m68f), ``details.fit_table`` Table II, ``details.truth`` the true parameters when
    known (``truth`` dict or ``rig.json``). The GIL is released; ``threads`` as for
    :func:`identify_cascade`.
    """
    sets, source, rig_truth = _actuator_sets(records, ts)
    names = _hysid.actuator_parameter_names()
    truth = truth if truth is not None else rig_truth
    if truth is not None:
        if not isinstance(truth, dict):
            raise TypeError("truth: give a dict name → value")
        unknown = [n for n in truth if n not in names]
        if unknown or len(truth) != len(names):
            raise ConfigError(f"truth: give a value for each of {', '.join(names)}")
        truth_values: Optional[List[float]] = [float(truth[n]) for n in names]
    else:
        truth_values = None
    text = _hysid.actuator_three_steps(
        sets,
        source,
        truth_values,
        float(gear_ratio),
        float(saddle_mass),
        float(cutoff_hz),
        bool(remove_mean),
        float(reversal_margin),
        bool(unfiltered_step3),
        _count(max_iterations, "max_iterations"),
        float(tolerance),
        _threads(threads),
    )
    return Result(json.loads(text))


class ActuatorRecord:
    """One data set of the virtual actuator rig: ``set`` (1–8), ``saddle_free``, ``u`` (motor
    torque [N·m]), ``y`` (motor angle [rad]), ``sampling_time`` [s] — the attributes of a
    ``nonlinear_benchmarks`` record, so it goes wherever one does."""

    __slots__ = ("set", "saddle_free", "u", "y", "sampling_time")

    def __init__(self, set: int, saddle_free: bool, u: np.ndarray, y: np.ndarray, sampling_time: float) -> None:
        self.set, self.saddle_free = set, saddle_free
        self.u, self.y, self.sampling_time = u, y, sampling_time

    def __repr__(self) -> str:
        return f"ActuatorRecord(set {self.set}, {self.u.size} samples at {1 / self.sampling_time:g} Hz)"

    def __getstate__(self):
        return tuple(getattr(self, s) for s in self.__slots__)

    def __setstate__(self, state):
        for name, v in zip(self.__slots__, state):
            object.__setattr__(self, name, v)


def actuator_rig(
    *,
    truth: Optional[Dict[str, float]] = None,
    backlash: float = 0.0,
    noise: float = 1.0,
    seed: int = 0,
    gear_ratio: float = ACTUATOR_GEAR_RATIO,
    saddle_mass: float = ACTUATOR_SADDLE_MASS,
) -> List[ActuatorRecord]:
    """The eight data sets of the virtual actuator rig (``hysid actuator rig``): the
    actuator of Gunnar et al. (2006) simulated at 1 kHz with the true parameters ``truth``
    (name → value for J, Fv, Fc, k1, k2, alpha, A; default Table I's m67), an optional
    backlash of width ``backlash`` [rad] in the flexibility, and quantisation-level noise
    times ``noise`` (seeded by ``seed``). Returns 8 :class:`ActuatorRecord` for
    :func:`actuator_three_steps`."""
    names = _hysid.actuator_parameter_names()
    values = None
    if truth is not None:
        if not isinstance(truth, dict):
            raise TypeError("truth: give a dict name → value")
        unknown = [n for n in truth if n not in names]
        if unknown:
            raise ConfigError(f"truth: no parameter '{unknown[0]}'; the parameters are {', '.join(names)}")
        defaults = dict(zip(names, _hysid.actuator_rig_truth()))
        defaults.update({k: float(v) for k, v in truth.items()})
        values = [defaults[n] for n in names]
    sets = _hysid.actuator_rig(
        values, float(backlash), float(noise), _count(seed, "seed"), float(gear_ratio), float(saddle_mass)
    )
    return [ActuatorRecord(k, free, tau, theta, t) for (k, free, t, tau, theta) in sets]


from . import fleet  # noqa: E402, F401  (imports Result from this module)
from .export import export as _export  # noqa: E402

Model.export = _export  # Model.export(target, name, out, *, inverse, ts, binary): hysid/export.py
