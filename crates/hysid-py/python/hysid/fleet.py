"""Fleets: one identification per record, mapped over a Dask cluster.

``identify_many(datasets, fit, client=None)`` applies ``fit`` to every element of
``datasets`` on ``dask.distributed`` workers and returns a :class:`FleetResult` whose
``results`` are in the order of ``datasets``; a record whose fit raised holds a
:class:`Failure` (the exception's type and message) in its place, and the others are
unaffected.

On one machine, leave ``client`` out: a ``LocalCluster`` with one single-threaded worker
process per core is started and closed again. On a real cluster, start a scheduler and
workers (``dask scheduler``; ``dask worker tcp://HOST:8786`` on each node, with hysid
installed there) and pass ``Client("tcp://HOST:8786")``: the same code runs unchanged.
``fit`` and the records travel by pickle, so ``fit`` must be a module-level function (or
a ``functools.partial`` of one), and hysid's results pickle exactly.

Each hysid fit releases the GIL, so a worker with several threads runs several fits at
once: give those fits ``threads=1`` (or call ``hysid.set_num_threads(1)`` in the worker),
else they share one pool of all cores and gain nothing. The default cluster here has
single-threaded worker processes, and a fit there may use all cores of its machine. With
Python-callback models (:class:`hysid.GreyBoxModel`) use worker processes
(``threads_per_worker=1``), since those callbacks need the GIL.
"""

from __future__ import annotations

import os
import time
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple


class Failure:
    """A record whose fit raised: ``index``, ``error`` (the exception's type name) and
    ``message``."""

    __slots__ = ("index", "error", "message")

    def __init__(self, index: int, error: str, message: str) -> None:
        self.index, self.error, self.message = index, error, message

    def __repr__(self) -> str:
        return f"Failure(record {self.index}: {self.error}: {self.message})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Failure) and (self.index, self.error, self.message) == (
            other.index,
            other.error,
            other.message,
        )

    def __getstate__(self) -> Tuple[int, str, str]:
        return (self.index, self.error, self.message)

    def __setstate__(self, state: Tuple[int, str, str]) -> None:
        self.index, self.error, self.message = state


class FleetResult:
    """The results of :func:`identify_many`: ``results`` (one per record, in order: a
    ``hysid.Result`` or whatever ``fit`` returned, or a :class:`Failure`), ``failures``,
    ``elapsed_s``, and ``summary()``: one row per record (pandas DataFrame when pandas is
    installed, else a list of dicts) with the parameter values, fit % and RMSE."""

    def __init__(self, results: List[Any], elapsed_s: float) -> None:
        self.results = results
        self.elapsed_s = elapsed_s

    @property
    def failures(self) -> List[Failure]:
        return [r for r in self.results if isinstance(r, Failure)]

    def summary(self) -> Any:
        rows = []
        for i, r in enumerate(self.results):
            row: Dict[str, Any] = {"record": i}
            if isinstance(r, Failure):
                row["error"] = f"{r.error}: {r.message}"
            elif hasattr(r, "parameters"):
                row.update({n: p.value for n, p in r.parameters.items()})
                row["fit_percent"] = r.fit_percent
                row["rmse"] = r.rmse
                row["error"] = None
            rows.append(row)
        try:
            import pandas as pd
        except ImportError:
            return rows
        return pd.DataFrame(rows).set_index("record")

    def __len__(self) -> int:
        return len(self.results)

    def __iter__(self) -> Iterator[Any]:
        return iter(self.results)

    def __getitem__(self, i: int) -> Any:
        return self.results[i]


def _guarded(fit: Callable[[Any], Any], index: int, record: Any) -> Any:
    """Runs ``fit(record)``; an exception becomes a Failure (the run goes on)."""
    try:
        return fit(record)
    except Exception as e:  # noqa: BLE001 — reported in the record's place
        return Failure(index, type(e).__name__, str(e))


def _gather(client: Any, fit: Callable[[Any], Any], records: List[Any]) -> List[Any]:
    futures = client.map(_guarded, [fit] * len(records), range(len(records)), records, pure=False)
    return list(client.gather(futures))


def identify_many(
    datasets: Sequence[Any],
    fit: Callable[[Any], Any],
    *,
    client: Optional[Any] = None,
    n_workers: Optional[int] = None,
) -> FleetResult:
    """Applies ``fit`` to every element of ``datasets`` on a ``dask.distributed`` cluster.

    ``client``: a ``dask.distributed.Client`` (any cluster); without one a
    ``LocalCluster`` of ``n_workers`` single-threaded worker processes (default: the
    number of cores) is started for this call and closed afterwards. Returns a
    :class:`FleetResult` in the order of ``datasets``; failed records hold a
    :class:`Failure`.
    """
    from dask.distributed import Client, LocalCluster

    if not callable(fit):
        raise TypeError("fit: give a callable applied to each record")
    records = list(datasets)
    clock = time.perf_counter()
    if client is not None:
        results = _gather(client, fit, records)
    else:
        # Called through Any: dask's own annotations differ between versions (untyped in
        # some, typed in others), so neither a `type: ignore` nor its absence suits all.
        make_cluster: Any = LocalCluster
        make_client: Any = Client
        cluster = make_cluster(
            n_workers=n_workers or os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
        )
        own = make_client(cluster)
        try:
            results = _gather(own, fit, records)
        finally:
            own.close()
            cluster.close()
    return FleetResult(list(results), time.perf_counter() - clock)
