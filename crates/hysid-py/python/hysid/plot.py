"""Figures of results, comparisons and compensations, drawn with matplotlib (an optional
dependency: ``pip install hysid[plot]``; imported when a figure is drawn).

Each function returns the :class:`~matplotlib.figure.Figure`; its first axes is the main
plot, with labelled axes and its data as lines. Given ``ax``, the main plot is drawn into
it and the secondary panels (residual, input) are left out. The methods ``plot()``,
``plot_loop()``, ``plot_residuals()`` of :class:`hysid.Result`, :class:`hysid.Comparison`
and :class:`hysid.Compensation` call these.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any, List, Optional, Tuple, cast

import numpy as np

from . import _hysid
from ._inputs import FloatArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .comparison import Comparison
    from .compensation import Compensation
    from .results import Result
else:  # matplotlib is optional: without it the annotations still resolve at run time
    Axes = Figure = Any

__all__ = ["Axes", "Figure", "RESIDUAL_LAGS", "fit", "loop", "residuals", "comparison", "compensation"]

#: Largest lag of the residual analysis (the grey-box reports').
RESIDUAL_LAGS = 25


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("hysid's plots need matplotlib: pip install 'hysid[plot]' (or pip install matplotlib)") from e
    return plt


def _axes(ax: Optional[Axes], panels: int) -> Tuple[Figure, List[Axes]]:
    """``ax`` and its figure, or a new figure of ``panels`` stacked axes (the first taller)."""
    if ax is not None:
        return cast(Figure, ax.figure), [ax]
    plt = _pyplot()
    ratios = [3] + [1] * (panels - 1)
    fig, axes = plt.subplots(
        panels, 1, squeeze=False, figsize=(8, 3 + 1.5 * panels), gridspec_kw={"height_ratios": ratios}
    )
    return cast(Figure, fig), list(axes[:, 0])


def _fitted(result: "Result") -> Tuple[FloatArray, FloatArray, FloatArray, float]:
    """(u, y, ŷ, ts): the data the result was fitted to and its model's simulation from
    the first measured output (as the reports compute the fit)."""
    if result.data is None:
        raise ValueError(
            "this result keeps no data to plot (the recipes of one input and one output keep it: "
            "identify_operator, identify_cascade, identify_hysteresis, compare)"
        )
    if result.model is None:
        raise ValueError("this result has no model to simulate")
    u, y, ts = result.data
    yhat = np.ravel(result.model.simulate(u, ts=ts, y0=float(y[0])))
    return u, y, yhat, ts


def _time(n: int, ts: float) -> FloatArray:
    return np.arange(n, dtype=np.float64) * ts


def fit(result: "Result", *, ax: Optional[Axes] = None) -> Figure:
    """Measured and simulated output against time; below, the residual y − ŷ."""
    u, y, yhat, ts = _fitted(result)
    fig, axes = _axes(ax, 2)
    t = _time(len(y), ts)
    main = axes[0]
    main.plot(t, y, label="measured")
    fit = "" if result.fit_percent is None else f" (fit {result.fit_percent:.2f} %)"
    main.plot(t, yhat, "--", label=f"simulated{fit}")
    main.set_xlabel("time [s]")
    main.set_ylabel("output y")
    main.set_title(f"{_name(result)}: measured and simulated output")
    main.legend(loc="best")
    if len(axes) > 1:
        axes[1].plot(t, y - yhat, color="C3", label="residual")
        axes[1].set_xlabel("time [s]")
        axes[1].set_ylabel("y − ŷ")
    fig.tight_layout()
    return fig


def loop(result: "Result", *, ax: Optional[Axes] = None) -> Figure:
    """The input–output loop: measured and simulated output against the input."""
    u, y, yhat, _ = _fitted(result)
    fig, axes = _axes(ax, 1)
    main = axes[0]
    main.plot(u, y, label="measured", linewidth=1.0)
    main.plot(u, yhat, "--", label="simulated", linewidth=1.0)
    main.set_xlabel("input u")
    main.set_ylabel("output y")
    main.set_title(f"{_name(result)}: input–output loop")
    main.legend(loc="best")
    fig.tight_layout()
    return fig


def residuals(result: "Result", *, lags: int = RESIDUAL_LAGS, ax: Optional[Axes] = None) -> Figure:
    """The residual's autocorrelation r_ε(τ), τ = 0…lags, and its cross-correlation with the
    input r_εu(τ), τ = −lags…lags, each with the 99 % band ±2.576/√N of white noise: the
    report's residual analysis when it holds one, else the library's, computed here."""
    analysis = _residual_analysis(result, lags)
    fig, axes = _axes(ax, 2)
    band = float(analysis["band"])
    auto = np.asarray(analysis["autocorrelation"], dtype=np.float64)
    main = axes[0]
    main.plot(np.arange(auto.size), auto, "o-", label="autocorrelation r_ε(τ)")
    for sign in (1.0, -1.0):
        main.axhline(sign * band, color="C3", linestyle="--", label="99 % band" if sign > 0 else None)
    main.set_xlabel("lag τ [samples]")
    main.set_ylabel("r_ε(τ)")
    main.set_title(f"{_name(result)}: residual analysis")
    main.legend(loc="best")
    if len(axes) > 1:
        cross = np.asarray(analysis["cross_correlation"][0], dtype=np.float64)
        m = (cross.size - 1) // 2
        axes[1].plot(np.arange(-m, m + 1), cross, "o-", label="cross-correlation r_εu(τ)")
        for sign in (1.0, -1.0):
            axes[1].axhline(sign * band, color="C3", linestyle="--")
        axes[1].set_xlabel("lag τ [samples]")
        axes[1].set_ylabel("r_εu(τ)")
    fig.tight_layout()
    return fig


def _residual_analysis(result: "Result", lags: int) -> Any:
    details = result.details
    stored = details.get("residual_analysis") if isinstance(details, dict) else None
    if isinstance(stored, list) and stored and stored[0].get("max_lag") == lags:
        return stored[0]
    u, y, yhat, ts = _fitted(result)
    return json.loads(_hysid.residual_analysis(u, y, yhat, ts, lags))


def comparison(c: "Comparison", *, ax: Optional[Axes] = None) -> Figure:
    """The measured validation loop and, over it, each family's (ranked, best first)."""
    fig, axes = _axes(ax, 1)
    main = axes[0]
    u, y, _ = c.validation
    main.plot(u, y, color="black", linewidth=2.0, label="measured")
    for row in c.table:
        name = row["family"]
        if name in c.simulated:
            main.plot(u, c.simulated[name], linewidth=1.0, label=f"{name} ({row['validation_fit_percent']:.2f} %)")
    main.set_xlabel("input u")
    main.set_ylabel("output y")
    main.set_title("Validation loops: measured and every family, ranked")
    main.legend(loc="best", fontsize="small")
    fig.tight_layout()
    return fig


def compensation(c: "Compensation", *, ax: Optional[Axes] = None) -> Figure:
    """Reference and predicted output against time; below, the compensating input."""
    fig, axes = _axes(ax, 2)
    t = _time(len(c.u), c.ts)
    main = axes[0]
    main.plot(t, c.reference, label="reference r")
    main.plot(t, c.predicted, "--", label="predicted output")
    if c.clipped:
        main.plot(t[c.clipped], c.reference[c.clipped], "x", color="C3", label="clipped")
    main.set_xlabel("time [s]")
    main.set_ylabel("output y")
    main.set_title(f"Compensation with the {c.model.family or c.model.kind} model")
    main.legend(loc="best")
    if len(axes) > 1:
        axes[1].plot(t, c.u, color="C2", label="command u")
        axes[1].set_xlabel("time [s]")
        axes[1].set_ylabel("command u")
    fig.tight_layout()
    return fig


def _name(result: "Result") -> str:
    details = result.details
    family = details.get("family") if isinstance(details, dict) else None
    return str(family) if family else result.command
