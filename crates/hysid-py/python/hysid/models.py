"""Fitted models: :class:`Model` (the ``hysid.model/1`` model file the CLI reads and
writes) and :func:`load_model`.

A model simulates itself, saves, pickles and prints. Further abilities go in their own
module and one method here each (see "Deployment" in :class:`Model`).
"""

from __future__ import annotations

import copy
import errno
import json
import math
import os
from typing import Any, Callable, Dict, List, Literal, Optional, Protocol, Sequence, Tuple, Union, get_args

import numpy as np

from . import _hysid
from ._fields import Fields, ReportError
from ._hysid import ModelFileError
from ._inputs import FloatArray, Samples, channels, choice, sample_time
from .export import Precision, Target, export
from .parameters import Parameter, ParameterTuple
from .stream import Compensator, Stepper, compensator, stepper

#: How an equation model's equations are evaluated: native code from the C compiler
#: (cached) else the tape interpreter (``auto``), native code only (``cc``: an error when no
#: C compiler works), or the tape interpreter (``tape``).
Evaluator = Literal["auto", "cc", "tape"]

#: A model written as Python functions, as the extension module takes it: (rhs, output,
#: state names, inputs, outputs, parameters, initial state).
CallbackSpec = Tuple[
    Optional[Callable[..., Any]], Optional[Callable[..., Any]], List[str], int, int, List[ParameterTuple], List[float]
]


#: The model file format this package reads and writes.
MODEL_SCHEMA = "hysid.model/1"


def _parameter(rec: Fields) -> Parameter:
    """A model file's parameter record, every field checked."""
    lower, upper = rec.optional("lower", float), rec.optional("upper", float)
    return Parameter(
        rec.get("name", str),
        rec.get("value", float),
        lower=-math.inf if lower is None else lower,
        upper=math.inf if upper is None else upper,
        fixed=rec.get("fixed", bool),
        unit=rec.get("unit", str),
        std=rec.optional("std", float),
    )


class Callbacks(Protocol):
    """What a :class:`Model` needs of a model written as Python functions
    (:class:`hysid.GreyBoxModel`): its functions with given parameter values."""

    def _spec(self, values: Optional[Sequence[float]] = None) -> CallbackSpec: ...


class Model:
    """A fitted model (the ``hysid.model/1`` model file the CLI reads and writes).

    ``simulate(u, *, ts, y0=None)`` returns the simulated output (1-D for one output,
    ``(samples, outputs)`` otherwise); ``save(path)`` writes the model file; ``.file`` is
    its content as a dict; ``.kind``, ``.parameters`` (name → :class:`Parameter`) and, for
    a hysteresis operator, ``.family`` are read from it once, checked
    (:class:`ReportError` for a missing or ill-typed field).
    """

    #: The model file's kind (``operator``, ``coleman_hodgdon``, ``ch_cascade``, ``bouc_wen``, …).
    kind: str
    #: The operator family of an ``operator`` model (``pi``, ``preisach``, …), else None.
    family: Optional[str]

    def __init__(self, file: Dict[str, Any], user: Optional[Callbacks] = None) -> None:
        fields = Fields(file, "model")
        schema = fields.get("schema", str)
        if schema != MODEL_SCHEMA:
            raise ReportError(f"model.schema is {schema!r}; this hysid reads {MODEL_SCHEMA!r}")
        self.kind = fields.get("kind", str)
        self.family = fields.absent_or("family", str) if self.kind == "operator" else None
        self._parameters = [_parameter(r) for r in fields.objects("parameters")]
        self.file = file
        self._user = user
        self._callback_simulation = None if user is None else _callback_simulation(fields)

    @property
    def sample_time(self) -> Optional[float]:
        """The sample time in seconds of the data the model was fitted on (the model
        file's ``sample_time``: every recipe's fit from Python writes its ``ts``); None in a
        file without one."""
        value = self.file.get("sample_time")
        return None if value is None else float(value)

    @property
    def columns(self) -> Optional[Tuple[List[str], List[str]]]:
        """The names of the input and output channels the model was fitted on (the model
        file's ``columns``, which name an export's inputs and outputs): ``(inputs,
        outputs)``; None in a file without them."""
        cols = self.file.get("columns")
        if not isinstance(cols, dict):
            return None
        return [str(n) for n in cols.get("inputs", [])], [str(n) for n in cols.get("outputs", [])]

    @property
    def parameters(self) -> Dict[str, Parameter]:
        """The parameters by name (copies: changing one leaves the model as it is)."""
        return {p.name: copy.copy(p) for p in self._parameters}

    def simulate(
        self, u: Samples, *, ts: float, y0: Optional[float] = None, evaluator: Optional[Evaluator] = None
    ) -> FloatArray:
        """The model's output for input ``u`` (1-D, or 2-D (samples, inputs)) sampled every
        ``ts`` seconds; ``y0`` is the measured initial output, for a hysteresis that starts
        from it. ``evaluator`` (an equation model's, the CLI's ``--evaluator``): ``"auto"``,
        ``"cc"`` (native code only: :class:`ConfigError` when no C compiler works) or
        ``"tape"``; None: ``HYSID_EVALUATOR``, else ``"auto"``; other models ignore it."""
        how = None if evaluator is None else choice(evaluator, "evaluator", get_args(Evaluator))
        step = sample_time(ts)
        inputs = channels(u, "u")
        start = None if y0 is None else float(y0)
        if self._user is not None and self._callback_simulation is not None:
            outs = _hysid.simulate_user(
                self._user._spec([p.value for p in self._parameters]), inputs, step, *self._callback_simulation
            )
        else:
            outs = _hysid.simulate_model(json.dumps(self.file), inputs, step, start, how)
        return outs[0] if len(outs) == 1 else np.column_stack(outs)

    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the model file (``hysid.model/1``) that ``hysid simulate --model`` reads."""
        if self._user is not None:
            raise ModelFileError(
                "a model written as Python functions cannot be saved as a model file (the CLI "
                "cannot run Python); pickle the Result instead"
            )
        with open(path, "w", encoding="utf-8") as f:
            f.write(_hysid.check_model(json.dumps(self.file)))
            f.write("\n")

    # Deployment: one method per module (stream.py: stepper, compensator; export.py: export).

    def stepper(self, *, ts: Optional[float] = None, y0: Optional[float] = None) -> Stepper:
        """The model one sample at a time (:mod:`hysid.stream`); ``ts`` defaults to the model
        file's sample time."""
        return stepper(self, ts=ts, y0=y0)

    def compensator(self, *, ts: Optional[float] = None, limits: Optional[Tuple[float, float]] = None) -> Compensator:
        """The model's compensator one sample at a time (:mod:`hysid.stream`), its command
        limited to ``limits`` (lo, hi), else to the model file's ``input_range``."""
        return compensator(self, ts=ts, limits=limits)

    def export(
        self,
        target: Target,
        name: str,
        out: "os.PathLike[str] | str",
        *,
        inverse: bool = False,
        ts: Optional[float] = None,
        binary: bool = True,
        y0: Optional[float] = None,
        limits: Optional[Tuple[float, float]] = None,
        precision: Precision = "double",
    ) -> List[str]:
        """The model as C99, a ``no_std`` Rust crate or an FMI 2.0 FMU (:mod:`hysid.export`,
        the command line's ``hysid export``; ``limits`` and ``precision`` as there); returns
        the paths written."""
        return export(
            self,
            target,
            name,
            out,
            inverse=inverse,
            ts=ts,
            binary=binary,
            y0=y0,
            limits=limits,
            precision=precision,
        )

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Model) and self.file == other.file

    def __repr__(self) -> str:
        values = ", ".join(f"{p.name}={p.value:.6g}" for p in self._parameters)
        return f"Model({self.kind}: {values})"

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_model_from_json, (json.dumps(self.file), self._user))


def model_in(value: Any, where: str, user: Optional[Callbacks] = None) -> Optional[Model]:
    """The model file ``value`` held by the report field ``where`` (None when null); errors
    name the field in the report."""
    if value is None:
        return None
    try:
        return Model(value, user)
    except ReportError as e:
        raise ReportError(f"{where}{str(e)[len('model') :]}") from None


def _callback_simulation(fields: Fields) -> Tuple[str, int, str]:
    """(integrator, substeps, interpolation) of a model written as Python functions, as
    the extension module takes them."""
    sim = fields.object("simulation")
    if sim is None:
        raise ReportError("model.simulation is null; a model written as Python functions needs its integrator")
    integrator = sim.get("integrator", str).lower()
    interpolation = sim.get("interpolation", str).lower().replace("_", "-")
    return (
        "newmark" if "newmark" in integrator else "rk4",
        sim.get("substeps", int),
        "band-limited" if "band" in interpolation else ("linear" if "linear" in interpolation else "zoh"),
    )


def _model_from_json(text: str, user: Optional[Callbacks]) -> Model:
    return Model(json.loads(text), user)


class ModelFileNotFoundError(ModelFileError, FileNotFoundError):
    """No model file at the path given: a ``FileNotFoundError`` (``errno.ENOENT``, with
    ``.filename``) as Python's own file functions raise, and a :class:`ModelFileError` as
    every other unreadable model file."""


def load_model(path: Union[str, "os.PathLike[str]"]) -> Model:
    """Reads a model file written by the CLI (``--model``) or by :meth:`Model.save`; a
    missing file is a :class:`ModelFileNotFoundError` (both ``FileNotFoundError`` and
    :class:`ModelFileError`)."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    where = os.fspath(path)
    if not os.path.exists(where):
        raise ModelFileNotFoundError(errno.ENOENT, "no model file there; check the path", where)
    return Model(json.loads(_hysid.load_model(where)))
