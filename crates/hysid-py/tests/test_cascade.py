"""identify_cascade / identify_hysteresis: equality with the CLI, round trips, models."""

import json
import os
import subprocess

import hysid
import numpy as np
import pytest
from conftest import DATA, rel_err

#: Example 1's truth (Vörös 2015 cascade as the project reconstructs it).
TRUTH = {"alpha": 0.3, "m1": 1.0, "c1": 0.5, "d": 3.0, "b1": 1.0, "b2": 0.5, "a1": -0.6, "a2": 0.2}


def cli_model():
    """The model file the CLI wrote for example1.csv (`hysid identify cascade --input x
    --output y --hysteresis ch4 --na 2 --nb 2 --delay 1 --model ...`)."""
    return json.loads((DATA / "example1_cli_model.json").read_text())


def test_cascade_equals_cli_to_1e12(example1):
    x, y = example1
    r = hysid.identify_cascade(x, y, hysteresis="ch4", na=2, nb=2, delay=1)
    cli = cli_model()
    assert [p["name"] for p in cli["parameters"]] == list(r.parameters)
    for rec in cli["parameters"]:
        p = r.parameters[rec["name"]]
        assert abs(p.value - rec["value"]) <= 1e-12 * max(1.0, abs(rec["value"])), rec["name"]
        if rec["std"] is not None:
            assert abs(p.std - rec["std"]) <= 1e-9 * abs(rec["std"]), rec["name"]
    for key in ("schema", "kind", "hysteresis", "delay"):
        assert r.model.file[key] == cli[key], key


@pytest.mark.skipif(not os.environ.get("HYSID_CLI"), reason="set HYSID_CLI to a hysid binary to compare live")
def test_cascade_equals_live_cli(example1, tmp_path):
    model = tmp_path / "m.json"
    subprocess.run(
        [
            os.environ["HYSID_CLI"],
            "identify",
            "cascade",
            "--data",
            str(DATA / "example1.csv"),
            "--input",
            "x",
            "--output",
            "y",
            "--hysteresis",
            "ch4",
            "--na",
            "2",
            "--nb",
            "2",
            "--delay",
            "1",
            "--model-out",
            str(model),
        ],
        check=True,
        capture_output=True,
    )
    cli = hysid.load_model(model)
    r = hysid.identify_cascade(*example1, hysteresis="ch4", na=2, nb=2, delay=1)
    for n, p in cli.parameters.items():
        assert abs(r.parameters[n].value - p.value) <= 1e-12 * max(1.0, abs(p.value))


def test_cascade_recovers_linear_block(example1):
    r = hysid.identify_cascade(*example1, hysteresis="ch4", na=2, nb=2, delay=1)
    for n, v in TRUTH.items():
        assert abs(r.parameters[n].value - v) < 0.05, n
    assert r.fit_percent > 90
    rep = r.report()
    assert rep["schema"] == "hysid.report/1" and rep["command"] == "identify cascade"
    assert rep["model"]["kind"] == "ch_cascade"


def test_model_simulate_reproduces_fit(example1):
    x, y = example1
    r = hysid.identify_cascade(x, y, hysteresis="ch4", na=2, nb=2, delay=1)
    yhat = r.model.simulate(x, ts=1.0)
    assert yhat.shape == x.shape
    fit = 100 * (1 - np.linalg.norm(y - yhat) / np.linalg.norm(y - y.mean()))
    assert abs(fit - r.fit_percent) < 1e-9


def test_save_load_round_trip(example1, tmp_path):
    x, y = example1
    r = hysid.identify_cascade(x, y, hysteresis="ch4", na=2, nb=2, delay=1)
    path = tmp_path / "model.json"
    r.model.save(path)
    back = hysid.load_model(path)
    for n, p in r.model.parameters.items():
        assert back.parameters[n].value == p.value, n
        # The library's model-file round trip keeps d's std to 1 ulp (reported to the lead).
        if p.std is not None:
            assert abs(back.parameters[n].std - p.std) <= 1e-15 * p.std, n
    np.testing.assert_array_equal(back.simulate(x, ts=1.0), r.model.simulate(x, ts=1.0))


def test_load_cli_model_file():
    m = hysid.load_model(DATA / "example1_cli_model.json")
    assert m.kind == "ch_cascade" and "a1" in m.parameters


def test_hysteresis_round_trip(example1):
    """The cascade's hysteresis simulated alone, then identified alone."""
    x, _ = example1
    r = hysid.identify_cascade(*example1, hysteresis="ch4", na=2, nb=2, delay=1)
    hfile = {
        "schema": "hysid.model/1",
        "kind": "coleman_hodgdon",
        "hysteresis": "ch4",
        "initial_output": "zero",
        "delay": None,
        "simulation": None,
        "initial_state": None,
        "parameters": [
            dict(p, std=None) for p in r.model.file["parameters"] if p["name"] not in ("a1", "a2", "b1", "b2")
        ],
    }
    v = hysid.Model(hfile).simulate(x, ts=1.0)
    h = hysid.identify_hysteresis(x, v, hysteresis="ch4", initial_output="zero")
    for rec in hfile["parameters"]:
        assert rel_err(h.parameters[rec["name"]].value, rec["value"]) < 1e-6, rec["name"]


def test_dataframe(example1):
    pd = pytest.importorskip("pandas")
    r = hysid.identify_cascade(*example1, hysteresis="ch4", na=2, nb=2, delay=1)
    df = r.to_dataframe()
    assert isinstance(df, pd.DataFrame)
    assert df.loc["a1", "value"] == r.parameters["a1"].value


def test_record_objects_accepted(example1):
    class Record:  # the nonlinear_benchmarks Input_output_data interface
        def __init__(self, u, y, ts):
            self.u, self.y, self.sampling_time = u, y, ts

    x, y = example1
    a = hysid.identify_cascade(Record(x, y, 1.0), na=2, nb=2, delay=1)
    b = hysid.identify_cascade(x, y, na=2, nb=2, delay=1)
    assert a.parameters == b.parameters


def timeless(report):
    """A report without its wall-clock figure, the command line's work counts
    (``search.model_steps``, ``estimated_model_steps``) and the data's names (a file vs numpy
    arrays: the command line also saves the record's sample time and columns with the
    model)."""
    report = json.loads(json.dumps(report))
    for key in ("elapsed_s", "model_steps", "estimated_model_steps"):
        report["search"].pop(key, None)
    report["data"].pop("source", None)
    for key in ("sample_time", "columns"):
        report["model"].pop(key, None)
    for e in report["fit"]["per_experiment"]:
        e.pop("experiment", None)
    return report


@pytest.mark.skipif(not os.environ.get("HYSID_CLI"), reason="set HYSID_CLI to a hysid binary to compare live")
def test_cascade_report_equals_live_cli(example1, tmp_path):
    """The library's report builder (hysid::report::cascade_report) gives the CLI's report."""
    path = tmp_path / "r.json"
    args = ["identify", "cascade", "--data", str(DATA / "example1.csv"), "--input", "x", "--output", "y"]
    args += ["--hysteresis", "ch4", "--na", "2", "--nb", "2", "--delay", "1", "--json", str(path)]
    subprocess.run([os.environ["HYSID_CLI"], *args], check=True, capture_output=True)
    r = hysid.identify_cascade(*example1, hysteresis="ch4", na=2, nb=2, delay=1)
    assert timeless(r.report()) == timeless(json.loads(path.read_text()))
