"""Checks of what a caller passes: arrays, records, counts, choices, the sample time.

Every public function of the package reads its arguments through these helpers, so a bad
argument gives the same one-line error wherever it is passed: ``TypeError`` for something of
the wrong kind, :class:`DataError` for unusable data, :class:`ConfigError` for a setting out
of range or unknown (both are also ``ValueError``).
"""

from __future__ import annotations

import math
from typing import Any, List, Optional, Protocol, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._hysid import ConfigError, DataError

#: A float64 numpy array, the package's signal type: what every function returns.
FloatArray = npt.NDArray[np.float64]

#: Samples as every function takes them: anything numpy reads as an array of real numbers
#: (a list, a tuple, a numpy or pandas array of ints or floats). Strings, booleans, complex
#: numbers and objects are refused with a ``TypeError``.
Samples = npt.ArrayLike


class RecordLike(Protocol):
    """A record holding a measured input ``.u`` and output ``.y`` (and, if it has one, a
    ``.sampling_time`` in seconds), such as ``nonlinear_benchmarks.Input_output_data``:
    accepted wherever a pair of arrays is."""

    @property
    def u(self) -> npt.ArrayLike:
        """The input samples."""
        ...

    @property
    def y(self) -> npt.ArrayLike:
        """The output samples."""
        ...


#: An input's samples, or a record holding the input and the output (the output argument
#: is then omitted).
SamplesOrRecord = Union[npt.ArrayLike, RecordLike]


def array(a: Any, name: str, *, ndim: Tuple[int, ...] = (1,)) -> FloatArray:
    """``a`` as a C-contiguous float64 array of one of the dimensions ``ndim``, finite and
    not empty; TypeError for something that is not numeric, DataError otherwise."""
    if isinstance(a, (str, bytes, dict)) or a is None:
        raise TypeError(f"{name}: expected a numeric array, got {type(a).__name__}")
    try:
        kind = np.asarray(a).dtype.kind
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: expected a numeric array, got {type(a).__name__} ({e})") from None
    if kind not in "iuf":
        # Strings ("1.5"), objects, booleans, complex numbers and dates are not samples:
        # numpy would parse or cast some of them silently.
        what = {"U": "strings", "S": "bytes", "O": "Python objects", "b": "booleans", "c": "complex numbers"}
        raise TypeError(f"{name}: expected a numeric array of real numbers, got an array of {what.get(kind, kind)}")
    try:
        arr: FloatArray = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: expected a numeric array, got {type(a).__name__} ({e})") from None
    if arr.ndim not in ndim:
        want = " or ".join(f"{d}-D" for d in ndim)
        raise DataError(f"{name}: expected a {want} array, got shape {arr.shape}")
    if arr.size == 0:
        raise DataError(f"{name}: the array is empty; give at least one sample")
    bad = np.flatnonzero(~np.isfinite(arr.ravel()))
    if bad.size:
        k = int(bad[0])
        idx = np.unravel_index(k, arr.shape)
        where = idx[0] if arr.ndim == 1 else tuple(int(i) for i in idx)
        raise DataError(f"{name}: sample {where} is {arr.ravel()[k]}, not finite; remove or interpolate it")
    return arr


def channels(a: Any, name: str) -> List[FloatArray]:
    """1-D → one channel; 2-D (samples, channels) → one contiguous array per column."""
    arr = array(a, name, ndim=(1, 2))
    if arr.ndim == 1:
        return [arr]
    return [np.ascontiguousarray(arr[:, j]) for j in range(arr.shape[1])]


def _unpack_record(x: Any, y: Any, ts: Optional[float], names: Tuple[str, str]) -> Tuple[Any, Any, Optional[float]]:
    """(x, y, ts) from two arrays, or from a record with ``.u``, ``.y``, ``.sampling_time``
    (``nonlinear_benchmarks.Input_output_data``) passed as ``x``."""
    if y is None and hasattr(x, "u") and hasattr(x, "y"):
        rec_ts = getattr(x, "sampling_time", None)
        x, y = x.u, x.y
        if ts is None and rec_ts is not None:
            ts = float(rec_ts)
    if y is None:
        raise TypeError(f"give {names[1]}, or pass a record with .u and .y as {names[0]}")
    return x, y, ts


def pair(x: Any, y: Any, names: Tuple[str, str], ts: Optional[float]) -> Tuple[FloatArray, FloatArray, Optional[float]]:
    """Two equally long 1-D signals (and the sample time a record carries, if any)."""
    x, y, ts = _unpack_record(x, y, ts, names)
    xa, ya = array(x, names[0]), array(y, names[1])
    if xa.shape != ya.shape:
        raise DataError(f"{names[0]} has {xa.shape[0]} samples and {names[1]} {ya.shape[0]}; give equal lengths")
    return xa, ya, ts


def pair_channels(u: Any, y: Any, ts: Optional[float]) -> Tuple[List[FloatArray], List[FloatArray], Optional[float]]:
    """Input and output channels of equal length (1-D or (samples, channels) each)."""
    u, y, ts = _unpack_record(u, y, ts, ("u", "y"))
    uc, yc = channels(u, "u"), channels(y, "y")
    if uc[0].shape[0] != yc[0].shape[0]:
        raise DataError(f"u has {uc[0].shape[0]} samples and y {yc[0].shape[0]}; give equal lengths")
    return uc, yc, ts


def sample_time(ts: Any, default: Optional[float] = None) -> float:
    """The sample time [s], positive and finite; ``default`` when ``ts`` is None."""
    if ts is None:
        if default is None:
            raise TypeError("give the sample time ts (seconds)")
        ts = default
    if isinstance(ts, bool) or not isinstance(ts, (int, float, np.floating, np.integer)):
        raise TypeError(f"ts: expected a number, got {type(ts).__name__}")
    value = float(ts)
    if not (math.isfinite(value) and value > 0):
        raise ConfigError(f"ts = {value}: give a positive, finite sample time")
    return value


def count(v: Any, name: str) -> int:
    """A non-negative integer."""
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {type(v).__name__}")
    if v < 0:
        raise ConfigError(f"{name} = {v}: give a non-negative integer")
    return int(v)


def number(v: Any, name: str) -> float:
    """A finite float."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
        raise TypeError(f"{name}: expected a number, got {type(v).__name__}")
    value = float(v)
    if not math.isfinite(value):
        raise ConfigError(f"{name} = {value}: give a finite number")
    return value


def choice(v: Any, name: str, allowed: Optional[Sequence[str]] = None) -> str:
    """A string, one of ``allowed`` when given (ConfigError, a ValueError, otherwise)."""
    if not isinstance(v, str):
        raise TypeError(f"{name}: expected a string, got {type(v).__name__}")
    if allowed is not None and v not in allowed:
        raise ConfigError(f"{name}={v!r}: unknown; use one of {', '.join(allowed)}")
    return v


def threads(v: Any) -> int:
    """``threads`` as the extension takes it: 0 for the process default."""
    return 0 if v is None else count(v, "threads")


def channel_labels(
    names: Optional[Sequence[str]], units: Optional[Sequence[str]], u: Any, y: Any
) -> Tuple[Tuple[str, str], Tuple[str, str]]:
    """The (input, output) names and units of a record: as given, else the names the arrays
    carry (a pandas Series' ``.name``, the CSV column it was read from), else ``("u", "y")``;
    units ``("", "")`` unless given. A pair of strings each, or a ``TypeError``."""

    def pair(v: Sequence[str], what: str) -> Tuple[str, str]:
        if isinstance(v, str) or len(v) != 2 or not all(isinstance(s, str) for s in v):
            raise TypeError(f"{what}: give a pair of strings (input, output), e.g. {what}=('voltage', 'displacement')")
        return (v[0], v[1])

    if names is None:
        carried = [getattr(a, "name", None) for a in (u, y)]
        found = [c if isinstance(c, str) and c else d for c, d in zip(carried, ("u", "y"))]
        given_names = (found[0], found[1])
    else:
        given_names = pair(names, "names")
    return given_names, ("", "") if units is None else pair(units, "units")
