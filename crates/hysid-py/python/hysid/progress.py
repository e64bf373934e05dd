"""Progress and time limits of the long calls: :class:`Progress`, :class:`HysidWarning`.

Every fitting function takes ``time_limit=`` (seconds for the whole call; then the searches
stop with the best result so far, the result's ``termination_code`` is ``"time_limit"`` and
a :class:`HysidWarning` says so, as the command line's ``--time-limit``) and ``progress=``
(a callable taking one :class:`Progress`, called on the calling thread when the call
starts, about twice a second while it runs, and when it ends; or ``True`` for a tqdm bar,
``pip install tqdm``). An exception raised by the callable stops the call and propagates,
and so does Ctrl-C (``KeyboardInterrupt``), within a fraction of a second.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Optional, Tuple, Union

from ._hysid import ConfigError


class HysidWarning(UserWarning):
    """A result that holds, with something the caller should know: a search stopped by its
    time limit, commands clipped to their limits."""


@dataclass(frozen=True)
class Progress:
    """What a long call is doing: ``stage`` (``"start"``, a phase such as ``"start"`` of a
    multi-start, ``"grid"``, ``"family"`` or ``"bootstrap replicate"``, ``"iteration"`` for
    a fit's iterations, ``"done"`` at the end), ``done`` of ``total`` steps of the phase (0
    of 0 when it has no count), the latest fit ``iteration`` and its ``cost`` S = Σ r² (None
    before the first), and the seconds ``elapsed`` since the call started."""

    stage: str
    done: int
    total: int
    iteration: Optional[int]
    cost: Optional[float]
    elapsed: float


#: What ``progress=`` accepts: None or False (nothing), True (a tqdm bar), or a callable.
ProgressArg = Union[None, bool, Callable[[Progress], object]]

#: The form the extension module calls: (stage, done, total, iteration, cost, elapsed).
_Raw = Callable[[str, int, int, Optional[int], Optional[float], float], None]


def watching(time_limit: Optional[float], progress: ProgressArg) -> Tuple[Optional[float], Optional[_Raw]]:
    """``time_limit`` and ``progress`` checked and in the extension module's form."""
    if time_limit is not None:
        if isinstance(time_limit, bool) or not isinstance(time_limit, numbers.Real):
            raise TypeError(f"time_limit: give a number of seconds or None, got {type(time_limit).__name__}")
        limit = float(time_limit)
        if not (math.isfinite(limit) and limit > 0):
            raise ConfigError(f"time_limit={time_limit}: give a positive number of seconds, or None for no limit")
        time_limit = limit
    if progress is None or progress is False:
        return time_limit, None
    if progress is True:
        return time_limit, _tqdm_bar()
    if not callable(progress):
        raise TypeError(f"progress: give a callable taking one hysid.Progress, or True, got {type(progress).__name__}")
    user = progress

    def raw(stage: str, done: int, total: int, iteration: Optional[int], cost: Optional[float], elapsed: float) -> None:
        user(Progress(stage, done, total, iteration, cost, elapsed))

    return time_limit, raw


def _tqdm_bar() -> _Raw:
    try:
        from tqdm.auto import tqdm
    except ImportError as e:
        raise ImportError("progress=True needs tqdm: pip install tqdm (or pass a callable)") from e
    bar: Any = tqdm(total=None, unit="it", leave=False)

    def raw(stage: str, done: int, total: int, iteration: Optional[int], cost: Optional[float], elapsed: float) -> None:
        if stage == "done":
            bar.close()
            return
        if total > 0:
            bar.total = total
            bar.n = done
        elif iteration is not None:
            bar.n = iteration
        bar.set_description(stage, refresh=False)
        if cost is not None:
            bar.set_postfix(cost=f"{cost:.4e}", refresh=False)
        bar.refresh()

    return raw


def warn_if_stopped(termination_code: Optional[str], time_limit: Optional[float], what: str) -> None:
    """The :class:`HysidWarning` of a call stopped by its time limit (the CLI's warning)."""
    if termination_code == "time_limit":
        warnings.warn(
            HysidWarning(
                f"{what}: the time limit of {time_limit} s stopped the search; the results are the best "
                "found so far (termination_code == 'time_limit')"
            ),
            stacklevel=3,
        )
