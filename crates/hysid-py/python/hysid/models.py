"""Fitted models: :class:`Model` (the ``hysid.model/1`` model file the CLI reads and
writes) and :func:`load_model`.

A model simulates itself, saves, pickles and prints. Further abilities go in their own
module and one method here each (see "Deployment" in :class:`Model`).
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, List, Optional, Protocol, Sequence, Tuple, Union

import numpy as np

from . import _hysid
from ._hysid import ModelFileError
from ._inputs import FloatArray, channels, sample_time
from .parameters import Parameter, ParameterTuple

#: A model written as Python functions, as the extension module takes it: (rhs, output,
#: state names, inputs, outputs, parameters, initial state).
CallbackSpec = Tuple[Callable[..., Any], Callable[..., Any], List[str], int, int, List[ParameterTuple], List[float]]


class Callbacks(Protocol):
    """What a :class:`Model` needs of a model written as Python functions
    (:class:`hysid.GreyBoxModel`): its functions with given parameter values."""

    def _spec(self, values: Optional[Sequence[float]] = None) -> CallbackSpec: ...


class Model:
    """A fitted model (the ``hysid.model/1`` model file the CLI reads and writes).

    ``simulate(u, *, ts, y0=None)`` returns the simulated output (1-D for one output,
    ``(samples, outputs)`` otherwise); ``save(path)`` writes the model file;
    ``.file`` is its content as a dict.
    """

    def __init__(self, file: Dict[str, Any], user: Optional[Callbacks] = None) -> None:
        self.file = file
        self._user = user

    @property
    def kind(self) -> str:
        """The model file's kind (``operator``, ``ch_cascade``, ``bouc_wen``, …)."""
        return str(self.file["kind"])

    @property
    def parameters(self) -> Dict[str, Parameter]:
        """The parameters by name (fresh copies)."""
        return {r["name"]: Parameter.from_record(r) for r in self.file["parameters"]}

    def simulate(self, u: Any, *, ts: float, y0: Optional[float] = None) -> FloatArray:
        """The model's output for input ``u`` (1-D, or 2-D (samples, inputs)) sampled every
        ``ts`` seconds; ``y0`` is the measured initial output, for a hysteresis that starts
        from it."""
        step = sample_time(ts)
        inputs = channels(u, "u")
        start = None if y0 is None else float(y0)
        if self._user is not None:
            sim = self.file.get("simulation") or {}
            outs = _hysid.simulate_user(
                self._user._spec([r["value"] for r in self.file["parameters"]]),
                inputs,
                step,
                _integrator_name(sim),
                int(sim.get("substeps") or 1),
                _interp_name(sim),
            )
        else:
            outs = _hysid.simulate_model(json.dumps(self.file), inputs, step, start)
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

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Model) and self.file == other.file

    def __repr__(self) -> str:
        values = ", ".join(f"{r['name']}={r['value']:.6g}" for r in self.file["parameters"])
        return f"Model({self.kind}: {values})"

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_model_from_json, (json.dumps(self.file), self._user))


def _integrator_name(sim: Dict[str, Any]) -> str:
    name = str(sim.get("integrator", "rk4")).lower()
    return "newmark" if "newmark" in name else "rk4"


def _interp_name(sim: Dict[str, Any]) -> str:
    name = str(sim.get("interpolation", "zoh")).lower().replace("_", "-")
    if "band" in name:
        return "band-limited"
    return "linear" if "linear" in name else "zoh"


def _model_from_json(text: str, user: Optional[Callbacks]) -> Model:
    return Model(json.loads(text), user)


def load_model(path: Union[str, "os.PathLike[str]"]) -> Model:
    """Reads a model file written by the CLI (``--model``) or by :meth:`Model.save`."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a str or path, got {type(path).__name__}")
    return Model(json.loads(_hysid.load_model(os.fspath(path))))
