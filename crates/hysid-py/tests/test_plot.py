"""The plots: each returns a Figure whose first axes is the main plot, with labelled axes
and its data as lines (Agg backend, no display)."""

import sys

import hysid
import pytest
from test_zoo import _loop

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402


@pytest.fixture(scope="module")
def fitted():
    u, y = _loop(600)
    return hysid.identify_operator(u, y, family="pi", thresholds=5)


@pytest.fixture(scope="module")
def comparison():
    return hysid.compare(*_loop(600), families=["pi", "backlash", "maxwell-slip"])


def _check(fig, lines, xlabel, ylabel):
    assert isinstance(fig, Figure)
    main = fig.axes[0]
    assert [len(a.get_lines()) for a in fig.axes] == lines
    assert main.get_xlabel() == xlabel and main.get_ylabel() == ylabel
    plt.close(fig)


def test_result_plots(fitted):
    _check(fitted.plot(), [2, 1], "time [s]", "y")
    _check(fitted.plot_loop(), [2], "u", "y")
    # r_ε and the two band lines; r_εu and its band
    _check(fitted.plot_residuals(), [3, 3], "lag τ [samples]", "r_ε(τ)")
    fig = fitted.plot()
    assert len(fig.axes[0].get_lines()[0].get_xdata()) == len(fitted.data.u)
    plt.close(fig)


def test_residuals_from_the_report_when_it_has_them(fitted):
    rep = fitted.report()
    rep["details"]["residual_analysis"] = [
        {"max_lag": 2, "autocorrelation": [1.0, 0.5, 0.25], "cross_correlation": [[0, 0.1, 0.2, 0.1, 0]], "band": 0.1}
    ]
    r = hysid.Result(rep, data=fitted.data)
    fig = r.plot_residuals(lags=2)
    assert list(fig.axes[0].get_lines()[0].get_ydata()) == [1.0, 0.5, 0.25]
    plt.close(fig)


def test_comparison_and_compensation_plots(comparison):
    # Small multiples: one panel per family, the measurement and the family in each.
    _check(comparison.plot(), [2] * len(comparison.results), "u", "y")
    c = hysid.compensate(comparison.model, comparison.validation.y)
    _check(c.plot(), [1 + bool(c.clipped), 1], "time [s]", "y")


def test_axes_carry_the_channels_names_and_units():
    u, y = _loop(600)
    names, units = ("current", "field"), ("A", "T")
    r = hysid.identify_operator(u, y, family="pi", thresholds=5, names=names, units=units)
    assert r.model.file["columns"] == {"inputs": ["current"], "outputs": ["field"]}
    _check(r.plot(), [2, 1], "time [s]", "field [T]")
    _check(r.plot_loop(), [2], "current [A]", "field [T]")
    c = hysid.compare(u, y, families=["pi", "backlash"], names=names, units=units)
    fig = c.plot()
    assert [a.get_title().split(":")[0] for a in fig.axes] == [f"{k + 1}. {r['family']}" for k, r in enumerate(c.table)]
    assert fig.axes[0].get_ylabel() == "field [T]" and fig.axes[-1].get_xlabel() == "current [A]"
    plt.close(fig)
    _check(c.plot(best=1), [2], "current [A]", "field [T]")
    comp = hysid.compensate(c.results["pi"], 0.5 * y)
    fig = comp.plot(plant=c.results["backlash"].model, units=units)
    reference, command, error = fig.axes
    assert reference.get_ylabel() == "field [T]" and command.get_ylabel() == "command current [A]"
    assert error.get_ylabel() == "y − r [T]"
    plant = c.results["backlash"].model.simulate(comp.u, ts=1.0)
    assert abs(error.get_lines()[0].get_ydata() - (plant - comp.reference)).max() < 1e-12
    plt.close(fig)


def test_names_are_taken_from_pandas_columns():
    pd = pytest.importorskip("pandas")
    u, y = _loop(600)
    frame = pd.DataFrame({"voltage": u, "displacement": y})
    r = hysid.identify_operator(frame["voltage"], frame["displacement"], family="pi", thresholds=5, ts=0.001)
    assert r.model.file["columns"] == {"inputs": ["voltage"], "outputs": ["displacement"]}
    assert r.model.file["sample_time"] == 0.001
    with pytest.raises(TypeError, match="names: give a pair of strings"):
        hysid.identify_operator(u, y, family="pi", names="voltage")  # type: ignore[arg-type]


def test_given_axes_hold_the_main_plot(fitted):
    fig, ax = plt.subplots()
    assert fitted.plot(ax=ax) is fig and len(fig.axes) == 1 and len(ax.get_lines()) == 2
    plt.close(fig)


def test_without_matplotlib_a_clear_import_error(fitted, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    with pytest.raises(ImportError, match=r"pip install 'hysid\[plot\]'"):
        fitted.plot()


def test_a_result_without_data_says_so(fitted):
    with pytest.raises(ValueError, match="keeps no data"):
        hysid.Result(fitted.report()).plot()
