"""Identify a fleet of 200 simulated actuators on Dask and plot the parameter spread.

Each actuator is a Bouc–Wen oscillator (m ÿ + c ẏ + k y + z = u, ż = α ẏ −
β_γ|ẏ| sgn(z)|z|^ν − β_δ ẏ|z|^ν; Noël & Schoukens 2016) whose stiffness k, damping c and
hysteretic stiffness α scatter by a few percent around the nominal values, as in a
production lot; each record is 1000 samples at 750 Hz of a seeded multisine with 1 µm of
measurement noise. ``hysid.fleet.identify_many`` fits all 200 on a LocalCluster (or on the
cluster of ``--scheduler tcp://HOST:8786``) and the script writes the histograms of the
identified k, c, α to ``fleet_actuators.png`` (matplotlib) or prints a text table.

Run: python crates/hysid-py/examples/fleet_actuators.py [--n 200] [--workers 2] [--scheduler ADDR]
"""

import argparse
import math
import time

import hysid
import numpy as np
from hysid.fleet import Failure, identify_many

FS = 750.0
NOMINAL = {"mL": 2.0, "cL": 10.0, "kL": 5e4, "alpha": 5e4, "beta_gamma": 800.0, "beta_delta": -1100.0, "nu": 1.0}
SCATTER = {"kL": 0.05, "cL": 0.10, "alpha": 0.05}


def actuator_model(values):
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
            "simulation": {"integrator": "rk4", "substeps": 2, "interpolation": "zero_order_hold"},
            "initial_state": [0.0, 0.0, 0.0],
        }
    )


def make_fleet(n, seed=2026):
    """n records (u, y) and their true parameters."""
    rng = np.random.default_rng(seed)
    t = np.arange(1000) / FS
    freqs = np.arange(5.0, 150.0, 5.0)
    records, truths = [], []
    for _ in range(n):
        truth = dict(NOMINAL)
        for name, rel in SCATTER.items():
            truth[name] *= 1 + rel * rng.standard_normal()
        phases = rng.uniform(0, 2 * np.pi, freqs.size)
        u = np.sin(2 * np.pi * freqs[:, None] * t[None, :] + phases[:, None]).sum(axis=0)
        u *= 50.0 / np.sqrt(np.mean(u**2))
        y = actuator_model(truth).simulate(u, ts=1 / FS) + 1e-6 * rng.standard_normal(t.size)
        records.append((u, y))
        truths.append(truth)
    return records, truths


def fit_actuator(record):
    """The fleet fit: Bouc–Wen output error from the nominal values (module level: it pickles)."""
    u, y = record
    return hysid.greybox_fit("bouc-wen", u, y, ts=1 / FS, substeps=2)


def plot(values, truths, path):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    fig, axes = plt.subplots(1, len(SCATTER), figsize=(12, 3.5))
    for ax, name in zip(axes, SCATTER):
        ax.hist([t[name] for t in truths], bins=20, alpha=0.5, label="true")
        ax.hist(values[name], bins=20, histtype="step", linewidth=2, label="identified")
        ax.set_title(name)
        ax.legend()
    fig.suptitle(f"{len(values[next(iter(SCATTER))])} actuators identified with hysid on Dask")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (a real cluster)")
    ap.add_argument("--out", default="fleet_actuators.png")
    args = ap.parse_args()
    records, truths = make_fleet(args.n)
    client = None
    if args.scheduler:
        from dask.distributed import Client

        client = Client(args.scheduler)
    t0 = time.perf_counter()
    fleet = identify_many(records, fit_actuator, client=client, n_workers=args.workers)
    wall = time.perf_counter() - t0
    ok = [(r, t) for r, t in zip(fleet.results, truths) if not isinstance(r, Failure)]
    print(f"{len(ok)}/{len(records)} actuators identified in {wall:.1f} s; {len(fleet.failures)} failed")
    values = {n: np.array([r.parameters[n].value for r, _ in ok]) for n in SCATTER}
    errors = {n: max(abs(r.parameters[n].value / t[n] - 1) for r, t in ok) for n in SCATTER}
    print(f"{'parameter':<10}{'mean':>12}{'std':>12}{'min':>12}{'max':>12}{'max rel. err':>14}")
    for n, v in values.items():
        print(f"{n:<10}{v.mean():>12.5g}{v.std():>12.4g}{v.min():>12.5g}{v.max():>12.5g}{errors[n]:>14.2e}")
    if plot(values, [t for _, t in ok], args.out):
        print(f"histogram: {args.out}")
    else:
        print("(matplotlib is not installed: text table only)")


if __name__ == "__main__":
    main()
