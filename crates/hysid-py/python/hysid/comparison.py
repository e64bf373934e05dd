"""Several hysteresis families compared on one record: :class:`Comparison`, built on the
``hysid compare`` report, every field read once and checked."""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List, Optional, Sequence, Tuple, TypedDict

import numpy as np

from ._fields import Fields, ReportError
from ._inputs import FloatArray
from .models import Model, model_in
from .plot import Axes, Figure
from .results import REPORT_SCHEMA, FitResult, Record, labelled


class CompareRow(TypedDict):
    """One family's row of a comparison (None where the family failed)."""

    family: str
    validation_fit_percent: Optional[float]
    validation_rmse: Optional[float]
    train_fit_percent: Optional[float]
    parameters: Optional[int]
    aic: Optional[float]
    fit_time_s: Optional[float]
    converged: Optional[bool]
    termination: Optional[str]
    orientation: Optional[str]
    orientation_source: Optional[str]
    initial_state: Optional[str]
    error: Optional[str]


def _row(f: Fields) -> CompareRow:
    return {
        "family": f.get("family", str),
        "validation_fit_percent": f.optional("validation_fit_percent", float),
        "validation_rmse": f.optional("validation_rmse", float),
        "train_fit_percent": f.optional("train_fit_percent", float),
        "parameters": f.optional("parameters", int),
        "aic": f.optional("aic", float),
        "fit_time_s": f.optional("fit_time_s", float),
        "converged": f.optional("converged", bool),
        "termination": f.optional("termination", str),
        "orientation": f.optional("orientation", str),
        "orientation_source": f.optional("orientation_source", str),
        "initial_state": f.optional("initial_state", str),
        "error": f.optional("error", str),
    }


#: The columns of :meth:`Comparison.to_dataframe`, in order.
COLUMNS = ("family", "validation_fit_percent", "validation_rmse", "parameters", "aic", "fit_time_s")


class Comparison:
    """Hysteresis families ranked by validation fit % (:func:`hysid.compare`).

    ``best``: the best family's name (None when every family failed); ``table``: one
    :class:`CompareRow` per family, best first, failed families last (family, validation
    fit %, RMSE, parameter count, AIC, fit time, the model's orientation and where it came
    from, its initial state, …); ``orientation`` and ``orientation_source``: the record's
    loop turning sense (``"ccw"``/``"cw"``) and ``"given"``, ``"detected"`` (on the
    training part) or ``"record"`` (on all the data, when the training part cannot tell: a
    family that could not tell was fitted with it), None when no data tell it;
    ``results``: family → :class:`FitResult` of its fit on the training samples (the
    families that succeeded, ranked); ``errors``: family → the one-line error of those that
    failed; ``model``: the best family's
    :class:`Model`; ``split``: how the data were split, in words; ``validation``: the
    scored validation samples (:class:`Record`) and ``simulated``: family → its output on
    them; ``termination_code``: ``"time_limit"`` when the call's ``time_limit`` stopped the
    families' searches (the best results so far), else None. ``to_dataframe()`` (pandas), ``plot()`` (matplotlib), ``report()``.
    """

    best: Optional[str]
    table: List[CompareRow]
    orientation: Optional[str]
    orientation_source: Optional[str]
    results: Dict[str, FitResult]
    errors: Dict[str, str]
    model: Optional[Model]
    split: str
    validation: Record
    simulated: Dict[str, FloatArray]
    termination_code: Optional[str]

    def __init__(
        self,
        report: Dict[str, Any],
        results: Sequence[Tuple[str, Optional[str]]],
        validation: Record,
        simulated: Sequence[FloatArray],
        training: Record,
    ) -> None:
        f = Fields(report, "report")
        if f.get("schema", str) != REPORT_SCHEMA or f.get("command", str) != "compare":
            raise ReportError("report: not the hysid.report/1 report of compare")
        details = f.object("details")
        if details is None:
            raise ReportError("report.details is null; a comparison lists its families there")
        self.best = details.optional("best", str)
        self.orientation = details.optional("orientation", str)
        self.orientation_source = details.optional("orientation_source", str)
        self.split = details.get("split_text", str)
        stopped = details.absent_or("stopped_by_time_limit_s", float)
        self.termination_code = None if stopped is None else "time_limit"
        split = details.object("split")
        kind = None if split is None else split.get("kind", str)
        train = split.get("train", int) if split is not None and kind == "fraction" else len(training.u)
        self.table = [_row(r) for r in details.objects("families")]
        self.model = model_in(f.raw("model"), "report.model")
        if [name for name, _ in results] != [r["family"] for r in self.table] or len(simulated) != len(self.table):
            raise ReportError("compare: the families' results do not match the report's rows")
        fitted = training._replace(u=training.u[:train], y=training.y[:train])
        self.results = {
            name: FitResult(labelled(json.loads(text), fitted), data=fitted)
            for name, text in results
            if text is not None
        }
        # The best family's model as its result holds it (with the record's sample time and
        # channel names), the same as the report's otherwise.
        if self.best is not None and self.best in self.results:
            self.model = self.results[self.best].model
        self.errors = {r["family"]: r["error"] for r in self.table if r["error"] is not None}
        self.validation = validation
        self.simulated = {r["family"]: s for r, s in zip(self.table, simulated) if r["family"] in self.results}
        self._report = report
        self._texts = list(results)
        self._training = training

    @classmethod
    def from_extension(
        cls,
        report: str,
        results: Sequence[Tuple[str, Optional[str]]],
        validation: Record,
        simulated: Sequence[FloatArray],
        training: Record,
    ) -> "Comparison":
        """The comparison from what the extension module's ``compare`` returns."""
        return cls(json.loads(report), results, validation, simulated, training)

    def report(self) -> Dict[str, Any]:
        """The ``hysid.report/1`` report of ``hysid compare`` as a dict (a copy)."""
        return copy.deepcopy(self._report)

    def to_dataframe(self) -> Any:
        """The table as a pandas DataFrame, one row per family in ranked order (columns
        validation_fit_percent, validation_rmse, parameters, aic, fit_time_s, error; index
        the family). Needs pandas."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError("to_dataframe() needs pandas: pip install pandas") from e
        rows = [{**{c: r[c] for c in COLUMNS}, "error": r["error"]} for r in self.table]  # type: ignore[literal-required]
        return pd.DataFrame(rows, columns=[*COLUMNS, "error"]).set_index("family")

    def plot(self, *, ax: Optional[Axes] = None, best: Optional[int] = None) -> Figure:
        """Small multiples of the validation loops, one panel per family, ranked, the
        measurement in each; ``best`` keeps the best few (:func:`hysid.plot.comparison`)."""
        from .plot import comparison

        return comparison(self, ax=ax, best=best)

    def __repr__(self) -> str:
        ranked = ", ".join(
            f"{r['family']} {r['validation_fit_percent']:.2f} %"
            for r in self.table[:3]
            if r["validation_fit_percent"] is not None
        )
        failed = f", {len(self.errors)} failed" if self.errors else ""
        return f"Comparison({len(self.table)} families{failed}: {ranked}{', …' if len(self.table) > 3 else ''})"

    def __eq__(self, other: object) -> bool:
        """The same ranking, figures and fitted models (the wall-clock times are not
        compared), on the same validation samples."""
        if not isinstance(other, Comparison):
            return NotImplemented
        return (
            _timeless(self._report) == _timeless(other._report)
            and self.results == other.results
            and np.array_equal(self.validation.u, other.validation.u)
            and np.array_equal(self.validation.y, other.validation.y)
        )

    __hash__ = None  # type: ignore[assignment]  # mutable, compared by value

    def __reduce__(self) -> Tuple[Any, ...]:
        simulated = [self.simulated.get(r["family"], self.validation.u[:0]) for r in self.table]
        return (
            Comparison.from_extension,
            (json.dumps(self._report), self._texts, self.validation, simulated, self._training),
        )


def _timeless(report: Dict[str, Any]) -> Dict[str, Any]:
    """A compare report without its wall-clock figures (each family's fit time)."""
    rep = copy.deepcopy(report)
    details = rep.get("details")
    if isinstance(details, dict):
        for row in details.get("families", []) or []:
            if isinstance(row, dict):
                row.pop("fit_time_s", None)
    if isinstance(rep.get("search"), dict):
        rep["search"].pop("elapsed_s", None)
    return rep
