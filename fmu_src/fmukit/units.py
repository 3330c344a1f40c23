"""SI units used by the project's FMUs, as FMI 2.0 ``<Unit>`` definitions.

Each entry maps a unit name to its SI base-unit exponents (FMI names: kg, m, s, A,
K, mol, cd, rad) and optional display units ``(name, factor)`` where
``display = factor * value``.
"""

from __future__ import annotations

UNITS: dict[str, tuple[dict[str, int], tuple[tuple[str, float], ...]]] = {
    "1": ({}, ()),
    "s": ({"s": 1}, (("ms", 1e3),)),
    "A": ({"A": 1}, (("mA", 1e3),)),
    "rad": ({"rad": 1}, (("deg", 57.29577951308232),)),
    "rad/s": ({"rad": 1, "s": -1}, (("rpm", 9.549296585513721),)),
    "rad/s2": ({"rad": 1, "s": -2}, ()),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, (("mN.m", 1e3),)),
    "kg.m2": ({"kg": 1, "m": 2}, (("g.cm2", 1e7),)),
    "N.m/A": ({"kg": 1, "m": 2, "s": -2, "A": -1}, (("mN.m/A", 1e3),)),
    "N.m/rad": ({"kg": 1, "m": 2, "s": -2, "rad": -1}, ()),
    "N.m.s/rad": ({"kg": 1, "m": 2, "s": -1, "rad": -1}, ()),
    "rad/s/A": ({"rad": 1, "s": -1, "A": -1}, ()),
    "kg.m2/(rad/s2)": ({"kg": 1, "m": 2, "rad": -1}, ()),
    "m": ({"m": 1}, (("mm", 1e3),)),
    "m/s": ({"m": 1, "s": -1}, ()),
    "kg": ({"kg": 1}, (("g", 1e3),)),
    "kg/m": ({"kg": 1, "m": -1}, ()),
    "N.m2": ({"kg": 1, "m": 3, "s": -2}, ()),
}


def check_unit(name: str) -> None:
    """Raise ``ValueError`` if ``name`` is not a unit defined in :data:`UNITS`."""
    if name not in UNITS:
        known = ", ".join(sorted(UNITS))
        raise ValueError(f"unit {name!r} is not defined in fmukit.units.UNITS (known: {known})")
