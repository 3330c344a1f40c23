"""The values of a TOML file checked one by one, each refusal one line that names the
file (``where``), the key and what it takes; and values shown as the file writes them.

Every check takes ``where`` (``"spec.toml:"``, or ``"spec.toml: plant.k[1]:"`` inside a
table), the key and the value, and returns the value (typed) or raises
:class:`~arcosim.errors.UserError`.
"""

from __future__ import annotations

import math

from arcosim.errors import UserError


def text_value(where: str, key: str, value: object) -> str:
    """A TOML string."""
    if not isinstance(value, str):
        raise UserError(f'{where} {key} = {shown(value)}: write a text in quotes ({key} = "…")')
    return value


def table_value(where: str, key: str, value: object) -> dict:
    """A TOML table."""
    if not isinstance(value, dict):
        raise UserError(f"{where} {key}: write a table ([{key}], then NAME = VALUE lines)")
    return value


def integer_value(where: str, key: str, value: object, low: int, high: int) -> int:
    """A TOML integer from ``low`` to ``high`` (a float, Boolean or text is refused)."""
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise UserError(f"{where} {key} = {shown(value)}: a whole number from {low} to {high}")
    return value


def real_value(
    where: str, key: str, value: object, low: float, high: float, low_open: bool = False
) -> float:
    """A finite TOML number in its range (an integer counts as a number)."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if ok:
        x = float(value)
        ok = math.isfinite(x) and (x > low if low_open else x >= low) and x <= high
    if not ok:
        bound = ">" if low_open else ">="
        raise UserError(
            f"{where} {key} = {shown(value)}: a finite number {bound} {low:g} and <= {high:g}"
        )
    return float(value)


def check_scalar(where: str, key: str, value: object) -> None:
    """A parameter value: a finite number, a Boolean or a text."""
    if isinstance(value, float) and not math.isfinite(value):
        raise UserError(f"{where} {key} = {shown(value)}: a finite number")
    if not isinstance(value, (int, float, str, bool)):
        raise UserError(f"{where} {key} = {shown(value)}: a number, true/false or a text")


def shown(value: object) -> str:
    """A value as a spec writes it, cut to a readable length, control characters escaped."""
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = repr(value)
    else:
        text = str(value)
    text = text.encode("unicode_escape").decode("ascii") if not text.isprintable() else text
    return text if len(text) <= 60 else text[:57] + "..."


def shown_key(key: str) -> str:
    """A TOML key for a message: control characters escaped, at most 60 characters."""
    return shown(key)[1:-1] if shown(key).startswith(("'", '"')) else shown(key)


def one_line(text: str) -> str:
    """``text`` with every run of white space, line breaks included, as one space."""
    return " ".join(text.split())
