"""Declarations of FMU variables: name, type, causality, unit, description, start.

A :class:`Variable` is a plain description; :class:`arcosim.fmu.fmukit.slave.FmuSlave` stores
the values and :func:`arcosim.fmu.fmukit.model_description.model_description` writes the XML.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal, Union

from .units import check_unit

VarType = Literal["Real", "Integer", "Boolean", "String"]
Causality = Literal["parameter", "input", "output"]
# Union, not |: this module runs inside the FMUs, in any CPython >= 3.9
Value = Union[float, int, bool, str]  # noqa: UP007


@dataclass(frozen=True)
class Variable:
    """One FMI 2.0 scalar variable.

    Parameters
    ----------
    name : str
        FMI structured name, e.g. ``"k[2]"``.
    type : str
        ``"Real"``, ``"Integer"``, ``"Boolean"`` or ``"String"``.
    causality : str
        ``"parameter"`` (fixed after initialization), ``"input"`` or ``"output"``
        (computed by ``doStep``, depending on no input directly).
    description : str
        One line for the user, with what the value means.
    unit : str
        Unit name from :data:`arcosim.fmu.fmukit.units.UNITS` (Real only; ``"1"`` when
        dimensionless).
    start : float, int, bool, str or None
        Start value (parameters and inputs, in ``unit``); outputs start at ``start`` or
        0 until the first step.

    Raises
    ------
    ValueError
        For an unknown unit, a unit on a non-Real variable, a parameter or input without
        a start value, or an empty description.
    """

    name: str
    type: VarType
    causality: Causality
    description: str
    unit: str = ""
    start: Value | None = None

    def __post_init__(self) -> None:
        if self.type == "Real":
            check_unit(self.unit or "?")
        elif self.unit:
            raise ValueError(f"{self.name}: only Real variables carry a unit")
        if self.causality in ("parameter", "input") and self.start is None:
            raise ValueError(f"{self.name}: a {self.causality} needs a start value")
        if not self.description:
            raise ValueError(f"{self.name}: every variable needs a description")

    @property
    def variability(self) -> str:
        """FMI variability: parameters are ``fixed``; Real signals ``continuous``."""
        if self.causality == "parameter":
            return "fixed"
        return "continuous" if self.type == "Real" else "discrete"

    @property
    def initial_value(self) -> Value:
        """The value held before initialization (start, or a typed zero)."""
        if self.start is not None:
            return self.start
        return {"Real": 0.0, "Integer": 0, "Boolean": False, "String": ""}[self.type]


def par(name: str, start: Value, unit: str, description: str) -> Variable:
    """A parameter; its type follows ``start`` (str → String, bool → Boolean, int → Integer)."""
    return Variable(name, type_of(start), "parameter", description, unit, start)


def inp(name: str, start: float, unit: str, description: str) -> Variable:
    """A Real input."""
    return Variable(name, "Real", "input", description, unit, float(start))


def out(name: str, unit: str, description: str, vtype: VarType = "Real") -> Variable:
    """An output (Real unless ``vtype`` says otherwise)."""
    return Variable(name, vtype, "output", description, unit if vtype == "Real" else "")


def array(
    kind: Callable[..., Variable],
    name: str,
    starts: Sequence[Value] | int,
    unit: str,
    describe: Callable[[int], str],
) -> list[Variable]:
    """Variables ``name[1] … name[n]`` made by ``kind`` (:func:`par`, :func:`inp`, :func:`out`).

    Parameters
    ----------
    kind : callable
        :func:`par`, :func:`inp` or :func:`out`.
    name : str
        The array's name.
    starts : Sequence or int
        Start values, one per element (parameters and inputs, in ``unit``), shape
        ``(n,)``; or n (outputs, a count).
    unit : str
        The elements' unit.
    describe : callable
        Description of element i (1-based).

    Returns
    -------
    list of Variable
        The n variables, in order.
    """
    if isinstance(starts, int):
        return [kind(f"{name}[{i}]", unit, describe(i)) for i in range(1, starts + 1)]
    return [kind(f"{name}[{i}]", x, unit, describe(i)) for i, x in enumerate(starts, start=1)]


def indexed(name: str, n: int) -> list[str]:
    """FMI structured names ``name[1] … name[n]`` (1-based, as in the paper)."""
    return [f"{name}[{i}]" for i in range(1, n + 1)]


def type_of(value: Value) -> VarType:
    """The FMI type of a Python value: str → String, bool → Boolean, int → Integer, else Real."""
    if isinstance(value, str):
        return "String"
    if isinstance(value, bool):
        return "Boolean"
    if isinstance(value, int):
        return "Integer"
    return "Real"
