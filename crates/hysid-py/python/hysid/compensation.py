"""Feed-forward compensation: :class:`Compensation`, the input that makes a fitted model
follow a reference, built on the ``hysid compensate`` report, every field read once and
checked."""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List, Optional, Tuple

from ._fields import Fields, ReportError
from ._inputs import FloatArray, Samples
from .models import Model, model_in
from .plot import Axes, Figure
from .results import REPORT_SCHEMA


class Compensation:
    """The input that makes a model follow a reference (:func:`hysid.compensate`).

    ``reference`` (r), ``u`` (the compensating input), ``predicted`` (the model's output
    for u: r wherever r is reachable), ``clipped`` (indices of the reference samples the
    model cannot reach, clipped to the nearest reachable output), ``clipped_ranges``
    (the same as inclusive (first, last) ranges), ``tracking_rms`` and ``tracking_max``
    (the predicted tracking error), ``model`` and ``ts``. ``plot()`` (matplotlib),
    ``report()``.
    """

    reference: FloatArray
    u: FloatArray
    predicted: FloatArray
    clipped: List[int]
    clipped_ranges: List[Tuple[int, int]]
    tracking_rms: float
    tracking_max: float
    model: Model
    ts: float

    def __init__(
        self, report: Dict[str, Any], reference: FloatArray, u: FloatArray, predicted: FloatArray, ts: float
    ) -> None:
        f = Fields(report, "report")
        if f.get("schema", str) != REPORT_SCHEMA or f.get("command", str) != "compensate":
            raise ReportError("report: not the hysid.report/1 report of compensate")
        model = model_in(f.raw("model"), "report.model")
        if model is None:
            raise ReportError("report.model is null; a compensation names its model")
        self.model = model
        details = f.object("details")
        if details is None:
            raise ReportError("report.details is null; a compensation holds its figures there")
        tracking = details.object("tracking_error")
        clipped = details.object("clipped")
        if tracking is None or clipped is None:
            raise ReportError("report.details: tracking_error and clipped must be objects")
        self.tracking_rms = tracking.get("rms", float)
        self.tracking_max = tracking.get("max", float)
        self.clipped = [_index(v, "report.details.clipped.indices") for v in clipped.get("indices", list)]
        self.clipped_ranges = [_range(v) for v in clipped.get("ranges", list)]
        if clipped.get("count", int) != len(self.clipped):
            raise ReportError("report.details.clipped: count and indices disagree")
        if not (len(reference) == len(u) == len(predicted)):
            raise ReportError("compensate: reference, u and predicted differ in length")
        self.reference, self.u, self.predicted, self.ts = reference, u, predicted, ts
        self._report = report

    def report(self) -> Dict[str, Any]:
        """The ``hysid.report/1`` report of ``hysid compensate`` as a dict (a copy)."""
        return copy.deepcopy(self._report)

    def plot(
        self,
        *,
        ax: Optional[Axes] = None,
        measured: Optional[Samples] = None,
        plant: Optional[Model] = None,
        units: Optional[Tuple[str, str]] = None,
    ) -> Figure:
        """The reference, the command below it and, given the ``measured`` response to the
        command or a ``plant`` model to simulate it, the tracking error
        (:func:`hysid.plot.compensation`)."""
        from .plot import compensation

        return compensation(self, ax=ax, measured=measured, plant=plant, units=units)

    def __repr__(self) -> str:
        kind = self.model.family or self.model.kind
        return (
            f"Compensation({kind}: {len(self.u)} samples, tracking RMS {self.tracking_rms:.3e}, "
            f"max {self.tracking_max:.3e}, {len(self.clipped)} clipped)"
        )

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_from_json, (json.dumps(self._report), self.reference, self.u, self.predicted, self.ts))


def _index(v: Any, where: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise ReportError(f"{where}: expected integers, got {type(v).__name__}")
    return v


def _range(v: Any) -> Tuple[int, int]:
    where = "report.details.clipped.ranges"
    if not isinstance(v, list) or len(v) != 2:
        raise ReportError(f"{where}: expected [first, last] pairs")
    return (_index(v[0], where), _index(v[1], where))


def _from_json(text: str, reference: FloatArray, u: FloatArray, predicted: FloatArray, ts: float) -> Compensation:
    return Compensation(json.loads(text), reference, u, predicted, ts)
