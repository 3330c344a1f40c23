"""Parameter overrides named by FMU and variable: ``plant.k[2]=0.2``, ``observer.g_dist=200``.

Values are typed from the FMU's model description (Real, Integer, Boolean), and an
unknown name is refused with the names that come closest.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Mapping

from arcosim.errors import UserError

Value = float | int | bool | str
#: The range of an FMI 2.0 Integer (32-bit).
INT_MIN, INT_MAX = -(2**31), 2**31 - 1


def parse_assignment(text: str) -> tuple[str, str]:
    """``"NAME=VALUE"`` → ``(NAME, VALUE)``; refuses text without ``=``.

    Parameters
    ----------
    text : str
        One assignment as written after ``--set``, e.g. ``"observer.g_dist=200"``; blanks
        around the name and the value are dropped.

    Returns
    -------
    tuple of (str, str)
        The name and the value, both as text (the value is typed later, from the FMU's
        model description).

    Raises
    ------
    UserError
        When ``text`` has no ``=``, or nothing before or after it.

    Examples
    --------
    >>> parse_assignment("observer.g_dist = 200")
    ('observer.g_dist', '200')
    """
    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise UserError(f"--set {_shown(text)!r}: write NAME=VALUE, e.g. observer.g_dist=200")
    return name.strip(), value.strip()


def typed_value(name: str, text: str, vtype: str) -> Value:
    """Convert ``text`` to the FMI type ``vtype`` of variable ``name``.

    Reals must be finite, Integers fit FMI's 32 bits, Strings are UTF-8 text without
    NUL; anything else is a :class:`UserError` naming the variable and what it takes.
    """
    shown = _shown(text)
    if vtype == "String":
        try:
            text.encode("utf-8")
        except UnicodeEncodeError:
            raise UserError(f"{name}={shown}: {name} takes UTF-8 text") from None
        if "\x00" in text:
            raise UserError(f"{name}={shown}: {name} takes text without a NUL character")
        return text
    try:
        if vtype == "Boolean":
            lowered = text.lower()
            if lowered in ("1", "true", "yes", "on"):
                return True
            if lowered in ("0", "false", "no", "off"):
                return False
            raise ValueError
        if vtype == "Integer":
            value = int(text)
            if not INT_MIN <= value <= INT_MAX:
                raise UserError(
                    f"{name}={shown}: {name} takes a whole number from {INT_MIN} to {INT_MAX}"
                )
            return value
        value = float(text)
    except ValueError:
        kind = {"Boolean": "true or false", "Integer": "a whole number"}.get(vtype, "a number")
        raise UserError(f"{name}={shown}: {name} takes {kind}") from None
    if not math.isfinite(value):
        raise UserError(f"{name}={shown}: {name} must be a finite number")
    return value


def _shown(text: str) -> str:
    """``text`` for a message: control characters escaped, at most 60 characters."""
    if not text.isprintable():
        text = text.encode("unicode_escape", "backslashreplace").decode("ascii")
    return text if len(text) <= 60 else text[:57] + "..."


def check_name(name: str, variables: Mapping[str, object], fmu: str) -> None:
    """Raise :class:`UserError` naming close matches if ``name`` is not a variable of ``fmu``."""
    if name in variables:
        return
    close = difflib.get_close_matches(name, list(variables), n=4, cutoff=0.5)
    hint = f" (did you mean {', '.join(close)}?)" if close else ""
    raise UserError(f"{fmu} has no variable {name!r}{hint}")


def split_overrides(
    assignments: Iterable[str], fmus: Mapping[str, Mapping[str, object]]
) -> dict[str, dict[str, Value]]:
    """Sort ``fmu.name=value`` assignments by FMU, typed and checked.

    Parameters
    ----------
    assignments : iterable of str
        Texts such as ``"plant.k[2]=0.2"`` (the value in the variable's unit).
    fmus : mapping of str to mapping
        For each FMU prefix (``"plant"``, ``"observer"``), its variables by name (fmpy
        ``ScalarVariable`` objects, which carry ``type`` and ``causality``).

    Returns
    -------
    dict of str to dict
        For each prefix, the typed start values by variable name.

    Raises
    ------
    UserError
        An assignment without a known FMU prefix, naming no variable of it or no
        parameter, or with a value of the wrong type.

    Examples
    --------
    Variables stand in for fmpy's ``ScalarVariable`` objects (no FMU needed):

    >>> from types import SimpleNamespace
    >>> gain = SimpleNamespace(type="Real", causality="parameter")
    >>> split_overrides(["observer.g_dist=200"], {"plant": {}, "observer": {"g_dist": gain}})
    {'plant': {}, 'observer': {'g_dist': 200.0}}
    """
    result: dict[str, dict[str, Value]] = {prefix: {} for prefix in fmus}
    for text in assignments:
        qualified, value = parse_assignment(text)
        prefix, dot, name = qualified.partition(".")
        if not dot or prefix not in fmus:
            raise UserError(
                f"--set {text!r}: name the FMU first: {', '.join(p + '.NAME' for p in fmus)}"
            )
        variables = fmus[prefix]
        check_name(name, variables, prefix)
        var = variables[name]
        if var.causality != "parameter":
            raise UserError(
                f"--set {text!r}: {prefix}.{name} is an {var.causality}, not a parameter"
            )
        result[prefix][name] = typed_value(qualified, value, var.type)
    return result
