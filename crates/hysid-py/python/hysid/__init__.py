"""hysid — identification of dynamic systems with hysteresis, from numpy arrays.

The Rust library hysid behind a Python API: numpy arrays (float64, 1-D; 2-D ``(samples,
channels)`` for several inputs) in and out, fits that release the GIL, results and models
that pickle exactly.

Models and methods
------------------
* The hysteresis zoo: every family of the library's registry (:data:`FAMILIES`: PI,
  Preisach, Bouc–Wen, Jiles–Atherton, Maxwell-slip, …) fitted from the data alone
  (:func:`identify_operator`), compared (:func:`compare`) and inverted (:func:`compensate`).
* Coleman–Hodgdon hysteresis (forms ``ch4``, ``ch6``) or any operator of the zoo followed by
  a linear block A(q⁻¹)y = q⁻ᵏB(q⁻¹)v: the cascade of J. Vörös, "Modeling and Identification
  of Discrete-Time Nonlinear Dynamic Cascade Systems with Input Hysteresis", Mathematical
  Problems in Engineering 2015, 393572 (key-term separation, then output error).
* Continuous-time grey-box models ẋ = f(t, x, u, θ), y = h(x, u, θ) fitted by output error
  (Levenberg–Marquardt, multi-start): built-in (Bouc–Wen oscillator, rigid body with
  friction, the actuator of J. Gunnar et al., ICRA 2006) or written as Python functions
  (:class:`GreyBoxModel`).
* The Bouc–Wen hysteretic benchmark of J.-P. Noël and M. Schoukens (2016), scored by
  e_RMS, the RMS of the simulation error.

Quick start::

    import numpy as np, hysid
    r = hysid.identify_cascade(x, y, hysteresis="ch4", na=2, nb=2, delay=1)
    print(r.parameters["a1"].value, r.fit_percent)
    yhat = r.model.simulate(x, ts=1.0)

Threads: every fit releases the GIL. ``threads=None`` (the default) runs a call's parallel
work on all cores, the fastest for one fit at a time; ``threads=1`` runs it on a worker of
its own, the best throughput when several fits run at once (Python threads, a thread
pool, Dask workers with several threads): n such calls use n cores.
:func:`set_num_threads` changes the default for the whole process.

Errors are :class:`HysidError` subclasses; bad data and bad settings are also
``ValueError`` (:class:`DataError`, :class:`ConfigError`), wrong types ``TypeError``.

Modules: ``parameters`` (:class:`Parameter`), ``models`` (:class:`Model`), ``greybox``
(:class:`GreyBoxModel`), ``results`` (:class:`Result`), ``recipes`` (the seed papers'
recipes), ``actuator``, ``zoo`` (the hysteresis families: :func:`identify_operator`,
:func:`compare`, :func:`compensate`), ``comparison`` (:class:`Comparison`),
``compensation`` (:class:`Compensation`), ``plot`` (matplotlib figures), ``fleet`` (Dask);
every public name is importable from ``hysid`` itself.
"""

from . import _hysid, fleet, plot, stream
from ._families import FAMILIES, FamilyName
from ._fields import ReportError
from ._hysid import (
    CallbackError,
    ConfigError,
    DataError,
    HysidError,
    InternalError,
    ModelFileError,
    NumericalError,
)
from .actuator import ACTUATOR_GEAR_RATIO, ACTUATOR_SADDLE_MASS, ActuatorRecord, actuator_rig, actuator_three_steps
from .comparison import CompareRow, Comparison
from .compensation import Compensation
from .greybox import GreyBoxModel
from .models import Model, ModelFileNotFoundError, load_model
from .parameters import Parameter
from .progress import HysidWarning, Progress, ProgressArg
from .recipes import (
    BOUC_WEN_FS,
    benchmark_bouc_wen,
    get_num_threads,
    greybox_fit,
    identify_cascade,
    identify_hysteresis,
    rigid_body_ls,
    set_num_threads,
)
from .results import FitResult, Record, Result, ValidationEntry
from .stream import Compensator, Stepper
from .zoo import compare, compensate, identify_operator

__version__: str = _hysid.__version__

__all__ = [
    "FAMILIES",
    "FamilyName",
    "identify_operator",
    "compare",
    "compensate",
    "Comparison",
    "CompareRow",
    "Compensation",
    "identify_cascade",
    "identify_hysteresis",
    "greybox_fit",
    "benchmark_bouc_wen",
    "rigid_body_ls",
    "actuator_three_steps",
    "actuator_rig",
    "ActuatorRecord",
    "set_num_threads",
    "get_num_threads",
    "load_model",
    "Parameter",
    "GreyBoxModel",
    "Result",
    "FitResult",
    "Record",
    "ValidationEntry",
    "ReportError",
    "Model",
    "Stepper",
    "Compensator",
    "HysidError",
    "DataError",
    "ConfigError",
    "NumericalError",
    "ModelFileError",
    "ModelFileNotFoundError",
    "CallbackError",
    "InternalError",
    "HysidWarning",
    "Progress",
    "ProgressArg",
    "fleet",
    "plot",
    "stream",
    "BOUC_WEN_FS",
    "ACTUATOR_GEAR_RATIO",
    "ACTUATOR_SADDLE_MASS",
]

for _cls in (HysidError, NumericalError, ModelFileError, CallbackError, InternalError):
    _cls.__module__ = "hysid"
del _cls
