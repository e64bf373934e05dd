"""The hysteresis families of the library's registry, as Python names.

Generated from ``hysid::model::operators::Family`` — do not edit: the test
``registry_python_names`` in ``crates/hysid-tests`` checks this file and rewrites it under
``HYSID_WRITE_SCHEMA=1 cargo test --release -p hysid-tests --test library registry``.
"""

from typing import Literal, Tuple

#: A hysteresis family's name, as ``hysid identify operator --family`` takes it.
FamilyName = Literal[
    "pi",
    "gpi",
    "preisach",
    "jiles-atherton",
    "bouc-wen",
    "duhem",
    "dahl",
    "maxwell-slip",
    "backlash",
    "kp",
    "ch4",
    "ch6",
]

#: Every family name, in the registry's order.
FAMILIES: Tuple[str, ...] = (
    "pi",
    "gpi",
    "preisach",
    "jiles-atherton",
    "bouc-wen",
    "duhem",
    "dahl",
    "maxwell-slip",
    "backlash",
    "kp",
    "ch4",
    "ch6",
)
