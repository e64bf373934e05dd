"""The covariance and correlation of a fit (issue #40 item 4, "lmfit-grade results"):
``Result.covariance`` and ``Result.correlation`` over ``Result.free_parameters``, in that
order, from the report's ``uncertainty.covariance``; each checked against the report and
against a numerical covariance σ²(JᵀJ)⁻¹, J the central-difference Jacobian of the fitted
model's simulated output with respect to the free parameters and σ² = RSS/(N − p), for
``identify_operator``, ``compare``, ``greybox_fit`` and ``identify_cascade``. The bounds the
fit held (a PI weight's lower 0), ``at_bound``, AIC and FPE on every recipe, and the
``[[Correlations]]`` of ``fit_report()``. All noise is seeded."""

import copy
import math
import pathlib
import re
import typing

import hysid
import numpy as np
import pytest
from hysid._inputs import FloatArray
from hysid.results import Result
from test_actuator import emps_record
from test_lmfit_grade import first_order
from test_strict_arguments import play_record

#: How close the report's covariance is to the numerical one: max |C − Cₙ| / √(Cᵢᵢ Cⱼⱼ)
#: (the operator fits are linear least squares, so the two agree to rounding; the grey-box
#: and cascade fits to the difference step, observed ≤ 3e-7). An error in σ² of p/N (N for
#: N − p) is 7e-3 here, well above it.
TOLERANCE = 1e-4


def _operator_value(file: typing.Dict[str, typing.Any], name: str, value: float) -> None:
    """Sets a PI parameter in the operator's structure (what the model simulates)."""
    op = file["operator"]
    if name == "a0":
        op["a0"] = value
    elif name == "c":
        op["offset"] = value
    else:
        op["weights"][int(name[1:]) - 1] = value


def _record_value(file: typing.Dict[str, typing.Any], name: str, value: float) -> None:
    """Sets a parameter record's value (an equation or cascade model simulates those)."""
    [record] = [p for p in file["parameters"] if p["name"] == name]
    record["value"] = value


def numerical_covariance(r: hysid.FitResult, set_value: typing.Callable[..., None], step: float = 1e-4) -> np.ndarray:
    """σ²(JᵀJ)⁻¹ over ``r.free_parameters``: J by central differences of the fitted model's
    simulation of ``r.data`` (as ``best_fit``), σ² = ‖residuals‖²/(N − p)."""
    assert r.data is not None and r.residuals is not None
    u, y, ts = r.data.u, r.data.y, r.data.ts
    columns = []
    for name in r.free_parameters:
        value = r.parameters[name].value
        h = step * max(abs(value), 1e-2)
        outputs = []
        for shift in (h, -h):
            file = copy.deepcopy(r.model.file)
            set_value(file, name, value + shift)
            outputs.append(np.asarray(hysid.Model(file).simulate(u, ts=ts, y0=float(y[0]))))
        columns.append((outputs[0] - outputs[1]) / (2 * h))
    jac = np.column_stack(columns)
    res = r.residuals
    sigma2 = float(res @ res) / (res.size - len(columns))
    return sigma2 * np.linalg.inv(jac.T @ jac)


@pytest.fixture(scope="module")
def fits() -> typing.Dict[str, typing.Tuple[hysid.FitResult, typing.Callable[..., None]]]:
    rng = np.random.default_rng(7)
    u, y = play_record()
    y = y + 0.01 * rng.standard_normal(y.size)
    x = np.repeat([5.0, 4.0, 3.5, 2.5], 250) * np.sin(2 * np.pi * np.arange(1000) / 40)
    truth = hysid.load_model(pathlib.Path(__file__).parent / "data" / "example1_cli_model.json")
    yc = truth.simulate(x, ts=1.0) + 0.01 * np.random.default_rng(0).standard_normal(x.size)
    ug = np.sin(np.arange(400) * 0.05) + 0.5 * np.sin(np.arange(400) * 0.37)
    yg = first_order(a=2.0, b=3.0).simulate(ug, ts=0.05) + 0.01 * rng.standard_normal(ug.size)
    return {
        "identify_operator": (hysid.identify_operator(u, y, family="pi", thresholds=6), _operator_value),
        "compare": (hysid.compare(u, y, families=["pi", "backlash"]).results["pi"], _operator_value),
        "greybox_fit": (hysid.greybox_fit(first_order(), ug, yg, ts=0.05), _record_value),
        "identify_cascade": (
            hysid.identify_cascade(x, yc, hysteresis="ch4", na=2, nb=2, delay=1),
            _record_value,
        ),
    }


RECIPES = ["identify_operator", "compare", "greybox_fit", "identify_cascade"]


@pytest.mark.parametrize("name", RECIPES)
def test_the_attributes_are_there_with_their_types(fits, name):
    r, _ = fits[name]
    free = r.free_parameters
    assert isinstance(free, tuple) and len(free) >= 2 and all(isinstance(n, str) for n in free)
    for m in (r.covariance, r.correlation):
        assert isinstance(m, np.ndarray) and m.dtype == np.float64 and m.shape == (len(free), len(free))
    assert type(r.nfev) is int and r.nfev >= 1
    assert isinstance(r.aic, float) and isinstance(r.fpe, float) and math.isfinite(r.aic) and r.fpe > 0
    for p in r.parameters.values():
        assert type(p.at_bound) is bool
        assert isinstance(p.lower, float) and isinstance(p.upper, float)
    assert r.best_fit is not None and r.residuals is not None


@pytest.mark.parametrize("name", RECIPES)
def test_the_covariance_is_the_reports(fits, name):
    r, _ = fits[name]
    cov = r.report()["uncertainty"]["covariance"]
    order = [cov["parameters"].index(n) for n in r.free_parameters]
    assert sorted(cov["parameters"]) == sorted(r.free_parameters)
    np.testing.assert_array_equal(r.covariance, np.array(cov["matrix"])[np.ix_(order, order)])
    # Its diagonal is the squared standard deviations, it is symmetric.
    np.testing.assert_allclose(np.diag(r.covariance), [r.parameters[n].std ** 2 for n in r.free_parameters], rtol=1e-12)
    np.testing.assert_array_equal(r.covariance, r.covariance.T)
    # A copy: changing it leaves the result as it is.
    r.covariance[0, 0] = -1.0
    assert r.covariance[0, 0] > 0


@pytest.mark.parametrize("name", RECIPES)
def test_the_correlation_is_the_normalised_covariance(fits, name):
    r, _ = fits[name]
    c, rho = r.covariance, r.correlation
    np.testing.assert_array_equal(np.diag(rho), 1.0)
    np.testing.assert_array_equal(rho, rho.T)
    assert np.all(np.abs(rho) <= 1.0)
    d = np.sqrt(np.diag(c))
    np.testing.assert_allclose(rho, c / np.outer(d, d), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("name", RECIPES)
def test_the_covariance_agrees_with_a_numerical_one(fits, name):
    r, set_value = fits[name]
    c, numerical = r.covariance, numerical_covariance(r, set_value)
    d = np.sqrt(np.diag(c))
    worst = float(np.max(np.abs(c - numerical) / np.outer(d, d)))
    assert worst < TOLERANCE, f"{name}: max |C − Cₙ|/√(CᵢᵢCⱼⱼ) = {worst:.3g}"
    np.testing.assert_allclose(np.sqrt(np.diag(numerical)), d, rtol=TOLERANCE)


def test_the_numerical_check_can_fail(fits):
    """A covariance off by the σ² of N instead of N − p, or with a parameter's column left
    out of the Jacobian, is outside the tolerance: the check above is not vacuous."""
    r, set_value = fits["identify_operator"]
    c, numerical = r.covariance, numerical_covariance(r, set_value)
    d = np.sqrt(np.diag(c))
    n, p = r.data.y.size, len(r.free_parameters)
    assert np.max(np.abs(c * (n - p) / n - numerical) / np.outer(d, d)) > TOLERANCE
    # Without the first parameter the others' marginal variances shrink.
    reduced = np.linalg.inv(np.linalg.inv(numerical)[1:, 1:])
    assert np.max(np.abs(np.diag(c)[1:] - np.diag(reduced)) / np.diag(c)[1:]) > TOLERANCE


def test_the_covariance_follows_free_parameters_whatever_the_reports_order(fits):
    r, _ = fits["greybox_fit"]
    report = r.report()
    cov = report["uncertainty"]["covariance"]
    cov["parameters"] = cov["parameters"][::-1]
    cov["matrix"] = [row[::-1] for row in cov["matrix"][::-1]]
    back = hysid.FitResult(report, data=r.data)
    np.testing.assert_array_equal(back.covariance, r.covariance)


def test_a_report_without_a_covariance_has_none(fits):
    r, _ = fits["identify_operator"]
    report = r.report()
    del report["uncertainty"]["covariance"]  # a report written before the key existed
    old = hysid.FitResult(report, data=r.data)
    assert old.covariance is None and old.correlation is None and old.correlations() == []
    assert "[[Correlations]]" not in old.fit_report()


def test_a_covariance_over_other_parameters_is_a_report_error(fits):
    r, _ = fits["greybox_fit"]
    report = r.report()
    report["uncertainty"]["covariance"]["parameters"] = ["a", "zz"]
    with pytest.raises(hysid.ReportError, match=r"uncertainty\.covariance\.parameters"):
        hysid.FitResult(report, data=r.data)
    report = r.report()
    report["uncertainty"]["covariance"]["matrix"] = [[1.0]]
    with pytest.raises(hysid.ReportError, match=r"uncertainty\.covariance\.matrix"):
        hysid.FitResult(report, data=r.data)


@pytest.mark.parametrize("name", RECIPES)
def test_fit_report_shows_the_correlations_as_lmfit(fits, name):
    r, _ = fits[name]
    text = r.fit_report()
    assert "AIC" in text and "FPE" in text and "# fcn evals" in text
    pairs = r.correlations()
    assert pairs, f"{name}: no correlation above 0.1"
    assert [abs(c) for _, _, c in pairs] == sorted((abs(c) for _, _, c in pairs), reverse=True)
    free, rho = r.free_parameters, r.correlation
    for a, b, c in pairs:
        assert abs(c) > 0.1 and c == rho[free.index(a), free.index(b)] and free.index(a) < free.index(b)
    section = text.split("[[Correlations]]", 1)[1].splitlines()[1:]
    shown = [re.fullmatch(r"    C\((\S+), (\S+)\)\s* = ([+-]\d\.\d{4})", line) for line in section]
    assert all(shown) and len(shown) == len(pairs)
    for m, (a, b, c) in zip(shown, pairs):
        assert (m[1], m[2]) == (a, b) and float(m[3]) == pytest.approx(c, abs=5e-5)
    # A higher threshold shows fewer.
    assert len(r.correlations(min_correl=0.99)) <= len(pairs)


def test_pi_weights_carry_their_non_negative_bound():
    """PI weights are fitted by NNLS (aᵢ ≥ 0): their records say lower 0, and a weight held
    at 0 is at its bound, without a standard deviation and not among the free parameters."""
    u, y = play_record()
    y = y + 0.01 * np.random.default_rng(7).standard_normal(y.size)
    r = hysid.identify_operator(u, y, family="pi", thresholds=6)
    weights = [p for n, p in r.parameters.items() if re.fullmatch(r"a[1-9]\d*", n)]
    assert len(weights) == 6 and all(p.lower == 0.0 and p.upper == math.inf for p in weights)
    zero = [p for p in weights if p.value == 0.0]
    assert zero, "the record leaves some weights at 0"
    for p in zero:
        assert p.at_bound is True and p.std is None and p.name not in r.free_parameters
        assert f"{p.name}:" in r.fit_report() and "(at bound)" in repr(p)
    for p in weights:
        if p.value > 0:
            assert p.at_bound is False and p.name in r.free_parameters


def test_rigid_body_ls_fills_aic_fpe_and_its_covariance():
    q, u, ts = emps_record()
    r = hysid.rigid_body_ls(q, u, ts=ts, gain=35.15065188, offset=True)
    fit = r.report()["fit"]
    assert r.aic == fit["aic"] and r.fpe == fit["fpe"]
    assert isinstance(r.aic, float) and math.isfinite(r.aic) and isinstance(r.fpe, float)
    # V = RMSE² of the scored prediction, p = 4 estimates, N its samples (Ljung's FPE).
    n = fit["per_experiment"][0]["samples"]
    assert r.fpe == pytest.approx(fit["rmse"] ** 2 * (1 + 4 / n) / (1 - 4 / n), rel=1e-9)
    assert r.free_parameters == ("M", "Fv", "Fc", "offset")
    assert r.covariance is not None and r.correlation is not None
    np.testing.assert_allclose(np.diag(r.covariance), [r.parameters[n].std ** 2 for n in r.free_parameters])
    np.testing.assert_array_equal(np.diag(r.correlation), 1.0)


def test_the_new_members_resolve_their_annotations():
    for member in (Result.covariance, Result.correlation):
        assert typing.get_type_hints(member.fget)["return"] == typing.Optional[FloatArray]
    hints = typing.get_type_hints(Result.correlations)
    assert hints["return"] == typing.List[typing.Tuple[str, str, float]]
    assert typing.get_type_hints(Result.fit_report)["min_correl"] is float


@pytest.fixture(scope="module")
def noisy_play() -> typing.Tuple[np.ndarray, np.ndarray]:
    u, y = play_record()
    return u, y + 0.01 * np.random.default_rng(3).standard_normal(y.size)


# Dahl's integration diverges on this record (its own tests use a friction record).
@pytest.mark.parametrize("family", [f for f in hysid.FAMILIES if f != "dahl"])
def test_every_family_fills_the_figures_and_marks_its_bounds(noisy_play, family):
    r = hysid.identify_operator(*noisy_play, family=family, thresholds=6, grid=6, dead_zones=2)
    assert isinstance(r.aic, float) and isinstance(r.fpe, float)
    assert r.covariance is not None and r.covariance.shape == (len(r.free_parameters),) * 2
    assert r.report()["uncertainty"]["covariance"]["parameters"] == list(r.free_parameters)
    for p in r.parameters.values():
        on_bound = p.value in (p.lower, p.upper)
        assert p.at_bound is (not p.fixed and p.std is None and on_bound), p
        # An NNLS weight held at 0 is at its bound: no weight without a σ off a bound.
        if re.fullmatch(r"(a|w|k|W|mu)\d[\d_]*", p.name) and p.name != "a0" and not p.fixed and p.value == 0.0:
            assert p.at_bound, p


def test_models_fitted_from_python_carry_their_sample_time_and_columns(fits):
    """Every recipe's model holds the ts it was fitted with and its channels' names, so
    that an export (an FMU needs its sample time) works from it."""
    assert fits["greybox_fit"][0].model.sample_time == 0.05
    assert fits["greybox_fit"][0].model.columns == (["u"], ["y"])
    for name in ("identify_operator", "compare", "identify_cascade"):
        model = fits[name][0].model
        assert model.sample_time == 1.0 and model.columns == (["u"], ["y"]), name
    u, y = play_record()
    r = hysid.identify_operator(u, y, family="pi", ts=0.002, names=("voltage", "stroke"))
    assert r.model.sample_time == 0.002 and r.model.columns == (["voltage"], ["stroke"])
    builtin = hysid.greybox_fit("rigid-body", u, y, ts=0.01, fix=["Fc"], substeps=1)
    assert builtin.model.sample_time == 0.01
    assert hysid.Model({k: v for k, v in r.model.file.items() if k != "sample_time"}).sample_time is None
