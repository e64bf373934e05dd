"""compare and compensate from Python: the command line's ranking, figures and input."""

import json
import os
import pickle
import subprocess

import hysid
import numpy as np
import pytest
from test_zoo import _loop

CLI = os.environ.get("HYSID_CLI")
needs_cli = pytest.mark.skipif(not CLI, reason="set HYSID_CLI to a hysid binary to compare live")
#: The families compared live (the quick ones; every family is compared alone in test_zoo).
QUICK = ["pi", "gpi", "maxwell-slip", "preisach", "backlash", "kp", "ch4"]


@pytest.fixture(scope="module")
def record():
    return _loop()


@pytest.fixture(scope="module")
def comparison(record):
    return hysid.compare(*record, families=QUICK)


def _csv(path, columns):
    names = list(columns)
    np.savetxt(path, np.column_stack([columns[n] for n in names]), delimiter=",", header=",".join(names), comments="")
    return path


def test_ranking_fields_and_results(record, comparison):
    fits = [r["validation_fit_percent"] for r in comparison.table]
    assert fits == sorted(fits, reverse=True)
    assert comparison.best == comparison.table[0]["family"] and list(comparison.results)[0] == comparison.best
    assert set(comparison.results) | set(comparison.errors) == set(QUICK)
    assert comparison.model == comparison.results[comparison.best].model
    # Each family's result is its fit on the training samples (the first 60 %).
    u, y = record
    train = round(0.6 * len(u))
    alone = hysid.identify_operator(u[:train], y[:train], family="pi")
    assert comparison.results["pi"] == alone
    assert len(comparison.validation.u) == len(u) - train
    for name, s in comparison.simulated.items():
        row = next(r for r in comparison.table if r["family"] == name)
        yv = comparison.validation.y
        fit = 100 * (1 - np.linalg.norm(yv - s) / np.linalg.norm(yv - yv.mean()))
        assert abs(fit - row["validation_fit_percent"]) < 1e-9


def test_dataframe_and_pickle(comparison):
    df = comparison.to_dataframe()
    assert list(df.index) == [r["family"] for r in comparison.table]
    assert list(df.columns)[:5] == ["validation_fit_percent", "validation_rmse", "parameters", "aic", "fit_time_s"]
    back = pickle.loads(pickle.dumps(comparison))
    assert back.table == comparison.table and back.results == comparison.results
    assert repr(back).startswith(f"Comparison({len(QUICK)} families")


def test_bad_families_are_value_errors(record):
    with pytest.raises(ValueError, match="unknown hysteresis family"):
        hysid.compare(*record, families=["pi", "prandtl"])
    with pytest.raises(ValueError, match="no family"):
        hysid.compare(*record, families=[])
    with pytest.raises(ValueError, match="'all' or a list"):
        hysid.compare(*record, families="pi")
    with pytest.raises(ValueError, match="threshold count"):
        hysid.compare(*record, families=["pi"], thresholds=0)


def test_validation_record(record):
    u, y = record
    c = hysid.compare(u[:600], y[:600], validate=(u[600:], y[600:]), families=["pi", "backlash"])
    assert len(c.validation.u) == 600 and "validation record" in c.split


@needs_cli
def test_compare_ranking_equals_the_command_line(tmp_path, record, comparison):
    u, y = record
    csv = _csv(tmp_path / "loop.csv", {"u": u, "y": y})
    report = tmp_path / "compare.json"
    args = ["-q", "compare", "--data", csv, "--input", "u", "--output", "y", "--families", ",".join(QUICK)]
    subprocess.run([CLI, *map(str, args), "--json", str(report)], check=True, capture_output=True)
    cli = json.loads(report.read_text())["details"]
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    py = hysid.compare(data[:, 0], data[:, 1], families=QUICK)
    assert [r["family"] for r in py.table] == [r["family"] for r in cli["families"]]
    assert py.best == cli["best"]
    for mine, theirs in zip(py.table, cli["families"]):
        for key in ("validation_fit_percent", "validation_rmse", "aic"):
            a, b = mine[key], theirs[key]
            assert (a is None and b is None) or abs(a - b) <= 1e-12 * max(1.0, abs(b)), (mine["family"], key)
        assert mine["parameters"] == theirs["parameters"]


def _reference(n=500):
    t = np.arange(n) / n
    return 1.2 * np.sin(2 * np.pi * 3 * t) * (1 - 0.5 * t) + 0.2


@pytest.mark.parametrize("family", ["pi", "maxwell-slip", "preisach", "ch4", "bouc-wen"])
def test_compensation_follows_the_reference(record, family):
    model = hysid.identify_operator(*record, family=family).model
    r = _reference()
    c = hysid.compensate(model, r)
    follows = np.setdiff1d(np.arange(r.size), c.clipped)
    assert np.max(np.abs(c.predicted[follows] - r[follows])) < 1e-6
    np.testing.assert_allclose(np.ravel(model.simulate(c.u, ts=1.0, y0=r[0])), c.predicted, atol=1e-9)
    back = pickle.loads(pickle.dumps(c))
    assert back.clipped == c.clipped and (back.u == c.u).all()


def test_unreachable_reference_is_listed(record):
    model = hysid.identify_operator(*record, family="ch4").model
    r = _reference() * 10
    c = hysid.compensate(model, r)
    assert c.clipped and c.clipped_ranges and c.clipped_ranges[0][0] == c.clipped[0]
    with pytest.raises(TypeError, match="hysid.Model"):
        hysid.compensate({"kind": "operator"}, r)


@needs_cli
@pytest.mark.parametrize("family", ["pi", "maxwell-slip", "preisach", "ch4", "bouc-wen"])
def test_compensate_equals_the_command_line(tmp_path, record, family):
    fitted = hysid.identify_operator(*record, family=family)
    path = tmp_path / "model.json"
    fitted.model.save(path)
    r = _reference()
    csv = _csv(tmp_path / "ref.csv", {"r": r})
    out = tmp_path / "u.csv"
    subprocess.run(
        [CLI, "-q", "compensate", "--model", str(path), "--data", str(csv), "--reference", "r", "--csv", str(out)],
        check=True,
        capture_output=True,
    )
    cli = np.genfromtxt(out, delimiter=",", names=True)
    ref = np.loadtxt(csv, delimiter=",", skiprows=1)
    for model in (fitted.model, str(path)):
        py = hysid.compensate(model, ref)
        assert np.max(np.abs(py.u - cli["u"])) <= 1e-12 * max(1.0, np.max(np.abs(cli["u"])))
        assert np.max(np.abs(py.predicted - cli["predicted"])) <= 1e-12 * max(1.0, np.max(np.abs(cli["predicted"])))


@needs_cli
@pytest.mark.parametrize("family", ["pi", "preisach"])
def test_operator_cascade_equals_the_command_line(tmp_path, record, family):
    u, y = record
    csv = _csv(tmp_path / "loop.csv", {"x": u, "y": y})
    report = tmp_path / "cascade.json"
    subprocess.run(
        [CLI, "-q", "identify", "cascade", "--hysteresis", family, "--data", str(csv), "--input", "x", "--output", "y"]
        + ["--na", "1", "--nb", "1", "--delay", "1", "--json", str(report)],
        check=True,
        capture_output=True,
    )
    cli = {p["name"]: p["value"] for p in json.loads(report.read_text())["model"]["parameters"]}
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    py = hysid.identify_cascade(data[:, 0], data[:, 1], hysteresis=family, na=1, nb=1, delay=1)
    assert set(py.parameters) == set(cli)
    for name, value in cli.items():
        assert abs(py.parameters[name].value - value) <= 1e-12 * max(1.0, abs(value)), name


def test_operator_cascade_options_are_checked(record):
    with pytest.raises(ValueError, match="grid applies to preisach"):
        hysid.identify_cascade(*record, hysteresis="pi", na=1, nb=1, delay=1, grid=5)
    with pytest.raises(ValueError, match="bootstrap"):
        hysid.identify_cascade(*record, hysteresis="pi", na=1, nb=1, delay=1, uncertainty="bootstrap")
    with pytest.raises(ValueError, match="unknown"):
        hysid.identify_cascade(*record, hysteresis="ch9", na=1, nb=1, delay=1)


def test_a_single_ferrite_loop_is_compared_with_the_records_orientation():
    """A B(H) loop measured from its tip (the vendored Mn-Zn ferrite's largest, 129 samples):
    its training part cannot tell the orientation, so the comparison detects it on the whole
    record and the families that could not tell are fitted with it (their rows say
    ``record``); none is refused as not exciting."""
    path = os.path.join(os.path.dirname(__file__), "..", "..", "..", "data", "ferrite", "mnzn_ferrite_bh_loops.csv")
    data = np.genfromtxt(path, delimiter=",", names=True)
    h, b = data["H4_A_per_m"], data["B4_T"]
    families = ["pi", "gpi", "preisach", "kp", "jiles-atherton"]
    c = hysid.compare(h, b, families=families)
    assert not c.errors, c.errors
    rows = {r["family"]: r for r in c.table}
    for name in ["pi", "gpi", "preisach", "kp"]:
        assert rows[name]["orientation"] == "ccw" and rows[name]["orientation_source"] == "record"
    assert rows["jiles-atherton"]["orientation_source"] == "detected"
    assert (c.orientation, c.orientation_source) == ("ccw", "record")
    assert c.best == "jiles-atherton"
