"""greybox_fit: built-in models, user models as Python functions, benchmark_bouc_wen,
rigid_body_ls."""

import time

import hysid
import numpy as np
import pytest
from conftest import BW_TRUTH, FS, bouc_wen_model, excitation, rel_err
from models import bouc_wen_python

START = {k: (v * 1.05 if k != "nu" else v) for k, v in BW_TRUTH.items()}


@pytest.fixture(scope="module")
def short_record():
    u = excitation(400, seed=5)
    return u, bouc_wen_model(substeps=1).simulate(u, ts=1 / FS)


def test_builtin_bouc_wen_round_trip(bw_record):
    u, y = bw_record
    r = hysid.greybox_fit("bouc-wen", u, y, ts=1 / FS, init={k: v for k, v in START.items() if k != "nu"}, substeps=2)
    for n, v in BW_TRUTH.items():
        assert rel_err(r.parameters[n].value, v) < 1e-8, n
    assert r.parameters["nu"].fixed and r.parameters["nu"].std is None
    assert r.converged


def test_user_model_recovers_parameters(short_record):
    """A Bouc–Wen oscillator written in Python: parameters to 1e-4 relative; the fit time
    is printed next to the built-in model's on the same data."""
    u, y = short_record
    t0 = time.perf_counter()
    user = hysid.greybox_fit(bouc_wen_python(START), u, y, ts=1 / FS, substeps=1)
    t_user = time.perf_counter() - t0
    t0 = time.perf_counter()
    builtin = hysid.greybox_fit(
        "bouc-wen", u, y, ts=1 / FS, substeps=1, init={k: v for k, v in START.items() if k != "nu"}
    )
    t_builtin = time.perf_counter() - t0
    print(
        f"\nuser-defined Bouc–Wen fit {t_user:.2f} s, built-in {t_builtin:.3f} s "
        f"({t_user / t_builtin:.0f}x), {len(u)} samples"
    )
    for n, v in BW_TRUTH.items():
        assert rel_err(user.parameters[n].value, v) < 1e-4, n
        assert rel_err(builtin.parameters[n].value, v) < 1e-4, n
    # The fitted user model simulates (same integrator) the data back.
    np.testing.assert_allclose(user.model.simulate(u, ts=1 / FS), y, rtol=0, atol=1e-9)


def test_benchmark_bouc_wen_on_simulated_records(bw_record):
    u = bw_record[0]
    truth = bouc_wen_model(substeps=4, interpolation="band-limited")  # the benchmark's settings
    y = truth.simulate(u, ts=1 / FS)
    ut = excitation(600, seed=9)
    yt = truth.simulate(ut, ts=1 / FS)
    r = hysid.benchmark_bouc_wen(u, y, tests=[(ut, yt)], starts=1)
    assert len(r.validation) == 1
    assert r.validation[0]["e_rms"] < 1e-6 and r.validation[0]["samples"] == 600
    assert r.report()["command"] == "benchmark bouc-wen"


def test_rigid_body_ls_round_trip():
    """g·u = M q̈ + Fv q̇ + Fc sgn(q̇) on a simulated smooth motion."""
    ts = 1e-3
    t = np.arange(4000) * ts
    q = 0.02 * np.sin(2 * np.pi * 1.5 * t) + 0.01 * np.sin(2 * np.pi * 4.0 * t)
    qd = np.gradient(q, ts)
    qdd = np.gradient(qd, ts)
    M, Fv, Fc = 1.5, 20.0, 3.0
    u = M * qdd + Fv * qd + Fc * np.sign(qd)
    r = hysid.rigid_body_ls(q, u, ts=ts, border=200)
    names = list(r.parameters)
    assert names[0] == "M"
    assert rel_err(r.parameters["M"].value, M) < 0.02
    assert r.report()["uncertainty"]["method"] == "least_squares"


def test_help_is_useful():
    assert "Coleman–Hodgdon" in hysid.identify_cascade.__doc__
    assert "RK4" in hysid.GreyBoxModel.__doc__
