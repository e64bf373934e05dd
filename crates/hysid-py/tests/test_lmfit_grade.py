"""Results as complete as lmfit's (issue: Python as a good citizen, item 4) and typed honestly
(item 3): the recipes that always fit return a FitResult whose model and fit are not
Optional; AIC/FPE wherever the report has them; each parameter's `at_bound`; the free
parameters; the fitted output and the residuals, checked against the report's fit %; the
number of function evaluations."""

import pathlib
import pickle
import typing

import hysid
import numpy as np
import pytest
from test_strict_arguments import play_record


def bouc_wen_record(n: int = 1500) -> typing.Tuple[np.ndarray, np.ndarray]:
    """A static Bouc–Wen operator (A = 1, β = γ = 0.5, n = 1) driven by a decaying sine:
    the fit's n sits on its lower bound 1."""
    u = 2.0 * np.sin(np.linspace(0.0, 12.0 * np.pi, n)) * np.linspace(1.0, 0.4, n)
    y, z = np.empty_like(u), 0.0
    for k in range(n):
        du = u[k] - u[k - 1] if k else 0.0
        z += du * (1.0 - (0.5 * np.sign(du * z) + 0.5) * abs(z))
        y[k] = 0.8 * u[k] + 1.5 * z
    return u, y


FIRST_ORDER = """
[model]
name = "first_order"
states = ["x"]
inputs = ["u"]
outputs = ["y"]

[parameters]
a = { value = 1.0, lower = 0.0 }
b = { value = 1.0 }

[initial]
x = { value = 0.0, fixed = true }

[equations]
x = "-a*x + b*u"

[output]
y = "x"
"""


def first_order(a: float = 1.0, b: float = 1.0) -> hysid.GreyBoxModel:
    """ẋ = −a x + b u, y = x, as an equation model with the given parameter values."""
    m = hysid.GreyBoxModel.from_equations(FIRST_ORDER)
    for p in m.parameters:
        p.value = {"a": a, "b": b}[p.name]
    return m


def fit_percent_of(y: np.ndarray, yhat: np.ndarray) -> float:
    return float(100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean())))


@pytest.fixture(scope="module")
def results() -> typing.Dict[str, hysid.FitResult]:
    u, y = play_record()
    x = np.repeat([5.0, 4.0, 3.5, 2.5], 250) * np.sin(2 * np.pi * np.arange(1000) / 40)
    truth = hysid.load_model(pathlib.Path(__file__).parent / "data" / "example1_cli_model.json")
    yc = truth.simulate(x, ts=1.0) + 0.01 * np.random.default_rng(0).standard_normal(x.size)
    ub, yb = bouc_wen_record()
    ug = np.sin(np.arange(400) * 0.05) + 0.5 * np.sin(np.arange(400) * 0.37)
    return {
        "pi": hysid.identify_operator(u, y, family="pi", thresholds=6),
        "bouc-wen": hysid.identify_operator(ub, yb, family="bouc-wen"),
        "cascade": hysid.identify_cascade(x, yc, hysteresis="ch4", na=2, nb=2, delay=1),
        "compare": hysid.compare(u, y, families=["pi", "backlash"]).results["pi"],
        "greybox": hysid.greybox_fit(first_order(), ug, first_order(a=2.0, b=3.0).simulate(ug, ts=0.05), ts=0.05),
    }


RECIPES = ["pi", "bouc-wen", "cascade", "compare", "greybox"]


@pytest.mark.parametrize("name", RECIPES)
def test_a_fitting_recipe_returns_a_fit_result(results, name):
    r = results[name]
    assert isinstance(r, hysid.FitResult) and isinstance(r, hysid.Result)
    assert isinstance(r.model, hysid.Model) and isinstance(r.fit_percent, float)
    # Pickled and back: the same class and content.
    back = pickle.loads(pickle.dumps(r))
    assert type(back) is hysid.FitResult and back == r


def test_the_recipes_promise_a_model_in_their_annotations():
    for f in (hysid.identify_operator, hysid.identify_cascade, hysid.identify_hysteresis, hysid.greybox_fit):
        assert typing.get_type_hints(f)["return"] is hysid.FitResult
    assert typing.get_type_hints(hysid.FitResult)["model"] is hysid.Model


@pytest.mark.parametrize("name", RECIPES)
def test_best_fit_and_residuals_reproduce_the_reports_fit(results, name):
    r = results[name]
    assert r.data is not None and r.best_fit is not None and r.residuals is not None
    y = r.data.y
    assert r.best_fit.shape == y.shape and r.best_fit.dtype == np.float64
    np.testing.assert_array_equal(r.residuals, y - r.best_fit)  # measured minus simulated
    assert abs(fit_percent_of(y, r.best_fit) - r.fit_percent) < 1e-9


@pytest.mark.parametrize("name", RECIPES)
def test_nfev_and_information_criteria_come_from_the_report(results, name):
    r = results[name]
    rep = r.report()
    assert type(r.nfev) is int and r.nfev == rep["search"]["evaluations"] and r.nfev >= 1
    fit, details = rep["fit"], rep["details"] if isinstance(rep["details"], dict) else {}
    for key in ("aic", "fpe"):
        expected = fit.get(key) if fit.get(key) is not None else details.get(key)
        assert getattr(r, key) == expected


def test_operator_fits_fill_aic_and_fpe():
    u, y = play_record()
    r = hysid.identify_operator(u, y, family="pi", thresholds=6)
    assert r.report()["fit"]["aic"] is None  # the report keeps them in details …
    assert r.aic == r.details["aic"] and r.fpe == r.details["fpe"]  # … and the result has them
    assert isinstance(r.aic, float) and np.isfinite(r.aic)


def test_a_parameter_on_its_bound_is_marked(results):
    r = results["bouc-wen"]
    n = r.parameters["n"]
    assert n.value == n.lower == 1.0 and n.std is None
    assert n.at_bound is True and type(n.at_bound) is bool
    assert "n" not in r.free_parameters
    assert "(at bound)" in r.fit_report() and "(at bound)" in repr(n)
    for p in r.parameters.values():
        assert type(p.at_bound) is bool
        if p.fixed:
            assert not p.at_bound


@pytest.mark.parametrize("name", RECIPES)
def test_free_parameters_are_those_with_a_standard_deviation(results, name):
    r = results[name]
    free = r.free_parameters
    assert isinstance(free, tuple) and free
    for name_, p in r.parameters.items():
        assert (name_ in free) == (not p.fixed and p.std is not None)
    assert "# fcn evals" in r.fit_report()
