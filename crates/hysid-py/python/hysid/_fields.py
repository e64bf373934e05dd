"""Reading a report or a model file once, field by field, with the type each field must
have: a missing or ill-typed field is a :class:`ReportError` naming it at construction of
the object that needs it, never a silent ``None`` later."""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Type, TypeVar

from ._hysid import HysidError

T = TypeVar("T", str, int, float, bool, Dict[str, Any], List[Any])


class ReportError(HysidError, ValueError):
    """A report or model file lacks a field a result needs, or holds one of the wrong type
    (written by another version of hysid, or edited)."""


ReportError.__module__ = "hysid"

_NAMES: Dict[type, str] = {
    str: "a string",
    int: "an integer",
    float: "a number",
    bool: "true or false",
    dict: "an object",
    list: "a list",
}


def _typed(value: Any, kind: Type[T], where: str) -> T:
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    ok = isinstance(value, kind) and not (kind in (int, float) and isinstance(value, bool))
    if not ok:
        got = "null" if value is None else type(value).__name__
        raise ReportError(f"{where}: expected {_NAMES[kind]}, got {got}")
    return value  # type: ignore[no-any-return]


class Fields:
    """The fields of one JSON object, ``where`` naming it in errors (``report.fit``)."""

    def __init__(self, obj: Any, where: str) -> None:
        if not isinstance(obj, Mapping):
            got = "null" if obj is None else type(obj).__name__
            raise ReportError(f"{where}: expected an object, got {got}")
        self._obj: Mapping[str, Any] = obj
        self.where = where

    def _raw(self, key: str) -> Any:
        if key not in self._obj:
            raise ReportError(f"{self.where}.{key} is missing")
        return self._obj[key]

    def get(self, key: str, kind: Type[T]) -> T:
        """The field ``key``, present, not null, of type ``kind``."""
        return _typed(self._raw(key), kind, f"{self.where}.{key}")

    def optional(self, key: str, kind: Type[T]) -> Optional[T]:
        """The field ``key``, present (null allowed), of type ``kind`` when not null."""
        value = self._raw(key)
        return None if value is None else _typed(value, kind, f"{self.where}.{key}")

    def absent_or(self, key: str, kind: Type[T]) -> Optional[T]:
        """The field ``key`` if present and not null (a field the format marks optional)."""
        value = self._obj.get(key)
        return None if value is None else _typed(value, kind, f"{self.where}.{key}")

    def object(self, key: str) -> Optional["Fields"]:
        """The object ``key`` (None when null)."""
        value = self._raw(key)
        return None if value is None else Fields(value, f"{self.where}.{key}")

    def objects(self, key: str) -> List["Fields"]:
        """The list of objects ``key``."""
        items = self.get(key, list)
        return [Fields(v, f"{self.where}.{key}[{i}]") for i, v in enumerate(items)]

    def raw(self, key: str) -> Any:
        """The field ``key`` as it is (present; any JSON value)."""
        return self._raw(key)

    def mapping(self) -> Dict[str, Any]:
        """The object itself."""
        return dict(self._obj)
