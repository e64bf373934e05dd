"""The result of a fit: :class:`Result`, built on the fit's ``hysid.report/1`` report.

Every field is read once, at construction, with the type the report format
(``docs/report.md``) gives it: a report that lacks one, or holds one of the wrong type, is a
:class:`ReportError` naming the field, never a silent ``None``.
"""

from __future__ import annotations

import copy
import json
import math
from typing import Any, Dict, List, NamedTuple, Optional, Tuple, TypedDict

from ._fields import Fields, ReportError
from ._inputs import FloatArray
from .models import Callbacks, Model, model_in
from .parameters import Parameter
from .plot import Axes, Figure

#: The report format this package reads.
REPORT_SCHEMA = "hysid.report/1"


class ValidationEntry(TypedDict):
    """One validation or test record of a report: its ``source``, the ``samples`` scored,
    ``fit_percent``, ``rmse`` and, for a benchmark, its own measure ``e_rms``."""

    source: str
    samples: int
    fit_percent: float
    rmse: float
    e_rms: Optional[float]


class Record(NamedTuple):
    """The signals a model was fitted to: input ``u``, output ``y``, sample time ``ts``."""

    u: FloatArray
    y: FloatArray
    ts: float


def _validation_entry(f: Fields) -> ValidationEntry:
    return {
        "source": f.get("source", str),
        "samples": f.get("samples", int),
        "fit_percent": f.get("fit_percent", float),
        "rmse": f.get("rmse", float),
        "e_rms": f.optional("e_rms", float),
    }


class Result:
    """The result of a fit, built on its ``hysid.report/1`` report.

    Attributes, read from the report once and checked: ``command`` (the CLI command whose
    report it is), ``parameters`` (dict name → :class:`Parameter` with ``.value``,
    ``.std``, ``.unit``, ``.fixed``; the names of the CLI report), ``fit_percent``
    (100 (1 − ‖y − ŷ‖/‖y − ȳ‖)), ``rmse``, ``aic``, ``fpe``, ``termination`` (why the
    search stopped, in words), ``termination_code``, ``converged``, ``iterations``,
    ``uncertainty`` (how the σ were obtained), ``validation`` (one entry per test record:
    source, samples, fit_percent, rmse, e_rms), ``warnings``, ``details`` (the command's
    own part of the report), ``model`` (:class:`Model`), ``elapsed_s``, and ``data`` (the
    :class:`Record` fitted, kept by the recipes of one input and one output). Figures a
    command does not produce are None.

    ``report()`` returns the report as a dict; ``fit_report()`` a text table of the
    parameters with σ, the fit and the termination; ``to_dataframe()`` the parameter table
    as a pandas DataFrame; ``plot()``, ``plot_loop()``, ``plot_residuals()`` draw the fit
    (matplotlib needed).
    """

    command: str
    model: Optional[Model]
    parameters: Dict[str, Parameter]
    fit_percent: Optional[float]
    rmse: Optional[float]
    aic: Optional[float]
    fpe: Optional[float]
    termination: str
    termination_code: Optional[str]
    converged: bool
    iterations: Optional[int]
    elapsed_s: Optional[float]
    uncertainty: Optional[str]
    validation: List[ValidationEntry]
    warnings: List[str]
    details: Any
    data: Optional[Record]

    def __init__(self, report: Dict[str, Any], user: Optional[Callbacks] = None, data: Optional[Record] = None) -> None:
        f = Fields(report, "report")
        schema = f.get("schema", str)
        if schema != REPORT_SCHEMA:
            raise ReportError(f"report.schema is {schema!r}; this hysid reads {REPORT_SCHEMA!r}")
        self.command = f.get("command", str)
        self.model = model_in(f.raw("model"), "report.model", user)
        self.parameters = self.model.parameters if self.model is not None else {}
        fit = f.object("fit")
        self.fit_percent = None if fit is None else fit.get("fit_percent", float)
        self.rmse = None if fit is None else fit.get("rmse", float)
        self.aic = None if fit is None else fit.optional("aic", float)
        self.fpe = None if fit is None else fit.optional("fpe", float)
        search = f.object("search")
        term = None if search is None else search.object("termination")
        if search is not None and term is None:
            raise ReportError("report.search.termination is null; a search says why it stopped")
        self.termination = "" if term is None else term.get("message", str)
        self.termination_code = None if term is None else term.get("code", str)
        self.converged = False if term is None else term.get("converged", bool)
        self.iterations = None if search is None else search.get("iterations", int)
        self.elapsed_s = None if search is None else search.get("elapsed_s", float)
        uncertainty = f.object("uncertainty")
        self.uncertainty = None if uncertainty is None else uncertainty.get("method", str)
        self.validation = [_validation_entry(v) for v in f.objects("validation")]
        self.warnings = [str(w) for w in f.get("warnings", list)]
        self.details = f.raw("details")
        self.data = data
        self._report = report
        self._user = user

    def report(self) -> Dict[str, Any]:
        """The ``hysid.report/1`` report as a dict (a copy)."""
        return copy.deepcopy(self._report)

    def to_json(self) -> str:
        """The report as JSON text."""
        return json.dumps(self._report, indent=2)

    def fit_report(self, *, max_parameters: int = 40) -> str:
        """The fit as a text table (as lmfit's ``fit_report``): the figures, how the
        search ended, then one line per parameter (at most ``max_parameters``) with its
        value, σ and σ relative to the value."""
        figures = [
            ("fit %", _num(self.fit_percent, ".4f")),
            ("RMSE", _num(self.rmse, ".6e")),
            ("AIC", _num(self.aic, ".2f")),
            ("FPE", _num(self.fpe, ".6e")),
        ]
        lines = [f"[[Fit: {self.command}]]"]
        lines += [f"    {name:<12}= {value}" for name, value in figures if value]
        if self.termination:
            state = "converged" if self.converged else "NOT converged"
            lines.append(f"    {'termination':<12}= {self.termination} ({state}, {self.iterations} iterations)")
        if self.uncertainty:
            lines.append(f"    {'uncertainty':<12}= {self.uncertainty}")
        if self.elapsed_s is not None:
            lines.append(f"    {'time':<12}= {self.elapsed_s:.4g} s")
        for v in self.validation:
            lines.append(f"    {'validation':<12}= {v['source']}: fit {v['fit_percent']:.4f} %, RMSE {v['rmse']:.6e}")
        lines.append("[[Parameters]]")
        width = max((len(n) for n in self.parameters), default=0)
        for p in list(self.parameters.values())[:max_parameters]:
            lines.append(f"    {p.name + ':':<{width + 1}} {_parameter_line(p)}")
        if len(self.parameters) > max_parameters:
            lines.append(f"    … {len(self.parameters) - max_parameters} more (see .parameters)")
        return "\n".join(lines)

    def to_dataframe(self) -> Any:
        """The parameters as a pandas DataFrame (columns value, std, unit, fixed, lower,
        upper; index the names). Needs pandas."""
        try:
            import pandas as pd
        except ImportError as e:
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

    def plot(self, *, ax: Optional[Axes] = None) -> Figure:
        """Measured and simulated output against time, the residual below
        (:func:`hysid.plot.fit`)."""
        from .plot import fit

        return fit(self, ax=ax)

    def plot_loop(self, *, ax: Optional[Axes] = None) -> Figure:
        """The input–output loop: measured and simulated output against the input
        (:func:`hysid.plot.loop`)."""
        from .plot import loop

        return loop(self, ax=ax)

    def plot_residuals(self, *, lags: int = 25, ax: Optional[Axes] = None) -> Figure:
        """The residuals' autocorrelation and their cross-correlation with the input, with
        the 99 % band of white noise (:func:`hysid.plot.residuals`)."""
        from .plot import residuals

        return residuals(self, lags=lags, ax=ax)

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
        shown = list(self.parameters.items())[:8]
        values = ", ".join(f"{n}={p.value:.6g}" for n, p in shown)
        if len(self.parameters) > len(shown):
            values += f", … ({len(self.parameters)} parameters)"
        fit = "n/a" if self.fit_percent is None else f"{self.fit_percent:.2f} %"
        return f"Result({self.command}: {values}; fit {fit})"

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_result_from_json, (json.dumps(self._report), self._user, self.data))


def _num(v: Optional[float], spec: str) -> str:
    return "" if v is None else format(v, spec)


def _parameter_line(p: Parameter) -> str:
    text = f"{p.value: .8g}"
    if p.std is not None:
        text += f" +/- {p.std:.4g}"
        if p.value != 0 and math.isfinite(p.std):
            text += f" ({100 * abs(p.std / p.value):.2f}%)"
    if p.unit:
        text += f" [{p.unit}]"
    if p.fixed:
        text += " (fixed)"
    return text


def _result_from_json(text: str, user: Optional[Callbacks] = None, data: Optional[Record] = None) -> Result:
    return Result(json.loads(text), user, data)
