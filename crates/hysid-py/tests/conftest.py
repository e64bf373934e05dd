"""Shared fixtures: the Bouc–Wen truth, simulated records, the Example-1 record."""

import math
import pathlib

import hysid
import numpy as np
import pytest

HERE = pathlib.Path(__file__).parent
DATA = HERE / "data"

#: Bouc–Wen truth (the benchmark's nominal values, Noël & Schoukens 2016).
BW_TRUTH = {"mL": 2.0, "cL": 10.0, "kL": 5e4, "alpha": 5e4, "beta_gamma": 800.0, "beta_delta": -1100.0, "nu": 1.0}
FS = 750.0


def bouc_wen_model(values=BW_TRUTH, substeps=2, interpolation="zoh"):
    """A built-in Bouc–Wen model file with the given parameter values."""
    defaults, _, _ = hysid._hysid.model_parameters("bouc-wen")
    params = [
        {
            "name": n,
            "value": values[n],
            "std": None,
            "unit": unit,
            "fixed": f,
            "lower": None if math.isinf(lo) else lo,
            "upper": None if math.isinf(hi) else hi,
        }
        for (n, _, lo, hi, f, unit) in defaults
    ]
    return hysid.Model(
        {
            "schema": "hysid.model/1",
            "kind": "bouc_wen",
            "parameters": params,
            "hysteresis": None,
            "delay": None,
            "initial_output": None,
            "simulation": {
                "integrator": "rk4",
                "substeps": substeps,
                "interpolation": {"zoh": "zero_order_hold", "band-limited": "band_limited"}.get(
                    interpolation, interpolation
                ),
            },
            "initial_state": [0.0, 0.0, 0.0],
        }
    )


def excitation(n, seed, amplitude=50.0):
    """A seeded random-phase multisine, 5–150 Hz at 750 Hz (the benchmark's band)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    freqs = np.arange(5.0, 150.0, 5.0)
    phases = rng.uniform(0, 2 * np.pi, freqs.size)
    u = np.sin(2 * np.pi * freqs[:, None] * t[None, :] + phases[:, None]).sum(axis=0)
    return amplitude * u / np.sqrt(np.mean(u**2))


@pytest.fixture(scope="session")
def bw_record():
    u = excitation(1500, seed=3)
    y = bouc_wen_model().simulate(u, ts=1 / FS)
    return u, y


@pytest.fixture(scope="session")
def example1():
    """Example 1 of the project (Vörös 2015 cascade, seed 1, SNR 50), written by
    `hysid generate voros --example 1 --seed 1`."""
    d = np.loadtxt(DATA / "example1.csv", delimiter=",", skiprows=1)
    return d[:, 1].copy(), d[:, 2].copy()


def rel_err(a, b):
    return abs(a - b) / max(abs(b), 1e-300)
