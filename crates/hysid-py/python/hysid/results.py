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

import numpy as np

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
    """The signals a model was fitted to: input ``u``, output ``y``, sample time ``ts``, and
    the channels' ``names`` and ``units`` (input, output), which label the plots' axes and
    name the model file's columns."""

    u: FloatArray
    y: FloatArray
    ts: float
    names: Tuple[str, str] = ("u", "y")
    units: Tuple[str, str] = ("", "")


def labelled(report: Dict[str, Any], record: Record) -> Dict[str, Any]:
    """``report`` with its model file carrying the record's sample time and channel names
    (``sample_time``, ``columns``, ``input_range``) where the library left them out, as the command line's
    model files do: so that every export (an FMU needs its sample time) works from a model
    fitted in Python."""
    model = report.get("model")
    if isinstance(model, dict):
        model.setdefault("sample_time", record.ts)
        model.setdefault("columns", {"inputs": [record.names[0]], "outputs": [record.names[1]]})
        if len(record.u):
            model.setdefault("input_range", [[float(np.min(record.u)), float(np.max(record.u))]])
    return report


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
    command does not produce are None. As lmfit's ``ModelResult``: ``nfev`` (the criterion
    evaluations), ``free_parameters`` (the names estimated with a σ), ``covariance`` and
    ``correlation`` (numpy arrays over ``free_parameters``, in that order), ``best_fit``
    (the model's output on ``data``) and ``residuals`` (y − best_fit, the
    system-identification sign), and each :class:`Parameter`'s ``at_bound``.

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
    nfev: Optional[int]
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
        raw_details = f.raw("details")
        details = Fields(raw_details, "report.details") if isinstance(raw_details, dict) else None
        # A recipe puts AIC and FPE in `fit` or, for one family's fit, in `details`.
        self.aic = _figure(fit, details, "aic")
        self.fpe = _figure(fit, details, "fpe")
        search = f.object("search")
        term = None if search is None else search.object("termination")
        if search is not None and term is None:
            raise ReportError("report.search.termination is null; a search says why it stopped")
        self.termination = "" if term is None else term.get("message", str)
        self.termination_code = None if term is None else term.get("code", str)
        self.converged = False if term is None else term.get("converged", bool)
        self.iterations = None if search is None else search.get("iterations", int)
        self.elapsed_s = None if search is None else search.get("elapsed_s", float)
        self.nfev = None if search is None else search.get("evaluations", int)
        uncertainty = f.object("uncertainty")
        self.uncertainty = None if uncertainty is None else uncertainty.get("method", str)
        self._covariance = _covariance(uncertainty, self.parameters)
        self.validation = [_validation_entry(v) for v in f.objects("validation")]
        self.warnings = [str(w) for w in f.get("warnings", list)]
        self.details = f.raw("details")
        self.data = data
        self._report = report
        self._user = user
        self._best_fit: Optional[FloatArray] = None

    @property
    def free_parameters(self) -> Tuple[str, ...]:
        """The names of the parameters that were estimated and have a standard deviation
        (neither fixed nor at a bound), in the model's order."""
        return tuple(n for n, p in self.parameters.items() if not p.fixed and p.std is not None)

    @property
    def covariance(self) -> Optional[FloatArray]:
        """The covariance matrix of the estimates over :attr:`free_parameters`, in that
        order (the report's ``uncertainty.covariance``, ``docs/report.md`` §1.4: σ²(JᵀJ)⁻¹
        at the estimate, or σ²(ΦᵀΦ)⁻¹ on the free set of a least-squares solve; its
        diagonal the squared ``std``); a copy. None when the report holds none: a report
        without standard deviations, or one written before the key existed."""
        return None if self._covariance is None else self._covariance.copy()

    @property
    def correlation(self) -> Optional[FloatArray]:
        """The correlation matrix of the estimates over :attr:`free_parameters`:
        C_ij / √(C_ii C_jj) of :attr:`covariance` (unit diagonal, symmetric); None when
        :attr:`covariance` is None. An estimate with a zero variance correlates 0 with the
        others."""
        if self._covariance is None:
            return None
        return _correlation(self._covariance)

    @property
    def best_fit(self) -> Optional[FloatArray]:
        """The model's output on the data it was fitted to, simulated from the first
        measured output as the report's fit % is computed (so ``100 (1 − ‖residuals‖ /
        ‖y − ȳ‖)`` is ``fit_percent``); None when the result keeps no data (``data``)."""
        if self.data is None or self.model is None:
            return None
        if self._best_fit is None:
            u, y, ts = self.data.u, self.data.y, self.data.ts
            y0 = float(y[0]) if y.ndim == 1 else None
            self._best_fit = np.asarray(self.model.simulate(u, ts=ts, y0=y0), dtype=np.float64)
        return self._best_fit.copy()

    @property
    def residuals(self) -> Optional[FloatArray]:
        """y − :attr:`best_fit` on the fitted data: the system-identification sign, measured
        minus simulated (lmfit's ``residual`` is the opposite); None without ``data``."""
        fitted = self.best_fit
        if fitted is None or self.data is None:
            return None
        return np.asarray(self.data.y - fitted, dtype=np.float64)

    def report(self) -> Dict[str, Any]:
        """The ``hysid.report/1`` report as a dict (a copy)."""
        return copy.deepcopy(self._report)

    def to_json(self) -> str:
        """The report as JSON text."""
        return json.dumps(self._report, indent=2)

    def fit_report(self, *, max_parameters: int = 40, min_correl: float = 0.1) -> str:
        """The fit as a text table (as lmfit's ``fit_report``): the figures (fit %, RMSE,
        AIC, FPE, the function evaluations, the free parameters), how the search ended, then
        one line per parameter (at most ``max_parameters``) with its value, σ and σ relative
        to the value, ``(fixed)`` or ``(at bound)``, and last the ``[[Correlations]]``: the
        pairs of free parameters correlated more than ``min_correl`` in magnitude, the
        strongest first, as ``C(a, b) = +0.9000``."""
        points = None if self.data is None else int(np.asarray(self.data.y).shape[0])
        lines = [f"[[Fit: {self.command}]]"]
        if self.termination:
            state = "converged" if self.converged else "NOT converged"
            lines.append(f"    {'termination':<15}= {self.termination} ({state}, {self.iterations} iterations)")
        if self.uncertainty:
            lines.append(f"    {'uncertainty':<15}= {self.uncertainty}")
        if self.elapsed_s is not None:
            lines.append(f"    {'time':<15}= {self.elapsed_s:.4g} s")
        # lmfit's [[Fit Statistics]], with the system-identification figures: AIC
        # (N ln V + 2p + N (ln 2π + 1), MATLAB's) and Akaike's FPE V (1 + p/N)/(1 − p/N).
        figures = [
            ("# fcn evals", "" if self.nfev is None else str(self.nfev)),
            ("# data points", "" if points is None else str(points)),
            ("# variables", str(len(self.free_parameters))),
            ("fit %", _num(self.fit_percent, ".4f")),
            ("RMSE", _num(self.rmse, ".6e")),
            ("AIC", _num(self.aic, ".2f")),
            ("FPE", _num(self.fpe, ".6e")),
        ]
        lines.append("[[Fit Statistics]]")
        lines += [f"    {name:<15}= {value}" for name, value in figures if value]
        for v in self.validation:
            lines.append(f"    {'validation':<15}= {v['source']}: fit {v['fit_percent']:.4f} %, RMSE {v['rmse']:.6e}")
        lines.append("[[Parameters]]")
        width = max((len(n) for n in self.parameters), default=0)
        for p in list(self.parameters.values())[:max_parameters]:
            lines.append(f"    {p.name + ':':<{width + 1}} {_parameter_line(p)}")
        if len(self.parameters) > max_parameters:
            lines.append(f"    … {len(self.parameters) - max_parameters} more (see .parameters)")
        pairs = self.correlations(min_correl=min_correl)
        if pairs:
            lines.append(f"[[Correlations]] (unreported correlations are < {min_correl:.3f})")
            width = max(len(f"C({a}, {b})") for a, b, _ in pairs)
            lines += [f"    {f'C({a}, {b})':<{width}} = {c:+.4f}" for a, b, c in pairs]
        return "\n".join(lines)

    def correlations(self, *, min_correl: float = 0.1) -> List[Tuple[str, str, float]]:
        """The pairs of :attr:`free_parameters` whose correlation exceeds ``min_correl``
        in magnitude, as ``(name, name, correlation)``, the strongest first (the pairs
        ``fit_report()`` shows under ``[[Correlations]]``, as lmfit's); empty without a
        :attr:`correlation`."""
        corr = self.correlation
        if corr is None:
            return []
        names = self.free_parameters
        pairs = [
            (names[i], names[j], float(corr[i, j]))
            for i in range(len(names))
            for j in range(i + 1, len(names))
            if abs(corr[i, j]) > min_correl
        ]
        return sorted(pairs, key=lambda t: -abs(t[2]))

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
        return (_rebuilt, (type(self), json.dumps(self._report), self._user, self.data))


class FitResult(Result):
    """The :class:`Result` of a recipe that always fits a model and scores it
    (:func:`~hysid.identify_operator`, :func:`~hysid.identify_cascade`,
    :func:`~hysid.identify_hysteresis`, :func:`~hysid.greybox_fit`,
    :func:`~hysid.benchmark_bouc_wen`, :func:`~hysid.rigid_body_ls`, and each family's result
    in a :class:`~hysid.Comparison`): ``model``, ``fit_percent`` and ``rmse`` are never None,
    so typed code uses them without a check. A report without a model or a fit is a
    :class:`ReportError` at construction."""

    model: Model
    fit_percent: float
    rmse: float

    def __init__(self, report: Dict[str, Any], user: Optional[Callbacks] = None, data: Optional[Record] = None) -> None:
        super().__init__(report, user, data)
        # The base class reads them as optional; this class promises them.
        if self.model is None:
            raise ReportError(f"report.model is null; a {self.command} report holds the fitted model")
        if self.fit_percent is None or self.rmse is None:
            raise ReportError(f"report.fit is null; a {self.command} report scores its fit")


def _figure(fit: Optional[Fields], details: Optional[Fields], key: str) -> Optional[float]:
    """The number ``key`` of the report's ``fit`` or, when that holds none, of its
    ``details``; None when neither has one."""
    value = None if fit is None else fit.optional(key, float)
    if value is None and details is not None:
        value = details.absent_or(key, float)
    return value


def _covariance(uncertainty: Optional[Fields], parameters: Dict[str, Parameter]) -> Optional[FloatArray]:
    """The report's ``uncertainty.covariance`` as a matrix over the free parameters (those
    neither fixed nor without a standard deviation, in the model's order), rows and columns
    mapped by name; None when the report has none. A matrix that is not square, names a
    parameter twice, or does not cover exactly the free parameters is a :class:`ReportError`."""
    raw = None if uncertainty is None else uncertainty.absent_or("covariance", dict)
    if raw is None:
        return None
    c = Fields(raw, "report.uncertainty.covariance")
    names = c.get("parameters", list)
    rows = c.get("matrix", list)
    where = "report.uncertainty.covariance"
    if not all(isinstance(n, str) for n in names) or len(set(names)) != len(names):
        raise ReportError(f"{where}.parameters: expected distinct names")
    free = [n for n, p in parameters.items() if not p.fixed and p.std is not None]
    if sorted(names) != sorted(free):
        raise ReportError(f"{where}.parameters: {names} are not the free parameters {free} (those with a std)")
    try:
        matrix = np.array(rows, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ReportError(f"{where}.matrix: expected rows of numbers ({e})") from None
    if matrix.shape != (len(names), len(names)):
        raise ReportError(f"{where}.matrix: expected {len(names)} rows of {len(names)}, got shape {matrix.shape}")
    order = [names.index(n) for n in free]
    return np.ascontiguousarray(matrix[np.ix_(order, order)])


def _correlation(c: FloatArray) -> FloatArray:
    """C_ij / √(C_ii C_jj), 1 on the diagonal, 0 where a variance is 0."""
    d = np.sqrt(np.clip(np.diag(c), 0.0, None))
    scale = np.outer(d, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(scale > 0, c / np.where(scale > 0, scale, 1.0), 0.0)
    r = np.clip(0.5 * (r + r.T), -1.0, 1.0)
    np.fill_diagonal(r, 1.0)
    return np.asarray(r, dtype=np.float64)


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
    elif p.at_bound:
        text += " (at bound)"
    return text


def _result_from_json(text: str, user: Optional[Callbacks] = None, data: Optional[Record] = None) -> Result:
    # Kept for results pickled before FitResult existed.
    return Result(json.loads(text), user, data)


def _rebuilt(cls: type[Result], text: str, user: Optional[Callbacks], data: Optional[Record]) -> Result:
    """An unpickled :class:`Result` or :class:`FitResult`: rebuilt from its report."""
    return cls(json.loads(text), user, data)
