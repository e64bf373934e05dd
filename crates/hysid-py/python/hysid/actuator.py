"""The linear actuator with hysteresis of J. Gunnar, E. Wernholt, G. Hovland, T. Brogårdh,
"Nonlinear Grey-Box Identification of Linear Actuators Containing Hysteresis", ICRA 2006:
the virtual rig's records and the three-step identification."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from . import _hysid
from . import _inputs as check
from ._hysid import ConfigError, DataError, ModelFileError
from ._inputs import FloatArray
from .progress import ProgressArg, warn_if_stopped, watching
from .results import Result

#: Gear ratio r [m/rad] and saddle mass m [kg] of the actuator of Gunnar et al. (2006).
ACTUATOR_GEAR_RATIO, ACTUATOR_SADDLE_MASS = 1.867e-3, 1.2


#: A data set as the extension module takes it: (torque, angle, sample time).
DataSet = Tuple[FloatArray, FloatArray, float]


def _actuator_sets(records: Any, ts: Optional[float]) -> Tuple[List[DataSet], str, Optional[Dict[str, float]]]:
    """(sets [(torque, angle, ts)] for data sets 1–8, source, truth from rig.json or None)."""
    if isinstance(records, (str, os.PathLike)):
        folder = os.fspath(records)
        sets = _hysid.actuator_read_data_sets(folder)
        truth = None
        rig = os.path.join(folder, "rig.json")
        if os.path.isfile(rig):
            with open(rig, encoding="utf-8") as f:
                given = json.load(f).get("truth") or {}
            names = _hysid.actuator_parameter_names()
            missing = [n for n in names if n not in given]
            if missing:
                raise ModelFileError(
                    f"{rig}: truth.{missing[0]} is missing (remove the file or rewrite it with hysid.actuator_rig)"
                )
            truth = {n: float(given[n]) for n in names}
        return sets, folder, truth
    if isinstance(records, dict):
        keys = sorted(records)
        if keys != list(range(1, 9)):
            raise DataError(f"records: the keys must be the data sets 1 to 8, got {keys}")
        records = [records[k] for k in keys]
    try:
        records = list(records)
    except TypeError:
        raise TypeError("records: give a directory, a list of 8 records or a dict {1: …, 8: …}") from None
    if len(records) != 8:
        raise DataError(f"records: {len(records)} data sets given; the procedure needs data sets 1 to 8 in order")
    sets = []
    for i, rec in enumerate(records):
        name = f"data set {i + 1}"
        if hasattr(rec, "u") and hasattr(rec, "y"):
            tau, theta, rts = rec.u, rec.y, getattr(rec, "sampling_time", None)
        elif isinstance(rec, (tuple, list)) and len(rec) in (2, 3):
            tau, theta, rts = rec[0], rec[1], (rec[2] if len(rec) == 3 else None)
        else:
            raise TypeError(f"records[{i}]: give (torque, angle), (torque, angle, ts) or a record with .u, .y")
        tau, theta, _ = check.pair(tau, theta, (f"{name} torque", f"{name} angle"), None)
        sets.append((tau, theta, check.sample_time(rts if rts is not None else ts)))
    return sets, "python (numpy arrays)", None


def actuator_three_steps(
    records: Any,
    *,
    ts: Optional[float] = None,
    truth: Optional[Dict[str, float]] = None,
    gear_ratio: float = ACTUATOR_GEAR_RATIO,
    saddle_mass: float = ACTUATOR_SADDLE_MASS,
    cutoff_hz: float = 100.0,
    remove_mean: bool = False,
    reversal_margin: float = 0.05,
    unfiltered_step3: bool = False,
    max_iterations: int = 30,
    tolerance: float = 1e-4,
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
) -> Result:
    """The three-step identification of a linear actuator with hysteresis (J. Gunnar,
    E. Wernholt, G. Hovland, T. Brogårdh, "Nonlinear Grey-Box Identification of Linear
    Actuators Containing Hysteresis", ICRA 2006), as ``hysid actuator identify`` runs it.

    ``records``: data sets 1–8 (motor torque τ [N·m] in, motor angle θ [rad] out), as a
    directory holding ``dataset1.csv`` … ``dataset8.csv`` (columns t_s, tau_Nm, theta_rad;
    a ``rig.json`` beside them gives the true parameters), a list of 8 records — each
    ``(torque, angle)``, ``(torque, angle, ts)`` or an object with ``.u`` (torque), ``.y``
    (angle) and ``.sampling_time`` — or a dict ``{1: …, 8: …}``. ``ts`` is the sample time
    of records that do not carry one.

    1. Rigid body (set 1, saddle free): Jt θ̈ + Fv θ̇ + Fc sgn(θ̇) = τ by least squares on the
       filtered, differentiated angle; J = Jt − r² m (``gear_ratio`` r, ``saddle_mass`` m).
    2. Steady-state loops (sets 2–5, saddle fixed): τn = k1 x1 + k2 x1³ + Cu/d(x1) with the
       Dhaouadi-type hysteresis branches, α by a profile search, k1, k2, A by least
       squares; samples within ``reversal_margin`` of a reversal are left out.
    3. Output error of the saddle-fixed model from m0 on set 6 with 7 (m67) and with 8
       (m68), all seven parameters free or J, Fv, Fc fixed (m67f, m68f); at most
       ``max_iterations`` iterations, stopped when the expected improvement falls below
       ``tolerance``.

    Preprocessing: 4th-order zero-phase Butterworth at ``cutoff_hz`` on every signal
    (``unfiltered_step3`` fits step 3 on the raw records), optional mean removal.

    Returns a :class:`Result` whose ``parameters`` and ``model`` are m67's (J, Fv, Fc, k1,
    k2, alpha, A), ``validation`` lists m67 on sets 6–8, and ``report()`` is the CLI's JSON
    report: ``details.steps`` holds one report per step (step 1, step 2, step 3 m67, m68,
    m67f, m68f), ``details.fit_table`` Table II, ``details.truth`` the true parameters when
    known (``truth`` dict or ``rig.json``). The GIL is released; ``threads`` as for
    :func:`identify_cascade`.
    """
    limit, tell = watching(time_limit, progress)
    sets, source, rig_truth = _actuator_sets(records, ts)
    names = _hysid.actuator_parameter_names()
    truth = truth if truth is not None else rig_truth
    if truth is not None:
        if not isinstance(truth, dict):
            raise TypeError("truth: give a dict name → value")
        unknown = [n for n in truth if n not in names]
        if unknown or len(truth) != len(names):
            raise ConfigError(f"truth: give a value for each of {', '.join(names)}")
        truth_values: Optional[List[float]] = [float(truth[n]) for n in names]
    else:
        truth_values = None
    text = _hysid.actuator_three_steps(
        sets,
        source,
        truth_values,
        float(gear_ratio),
        float(saddle_mass),
        float(cutoff_hz),
        bool(remove_mean),
        float(reversal_margin),
        bool(unfiltered_step3),
        check.count(max_iterations, "max_iterations"),
        float(tolerance),
        check.threads(threads),
        limit,
        tell,
    )
    result = Result(json.loads(text))
    warn_if_stopped(result.termination_code, limit, "actuator_three_steps")
    return result


class ActuatorRecord:
    """One data set of the virtual actuator rig: ``set`` (1–8), ``saddle_free``, ``u`` (motor
    torque [N·m]), ``y`` (motor angle [rad]), ``sampling_time`` [s] — the attributes of a
    ``nonlinear_benchmarks`` record, so it goes wherever one does."""

    __slots__ = ("set", "saddle_free", "u", "y", "sampling_time")

    def __init__(self, set: int, saddle_free: bool, u: np.ndarray, y: np.ndarray, sampling_time: float) -> None:
        self.set, self.saddle_free = set, saddle_free
        self.u, self.y, self.sampling_time = u, y, sampling_time

    def __repr__(self) -> str:
        return f"ActuatorRecord(set {self.set}, {self.u.size} samples at {1 / self.sampling_time:g} Hz)"

    def __getstate__(self) -> Tuple[Any, ...]:
        return tuple(getattr(self, s) for s in self.__slots__)

    def __setstate__(self, state: Tuple[Any, ...]) -> None:
        for name, v in zip(self.__slots__, state):
            object.__setattr__(self, name, v)


def actuator_rig(
    *,
    truth: Optional[Dict[str, float]] = None,
    backlash: float = 0.0,
    noise: float = 1.0,
    seed: int = 0,
    gear_ratio: float = ACTUATOR_GEAR_RATIO,
    saddle_mass: float = ACTUATOR_SADDLE_MASS,
) -> List[ActuatorRecord]:
    """The eight data sets of the virtual actuator rig (``hysid actuator rig``): the
    actuator of Gunnar et al. (2006) simulated at 1 kHz with the true parameters ``truth``
    (name → value for J, Fv, Fc, k1, k2, alpha, A; default Table I's m67), an optional
    backlash of width ``backlash`` [rad] in the flexibility, and quantisation-level noise
    times ``noise`` (seeded by ``seed``). Returns 8 :class:`ActuatorRecord` for
    :func:`actuator_three_steps`."""
    names = _hysid.actuator_parameter_names()
    values = None
    if truth is not None:
        if not isinstance(truth, dict):
            raise TypeError("truth: give a dict name → value")
        unknown = [n for n in truth if n not in names]
        if unknown:
            raise ConfigError(f"truth: no parameter '{unknown[0]}'; the parameters are {', '.join(names)}")
        defaults = dict(zip(names, _hysid.actuator_rig_truth()))
        defaults.update({k: float(v) for k, v in truth.items()})
        values = [defaults[n] for n in names]
    sets = _hysid.actuator_rig(
        values, float(backlash), float(noise), check.count(seed, "seed"), float(gear_ratio), float(saddle_mass)
    )
    return [ActuatorRecord(k, free, tau, theta, t) for (k, free, t, tau, theta) in sets]
