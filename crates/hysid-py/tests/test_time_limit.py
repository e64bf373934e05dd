"""``time_limit=`` and ``progress=`` on the fitting functions: a time limit bounds the whole
call and returns the best result so far, marked ``time_limit`` with a ``HysidWarning``; a
progress callable hears from the call at its start, at least once a second, and at its end.
"""

import pathlib
import time
import warnings

import hysid
import numpy as np
import pytest

PIEZO = pathlib.Path(__file__).resolve().parents[3] / "data" / "piezo" / "piezo_150V_1Hz.csv"


def piezo(copies: int):
    """The vendored piezo record (2 000 samples: voltage, displacement) repeated `copies`
    times: at 100 copies (200 000 samples) a Bouc–Wen fit with defaults runs for about 3 s on
    one thread (it was over 20 s before long records were refined on their subsample)."""
    d = np.genfromtxt(PIEZO, delimiter=",", names=True)
    return np.tile(d["voltage_V"], copies), np.tile(d["displacement_um"], copies)


def test_a_time_limit_returns_the_best_result_so_far_in_time():
    u, y = piezo(100)
    calls = []
    start = time.monotonic()
    with pytest.warns(hysid.HysidWarning, match="time limit of 1.0 s"):
        r = hysid.identify_operator(
            u, y, family="bouc-wen", threads=1, time_limit=1, progress=lambda p: calls.append((time.monotonic(), p))
        )
    took = time.monotonic() - start
    assert took < 2.0, took
    assert r.termination_code == "time_limit"
    assert not r.converged
    assert r.model is not None and r.fit_percent is not None and np.isfinite(r.fit_percent)
    # Progress: the start, at least once a second, the end.
    assert calls[0][1].stage == "start" and calls[-1][1].stage == "done"
    stamps = [start] + [c[0] for c in calls] + [start + took]
    assert max(np.diff(stamps)) < 1.0, np.diff(stamps)
    assert all(isinstance(p, hysid.Progress) and p.elapsed >= 0 for _, p in calls)


def test_without_a_time_limit_the_same_fit_runs_longer():
    """The fit of the test above, unbounded: it runs well past the 1 s limit there and ends
    on its own criteria, not on time."""
    u, y = piezo(100)
    start = time.monotonic()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hysid.HysidWarning)  # its convergence is not the point
        r = hysid.identify_operator(u, y, family="bouc-wen", threads=1)
    assert r.termination_code != "time_limit"
    assert time.monotonic() - start > 1.5


def test_progress_reports_iterations_and_a_quick_fit_ends_normally():
    u, y = piezo(2)
    seen = []
    with warnings.catch_warnings():
        warnings.simplefilter("error", hysid.HysidWarning)
        r = hysid.identify_operator(u, y, family="bouc-wen", time_limit=600, progress=seen.append)
    assert r.termination_code != "time_limit"
    assert seen[0].stage == "start" and seen[-1].stage == "done"
    assert seen[-1].done >= 0 and seen[-1].elapsed > 0


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), float("inf")])
def test_a_time_limit_must_be_a_positive_number(bad):
    u, y = piezo(1)
    with pytest.raises(hysid.ConfigError, match="time_limit"):
        hysid.identify_operator(u, y, family="pi", time_limit=bad)


def test_time_limit_and_progress_types_are_checked():
    u, y = piezo(1)
    with pytest.raises(TypeError, match="time_limit"):
        hysid.identify_operator(u, y, family="pi", time_limit="1")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="progress"):
        hysid.identify_operator(u, y, family="pi", progress=3)  # type: ignore[arg-type]


def test_an_exception_in_progress_stops_the_call():
    u, y = piezo(100)

    class Enough(Exception):
        pass

    def stop(p: hysid.Progress) -> None:
        if p.elapsed > 0.5:
            raise Enough

    start = time.monotonic()
    with pytest.raises(Enough):
        hysid.identify_operator(u, y, family="bouc-wen", threads=1, progress=stop)
    assert time.monotonic() - start < 2.0


def test_compare_shares_one_time_limit_over_every_family():
    u, y = piezo(100)
    start = time.monotonic()
    with pytest.warns(hysid.HysidWarning, match="compare"):
        c = hysid.compare(u, y, families=["bouc-wen", "duhem", "pi"], threads=1, time_limit=1.5)
    assert time.monotonic() - start < 3.0
    assert c.termination_code == "time_limit"


def test_progress_true_draws_a_tqdm_bar(capsys):
    pytest.importorskip("tqdm")
    u, y = piezo(2)
    r = hysid.identify_operator(u, y, family="bouc-wen", progress=True)
    assert r.fit_percent > 90
    assert "it" in capsys.readouterr().err
