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
    fitted = result.best_fit
    if fitted is None:
        raise ValueError("this result has no model to simulate")
    return result.data.u, result.data.y, np.ravel(fitted), result.data.ts


def _time(n: int, ts: float) -> FloatArray:
    return np.arange(n, dtype=np.float64) * ts


def _label(name: str, unit: str) -> str:
    """An axis label: the channel's name and, when known, its unit in brackets."""
    return f"{name} [{unit}]" if unit else name


def _labels(result: "Result") -> Tuple[str, str, str]:
    """(input label, output label, the output's unit) of a result's data."""
    if result.data is None:
        return "input u", "output y", ""
    (ni, no), (ui, uo) = result.data.names, result.data.units
    return _label(ni, ui), _label(no, uo), uo


def fit(result: "Result", *, ax: Optional[Axes] = None) -> Figure:
    """Measured and simulated output against time; below, the residual y − ŷ."""
    u, y, yhat, ts = _fitted(result)
    x_label, y_label, y_unit = _labels(result)
    fig, axes = _axes(ax, 2)
    t = _time(len(y), ts)
    main = axes[0]
    main.plot(t, y, label="measured")
    fit = "" if result.fit_percent is None else f" (fit {result.fit_percent:.2f} %)"
    main.plot(t, yhat, "--", label=f"simulated{fit}")
    main.set_xlabel("time [s]")
    main.set_ylabel(y_label)
    main.set_title(f"{_name(result)}: measured and simulated output")
    main.legend(loc="best")
    if len(axes) > 1:
        axes[1].plot(t, y - yhat, color="C3", label="residual")
        axes[1].set_xlabel("time [s]")
        axes[1].set_ylabel(_label("residual y − ŷ", y_unit))
    fig.tight_layout()
    return fig


def loop(result: "Result", *, ax: Optional[Axes] = None) -> Figure:
    """The input–output loop: measured and simulated output against the input."""
    u, y, yhat, _ = _fitted(result)
    x_label, y_label, _ = _labels(result)
    fig, axes = _axes(ax, 1)
    main = axes[0]
    main.plot(u, y, label="measured", linewidth=1.0)
    main.plot(u, yhat, "--", label="simulated", linewidth=1.0)
    main.set_xlabel(x_label)
    main.set_ylabel(y_label)
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


def comparison(c: "Comparison", *, ax: Optional[Axes] = None, best: Optional[int] = None) -> Figure:
    """Small multiples of the validation loops: one panel per family, ranked (best first),
    each with the measured loop in grey beneath the family's simulated one and its
    validation fit % in the title, on shared axes; ``best`` keeps the best few panels.
    Given ``ax``, the best family alone is drawn there over the measurement."""
    u, y = c.validation.u, c.validation.y
    (ni, no), (ui, uo) = c.validation.names, c.validation.units
    ranked = [row for row in c.table if row["family"] in c.simulated]
    if best is not None:
        ranked = ranked[: max(1, int(best))]
    if ax is not None:
        ranked = ranked[:1]
    if not ranked:
        raise ValueError("no family of this comparison has a simulated output to plot (every fit failed)")
    if ax is not None:
        fig, panels = cast(Figure, ax.figure), [ax]
    else:
        plt = _pyplot()
        cols = min(3, len(ranked))
        rows = -(-len(ranked) // cols)
        fig, grid = plt.subplots(rows, cols, squeeze=False, sharex=True, sharey=True, figsize=(3.6 * cols, 3.0 * rows))
        panels = list(grid.ravel())
        for extra in panels[len(ranked) :]:
            extra.set_visible(False)
    for k, (panel, row) in enumerate(zip(panels, ranked)):
        name = row["family"]
        panel.plot(u, y, color="0.7", linewidth=2.0, label="measured")
        panel.plot(u, c.simulated[name], color="C0", linewidth=1.0, label=name)
        panel.set_title(f"{k + 1}. {name}: {row['validation_fit_percent']:.2f} %", fontsize="medium")
        cols = len(panels) if len(panels) < 3 else 3
        if k + cols >= len(ranked):  # the lowest panel of its column
            panel.set_xlabel(_label(ni, ui))
            panel.tick_params(labelbottom=True)
        if k % cols == 0:
            panel.set_ylabel(_label(no, uo))
    panels[0].legend(loc="best", fontsize="small")
    fig.suptitle("Validation loops, ranked by validation fit %")
    fig.tight_layout()
    return fig


def compensation(
    c: "Compensation",
    *,
    ax: Optional[Axes] = None,
    measured: Optional[Any] = None,
    plant: Optional[Any] = None,
    units: Optional[Tuple[str, str]] = None,
) -> Figure:
    """The reference r against time (the clipped samples marked); below, the command u;
    and, where a measured response (``measured``, the output the plant gave for u) or a
    plant model (``plant``, a :class:`~hysid.Model` simulated with u) is given, the
    tracking error y − r. Axes carry the model's channel names and ``units``
    (input, output). Given ``ax``, the reference panel alone is drawn there."""
    names = _columns(c)
    (ui, uo) = units if units is not None else ("", "")
    response: Optional[FloatArray] = None
    if measured is not None:
        response = np.asarray(measured, dtype=np.float64).ravel()
        if response.shape != c.reference.shape:
            raise ValueError(f"measured has {response.size} samples; the reference has {c.reference.size}")
    elif plant is not None:
        response = np.ravel(plant.simulate(c.u, ts=c.ts))
    fig, axes = _axes(ax, 2 if response is None else 3)
    t = _time(len(c.u), c.ts)
    main = axes[0]
    main.plot(t, c.reference, label="reference r")
    if response is not None:
        main.plot(t, response, "--", label="measured" if measured is not None else "plant output")
    if c.clipped:
        main.plot(t[c.clipped], c.reference[c.clipped], "x", color="C3", label=f"clipped ({len(c.clipped)})")
    main.set_xlabel("time [s]")
    main.set_ylabel(_label(names[1], uo))
    main.set_title(f"Compensation with the {c.model.family or c.model.kind} model")
    main.legend(loc="best")
    if len(axes) > 1:
        axes[1].plot(t, c.u, color="C2", label="command u")
        axes[1].set_xlabel("time [s]")
        axes[1].set_ylabel(_label(f"command {names[0]}", ui))
    if len(axes) > 2 and response is not None:
        error = response - c.reference
        rms = float(np.sqrt(np.mean(error**2)))
        axes[2].plot(t, error, color="C3", label=f"tracking error (RMS {rms:.3g})")
        axes[2].axhline(0.0, color="0.5", linewidth=0.8)
        axes[2].set_xlabel("time [s]")
        axes[2].set_ylabel(_label("y − r", uo))
        axes[2].legend(loc="best", fontsize="small")
    fig.tight_layout()
    return fig


def _columns(c: "Compensation") -> Tuple[str, str]:
    """The compensated model's (input, output) channel names from its model file's
    ``columns``, else ``("u", "y")``."""
    columns = c.model.file.get("columns")
    if isinstance(columns, dict):
        ins, outs = columns.get("inputs"), columns.get("outputs")
        if isinstance(ins, list) and isinstance(outs, list) and ins and outs:
            return str(ins[0]), str(outs[0])
    return "u", "y"


def _name(result: "Result") -> str:
    details = result.details
    family = details.get("family") if isinstance(details, dict) else None
    return str(family) if family else result.command
