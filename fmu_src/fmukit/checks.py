"""Parameter checks that name the parameter and say what is wrong."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable


def range_problems(
    value: Callable[[str], float],
    *,
    positive: Iterable[str] = (),
    non_negative: Iterable[str] = (),
    finite: Iterable[str] = (),
) -> list[str]:
    """Sentences for every parameter outside its allowed range.

    Args:
        value: looks a parameter's value up by name.
        positive: names that must be finite and > 0.
        non_negative: names that must be finite and ≥ 0.
        finite: names that must be finite numbers.
    """
    problems = []
    for names, test, text in (
        (positive, lambda x: x > 0.0, "must be > 0"),
        (non_negative, lambda x: x >= 0.0, "must be >= 0"),
        (finite, lambda x: True, ""),
    ):
        for name in names:
            x = value(name)
            if not math.isfinite(x):
                problems.append(f"parameter {name} = {x!r} is not a finite number")
            elif not test(x):
                problems.append(f"parameter {name} = {x!r} {text}")
    return problems


def choice_problem(name: str, value: int, allowed: dict[int, str]) -> str | None:
    """A sentence if ``value`` is not one of ``allowed`` (value → meaning), else None."""
    if value in allowed:
        return None
    options = ", ".join(f"{k} = {v}" for k, v in allowed.items())
    return f"parameter {name} = {value} is not allowed (use {options})"
