"""Grey-box models written by the user: :class:`GreyBoxModel`, as Python functions or as an
equation file's text."""

from __future__ import annotations

import copy
import json
import math
import os
from typing import Any, Callable, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np

from . import _hysid
from ._hysid import CallbackError, ConfigError, DataError, ModelFileError
from ._inputs import FloatArray, Samples, array, choice, count
from .models import CallbackSpec, Evaluator, Model
from .parameters import Parameter

#: How a continuous-time model is integrated between samples.
Integrator = Literal["rk4", "newmark"]

#: What the input does between samples: held, interpolated, or band-limited.
Interpolation = Literal["zoh", "linear", "band-limited"]

#: A model function f(t, x, u, p) -> array.
ModelFunction = Callable[[float, FloatArray, FloatArray, FloatArray], Any]


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
    #: The state names.
    states: List[str]
    #: The parameters, in the order of ``p``.
    parameters: List[Parameter]
    #: The right-hand side f and the output map h (None for an equation model).
    rhs: Optional[ModelFunction]
    output: Optional[ModelFunction]
    #: Input and output counts.
    inputs: int
    outputs: int
    #: An equation model's name, input and output names, and which initial states it estimates.
    name: str
    input_names: List[str]
    output_names: List[str]
    x0_estimated: List[bool]
    #: The initial state.
    x0: FloatArray

    def __init__(
        self,
        states: Any,
        parameters: Sequence[Parameter],
        rhs: ModelFunction,
        output: ModelFunction,
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
        self.inputs = count(inputs, "inputs")
        if x0 is None:
            self.x0 = np.zeros(len(self.states))
        else:
            self.x0 = array(x0, "x0")
            if self.x0.shape != (len(self.states),):
                raise DataError(f"x0 has {self.x0.size} values for {len(self.states)} states")
        self.outputs = self._probe(rhs, output)

    def _probe(self, rhs: ModelFunction, output: ModelFunction) -> int:
        """Calls rhs and output once at x0 to check their shapes; returns the output count."""
        x, u = self.x0.copy(), np.zeros(self.inputs)
        p = np.array([q.value for q in self.parameters])
        dx = _call_checked(rhs, "rhs", (0.0, x, u, p))
        if dx.shape != (len(self.states),):
            raise CallbackError(f"rhs(t, x, u, p) returned shape {dx.shape}; it must return ({len(self.states)},)")
        y = _call_checked(output, "output", (math.nan, x, u, p))
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
    def from_equations_file(cls, path: Union[str, "os.PathLike[str]"]) -> "GreyBoxModel":
        """:meth:`from_equations` on the text of the file at ``path`` (errors name the file)."""
        if not isinstance(path, (str, os.PathLike)):
            raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise ModelFileError(f"cannot read equation file {os.fspath(path)}: {e.strerror}") from None
        return cls.from_equations(text, origin=os.fspath(path))

    def to_model(
        self, *, integrator: Integrator = "rk4", substeps: int = 10, interpolation: Interpolation = "zoh"
    ) -> "Model":
        """The model with its current parameter values as a :class:`Model` (simulate, save;
        an equation model's file is the ``equations`` kind the CLI reads)."""
        sim = (choice(integrator, "integrator"), count(substeps, "substeps"), choice(interpolation, "interpolation"))
        if self.equations is not None:
            params = [p.as_tuple() for p in self.parameters]
            x0 = [float(v) for v in self.x0]
            return Model(json.loads(_hysid.equation_model_file(self.equations, params, x0, *sim)))
        records = [dict(p.to_record(), std=None) for p in self.parameters]
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
        self,
        u: Samples,
        *,
        ts: float,
        integrator: Integrator = "rk4",
        substeps: int = 10,
        interpolation: Interpolation = "zoh",
        evaluator: Optional[Evaluator] = None,
    ) -> FloatArray:
        """The output for input ``u`` (1-D, or 2-D (samples, inputs)) sampled every ``ts``
        seconds, from ``x0`` with the current parameter values (RK4 with ``substeps`` per
        sample; inputs ``zoh``, ``linear`` or ``band-limited`` between samples); an
        equation model's ``evaluator`` as in :meth:`Model.simulate`."""
        model = self.to_model(integrator=integrator, substeps=substeps, interpolation=interpolation)
        return model.simulate(u, ts=ts, evaluator=evaluator)

    def _spec(self, values: Optional[Sequence[float]] = None) -> CallbackSpec:
        """The model as the extension module takes it, with ``values`` for the parameters."""
        params = [p.as_tuple() for p in self.parameters]
        if values is not None:
            params = [(n, float(v), lo, hi, f, unit) for (n, _, lo, hi, f, unit), v in zip(params, values)]
        return (self.rhs, self.output, self.states, self.inputs, self.outputs, params, [float(v) for v in self.x0])

    def __repr__(self) -> str:
        kind = f"equations '{self.name}', " if self.equations is not None else ""
        return f"GreyBoxModel({kind}states={self.states}, parameters={[p.name for p in self.parameters]}, inputs={self.inputs}, outputs={self.outputs})"


def _call_checked(f: ModelFunction, which: str, args: Tuple[float, FloatArray, FloatArray, FloatArray]) -> FloatArray:
    try:
        out = f(*args)
    except Exception as e:  # noqa: BLE001 — re-raised with the callback's name
        raise CallbackError(f"{which}(t, x, u, p) raised {type(e).__name__}: {e}") from e
    try:
        return np.asarray(out, dtype=np.float64)
    except (TypeError, ValueError):
        raise CallbackError(f"{which}(t, x, u, p) returned {out!r}; return a 1-D float array") from None
