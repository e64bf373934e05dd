"""Streaming models: a saved model one sample at a time, as a controller runs it.

``Model.stepper()`` returns a :class:`Stepper` whose ``step(u)`` gives the model's output
for one input sample (exactly the sample ``Model.simulate`` gives there) and then advances
its state; ``Model.compensator()`` a :class:`Compensator` whose ``step(r)`` gives the
command that makes the model follow the reference ``r`` (clipped to the reachable range as
``hysid compensate`` clips, and counted in ``.clipped``). Both have ``run(array)``, which
feeds a whole record from the current state, and ``reset()``, back to the model's initial
state. The semantics are the library's (``hysid::model::stream``), with its two safety
rules (``docs/export.md``, "Limits and bad samples"): a compensator's command is limited to
``limits`` (default: the model file's ``input_range``), a limited command counting as
clipped; a NaN or infinite sample leaves the state unchanged, repeats the last good output
(a compensator: the limits' midpoint before any) and is counted in ``.faults``.
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any, Optional, Tuple, Union

import numpy as np

from . import _hysid
from ._inputs import FloatArray, Samples

if TYPE_CHECKING:  # pragma: no cover
    from .models import Model


class Stepper:
    """A model one sample at a time (see the module doc)."""

    def __init__(self, inner: Any, kind: str = "model", ts: float = math.nan) -> None:
        self._inner = inner
        self._kind = kind
        self._ts = ts

    def __repr__(self) -> str:
        ts = "" if math.isnan(self._ts) else f", ts={self._ts:g} s"
        return f"Stepper({self._kind}: {self.n_inputs} input(s), {self.n_outputs} output(s){ts})"

    @property
    def n_inputs(self) -> int:
        return int(self._inner.n_inputs)

    @property
    def n_outputs(self) -> int:
        return int(self._inner.n_outputs)

    @property
    def faults(self) -> int:
        """How many bad (non-finite) input samples since the last reset."""
        return int(self._inner.faults)

    def reset(self) -> None:
        """Back to the model's initial state."""
        self._inner.reset()

    def step(self, u: Union[float, Samples]) -> Union[float, FloatArray]:
        """The output for one input sample (a float, or one value per input); a float for a
        model of one output, else an array."""
        values = [float(v) for v in np.atleast_1d(np.asarray(u, dtype=np.float64))]
        y = self._inner.step(values)
        return y[0] if len(y) == 1 else np.asarray(y)

    def run(self, u: Samples) -> FloatArray:
        """The outputs for the input samples ``u`` (1-D, or 2-D (samples, inputs)) from the
        current state: 1-D for one output, ``(samples, outputs)`` otherwise."""
        a = np.asarray(u, dtype=np.float64)
        channels = [np.ascontiguousarray(a)] if a.ndim == 1 else [np.ascontiguousarray(c) for c in a.T]
        outs = self._inner.run(channels)
        return outs[0] if len(outs) == 1 else np.column_stack(outs)


class Compensator:
    """A model's compensator one sample at a time (see the module doc)."""

    def __init__(self, inner: Any, kind: str = "model", ts: float = math.nan) -> None:
        self._inner = inner
        self._kind = kind
        self._ts = ts

    def __repr__(self) -> str:
        ts = "" if math.isnan(self._ts) else f", ts={self._ts:g} s"
        return f"Compensator({self._kind}: preview {self.preview}, {self.clipped} clipped{ts})"

    @property
    def clipped(self) -> int:
        """How many references were clipped since the last reset."""
        return int(self._inner.clipped)

    @property
    def faults(self) -> int:
        """How many bad (non-finite) references since the last reset."""
        return int(self._inner.faults)

    @property
    def limits(self) -> Optional[Tuple[float, float]]:
        """The command limits (lo, hi), or None when the command is not limited."""
        limits = self._inner.limits
        return None if limits is None else (float(limits[0]), float(limits[1]))

    @property
    def preview(self) -> int:
        """How many samples ahead the reference is given (a cascade's delay; 0 otherwise)."""
        return int(self._inner.preview)

    def reset(self) -> None:
        """Back to the model's initial state (and ``clipped`` and ``faults`` to 0)."""
        self._inner.reset()

    def step(self, r: float) -> float:
        """The command for the reference sample ``r``."""
        u, _, _ = self._inner.step(float(r))
        return float(u)

    def run(self, r: Samples) -> FloatArray:
        """The commands for the references ``r`` (1-D) from the current state."""
        u, _ = self._inner.run(np.ascontiguousarray(np.asarray(r, dtype=np.float64)))
        return np.asarray(u, dtype=np.float64)


def _ts(model: "Model", ts: Optional[float]) -> float:
    """The sample time: the given one, else the model file's, else NaN (refused by the
    models that need one, unused by the others)."""
    if ts is not None:
        return float(ts)
    saved = model.file.get("sample_time")
    return float(saved) if saved is not None else math.nan


def stepper(model: "Model", *, ts: Optional[float] = None, y0: Optional[float] = None) -> Stepper:
    """The :class:`Stepper` of ``model``."""
    step = _ts(model, ts)
    inner = _hysid.model_stepper(json.dumps(model.file), step, None if y0 is None else float(y0))
    return Stepper(inner, model.kind, step)


def compensator(
    model: "Model", *, ts: Optional[float] = None, limits: Optional[Tuple[float, float]] = None
) -> Compensator:
    """The :class:`Compensator` of ``model``, its command limited to ``limits`` (lo, hi),
    else to the model file's ``input_range``, else not at all."""
    step = _ts(model, ts)
    inner = _hysid.model_compensator(json.dumps(model.file), step, _limits(limits))
    return Compensator(inner, model.kind, step)


def _limits(limits: Optional[Tuple[float, float]]) -> Optional[Tuple[float, float]]:
    """``limits`` checked: None, or two numbers (lo, hi)."""
    if limits is None:
        return None
    try:
        lo, hi = limits
    except (TypeError, ValueError):
        raise TypeError(f"limits: give (lo, hi), two numbers, got {limits!r}") from None
    return (float(lo), float(hi))
