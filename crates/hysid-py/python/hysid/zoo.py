"""The hysteresis model zoo: every family of the library's registry fitted from Python, as
``hysid identify operator`` fits it."""

from __future__ import annotations

import json
import math
from typing import Any, Optional, Sequence

import numpy as np

from . import _hysid
from . import _inputs as check
from ._families import FAMILIES, FamilyName
from ._hysid import ConfigError
from .results import Result


def identify_operator(
    u: Any,
    y: Any = None,
    *,
    family: FamilyName,
    ts: float = 1.0,
    thresholds: "int | Sequence[float]" = 10,
    grid: int = 20,
    lambda_: float = 1e-6,
    dead_zones: int = 4,
    threads: Optional[int] = None,
) -> Result:
    """Fits one hysteresis family y = Γ[u] to a measured input ``u`` and output ``y`` from
    the data alone (no initial guess): the CLI's ``hysid identify operator``, the same
    estimates and report.

    ``family``: one of :data:`FAMILIES` (``"pi"``, ``"preisach"``, ``"bouc-wen"``, …; see
    ``docs/zoo.md``). ``thresholds``: PI/GPI thresholds and Maxwell-slip elements, a count
    (a uniform grid over the input range) or the thresholds themselves (strictly increasing,
    > 0). ``grid``: Preisach intervals; ``lambda_``: Preisach smoothness; ``dead_zones``: GPI
    dead zones per side. ``u`` may be a record with ``.u``, ``.y`` (then ``y`` is omitted).
    """
    u, y, ts = check.pair(u, y, ("u", "y"), ts)
    name = check.choice(family, "family")
    if name not in FAMILIES:
        raise ConfigError(f"family={family!r}: unknown hysteresis family; use one of {', '.join(FAMILIES)}")
    if isinstance(thresholds, (int, np.integer)) and not isinstance(thresholds, bool):
        count, grid_values = check.count(thresholds, "thresholds"), []
    else:
        grid_values = [float(r) for r in check.array(thresholds, "thresholds")]
        count = len(grid_values)
    lam = float(lambda_)
    if not (math.isfinite(lam) and lam >= 0.0):
        raise ConfigError(f"lambda_={lambda_!r}: the Preisach smoothness must be finite and >= 0")
    text = _hysid.identify_operator(
        u,
        y,
        name,
        check.sample_time(ts, 1.0),
        count,
        grid_values,
        check.count(grid, "grid"),
        lam,
        check.count(dead_zones, "dead_zones"),
        check.threads(threads),
    )
    return Result(json.loads(text))
