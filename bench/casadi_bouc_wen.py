#!/usr/bin/env python3
"""The Bouc–Wen training fit as a CasADi expert writes it, for comparison with hysid.

Same problem as `hysid benchmark bouc-wen --train data/bouc-wen/train_multisine_5periods.csv
--start-factor 2 --starts 1`, and solved the same way, so that the two can be timed side by
side (bench/bouc_wen_fit.sh) and their estimates compared:

* the benchmark's oscillator (docs/benchmarks.md §1.1) with nu = 1 fixed,
      mL y'' + cL y' + kL y + z = u,
      z' = alpha y' - beta_gamma |y'| sign(z)|z|^nu - beta_delta y' |z|^nu,
  states (y, y', z) from rest, output y, free theta = (mL, cL, kL, alpha, beta_gamma,
  beta_delta) with hysid's bounds (mL >= 1e-9; cL, kL, alpha >= 0);
* classical RK4 at 4 sub-steps per sample; the input between samples as hysid reads it: the
  record's band-limited (periodic, zero-padded DFT) interpolation tabulated at the 2·4 + 1
  half-step nodes of each sample interval (hysid-spectral's band_limited_upsample and
  InputTrack::nodes; the table index is clamped at its end, which only the unused step after
  the last sample reads);
* the criterion S(theta) = sum over all 40 960 samples of (yhat - y)^2 (no skipped samples,
  weight 1), as hysid's output-error fit forms it;
* exact forward sensitivities by CasADi's forward-mode AD: one sample interval (4 RK4
  sub-steps) is written symbolically (SX) and `jtimes` pushes the six parameter directions
  through it; the step also accumulates S, J'r and J'J (upper triangle) so that a `fold`
  over the record returns the normal equations alone (no 40 960 x 7 Jacobian leaves C);
  1/mL enters the expressions as a variable of its own, its direction seeded with
  d(1/mL)/dmL = -1/mL^2 (CasADi turns x*(1/m) back into x/m, and a division per direction and
  stage cost a quarter of the run time);
* the fold generated as C by CasADi's CodeGenerator, compiled by the system compiler
  (`cc -O2 -fPIC -shared`, $CC overrides cc) and loaded with casadi.external; with
  --cache DIR the library is kept in DIR under the SHA-256 of its source and flags and
  reused while they are unchanged (default: compiled afresh in a temporary directory);
* Levenberg–Marquardt in NumPy with the rules of hysid's default engine: Marquardt scaling
  D = diag(J'J) (floored at 1e-12·max), lambda0 = 1e-3, Nielsen's update (lambda·max(1/3,
  1 - (2 rho - 1)^3) on success, lambda·nu with nu doubling on failure, rho > 1e-4 to accept),
  bounds by an active set and projection; stop when the Gauss–Newton step promises a relative
  decrease < 1e-10 or an accepted step both gave and promised less than that. As hysid does
  for its grey-box models, every trial point is evaluated with its sensitivities, so an
  accepted point's normal equations are already there.

The start is hysid's: the nominal parameters times --start-factor (the CLI's start values;
with --starts 1 hysid runs no screening or other preliminary step). The first trial point of
the first iteration (lambda = 1e-3 from that start) is printed: with factor 2 it is hysid's
first simulated point after the start, mL 0.2567, cL 0 (on its bound), kL 10110.04, ...

Nothing random. Run (numpy and casadi needed; bench/bouc_wen_fit.sh makes a venv):

    python3 bench/casadi_bouc_wen.py [--cache DIR] [--json FILE] [--data CSV]

Prints the set-up times, the estimates, the criterion, the iterations and the fit's wall time.
"""

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time

import casadi as ca
import numpy as np

NAMES = ["mL", "cL", "kL", "alpha", "beta_gamma", "beta_delta"]
NOMINAL = np.array([2.0, 10.0, 5e4, 5e4, 800.0, -1100.0])
LOWER = np.array([1e-9, 0.0, 0.0, 0.0, -np.inf, -np.inf])
UPPER = np.full(6, np.inf)
NU = 1.0  # fixed, as in the benchmark fit
P = 6  # free parameters
# The accumulator of the fold: x (3), its sensitivities column-major (18), the criterion (1),
# J'r (6), J'J's upper triangle by columns (21), q = (1/mL, cL, kL, alpha, beta_gamma,
# beta_delta) (6) and dq = d(1/mL)/dmL (1), both passed through unchanged.
N_ACC = 3 + 3 * P + 1 + P + P * (P + 1) // 2 + P + 1
TRI = [(i, j) for j in range(P) for i in range(j + 1)]
CFLAGS = ["-O2", "-fPIC", "-shared"]


def load(path):
    """u, y and the sample time (the time column's mean step, as hysid reads it)."""
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    t, u, y = data[:, 0], data[:, 1], data[:, 2]
    return u, y, (t[-1] - t[0]) / (len(t) - 1)


def band_limited_upsample(x, factor):
    """The trigonometric interpolation of the periodic record x at `factor` points a sample:
    the DFT zero-padded to n·factor bins (the Nyquist bin of an even n split between the two
    halves), inverse-transformed and scaled by 1/n."""
    n = len(x)
    m = n * factor
    spectrum = np.fft.fft(x)
    padded = np.zeros(m, dtype=complex)
    half = n // 2
    padded[: half + 1] = spectrum[: half + 1]
    k = np.arange(1, n - half)
    padded[m - k] = spectrum[n - k]
    if n % 2 == 0:
        padded[half] = padded[m - half] = 0.5 * spectrum[half]
    # numpy's inverse divides by m; the interpolation divides by n.
    return np.fft.ifft(padded).real * (m / n)


def input_nodes(u, substeps):
    """The input at nodes 0..2m of every sample interval (rows: samples), m sub-steps."""
    res = 2 * substeps
    fine = band_limited_upsample(u, res)
    index = np.arange(len(u))[:, None] * res + np.arange(res + 1)[None, :]
    return fine[np.minimum(index, len(fine) - 1)]


def sample_step(ts, substeps):
    """One sample interval as an SX function: (acc, u nodes, y measured) -> acc."""
    res = 2 * substeps
    x = ca.SX.sym("x", 3)
    s = ca.SX.sym("S", 3, P)
    cost = ca.SX.sym("cost")
    jtr = ca.SX.sym("jtr", P)
    jtj = ca.SX.sym("jtj", len(TRI))
    q = ca.SX.sym("q", P)
    dq = ca.SX.sym("dq")
    nodes = ca.SX.sym("u", res + 1)
    y_meas = ca.SX.sym("y")
    inv_m, c, k, alpha, bg, bd = ca.vertsplit(q)

    def rates(state, u):
        pos, vel, z = state[0], state[1], state[2]
        # sign(z)|z|^nu: with nu = 1 that is z (the same number), |z|^nu is |z|.
        if NU == 1.0:
            signed, mag = z, ca.fabs(z)
        else:
            signed, mag = ca.sign(z) * ca.fabs(z) ** NU, ca.fabs(z) ** NU
        return ca.vertcat(
            vel,
            (u - c * vel - k * pos - z) * inv_m,
            alpha * vel - bg * ca.fabs(vel) * signed - bd * vel * mag,
        )

    h = ts / substeps
    xn = x
    for j in range(substeps):
        u0, um, u1 = nodes[2 * j], nodes[2 * j + 1], nodes[2 * j + 2]
        k1 = rates(xn, u0)
        k2 = rates(xn + (0.5 * h) * k1, um)
        k3 = rates(xn + (0.5 * h) * k2, um)
        k4 = rates(xn + h * k3, u1)
        xn = xn + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    # Forward mode, six directions: d x_next = (dx_next/dx) S + (dx_next/dq) dq/dtheta.
    seed = ca.SX.eye(P)
    seed[0, 0] = dq
    sn = ca.jtimes(xn, ca.vertcat(x, q), ca.vertcat(s, seed))
    r = x[0] - y_meas  # yhat(t_k) - y(t_k): the output is read before the step
    row = s[0, :].T  # d yhat(t_k) / d theta
    acc = ca.vertcat(x, ca.vec(s), cost, jtr, jtj, q, dq)
    acc_next = ca.vertcat(
        xn,
        ca.vec(sn),
        cost + r * r,
        jtr + row * r,
        jtj + ca.vertcat(*[row[i] * row[j] for i, j in TRI]),
        q,
        dq,
    )
    return ca.Function("bw_step", [acc, nodes, y_meas], [acc_next])


def record_fold(step, n, chunk=64):
    """`step` folded over n samples: (acc, nodes 9 x n, y 1 x n) -> acc.

    Built as a fold of folds of `chunk` samples (and a fold of the remainder): the same loop,
    but CasADi constructs `step.fold(40960)` in 0.4 s and this in 0.03 s, and its code runs as
    fast or faster."""
    q, r = divmod(n, chunk)
    if q == 0:
        return step.fold(n)
    body = step.fold(chunk).fold(q) if q > 1 else step.fold(chunk)
    if r == 0:
        return body
    acc = ca.MX.sym("acc", N_ACC)
    nodes = ca.MX.sym("nodes", step.size1_in(1), n)
    y = ca.MX.sym("y", 1, n)
    split = q * chunk
    out = body(acc, nodes[:, :split], y[:, :split])
    out = step.fold(r)(out, nodes[:, split:], y[:, split:])
    return ca.Function("bw_fold", [acc, nodes, y], [out])


def compile_fold(fold, cache):
    """Generates the fold's C, compiles it (or finds it in `cache`), loads it."""
    clock = time.perf_counter()
    gen = ca.CodeGenerator("bw_fold", {"with_header": False})
    gen.add(fold)
    source = gen.dump()
    codegen_s = time.perf_counter() - clock
    cc = os.environ.get("CC", "cc")
    key = hashlib.sha256("\0".join([source, cc, *CFLAGS]).encode()).hexdigest()[:20]
    clock = time.perf_counter()
    if cache:
        os.makedirs(cache, exist_ok=True)
        lib = os.path.join(cache, f"bw_fold_{key}.so")
        compiled = not os.path.exists(lib)
        if compiled:
            tmp = tempfile.mkdtemp(dir=cache)
            c_file = os.path.join(tmp, "bw_fold.c")
            with open(c_file, "w") as f:
                f.write(source)
            subprocess.run([cc, *CFLAGS, "-o", os.path.join(tmp, "lib.so"), c_file], check=True)
            os.replace(os.path.join(tmp, "lib.so"), lib)  # atomic: a reader sees all or none
            os.remove(c_file)
            os.rmdir(tmp)
        function = ca.external(fold.name(), lib)
    else:
        compiled = True
        with tempfile.TemporaryDirectory() as tmp:
            c_file = os.path.join(tmp, "bw_fold.c")
            lib = os.path.join(tmp, "bw_fold.so")
            with open(c_file, "w") as f:
                f.write(source)
            subprocess.run([cc, *CFLAGS, "-o", lib, c_file], check=True)
            function = ca.external(fold.name(), lib)  # dlopen'ed: the file may go
    return function, compiled, codegen_s, time.perf_counter() - clock, len(source)


class Problem:
    """The criterion and its normal equations at theta, one compiled fold each."""

    def __init__(self, fold, nodes, y):
        self.fold = fold
        self.nodes = ca.DM(nodes.T)  # 9 x n, one column a sample
        self.y = ca.DM(y[None, :])
        self.evaluations = 0

    def normal_equations(self, theta):
        """(S, J'r, J'J) at theta; None where the simulation is not finite."""
        self.evaluations += 1
        acc = np.zeros(N_ACC)
        acc[-7] = 1.0 / theta[0]
        acc[-6:-1] = theta[1:]
        acc[-1] = -1.0 / theta[0] ** 2
        out = np.asarray(self.fold(acc, self.nodes, self.y)).ravel()
        if not np.all(np.isfinite(out[: 22 + P + len(TRI)])):
            return None
        cost = out[21]
        jtr = out[22 : 22 + P].copy()
        jtj = np.zeros((P, P))
        for (i, j), v in zip(TRI, out[22 + P : 22 + P + len(TRI)]):
            jtj[i, j] = jtj[j, i] = v
        return cost, jtr, jtj


def levenberg_marquardt(problem, theta0, tol=1e-10, max_iterations=100):
    """Bounded LM (see the module docs); returns a dict of the outcome."""
    step_tol = grad_tol = 1e-12
    theta = theta0.copy()
    system = problem.normal_equations(theta)
    if system is None:
        sys.exit("the model cannot be simulated from its start")
    cost, jtr, jtj = system
    initial_cost = cost
    lam, nu = 1e-3, 2.0
    iterations = 0
    history = []
    first_trial = None

    def step(lam_):
        """Damped step for the parameters not held by a bound: (indices, delta) or None."""
        held = ((theta <= LOWER) & (jtr > 0)) | ((theta >= UPPER) & (jtr < 0))
        idx = np.flatnonzero(~held)
        if idx.size == 0:
            return None
        floor = 1e-12 * max(np.max(np.diag(jtj)), np.finfo(float).tiny)
        a = jtj[np.ix_(idx, idx)].copy()
        a[np.diag_indices(idx.size)] += lam_ * np.maximum(np.diag(jtj)[idx], floor)
        try:
            np.linalg.cholesky(a)  # positive definite, as the engine requires
        except np.linalg.LinAlgError:
            return None
        delta = np.linalg.solve(a, -jtr[idx])
        return (idx, delta) if np.all(np.isfinite(delta)) else None

    def predicted_decrease(d):
        return -2.0 * d @ jtr - d @ jtj @ d

    while True:
        if cost <= 0.0:
            termination = "zero residual"
            break
        diag = np.diag(jtj)
        if np.all((diag == 0.0) | (np.abs(jtr) <= grad_tol * np.sqrt(diag * cost))):
            termination = "gradient below tolerance"
            break
        gn = step(1e-12)
        if gn is None:
            expected = np.inf
        else:
            idx, d = gn
            g, h = jtr[idx], jtj[np.ix_(idx, idx)]
            expected = (-2.0 * d @ g - d @ h @ d) / cost
        if expected < tol:
            termination = f"expected improvement {expected:.2e} below tolerance"
            break
        if iterations >= max_iterations:
            termination = "maximum iterations"
            break
        iterations += 1
        outcome = None
        for _ in range(60):
            damped = step(lam)
            if damped is None:
                lam, nu = lam * nu, 2.0 * nu
                continue
            idx, d = damped
            candidate = theta.copy()
            candidate[idx] = np.clip(theta[idx] + d, LOWER[idx], UPPER[idx])
            step_norm = np.linalg.norm(candidate - theta)
            theta_norm = np.sqrt(theta @ theta + NU * NU)  # hysid's vector holds nu too
            if step_norm <= step_tol * (theta_norm + step_tol):
                outcome = "step"
                break
            predicted = predicted_decrease(candidate - theta)
            if first_trial is None:
                first_trial = candidate.copy()
            trial = problem.normal_equations(candidate)
            if trial is not None:
                rho = (cost - trial[0]) / predicted
                if trial[0] < cost and predicted > 0.0 and rho > 1e-4:
                    old = cost
                    theta = candidate
                    cost, jtr, jtj = trial
                    lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                    nu = 2.0
                    outcome = ((old - cost) / old, predicted / old)
                    break
            lam, nu = lam * nu, 2.0 * nu
        if outcome is None:
            termination = "no descent"
            break
        if outcome == "step":
            termination = "step below tolerance"
            break
        history.append(
            {"iteration": iterations, "cost": cost, "lambda": lam, "theta": theta.tolist()}
        )
        if outcome[0] < tol and outcome[1] < tol:
            termination = f"relative improvement {outcome[0]:.2e} below tolerance"
            break
    return {
        "theta": theta,
        "cost": cost,
        "initial_cost": initial_cost,
        "iterations": iterations,
        "evaluations": problem.evaluations,
        "termination": termination,
        "first_trial": first_trial,
        "history": history,
        "jtj": jtj,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", default="data/bouc-wen/train_multisine_5periods.csv")
    parser.add_argument("--start-factor", type=float, default=2.0)
    parser.add_argument("--substeps", type=int, default=4)
    parser.add_argument("--tolerance", type=float, default=1e-10)
    parser.add_argument("--max-iterations", type=int, default=100)
    parser.add_argument("--cache", help="keep the compiled library here and reuse it")
    parser.add_argument("--json", help="write the outcome here")
    parser.add_argument("-q", "--quiet", action="store_true")
    args = parser.parse_args()

    clock = time.perf_counter()
    u, y, ts = load(args.data)
    nodes = input_nodes(u, args.substeps)
    load_s = time.perf_counter() - clock

    clock = time.perf_counter()
    fold = record_fold(sample_step(ts, args.substeps), len(u))
    build_s = time.perf_counter() - clock
    function, compiled, codegen_s, compile_s, source_chars = compile_fold(fold, args.cache)

    problem = Problem(function, nodes, y)
    theta0 = NOMINAL * args.start_factor
    clock = time.perf_counter()
    fit = levenberg_marquardt(problem, theta0, args.tolerance, args.max_iterations)
    fit_s = time.perf_counter() - clock

    theta = fit["theta"]
    n = len(u)
    if not args.quiet:
        print(
            f"CasADi {ca.__version__}, NumPy {np.__version__}; {n} samples, RK4 x{args.substeps}, "
            f"band-limited input"
        )
        print(
            f"load + input table {load_s:.3f} s; graph {build_s:.3f} s; C generated in "
            f"{codegen_s:.3f} s ({source_chars} chars); "
            + (
                f"compiled in {compile_s:.3f} s"
                if compiled
                else f"cached library loaded in {compile_s:.3f} s"
            )
        )
        trial = ", ".join(f"{name} {v:.6g}" for name, v in zip(NAMES, fit["first_trial"]))
        print(
            f"start: nominal x {args.start_factor:g}, S = {fit['initial_cost']:.6e}; "
            f"first trial point: {trial}"
        )
        for name, v, nominal in zip(NAMES, theta, NOMINAL):
            print(f"  {name:<11} {v: .15e}   ({100 * (v / nominal - 1):+.4f} % from nominal)")
        print(
            f"criterion S = {fit['cost']:.12e} (e_RMS {np.sqrt(fit['cost'] / n):.4e} m); "
            f"{fit['iterations']} iterations, {fit['evaluations']} simulations with sensitivities; "
            f"stopped: {fit['termination']}"
        )
        print(f"fit (LM loop) {fit_s:.3f} s")
    if args.json:
        report = {
            "tool": f"casadi {ca.__version__}",
            "parameters": dict(zip(NAMES, theta.tolist())),
            "criterion": fit["cost"],
            "initial_criterion": fit["initial_cost"],
            "e_rms": float(np.sqrt(fit["cost"] / n)),
            "iterations": fit["iterations"],
            "evaluations": fit["evaluations"],
            "termination": fit["termination"],
            "start": dict(zip(NAMES, theta0.tolist())),
            "first_trial": dict(zip(NAMES, fit["first_trial"].tolist())),
            "history": fit["history"],
            "compiled": compiled,
            "seconds": {
                "load": load_s,
                "graph": build_s,
                "codegen": codegen_s,
                "compile_or_load": compile_s,
                "fit": fit_s,
            },
        }
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)


if __name__ == "__main__":
    main()
