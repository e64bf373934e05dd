"""The recipes of the seed papers and the grey-box engine: Coleman–Hodgdon cascades and
hysteresis (Vörös 2015), grey-box output error, the Bouc–Wen benchmark (Noël & Schoukens
2016), rigid-body least squares (Gunnar et al. 2006); and the worker threads of every call.
Each returns a :class:`FitResult` (a :class:`Result` whose model and fit are always there) built
on the report the CLI writes for the same command."""

from __future__ import annotations

import copy
import json
import math
import typing
from typing import Any, Dict, Iterable, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np

from . import _hysid
from . import _inputs as check
from ._families import FAMILIES, FamilyName
from ._hysid import ConfigError, DataError
from ._inputs import Samples, SamplesOrRecord
from .greybox import GreyBoxModel, Integrator, Interpolation
from .models import Evaluator
from .parameters import Parameter
from .progress import ProgressArg, warn_if_stopped, watching
from .results import FitResult, Record, labelled


def set_num_threads(n: Optional[int]) -> None:
    """Sets the worker threads of every later call that does not pass ``threads``.

    ``None`` or 0: all cores (rayon's global pool; the default, fastest for one fit at a
    time). 1: each call on a worker of its own, for the best throughput when several calls
    run at once from Python threads or a Dask worker's threads. Pools are built once per
    calling thread and count, then reused."""
    _hysid.set_num_threads(check.threads(n))


def get_num_threads() -> int:
    """The worker threads of a call that does not pass ``threads`` (0: all cores)."""
    return int(_hysid.get_num_threads())


#: The Coleman–Hodgdon forms of the seed paper's pipeline (every other family of the
#: registry is an operator: :func:`identify_cascade` fits it as an operator cascade).
ChForm = Literal["ch4", "ch6"]
CH_FORMS: Tuple[str, ...] = typing.get_args(ChForm)

#: How the standard deviations of a cascade are obtained.
UncertaintyMethod = Literal["asymptotic", "bootstrap"]

#: The built-in grey-box models of :func:`greybox_fit`.
BuiltinModel = Literal["bouc-wen", "rigid-body", "actuator-fixed", "actuator-free"]

#: What a Coleman–Hodgdon hysteresis starts from.
InitialOutput = Literal["measured", "zero"]


def identify_cascade(
    x: SamplesOrRecord,
    y: Optional[Samples] = None,
    *,
    hysteresis: FamilyName = "ch4",
    na: int,
    nb: int,
    delay: int,
    ts: float = 1.0,
    uncertainty: UncertaintyMethod = "asymptotic",
    seed: int = 0,
    replicates: int = 30,
    thresholds: Optional[int] = None,
    grid: Optional[int] = None,
    orientation: Optional[str] = None,
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
    names: Optional[Tuple[str, str]] = None,
    units: Optional[Tuple[str, str]] = None,
) -> FitResult:
    """Identifies a hysteresis + linear-block cascade: v(k) = H[x](k), A(q⁻¹) y(k) =
    q⁻ᵈᵉˡᵃʸ B(q⁻¹) v(k) with ``na`` denominator and ``nb`` numerator coefficients.

    ``hysteresis``: ``"ch4"`` or ``"ch6"``, the Coleman–Hodgdon hysteresis of Vörös (2015),
    estimated by a grid over the switching threshold, the paper's key-term separation
    iteration, then output error (Levenberg–Marquardt) from the best candidates; or any
    operator family of :data:`FAMILIES` (``"pi"``, ``"bouc-wen"``, …), estimated from the
    family's own start and ARX, then output error (the CLI's ``identify cascade
    --hysteresis FAMILY``). ``uncertainty``: ``"asymptotic"`` (σ²(JᵀJ)⁻¹) or, for ch4/ch6,
    ``"bootstrap"`` (parametric bootstrap, ``replicates`` re-identifications seeded by
    ``seed``). ``thresholds`` (PI, GPI, Maxwell-slip; default 10) and ``grid`` (Preisach;
    default 10) size an operator's structure. ``orientation`` (operator families): the
    operator loop's turning sense in the (u, y) plane, ``"ccw"`` or ``"cw"`` (None: the
    family's start decides; a value a start cannot take is an error). ``x`` may be a record with ``.u``, ``.y``
    (then ``y`` is omitted). Runs with the GIL released; ``threads``: worker threads
    (None: the process default, all cores; 1 for concurrent fits). The report is the CLI's
    ``identify cascade`` report.
    """
    labels, unit_labels = check.channel_labels(names, units, x, y)
    x, y, given_ts = check.pair(x, y, ("x", "y"), ts)
    step = check.sample_time(given_ts, 1.0)
    limit, tell = watching(time_limit, progress)
    name = check.choice(hysteresis, "hysteresis", FAMILIES)
    method = check.choice(uncertainty, "uncertainty", typing.get_args(UncertaintyMethod))
    orders = (check.count(na, "na"), check.count(nb, "nb"), check.count(delay, "delay"))
    if name in CH_FORMS:
        for option, value in (("thresholds", thresholds), ("grid", grid), ("orientation", orientation)):
            if value is not None:
                raise ConfigError(f"{option} applies to operator cascades, not to {name}")
        text = _hysid.identify_cascade(
            x,
            y,
            name,
            *orders,
            step,
            method,
            check.count(replicates, "replicates"),
            check.count(seed, "seed"),
            check.threads(threads),
            limit,
            tell,
        )
    else:
        if method != "asymptotic":
            raise ConfigError(
                f"uncertainty={method!r} is available for ch4 and ch6; operator cascades report "
                "asymptotic standard deviations (use uncertainty='asymptotic')"
            )
        if thresholds is not None and name not in ("pi", "gpi", "maxwell-slip"):
            raise ConfigError(f"thresholds applies to pi, gpi and maxwell-slip, not {name}")
        if grid is not None and name != "preisach":
            raise ConfigError(f"grid applies to preisach, not {name}")
        text = _hysid.identify_operator_cascade(
            x,
            y,
            name,
            *orders,
            step,
            10 if thresholds is None else check.count(thresholds, "thresholds"),
            10 if grid is None else check.count(grid, "grid"),
            check.threads(threads),
            None if orientation is None else check.choice(orientation, "orientation", ("ccw", "cw")),
            limit,
            tell,
        )
    record = Record(x, y, step, labels, unit_labels)
    return _finished(FitResult(labelled(json.loads(text), record), data=record), limit, "identify_cascade")


def identify_hysteresis(
    x: SamplesOrRecord,
    y: Optional[Samples] = None,
    *,
    hysteresis: ChForm = "ch4",
    ts: float = 1.0,
    initial_output: InitialOutput = "measured",
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
    names: Optional[Tuple[str, str]] = None,
    units: Optional[Tuple[str, str]] = None,
) -> FitResult:
    """Identifies a Coleman–Hodgdon hysteresis y = H[x] alone: separated linear regression
    with the switching threshold re-estimated, then output error. ``initial_output``:
    ``"measured"`` (the model starts from y[0]) or ``"zero"``. ``threads``: as for
    :func:`identify_cascade`."""
    labels, unit_labels = check.channel_labels(names, units, x, y)
    x, y, given_ts = check.pair(x, y, ("x", "y"), ts)
    step = check.sample_time(given_ts, 1.0)
    limit, tell = watching(time_limit, progress)
    text = _hysid.identify_hysteresis(
        x,
        y,
        check.choice(hysteresis, "hysteresis", CH_FORMS),
        step,
        check.choice(initial_output, "initial_output", typing.get_args(InitialOutput)),
        check.threads(threads),
        limit,
        tell,
    )
    record = Record(x, y, step, labels, unit_labels)
    return _finished(FitResult(labelled(json.loads(text), record), data=record), limit, "identify_hysteresis")


def _configure(
    params: List[Parameter],
    init: Optional[Dict[str, float]],
    fix: Union[str, Iterable[str]],
    bounds: Optional[Dict[str, Tuple[float, float]]],
) -> List[Parameter]:
    by_name = {p.name: p for p in params}

    def get(name: str, what: str) -> Parameter:
        if name not in by_name:
            raise ConfigError(f"{what}: no parameter '{name}'; the model's are {', '.join(by_name)}")
        return by_name[name]

    if init is not None:
        if not isinstance(init, dict):
            raise TypeError("init: give a dict name → start value")
        for name, v in init.items():
            get(name, "init").value = float(v)
    if isinstance(fix, str):
        fix = (fix,)
    for name in fix:
        get(name, "fix").fixed = True
    if bounds is not None:
        if not isinstance(bounds, dict):
            raise TypeError("bounds: give a dict name → (lower, upper)")
        for name, (lo, hi) in bounds.items():
            p = get(name, "bounds")
            p.lower, p.upper = float(lo), float(hi)
    for p in params:
        if not math.isfinite(p.value):
            raise ConfigError(f"parameter {p.name}: start value {p.value} is not finite")
    return params


def greybox_fit(
    model: Union[BuiltinModel, GreyBoxModel],
    u: SamplesOrRecord,
    y: Optional[Samples] = None,
    *,
    ts: Optional[float] = None,
    init: Optional[Dict[str, float]] = None,
    fix: Iterable[str] = (),
    bounds: Optional[Dict[str, Tuple[float, float]]] = None,
    starts: int = 1,
    seed: int = 0,
    integrator: Integrator = "rk4",
    substeps: int = 10,
    interpolation: Interpolation = "zoh",
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
    evaluator: Optional[Evaluator] = None,
) -> FitResult:
    """Output-error fit of a continuous-time grey-box model ẋ = f(t, x, u, θ), y = h(x, u, θ).

    ``model``: a built-in name (``"bouc-wen"``, ``"rigid-body"``, ``"actuator-fixed"``,
    ``"actuator-free"``) or a :class:`GreyBoxModel`. ``u``: 1-D or (samples, inputs);
    ``y``: 1-D or (samples, outputs). ``init`` (name → start value), ``fix`` (names held
    fixed), ``bounds`` (name → (lower, upper)) change the model's parameters; ``starts``
    > 1 screens that many random starts (seeded by ``seed``) before the full fit.
    Integration: RK4 (or Newmark) with ``substeps`` per sample, inputs held (``zoh``),
    interpolated (``linear``) or band-limited between samples. Built-in models and
    equation models (:meth:`GreyBoxModel.from_equations`) use exact sensitivities and
    ``threads`` workers (None: the process default, all cores); a :class:`GreyBoxModel`
    written as Python functions uses finite differences, on one thread. The report is the
    CLI's ``greybox fit`` report (``--model-file`` for an equation model).
    ``evaluator`` (equation models only, the CLI's ``--evaluator``): ``"auto"`` (native
    code from the C compiler, cached, else the tape interpreter), ``"cc"`` (native code
    only: :class:`ConfigError` when no C compiler works) or ``"tape"``; None: the
    environment variable ``HYSID_EVALUATOR``, else ``"auto"``. The report's
    ``details["evaluation"]`` says which ran.
    """
    u, y, ts = check.pair_channels(u, y, ts)
    ts = check.sample_time(ts)
    # The fitted record, kept for best_fit, residuals and the plots.
    fitted = Record(_joined(u), _joined(y), ts)
    limit, tell = watching(time_limit, progress)
    args = (
        check.count(starts, "starts"),
        check.count(seed, "seed"),
        check.choice(integrator, "integrator"),
        check.count(substeps, "substeps"),
        check.choice(interpolation, "interpolation"),
    )
    chosen_evaluator = None if evaluator is None else check.choice(evaluator, "evaluator", typing.get_args(Evaluator))
    if chosen_evaluator is not None and not (isinstance(model, GreyBoxModel) and model.equations is not None):
        raise ConfigError("evaluator: applies to an equation model (GreyBoxModel.from_equations); leave it out")
    if isinstance(model, GreyBoxModel):
        user = copy.copy(model)
        user.parameters = _configure([copy.copy(p) for p in model.parameters], init, fix, bounds)
        if len(u) != user.inputs:
            raise DataError(f"u has {len(u)} channel(s); the model has {user.inputs} input(s)")
        if len(y) != user.outputs:
            raise DataError(f"y has {len(y)} channel(s); the model has {user.outputs} output(s)")
        if user.equations is not None:
            params = [p.as_tuple() for p in user.parameters]
            text = _hysid.greybox_fit_equations(
                user.equations, u, y, ts, params, *args, check.threads(threads), limit, tell, chosen_evaluator
            )
            report = _greybox_labelled(json.loads(text), ts, user.input_names, user.output_names)
            return _finished(FitResult(report, data=fitted), limit, "greybox_fit")
        if limit is not None or tell is not None:
            raise ConfigError(
                "time_limit and progress are not available for a model written as Python functions (its "
                "callbacks run on the fit's thread); write it as equations (GreyBoxModel.from_equations)"
            )
        text = _hysid.greybox_fit_user(user._spec(), u, y, ts, *args)
        return FitResult(_greybox_labelled(json.loads(text), ts, [], []), user, fitted)
    if not isinstance(model, str):
        raise TypeError(f"model: give a built-in model name or a hysid.GreyBoxModel, got {type(model).__name__}")
    defaults, _, _ = _hysid.model_parameters(model)
    built_in = [Parameter(n, v, lower=lo, upper=hi, fixed=f, unit=unit) for (n, v, lo, hi, f, unit) in defaults]
    chosen = _configure(built_in, init, fix, bounds)
    text = _hysid.greybox_fit(
        model, u, y, ts, [p.as_tuple() for p in chosen], *args, check.threads(threads), limit, tell
    )
    report = _greybox_labelled(json.loads(text), ts, [], [])
    return _finished(FitResult(report, data=fitted), limit, "greybox_fit")


#: Sampling frequency of the Bouc–Wen benchmark records [Hz].
BOUC_WEN_FS = 750.0


def benchmark_bouc_wen(
    u_train: SamplesOrRecord,
    y_train: Optional[Samples] = None,
    *,
    tests: Sequence[Any] = (),
    steady_state: bool = False,
    ts: Optional[float] = None,
    starts: int = 8,
    seed: int = 1,
    substeps: int = 4,
    start_factor: float = 1.0,
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
) -> FitResult:
    """The Bouc–Wen hysteretic benchmark (Noël & Schoukens 2016): fits the Bouc–Wen
    oscillator m ÿ + c ẏ + k y + z = u, ż = α ẏ − β(γ|ẏ||z|^(ν−1) z − δ ẏ|z|^ν)
    (RK4 with ``substeps`` per sample, band-limited input) on the training record from the
    nominal parameters times ``start_factor`` with ``starts`` screened starts, then scores
    each test record by e_RMS = RMS(y − ŷ) in simulation mode (from rest, or with
    ``steady_state`` in the periodic steady state: the input applied twice). ``tests``:
    (u, y) pairs or records with ``.u``, ``.y``; ``Result.validation`` holds one entry per
    test with ``e_rms``. Records default to 750 Hz. ``threads``: as for
    :func:`identify_cascade`. The report is the CLI's ``benchmark bouc-wen`` report.
    """
    u, y, ts = check.pair(u_train, y_train, ("u_train", "y_train"), ts)
    ts = check.sample_time(ts, 1.0 / BOUC_WEN_FS)
    limit, tell = watching(time_limit, progress)

    records = []
    for i, t in enumerate(tests):
        if hasattr(t, "u") and hasattr(t, "y"):
            tu, ty, tts = t.u, t.y, getattr(t, "sampling_time", None)
            name = str(getattr(t, "name", None) or f"test {i + 1}")
        else:
            try:
                tu, ty = t
            except (TypeError, ValueError):
                raise TypeError(f"tests[{i}]: give a (u, y) pair or a record with .u and .y") from None
            tts, name = None, f"test {i + 1}"
        tu, ty, _ = check.pair(tu, ty, (f"tests[{i}].u", f"tests[{i}].y"), None)
        records.append((tu, ty, check.sample_time(tts, ts), name))
    defaults, _, _ = _hysid.model_parameters("bouc-wen")
    params = [(n, v * float(start_factor) if not f else v, lo, hi, f, unit) for (n, v, lo, hi, f, unit) in defaults]
    text = _hysid.benchmark_bouc_wen(
        u,
        y,
        ts,
        params,
        records,
        bool(steady_state),
        check.count(starts, "starts"),
        check.count(seed, "seed"),
        check.count(substeps, "substeps"),
        check.threads(threads),
        limit,
        tell,
    )
    return _finished(FitResult(json.loads(text)), limit, "benchmark_bouc_wen")


def rigid_body_ls(
    q: Samples,
    u: Samples,
    *,
    ts: float,
    gain: float = 1.0,
    offset: bool = False,
    cutoff_hz: float = 100.0,
    order: int = 4,
    decimation: int = 10,
    border: int = 50,
    inertia_name: str = "M",
    threads: Optional[int] = None,
    time_limit: Optional[float] = None,
    progress: ProgressArg = None,
) -> FitResult:
    """Rigid-body least squares (step 1 of Gunnar et al., ICRA 2006): position ``q``
    filtered by a zero-phase Butterworth low-pass (``order``, ``cutoff_hz``), velocity and
    acceleration by central differences, and g·u = M q̈ + Fv q̇ + Fc sgn(q̇) (+ offset)
    solved by linear least squares; ``decimation`` keeps every n-th equation, ``border``
    drops samples at each end (defaults: the CLI's, 10 and 50). ``Result.parameters`` holds the estimates and their std;
    the report's details hold the relative error and condition numbers (the CLI's
    ``rigid-body ls`` report); the model is the built-in ``rigid_body`` model."""
    qa, ua, _ = check.pair(q, u, ("q", "u"), None)
    limit, tell = watching(time_limit, progress)
    text = _hysid.rigid_body_ls(
        qa,
        ua,
        check.sample_time(ts),
        float(gain),
        bool(offset),
        float(cutoff_hz),
        check.count(order, "order"),
        check.count(decimation, "decimation"),
        check.count(border, "border"),
        str(inertia_name),
        check.threads(threads),
        limit,
        tell,
    )
    return _finished(FitResult(json.loads(text)), limit, "rigid_body_ls")


def _greybox_labelled(
    report: Dict[str, Any], ts: float, inputs: Sequence[str], outputs: Sequence[str]
) -> Dict[str, Any]:
    """The grey-box report with its model file carrying the fit's sample time and, for an
    equation model, its input and output names as ``columns`` (what the command line's
    model files hold), where the library left them out: so that every export works from the
    model."""
    model = report.get("model")
    if isinstance(model, dict):
        model.setdefault("sample_time", ts)
        if inputs and outputs:
            model.setdefault("columns", {"inputs": list(inputs), "outputs": list(outputs)})
    return report


def _joined(channels: List[check.FloatArray]) -> check.FloatArray:
    """One channel as it is, several as the columns of one (samples, channels) array."""
    return channels[0] if len(channels) == 1 else np.column_stack(channels)


def _finished(result: FitResult, time_limit: Optional[float], what: str) -> FitResult:
    """``result``, with the :class:`HysidWarning` of a search its time limit stopped."""
    warn_if_stopped(result.termination_code, time_limit, what)
    return result
