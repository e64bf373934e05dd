#!/usr/bin/env python3
"""The Bouc–Wen training fit as a SciPy user writes it, for comparison with hysid.

Same problem as `hysid benchmark bouc-wen --train data/bouc-wen/train_multisine_5periods.csv
--start-factor 2 --starts 1`: the benchmark's oscillator (docs/benchmarks.md §1.1) in the identifiable
parameters (mL, cL, kL, alpha, beta_gamma, beta_delta; nu = 1), simulated by fixed-step RK4 at
4 steps per sample with the band-limited (FFT-resampled) input, fitted by output error from
every parameter at twice its nominal value with scipy.optimize.least_squares (trust-region
reflective, bounds, finite-difference Jacobian — what `nlgreyest`-like scripts use).

The simulation loop is plain Python over floats: the fastest way without a compiler (NumPy
cannot vectorise a sequential recursion). Nothing here is tuned against hysid.

Run:  python3 bench/scipy_bouc_wen.py [--max-nfev N]
Prints the time, the number of simulations, the estimates and the training e_RMS.
"""
import argparse
import time

import numpy as np
import scipy
from scipy import optimize, signal

SUBSTEPS = 4
NOMINAL = np.array([2.0, 10.0, 5e4, 5e4, 800.0, -1100.0])
NAMES = ["mL", "cL", "kL", "alpha", "beta_gamma", "beta_delta"]


def load(path):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 1], data[:, 2], data[1, 0] - data[0, 0]


def simulate(theta, u_fine, ts, n):
    """RK4 at ts/SUBSTEPS; u_fine holds the input at every half sub-step."""
    ml, cl, kl, alpha, bg, bd = (float(v) for v in theta)
    h = ts / SUBSTEPS
    y = np.empty(n)
    x0 = x1 = x2 = 0.0

    def f(x0, x1, x2, u):
        return (
            x1,
            (u - cl * x1 - kl * x0 - x2) / ml,
            alpha * x1 - bg * abs(x1) * x2 - bd * x1 * abs(x2),
        )

    uf = u_fine.tolist()
    for k in range(n):
        y[k] = x0
        for s in range(SUBSTEPS):
            j = 2 * (k * SUBSTEPS + s)
            u0, um, u1 = uf[j], uf[j + 1], uf[j + 2]
            a0, a1, a2 = f(x0, x1, x2, u0)
            b0, b1, b2 = f(x0 + 0.5 * h * a0, x1 + 0.5 * h * a1, x2 + 0.5 * h * a2, um)
            c0, c1, c2 = f(x0 + 0.5 * h * b0, x1 + 0.5 * h * b1, x2 + 0.5 * h * b2, um)
            d0, d1, d2 = f(x0 + h * c0, x1 + h * c1, x2 + h * c2, u1)
            x0 += h / 6 * (a0 + 2 * b0 + 2 * c0 + d0)
            x1 += h / 6 * (a1 + 2 * b1 + 2 * c1 + d1)
            x2 += h / 6 * (a2 + 2 * b2 + 2 * c2 + d2)
    return y


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default="data/bouc-wen/train_multisine_5periods.csv")
    parser.add_argument("--max-nfev", type=int, default=None)
    args = parser.parse_args()

    u, y, ts = load(args.data)
    n = len(u)
    factor = 2 * SUBSTEPS
    # Band-limited input at every half sub-step (periodic record), one extra sample at the end.
    u_fine = signal.resample(u, n * factor)
    u_fine = np.append(u_fine, u_fine[0])

    sims = 0

    def residuals(theta):
        nonlocal sims
        sims += 1
        return simulate(theta, u_fine, ts, n) - y

    clock = time.perf_counter()
    r = residuals(NOMINAL)
    one_sim = time.perf_counter() - clock
    print(f"SciPy {scipy.__version__}, NumPy {np.__version__}; {n} samples, RK4 x{SUBSTEPS}")
    print(f"one simulation: {one_sim:.2f} s; e_RMS at the nominal parameters {np.sqrt(np.mean(r**2)):.4e} m")

    sims = 0
    lower = [1e-9, 0.0, 0.0, 0.0, -np.inf, -np.inf]
    clock = time.perf_counter()
    fit = optimize.least_squares(
        residuals,
        2.0 * NOMINAL,
        bounds=(lower, np.inf),
        x_scale="jac",
        max_nfev=args.max_nfev,
    )
    elapsed = time.perf_counter() - clock
    print(f"least_squares: {elapsed:.1f} s, {sims} simulations, status {fit.status}: {fit.message}")
    for name, v, nominal in zip(NAMES, fit.x, NOMINAL):
        print(f"  {name:<11} {v: .8e}   ({100 * (v / nominal - 1):+.3f} % from nominal)")
    print(f"training e_RMS {np.sqrt(np.mean(fit.fun**2)):.4e} m")


if __name__ == "__main__":
    main()
