"""actuator_three_steps (Gunnar et al. 2006) against known parameters and the CLI, and
rigid_body_ls on the EMPS record against the CLI."""

import json
import os
import pathlib
import subprocess

import hysid
import numpy as np
import pytest
from conftest import DATA, rel_err

REPO = pathlib.Path(__file__).resolve().parents[3]
EMPS = REPO / "data" / "emps" / "DATA_EMPS.csv"
NAMES = ["J", "Fv", "Fc", "k1", "k2", "alpha", "A"]
CLI = os.environ.get("HYSID_CLI")


def write_rig(records, folder):
    """The records as `hysid actuator rig` writes them (t = k·ts; shortest round-trip
    decimals, so the CLI's reader gets the same numbers back)."""
    folder.mkdir(parents=True, exist_ok=True)
    for r in records:
        t = np.arange(r.u.size) * r.sampling_time
        with open(folder / f"dataset{r.set}.csv", "w") as f:
            f.write("t_s,tau_Nm,theta_rad\n")
            for row in zip(t.tolist(), r.u.tolist(), r.y.tolist()):
                f.write(",".join(repr(v) for v in row) + "\n")
    return folder


def without_clock(report):
    """The report without wall-clock figures, the work counts the command line adds
    (``search.model_steps``, ``estimated_model_steps``: the process's accounting) and the
    data source (path vs arrays)."""
    report = json.loads(json.dumps(report))

    def strip(r):
        for key in ("elapsed_s", "model_steps", "estimated_model_steps"):
            r.get("search", {}) and r["search"].pop(key, None)
        r.get("data", {}) and r["data"].pop("source", None)
        for step in (r.get("details") or {}).get("steps", []) if isinstance(r.get("details"), dict) else []:
            strip(step)
        if isinstance(r.get("details"), dict):
            r["details"].pop("elapsed_s", None)

    strip(report)
    return report


@pytest.fixture(scope="module")
def noise_free_rig():
    return hysid.actuator_rig(noise=0.0, seed=0)


@pytest.fixture(scope="module")
def rig_fit(noise_free_rig):
    return hysid.actuator_three_steps(noise_free_rig)


def test_rig_records(noise_free_rig):
    assert [r.set for r in noise_free_rig] == list(range(1, 9))
    assert noise_free_rig[0].saddle_free and not noise_free_rig[1].saddle_free
    assert all(abs(r.sampling_time - 1e-3) < 1e-15 for r in noise_free_rig)


def test_three_steps_recover_the_rig_truth(rig_fit):
    """Noise-free rig (Table I's m67 as the truth): m67 within 0.1 % (the CLI's bar)."""
    truth = dict(zip(NAMES, hysid._hysid.actuator_rig_truth()))
    assert list(rig_fit.parameters) == NAMES
    for n in NAMES:
        assert rel_err(rig_fit.parameters[n].value, truth[n]) < 1e-3, n
    rep = rig_fit.report()
    assert rep["command"] == "actuator identify"
    steps = [s["command"] for s in rep["details"]["steps"]]
    assert steps == ["actuator identify: step 1", "actuator identify: step 2"] + [
        f"actuator identify: step 3 {m}" for m in ("m67", "m68", "m67f", "m68f")
    ]
    assert [v["source"] for v in rep["validation"]][0].startswith("data set 6")
    assert rep["model"] == rep["details"]["steps"][2]["model"]


def test_three_steps_with_other_known_parameters():
    """A simulated actuator with scattered parameters: recovered within 0.5 %."""
    truth = dict(zip(NAMES, hysid._hysid.actuator_rig_truth()))
    truth = {n: v * f for (n, v), f in zip(truth.items(), (1.1, 0.9, 1.05, 0.95, 1.1, 1.0, 0.9))}
    records = hysid.actuator_rig(truth=truth, noise=0.0)
    r = hysid.actuator_three_steps({rec.set: (rec.u, rec.y) for rec in records}, ts=1e-3, truth=truth)
    for n in NAMES:
        assert rel_err(r.parameters[n].value, truth[n]) < 5e-3, n
    assert r.report()["details"]["truth"] == truth


def test_three_steps_equal_the_cli_figures(noise_free_rig, tmp_path):
    """The CLI's `actuator identify` on its own `actuator rig --noise 0 --seed 0` data
    (tests/data/actuator_cli_figures.json): every step-3 estimate equal to 1e-12."""
    cli = json.loads((DATA / "actuator_cli_figures.json").read_text())
    folder = write_rig(noise_free_rig, tmp_path / "rig")
    r = hysid.actuator_three_steps(folder)
    steps = {s["command"].rsplit(" ", 1)[-1]: s for s in r.report()["details"]["steps"][2:]}
    for model, values in cli["step3"].items():
        got = {p["name"]: p["value"] for p in steps[model]["model"]["parameters"]}
        for n, v in values.items():
            assert abs(got[n] - v) <= 1e-12 * abs(v), (model, n, got[n], v)


@pytest.mark.skipif(not CLI, reason="set HYSID_CLI to a hysid binary to compare live")
def test_three_steps_report_equals_live_cli(tmp_path):
    folder = tmp_path / "rig"
    subprocess.run(
        [CLI, "actuator", "rig", "--data-out", str(folder), "--noise", "0.5", "--seed", "3"],
        check=True,
        capture_output=True,
    )
    report = tmp_path / "report.json"
    subprocess.run(
        [CLI, "actuator", "identify", "--data", str(folder), "--json", str(report)], check=True, capture_output=True
    )
    cli = json.loads(report.read_text())
    r = hysid.actuator_three_steps(folder)
    assert without_clock(r.report()) == without_clock(cli)
    for n in NAMES:
        p = next(p for p in cli["model"]["parameters"] if p["name"] == n)
        assert abs(r.parameters[n].value - p["value"]) <= 1e-12 * abs(p["value"])


def test_three_steps_bad_input():
    with pytest.raises(hysid.DataError, match="8"):
        hysid.actuator_three_steps([(np.zeros(10), np.zeros(10))] * 3, ts=1e-3)
    recs = hysid.actuator_rig(noise=0.0)
    bad = [(r.u, r.y) for r in recs]
    bad[3] = (bad[3][0], bad[3][1][:-1])
    with pytest.raises(hysid.DataError, match="data set 4"):
        hysid.actuator_three_steps(bad, ts=1e-3)
    nan = [(r.u.copy(), r.y) for r in recs]
    nan[0][0][5] = np.nan
    with pytest.raises(hysid.DataError, match="not finite"):
        hysid.actuator_three_steps(nan, ts=1e-3)
    with pytest.raises(hysid.ConfigError, match="truth"):
        hysid.actuator_three_steps(recs, truth={"J": 1.0})
    with pytest.raises(TypeError):
        hysid.actuator_three_steps(42)
    with pytest.raises(hysid.ConfigError, match="noise"):
        hysid.actuator_rig(noise=-1.0)


def emps_record():
    d = np.genfromtxt(EMPS, delimiter=",", names=True)
    t = d["t_s"]
    return d["qm_m"].copy(), d["vir_V"].copy(), (t[-1] - t[0]) / (t.size - 1)


def test_rigid_body_ls_on_emps():
    """The EMPS record (Janot, Gautier & Brunot 2019): the published IDIM estimates, and the
    CLI's figures (tests/data/emps_cli_figures.json) to 1e-12."""
    q, u, ts = emps_record()
    r = hysid.rigid_body_ls(q, u, ts=ts, gain=35.15065188, offset=True)
    for name, published, tol in [
        ("M", 95.1089, 0.005),
        ("Fv", 203.5034, 0.005),
        ("Fc", 20.3935, 0.005),
        ("offset", -3.1648, 0.02),
    ]:
        assert rel_err(r.parameters[name].value, published) < tol, name
    cli = json.loads((DATA / "emps_cli_figures.json").read_text())
    for name, v in cli["parameters"].items():
        assert abs(r.parameters[name].value - v) <= 1e-12 * abs(v), name
    assert r.report()["details"]["records"][0]["relative_error_percent"] == pytest.approx(
        cli["relative_error_percent"], rel=1e-12
    )
