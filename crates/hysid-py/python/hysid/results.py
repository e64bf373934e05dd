"""The result of a fit: :class:`Result`, built on the fit's ``hysid.report/1`` report."""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List, Optional, Tuple

from .models import Callbacks, Model
from .parameters import Parameter


class Result:
    """The result of a fit, built on its ``hysid.report/1`` report.

    Attributes: ``parameters`` (dict name → :class:`Parameter` with ``.value``, ``.std``,
    ``.unit``, ``.fixed``), ``fit_percent`` (100 (1 − ‖y − ŷ‖/‖y − ȳ‖)), ``rmse``,
    ``termination`` (why the search stopped), ``converged``, ``validation`` (one dict per
    test record: source, samples, fit_percent, rmse, e_rms), ``model`` (:class:`Model`),
    ``elapsed_s``. ``report()`` returns the report as a dict; ``to_dataframe()`` the
    parameter table as a pandas DataFrame.
    """

    def __init__(self, report: Dict[str, Any], user: Optional[Callbacks] = None) -> None:
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
        """The report as JSON text."""
        return json.dumps(self._report, indent=2)

    def to_dataframe(self) -> Any:
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

    def __reduce__(self) -> Tuple[Any, ...]:
        return (_result_from_json, (json.dumps(self._report), self._user))


def _result_from_json(text: str, user: Optional[Callbacks] = None) -> Result:
    return Result(json.loads(text), user)
