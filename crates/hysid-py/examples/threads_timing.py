"""The two-thread bar: two Python threads fitting at once against one after the other.

Each fit is the project's Example-1 cascade (J. Vörös 2015: Coleman–Hodgdon hysteresis +
second-order linear block, seed 1, SNR 50) identified by
``hysid.identify_cascade(x, y, na=2, nb=2, delay=1, threads=1)`` — one worker per call, so
two calls can only overlap if each releases the GIL while it works. The script times
2 × ``--fits`` fits one after the other and the same fits in two Python threads started
together (``--fits`` each), ``--tries`` times, and prints the medians and their ratio (runs
of a second or more: single fits of 0.2 s vary by 20 % on a shared virtual machine). It checks that every concurrent fit returns
the sequential fit's estimates, and exits with status 1 when the ratio is below ``--bar``
(1.6 by default): run it on a machine with two idle cores — a loaded machine has no idle
core to gain from, which is why this is a benchmark command and not a test.

Run: python crates/hysid-py/examples/threads_timing.py [--fits 5] [--tries 3] [--bar 1.6]
"""

import argparse
import os
import pathlib
import statistics
import sys
import threading
import time

import hysid
import numpy as np

DATA = pathlib.Path(__file__).resolve().parents[1] / "tests" / "data" / "example1.csv"


def example1() -> tuple[np.ndarray, np.ndarray]:
    d = np.loadtxt(DATA, delimiter=",", skiprows=1)
    return d[:, 1].copy(), d[:, 2].copy()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fits", type=int, default=5, help="fits per thread in one timed run")
    parser.add_argument("--tries", type=int, default=3, help="timed runs (median reported)")
    parser.add_argument("--bar", type=float, default=1.6, help="speed-up below which the exit status is 1")
    args = parser.parse_args()
    x, y = example1()

    def fit() -> hysid.Result:
        return hysid.identify_cascade(x, y, na=2, nb=2, delay=1, threads=1)

    reference = fit()  # warm-up: builds this thread's one-worker pool
    sequential, concurrent = [], []
    for _ in range(args.tries):
        t0 = time.perf_counter()
        for _ in range(2 * args.fits):
            fit()
        sequential.append(time.perf_counter() - t0)
        out: list = [[], []]

        def work(i: int, out: list = out) -> None:
            out[i] = [fit() for _ in range(args.fits)]

        threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
        t0 = time.perf_counter()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        concurrent.append(time.perf_counter() - t0)
        if any(r.parameters != reference.parameters for rs in out for r in rs):
            print("a concurrent fit differs from the sequential one", file=sys.stderr)
            return 2
    t_seq, t_par = statistics.median(sequential), statistics.median(concurrent)
    speedup = t_seq / t_par
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"{2 * args.fits} cascade fits (threads=1 each): one after the other {t_seq:.3f} s, in two "
        f"Python threads at once {t_par:.3f} s, speed-up {speedup:.2f}x (median of {args.tries}; "
        f"{os.cpu_count()} cores, 1-minute load {load:.1f}; bar {args.bar}x)"
    )
    return 0 if speedup >= args.bar else 1


if __name__ == "__main__":
    sys.exit(main())
