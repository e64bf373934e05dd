"""The hysteresis model zoo: every family of the library's registry fitted from Python
(:func:`identify_operator`), compared on one record (:func:`compare`) and inverted
(:func:`compensate`), as ``hysid identify operator``, ``hysid compare`` and ``hysid
compensate`` do: the same library calls, the same reports."""

from __future__ import annotations

import json
import math
import os
import warnings
from typing import Any, Callable, List, Literal, NamedTuple, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np

from . import _hysid
from . import _inputs as check
from ._families import FAMILIES, FamilyName
from ._hysid import ConfigError
from ._inputs import RecordLike, Samples, SamplesOrRecord
from .comparison import Comparison
from .compensation import Compensation
from .models import Model, load_model
from .progress import HysidWarning, ProgressArg, warn_if_stopped, watching
from .results import FitResult, Record, Result, labelled
from .stream import _limits

#: ``families="all"``: every family of the registry.
AllFamilies = Literal["all"]
#: A loop's turning sense in the (u, y) plane: ``"ccw"`` (the output lags the input) or ``"cw"``.
LoopOrientation = Literal["ccw", "cw"]


#: The initial hysteresis state of an operator fit (``docs/zoo.md``, "Initial states").
InitialStateName = Literal["demagnetised", "descending", "ascending", "estimate"]


#: The PI's static envelope (``docs/zoo.md``, "Static envelope"): chosen with the thresholds,
#: none, or a cubic.
EnvelopeName = Literal["auto", "none", "cubic"]


def _envelope(value: Optional[str]) -> Optional[str]:
    if value is None:
        return None
    return check.choice(value, "envelope", ("auto", "none", "cubic"))


def _initial_state(value: Optional[str]) -> Optional[str]:
    if value is None:
        return None
    return check.choice(value, "initial_state", ("demagnetised", "descending", "ascending", "estimate"))


def _orientation(value: Optional[str]) -> Optional[str]:
    if value is None:
        return None
    return check.choice(value, "orientation", ("ccw", "cw"))


class _FitArguments(TypedDict):
    """The extension module's keyword arguments of every family fit."""

    threads: int
    orientation: Optional[str]
    time_limit: Optional[float]
    progress: Optional[Callable[[str, int, int, Optional[int], Optional[float], float], None]]
    initial_state: Optional[str]
    envelope: Optional[str]


def _fit_arguments(
    threads: Optional[int],
    orientation: Optional[str],
    initial_state: Optional[str],
    time_limit: Optional[float],
    progress: ProgressArg,
    envelope: Optional[str] = None,
) -> _FitArguments:
    """The fit's threads, orientation, initial state, time limit, progress and envelope
    checked and in the extension module's form."""
    limit, tell = watching(time_limit, progress)
    return _FitArguments(
        threads=check.threads(threads),
        orientation=_orientation(orientation),
        time_limit=limit,
        progress=tell,
        initial_state=_initial_state(initial_state),
        envelope=_envelope(envelope),
    )


class _FamilyOptions(NamedTuple):
    """The families' options as the extension module takes them."""

    thresholds: Optional[int]
    threshold_grid: List[float]
    grid: Optional[int]
    lambda_: float
    dead_zones: Optional[int]


def _family_options(
    thresholds: Union[int, Sequence[float], None],
    grid: Optional[int],
    lambda_: float,
    dead_zones: Optional[int],
) -> _FamilyOptions:
    """None for ``thresholds``, ``grid`` or ``dead_zones``: chosen from the data, as the
    command line does without ``--thresholds``/``--grid``/``--dead-zones``."""
    count: Optional[int]
    values: List[float]
    if thresholds is None:
        count, values = None, []
    elif isinstance(thresholds, (int, np.integer)) and not isinstance(thresholds, bool):
        count, values = check.count(thresholds, "thresholds"), []
    elif isinstance(thresholds, (bool, float, np.floating, str)):
        raise TypeError(
            f"thresholds={thresholds!r}: give a count (an int, e.g. thresholds=20) or the thresholds "
            "themselves (a sequence of increasing positive floats, e.g. thresholds=[0.5, 1.0, 2.0])"
        )
    else:
        values = [float(r) for r in check.array(thresholds, "thresholds")]
        count = len(values)
    lam = float(lambda_)
    if not (math.isfinite(lam) and lam >= 0.0):
        raise ConfigError(f"lambda_={lambda_!r}: the Preisach smoothness must be finite and >= 0")
    grid_count = None if grid is None else check.count(grid, "grid")
    zones = None if dead_zones is None else check.count(dead_zones, "dead_zones")
    return _FamilyOptions(count, values, grid_count, lam, zones)


def _family(name: Any, what: str = "family") -> str:
    value = check.choice(name, what)
    if value not in FAMILIES:
        raise ConfigError(f"{what}={name!r}: unknown hysteresis family; use one of {', '.join(FAMILIES)}")
    return value


def identify_operator(
    u: SamplesOrRecord,
    y: Optional[Samples] = None,
    *,
    family: FamilyName,
    ts: float = 1.0,
    thresholds: Union[int, Sequence[float], None] = None,
    grid: Optional[int] = None,
    lambda_: float = 1e-6,
    dead_zones: Optional[int] = None,
    orientation: Optional[LoopOrientation] = None,
    initial_state: Optional[InitialStateName] = None,
    envelope: Optional[EnvelopeName] = None,
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
    names: Optional[Tuple[str, str]] = None,
    units: Optional[Tuple[str, str]] = None,
) -> FitResult:
    """Fits one hysteresis family y = Γ[u] to a measured input ``u`` and output ``y`` from
    the data alone (no initial guess): the CLI's ``hysid identify operator``, the same
    estimates and report.

    ``family``: one of :data:`FAMILIES` (``"pi"``, ``"preisach"``, ``"bouc-wen"``, …; see
    ``docs/zoo.md``). ``thresholds``: PI/GPI thresholds and Maxwell-slip elements, a count
    (a uniform grid over the input range) or the thresholds themselves (strictly increasing,
    > 0); None (the default) chooses the count and placement from the data (held-out
    validation within a work bound, ``docs/zoo.md``), as the command line does without
    ``--thresholds``. ``grid``: Preisach/KP intervals, None (the default) likewise chosen; ``lambda_``: Preisach smoothness; ``dead_zones``: GPI
    dead zones per side, None (the default) chosen with the thresholds (4, 8 or 12). ``u`` may be a record with ``.u``, ``.y`` (then ``y`` is omitted).
    ``orientation``: the loop's turning sense in the (u, y) plane, ``"ccw"``
    (counter-clockwise: the output lags the input, as a piezo stack or a magnet's B(H)) or
    ``"cw"``; None (default) detects it from the area between the ascending and descending
    branches (a :class:`DataError` naming this argument when the record cannot tell); the
    report's ``details.orientation`` and ``details.orientation_source`` say which was used.
    ``initial_state``: where the record's memory starts, ``"demagnetised"`` (the family's
    neutral state), ``"descending"`` (after a descent from above the record's maximum, a
    standardised magnet), ``"ascending"``, or ``"estimate"`` (None, the default: fitted from
    the data); the command line's ``--initial-state``, reported in
    ``details.initial_state`` and saved in the model.
    ``envelope``: the PI's monotone static envelope beside its plays, for a static curve they
    cannot follow (a saturating magnet): ``"auto"`` (None, the default: each candidate size is
    tried without and with a cubic on the held-out part; none when ``thresholds`` is given),
    ``"none"`` or ``"cubic"``; the command line's ``--envelope``, read by ``"pi"`` only.
    An unknown family or an option out of range is a :class:`ConfigError` (a ``ValueError``).
    ``names`` and ``units``: the (input, output) channels' names and units, e.g.
    ``names=("voltage", "displacement"), units=("V", "µm")``, which label the plots' axes
    and name the model file's columns (default: the names the arrays carry, a pandas
    Series' ``.name``, else ``("u", "y")``).
    """
    labels, unit_labels = check.channel_labels(names, units, u, y)
    u, y, given_ts = check.pair(u, y, ("u", "y"), ts)
    step = check.sample_time(given_ts, 1.0)
    name = _family(family)
    options = _family_options(thresholds, grid, lambda_, dead_zones)
    arguments = _fit_arguments(threads, orientation, initial_state, time_limit, progress, envelope)
    text = _hysid.identify_operator(u, y, name, step, *options, **arguments)
    record = Record(u, y, step, labels, unit_labels)
    result = FitResult(labelled(json.loads(text), record), data=record)
    warn_if_stopped(result.termination_code, arguments["time_limit"], "identify_operator")
    return result


def compare(
    u: SamplesOrRecord,
    y: Optional[Samples] = None,
    *,
    validate: Union[RecordLike, Tuple[Samples, Samples], None] = None,
    families: Union[AllFamilies, Sequence[FamilyName]] = "all",
    ts: float = 1.0,
    thresholds: Union[int, Sequence[float], None] = None,
    grid: Optional[int] = None,
    lambda_: float = 1e-6,
    dead_zones: Optional[int] = None,
    orientation: Optional[LoopOrientation] = None,
    initial_state: Optional[InitialStateName] = None,
    envelope: Optional[EnvelopeName] = None,
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
    names: Optional[Tuple[str, str]] = None,
    units: Optional[Tuple[str, str]] = None,
) -> Comparison:
    """Fits several hysteresis families to one record and ranks them by how well they
    predict data they were not fitted to: the CLI's ``hysid compare``, the same ranking
    and report.

    ``validate``: a separate validation record, a pair ``(u_val, y_val)`` or an object with
    ``.u`` and ``.y``; without it the first 60 % of (u, y) trains every family and the rest
    validates it (each model simulated over the whole record, so the memory built on the
    training part carries over). ``families``: ``"all"`` (the registry's, :data:`FAMILIES`)
    or a list of names. The options are :func:`identify_operator`'s. A family whose fit
    fails keeps its error in its row (:attr:`Comparison.errors`); the others go on.
    ``names`` and ``units``: the (input, output) channels' names and units, e.g.
    ``names=("voltage", "displacement"), units=("V", "µm")``, which label the plots' axes
    and name the model file's columns (default: the names the arrays carry, a pandas
    Series' ``.name``, else ``("u", "y")``).
    """
    labels, unit_labels = check.channel_labels(names, units, u, y)
    u, y, given_ts = check.pair(u, y, ("u", "y"), ts)
    step = check.sample_time(given_ts, 1.0)
    chosen = _families(families)
    u_val: Optional[check.FloatArray] = None
    y_val: Optional[check.FloatArray] = None
    if validate is not None:
        pair: Tuple[Samples, Samples]
        if isinstance(validate, (tuple, list)) and len(validate) == 2:
            pair = (validate[0], validate[1])
        elif hasattr(validate, "u") and hasattr(validate, "y"):
            record: RecordLike = validate
            pair = (record.u, record.y)
        else:
            raise TypeError("validate: give a pair (u_val, y_val) or a record with .u and .y")
        u_val, y_val, _ = check.pair(pair[0], pair[1], ("validate u", "validate y"), None)
    options = _family_options(thresholds, grid, lambda_, dead_zones)
    arguments = _fit_arguments(threads, orientation, initial_state, time_limit, progress, envelope)
    report, results, v_in, v_out, simulated = _hysid.compare(u, y, u_val, y_val, chosen, step, *options, **arguments)
    comparison = Comparison.from_extension(
        report,
        results,
        Record(v_in, v_out, step, labels, unit_labels),
        simulated,
        Record(u, y, step, labels, unit_labels),
    )
    warn_if_stopped(comparison.termination_code, arguments["time_limit"], "compare")
    return comparison


def _families(families: Any) -> List[str]:
    if isinstance(families, str):
        if families == "all":
            return list(FAMILIES)
        raise ConfigError(f"families={families!r}: give 'all' or a list of family names")
    try:
        names = list(families)
    except TypeError:
        raise TypeError(f"families: give 'all' or a list of family names, got {type(families).__name__}") from None
    if not names:
        raise ConfigError("families=[]: no family to compare; name at least one")
    return [_family(n, "families") for n in names]


def compensate(
    model: Union[Model, Result, str, "os.PathLike[str]"],
    reference: Samples,
    *,
    ts: Optional[float] = None,
    limits: Optional[Tuple[float, float]] = None,
) -> Compensation:
    """The input u that makes a fitted hysteresis model's output follow ``reference``: the
    CLI's ``hysid compensate``, the same library inverse and report.

    ``model``: a :class:`Model`, a :class:`Result` (its model) or the path of a model file;
    an operator of any family, a Coleman–Hodgdon hysteresis (ch4/ch6) or an operator
    cascade with a minimum-phase linear block (other kinds are a :class:`NumericalError`).
    ``ts``: the reference's sample time (default 1). A reference sample the model cannot
    reach is clipped to the nearest reachable output and listed in
    :attr:`Compensation.clipped`, never silently. ``limits``: the command's range (lo, hi)
    (``--limits``); default the model file's ``input_range``; a command beyond it is set to
    the nearer limit and clipped. When samples were clipped a :class:`HysidWarning` gives
    their count.
    """
    if isinstance(model, (str, os.PathLike)):
        source, model = os.fspath(model), load_model(model)
    else:
        source = "python (hysid.Model)"
    if isinstance(model, Result):
        if model.model is None:
            raise TypeError("model: this result has no model to compensate with")
        model = model.model
    if not isinstance(model, Model):
        raise TypeError(f"model: give a hysid.Model, a hysid.Result or a model file's path, got {type(model).__name__}")
    r = check.array(reference, "reference")
    step = check.sample_time(ts, 1.0)
    report, u, predicted = _hysid.compensate(json.dumps(model.file), r, step, source, _limits(limits))
    parsed = json.loads(report)
    # The report's model keeps the given model's channel names (the plots' labels).
    if isinstance(parsed.get("model"), dict) and "columns" in model.file:
        parsed["model"].setdefault("columns", model.file["columns"])
    result = Compensation(parsed, r, u, predicted, step)
    if result.clipped:
        warnings.warn(
            f"{len(result.clipped)} of {len(r)} reference samples were clipped (beyond the model's "
            "reach or needing a command beyond the limits); see Compensation.clipped",
            HysidWarning,
            stacklevel=2,
        )
    return result
