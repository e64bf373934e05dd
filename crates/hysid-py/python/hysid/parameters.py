"""Model parameters: :class:`Parameter`, the unit a model file's parameter records map to."""

from __future__ import annotations

import math
from typing import Any, Dict, Optional, Tuple

import numpy as np

from ._hysid import ConfigError

#: A parameter as the extension module takes it: (name, value, lower, upper, fixed, unit).
ParameterTuple = Tuple[str, float, float, float, bool, str]


class Parameter:
    """A model parameter: name, value, bounds [lower, upper], fixed flag, unit, and — in a
    :class:`Result` — the standard deviation ``std`` of the estimate (None when fixed or not
    estimated)."""

    __slots__ = ("name", "value", "lower", "upper", "fixed", "unit", "std")

    name: str
    value: float
    lower: float
    upper: float
    fixed: bool
    unit: str
    std: Optional[float]

    def __init__(
        self,
        name: str,
        value: float,
        *,
        lower: float = -math.inf,
        upper: float = math.inf,
        fixed: bool = False,
        unit: str = "",
        std: Optional[float] = None,
    ) -> None:
        if not isinstance(name, str) or not name:
            raise TypeError("Parameter name: expected a non-empty string")
        for label, v in (("value", value), ("lower", lower), ("upper", upper)):
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)):
                raise TypeError(f"parameter {name}: {label} must be a number, got {type(v).__name__}")
        self.name, self.value = name, float(value)
        self.lower, self.upper = float(lower), float(upper)
        self.fixed, self.unit = bool(fixed), str(unit)
        self.std = None if std is None else float(std)
        if not math.isfinite(self.value):
            raise ConfigError(f"parameter {name}: value {self.value} is not finite; give a finite start value")
        if math.isnan(self.lower) or math.isnan(self.upper) or self.lower > self.upper:
            raise ConfigError(f"parameter {name}: bounds [{self.lower}, {self.upper}] are not an interval")

    @property
    def at_bound(self) -> bool:
        """True when the estimate sits on one of its bounds (``value == lower`` or
        ``value == upper``) and was not held fixed: its standard deviation is then not given
        (``std`` is None), since the asymptotic covariance holds for an interior optimum
        only (as lmfit, which reports no uncertainty for a parameter at a bound)."""
        return bool(not self.fixed and self.std is None and self.value in (self.lower, self.upper))

    def to_record(self) -> Dict[str, Any]:
        """The model file's record of the parameter (infinite bounds are null)."""
        return {
            "name": self.name,
            "value": self.value,
            "std": self.std,
            "unit": self.unit,
            "fixed": self.fixed,
            "lower": None if math.isinf(self.lower) else self.lower,
            "upper": None if math.isinf(self.upper) else self.upper,
        }

    def as_tuple(self) -> ParameterTuple:
        """The parameter as the extension module takes it."""
        return (self.name, self.value, self.lower, self.upper, self.fixed, self.unit)

    def __repr__(self) -> str:
        std = "" if self.std is None else f" ± {self.std:.3e}"
        unit = f" {self.unit}" if self.unit else ""
        fixed = " (fixed)" if self.fixed else " (at bound)" if self.at_bound else ""
        return f"Parameter({self.name} = {self.value!r}{std}{unit}{fixed})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Parameter) and all(getattr(self, s) == getattr(other, s) for s in self.__slots__)

    def __getstate__(self) -> Dict[str, Any]:
        return {s: getattr(self, s) for s in self.__slots__}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        for s in self.__slots__:
            object.__setattr__(self, s, state[s])
