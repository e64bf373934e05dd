"""Command limits and bad samples from Python (issue 39 items 2-3, issue 40 item 5): the
library's rule (``hysid::model::limits``), a ``HysidWarning`` with the clipped count."""

import csv
import math
import os
import warnings

import hysid
import numpy as np

PIEZO = os.path.join(os.path.dirname(__file__), "..", "..", "..", "data", "piezo", "piezo_150V_1Hz.csv")


def _piezo():
    with open(PIEZO) as f:
        rows = list(csv.DictReader(f))
    u = np.array([float(r["voltage_V"]) for r in rows])
    y = np.array([float(r["displacement_um"]) for r in rows])
    return u, y


def test_limits_faults_and_the_clipped_warning():
    u, y = _piezo()
    model = hysid.identify_operator(u, y, family="pi").model
    lo, hi = model.file["input_range"][0]
    assert (lo, hi) == (float(u.min()), float(u.max()))
    c = model.compensator()
    assert c.limits == (lo, hi)
    assert c.step(math.nan) == 0.5 * (lo + hi)  # before any good reference: the midpoint
    assert c.step(1e6) == hi and c.step(-1e6) == lo
    assert (c.faults, c.clipped) == (1, 2)
    # The next good reference is what it would have been without the bad one.
    fresh = model.compensator()
    seq = [5.0, 7.0, 3.0]
    want = [fresh.step(r) for r in seq]
    c.reset()
    got = [c.step(r) for r in [5.0, math.inf, 7.0, -math.inf, math.nan, 3.0]]
    assert [got[0], got[2], got[5]] == want and got[1] == got[0] and got[3] == got[4] == got[2]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        comp = hysid.compensate(model, np.concatenate([y, [1e4, -1e4]]), limits=(0.0, 150.0))
    assert float(comp.u.min()) == 0.0 and float(comp.u.max()) == 150.0
    messages = [str(w.message) for w in caught if issubclass(w.category, hysid.HysidWarning)]
    assert len(messages) == 1 and messages[0].startswith(f"{len(comp.clipped)} of {len(y) + 2}")
    s = model.stepper()
    assert s.step(math.nan) == 0.0 and s.faults == 1
