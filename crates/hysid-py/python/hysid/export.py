"""``Model.export``: a fitted model as C99, a no_std Rust crate or an FMI 2.0 FMU (the
command line's ``hysid export``)."""

from __future__ import annotations

import json
import os
from typing import TYPE_CHECKING, List, Literal, Optional, Tuple

from . import _hysid

if TYPE_CHECKING:  # pragma: no cover
    from .models import Model

Target = Literal["c", "rust", "fmu"]
Precision = Literal["double", "single"]


def export(
    self: Model,
    target: Target,
    name: str,
    out: "os.PathLike[str] | str",
    *,
    inverse: bool = False,
    ts: Optional[float] = None,
    binary: bool = True,
    y0: Optional[float] = None,
    limits: Optional[Tuple[float, float]] = None,
    precision: Precision = "double",
) -> List[str]:
    """Writes the model as ``target`` (``"c"``: ``NAME.h`` and ``NAME.c``; ``"rust"``: the
    crate ``NAME/``; ``"fmu"``: ``NAME.fmu``) into the directory ``out``, created if missing
    and refused if it holds any file; returns the paths written.

    ``inverse`` exports the compensator (input: the reference; output: the command); its C
    and Rust also count the steps whose reference was clipped to the reachable range
    (``NAME_clipped`` / ``Model::clipped``, the length of ``Compensation.clipped`` for the
    same references); the FMU does not expose the count.
    ``ts`` is the sample time in seconds, needed when the model file has none and equal to
    its own when it has one. ``binary=False`` leaves the FMU's compiled binary out (a
    source-only FMU; the binary is built with ``$CC``, else ``cc``). ``y0`` is the measured
    initial output a Coleman–Hodgdon hysteresis saved with ``initial_output: measured``
    starts from (required to export its forward step). ``limits=(lo, hi)`` limits a
    compensator's command (default: the input range of the data the model was fitted on, as
    ``compensate``). ``precision="single"`` writes ``float`` / ``f32`` code for a
    single-precision FPU (C and Rust; refused when its measured deviation from the double
    code exceeds 1e-4 of the output's range; the header states the bound). Errors: ``ConfigError``
    for a model or request that cannot be exported (a kind without an exporter, no inverse,
    a missing sample time, no C compiler), ``ModelFileError`` for an output directory that
    holds files.
    """
    if self._user is not None:
        raise _hysid.ModelFileError(
            "a model written as Python functions cannot be exported (its equations are Python "
            "code); write it as an equation file (GreyBoxModel.from_equations) to export it"
        )
    if not isinstance(out, (str, os.PathLike)):
        raise TypeError(f"out: expected a str or path, got {type(out).__name__}")
    paths = _hysid.export_model(
        json.dumps(self.file),
        str(target),
        str(name),
        os.fspath(out),
        bool(inverse),
        None if ts is None else float(ts),
        bool(binary),
        None if y0 is None else float(y0),
        None if limits is None else _limits(limits),
        _precision(precision),
    )
    return [os.fspath(p) for p in paths]


def _limits(limits: Tuple[float, float]) -> Tuple[float, float]:
    """``limits`` as two floats; a TypeError for anything else."""
    if isinstance(limits, (str, bytes)) or len(limits) != 2:
        raise TypeError(f"limits: expected a pair (lo, hi) of numbers, got {limits!r}")
    return (float(limits[0]), float(limits[1]))


def _precision(precision: str) -> str:
    """``precision`` checked: ``"double"`` or ``"single"``."""
    if precision not in ("double", "single"):
        raise ValueError(f"precision: expected 'double' or 'single', got {precision!r}")
    return precision
