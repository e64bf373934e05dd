"""Streaming models: ``Model.stepper()`` against ``Model.simulate`` and ``Model.compensator()``
against ``hysid compensate`` (with ``HYSID_CLI``), for every family of the registry."""

import json
import os
import subprocess

import hysid
import numpy as np
import pytest

CLI = os.environ.get("HYSID_CLI")


def _loop(n=800):
    """A loop with nested reversals (minor loops) through three plays (as ``test_zoo``'s)."""
    t = np.arange(n) / n
    u = 2.0 * (1.0 - 0.6 * t) * np.sin(2 * np.pi * 5 * t) + 0.3 * np.sin(2 * np.pi * 23 * t)
    y = np.empty(n)
    plays = np.zeros(3)
    for k, uk in enumerate(u):
        for i, r in enumerate((0.2, 0.5, 0.9)):
            plays[i] = max(uk - r, min(uk + r, plays[i]))
        y[k] = 0.4 * uk + plays @ np.array([0.5, 0.3, 0.2]) + 0.1
    return u, y


def _assert_close(a, b, what):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    scale = max(1.0, float(np.max(np.abs(b))))
    assert np.max(np.abs(a - b)) <= 1e-15 * scale, what


@pytest.fixture(scope="module")
def models():
    u, y = _loop()
    # The loop is counter-clockwise and rising, which no Dahl operator represents: Dahl
    # refuses it, and asked to turn counter-clockwise stops as worse than a straight line;
    # turned clockwise (as asked) it is fitted, poorly, and streams like any model.
    given = {"dahl": {"orientation": "cw"}}
    return (
        u,
        y,
        {f: hysid.identify_operator(u, y, family=f, **given.get(f, {})).model for f in hysid.FAMILIES},
    )


@pytest.mark.parametrize("family", list(hysid.FAMILIES))
def test_stepper_runs_as_simulate(models, family):
    u, y, fitted = models
    model = fitted[family]
    stepper = model.stepper(ts=1.0, y0=y[0])
    batch = model.simulate(u, ts=1.0, y0=y[0])
    _assert_close(stepper.run(u), batch, family)
    stepper.reset()
    one_by_one = [stepper.step(x) for x in u[:50]]
    _assert_close(one_by_one, batch[:50], family)
    stepper.reset()
    _assert_close(stepper.run(u), batch, f"{family} after reset")


def test_compensator_counts_clipped_references(models):
    u, y, fitted = models
    compensator = fitted["pi"].compensator()
    command = compensator.run(y)
    assert compensator.clipped == 0
    assert np.allclose(fitted["pi"].simulate(command, ts=1.0), y, rtol=0, atol=1e-9)
    compensator.reset()
    assert compensator.clipped == 0
    assert isinstance(compensator.step(float(y[0])), float)


def _record(name, value):
    return {"name": name, "value": value, "std": None, "unit": "", "fixed": False, "lower": None, "upper": None}


def test_a_kind_without_inverse_is_a_config_error():
    values = {"alpha": 0.3, "m1": 1.0, "c1": 0.5, "d": 3.0, "b1": 1.0, "b2": 0.4, "a1": -0.5}
    cascade = hysid.Model(
        {
            "schema": "hysid.model/1",
            "kind": "ch_cascade",
            "hysteresis": "ch4",
            "delay": 1,
            "parameters": [_record(n, v) for n, v in values.items()],
        }
    )
    u, _ = _loop(300)
    _assert_close(cascade.stepper(ts=1.0).run(u), cascade.simulate(u, ts=1.0), "ch_cascade")
    with pytest.raises(hysid.ConfigError, match="not invertible"):
        cascade.compensator()


@pytest.mark.skipif(not CLI, reason="set HYSID_CLI to a hysid binary to compare live")
@pytest.mark.parametrize("family", list(hysid.FAMILIES))
def test_compensator_equals_the_command_line(tmp_path, models, family):
    u, y, fitted = models
    model = fitted[family]
    reference = 1.2 * y  # partly beyond a saturating family's reach: clipped samples
    model_file = tmp_path / "model.json"
    model.save(model_file)
    data = tmp_path / "r.csv"
    np.savetxt(data, reference[:, None], delimiter=",", header="r", comments="", fmt="%.17g")
    out, report = tmp_path / "u.csv", tmp_path / "report.json"
    subprocess.run(
        [CLI, "-q", "compensate", "--model", str(model_file), "--data", str(data), "--reference", "r"]
        + ["--csv", str(out), "--json", str(report)],
        check=True,
    )
    cli = np.loadtxt(out, delimiter=",", skiprows=1)
    compensator = model.compensator()
    _assert_close(compensator.run(reference), cli[:, 1], family)
    clipped = json.loads(report.read_text())["details"]["clipped"]["count"]
    assert compensator.clipped == clipped, family
