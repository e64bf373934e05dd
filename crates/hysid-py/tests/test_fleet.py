"""hysid.fleet.identify_many on a 2-worker LocalCluster."""

import time

import numpy as np
import pytest
from hysid.fleet import Failure, identify_many
from models import cascade_fit

distributed = pytest.importorskip("dask.distributed")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def records(example1, n):
    x, y = example1
    rng = np.random.default_rng(11)
    return [(x, y + 0.01 * rng.standard_normal(y.size)) for _ in range(n)]


def test_identify_many_matches_loop_and_isolates_failures(client, example1):
    recs = records(example1, 6)
    recs.insert(3, (np.zeros(10), np.zeros(11)))  # a bad record
    fleet = identify_many(recs, cascade_fit, client=client)
    assert len(fleet) == 7
    assert isinstance(fleet[3], Failure) and fleet[3].error == "DataError"
    assert "x has 10 samples and y 11" in fleet[3].message
    for i, rec in enumerate(recs):
        if i != 3:
            assert fleet[i] == cascade_fit(rec)
    table = fleet.summary()
    assert len(table) == 7


@pytest.mark.slow
def test_identify_many_100_records_timing(client, example1):
    recs = records(example1, 100)
    t0 = time.perf_counter()
    loop = [cascade_fit(r) for r in recs]
    t_loop = time.perf_counter() - t0
    t0 = time.perf_counter()
    fleet = identify_many(recs, cascade_fit, client=client)
    t_dask = time.perf_counter() - t0
    print(
        f"\n100 cascade fits: loop {t_loop:.2f} s, Dask 2-worker LocalCluster {t_dask:.2f} s, "
        f"speed-up {t_loop / t_dask:.2f}x"
    )
    assert fleet.results == loop
