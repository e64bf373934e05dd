"""Wall time of 100 identifications: a plain loop, Python threads, and Dask.

The records are the project's Example 1 (J. Vörös 2015 cascade: Coleman–Hodgdon
hysteresis + second-order linear block, 1000 samples) with 100 seeded noise realisations;
each is fitted by ``hysid.identify_cascade(..., na=2, nb=2, delay=1)``. The script prints
the wall time of

* a loop, each fit on all cores (``threads=None``, the default) and on one (``threads=1``);
* a ``concurrent.futures`` pool of as many Python threads as cores, each fit ``threads=1``;
* ``hysid.fleet.identify_many`` on a ``LocalCluster`` of ``--workers`` single-threaded
  worker processes, each fit with the default threads and with ``threads=1``;

and checks that every route returns the loop's results. On a real cluster pass
``--scheduler tcp://HOST:8786`` (a running ``dask scheduler`` with ``dask worker`` processes
that have hysid installed): the same ``identify_many`` call then runs there.

Run: python crates/hysid-py/examples/fleet_timing.py [--n 100] [--workers 2] [--scheduler ADDR]
"""

import argparse
import concurrent.futures
import functools
import os
import pathlib
import time

import hysid
import numpy as np
from hysid.fleet import identify_many

DATA = pathlib.Path(__file__).resolve().parents[1] / "tests" / "data" / "example1.csv"


def records(n, seed=11):
    """n noisy copies of the Example-1 record."""
    d = np.loadtxt(DATA, delimiter=",", skiprows=1)
    x, y = d[:, 1].copy(), d[:, 2].copy()
    rng = np.random.default_rng(seed)
    return [(x, y + 0.01 * rng.standard_normal(y.size)) for _ in range(n)]


def cascade_fit(record, threads=None):
    """One fleet fit (module level, so that it pickles)."""
    x, y = record
    return hysid.identify_cascade(x, y, na=2, nb=2, delay=1, threads=threads)


def timed(label, f, rows):
    t0 = time.perf_counter()
    out = f()
    rows.append((label, time.perf_counter() - t0))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (a real cluster)")
    args = ap.parse_args()
    recs = records(args.n)
    cores = os.cpu_count() or 1
    one = functools.partial(cascade_fit, threads=1)
    rows = []
    cascade_fit(recs[0])  # warm-up: loads the library, builds the pools
    loop = timed("loop, threads=None (all cores per fit)", lambda: [cascade_fit(r) for r in recs], rows)
    same = timed("loop, threads=1", lambda: [one(r) for r in recs], rows)
    with concurrent.futures.ThreadPoolExecutor(cores) as pool:
        threaded = timed(f"{cores} Python threads, threads=1", lambda: list(pool.map(one, recs)), rows)
    from dask.distributed import Client, LocalCluster

    if args.scheduler:
        client, cluster = Client(args.scheduler), None
        where = f"Dask at {args.scheduler}"
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
        where = f"Dask LocalCluster, {args.workers} workers"
    try:
        identify_many(recs[: args.workers], cascade_fit, client=client)  # warm-up of the workers
        dask_all = timed(
            f"{where}, threads=None", lambda: identify_many(recs, cascade_fit, client=client).results, rows
        )
        dask_one = timed(f"{where}, threads=1", lambda: identify_many(recs, one, client=client).results, rows)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    for name, got in [
        ("loop threads=1", same),
        ("threads", threaded),
        ("Dask", dask_all),
        ("Dask threads=1", dask_one),
    ]:
        assert got == loop, f"{name}: results differ from the loop's"
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{args.n} cascade fits (Example 1, 1000 samples each); {cores} cores, load {load:.1f} at the end")
    base = rows[0][1]
    for label, wall in rows:
        print(f"  {label:<52} {wall:8.2f} s   {base / wall:5.2f}x the loop")
    print("  every route returned the loop's results exactly")


if __name__ == "__main__":
    main()
