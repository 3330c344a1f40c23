"""Parameter checks that name the parameter and say what is wrong.

The numbers every FMU computes in (SI units): a Real parameter or input of magnitude
above :data:`LARGEST`, or a chain whose fastest mode or decay exceeds
:data:`FASTEST_RATE` is refused, and a step below :data:`SMALLEST_STEP` takes no new
sample, so no output can become infinite or NaN from them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence

#: Largest magnitude of a Real parameter or input (SI units).
LARGEST = 1e15
#: Shortest step (s) that takes a new sample. A shorter one (a host that sums its time
#: ends 10 s of 1 ms steps on one of 1.03e-13 s) is accepted and only advances the time:
#: the Python FMUs hold their state and outputs (their filters divide by the step, and a
#: difference over 1e-13 s has no digit left), the C plant integrates it exactly but keeps
#: its measured outputs. 1e-9 s is the communication point's tolerance (``1e-9 *
#: max(1, |t|)``) and was the refusal limit before, so every step taken before is
#: integrated as before.
SMALLEST_STEP = 1e-9
#: Relative change of the step (s) below which a step is taken as the previous one: a host
#: that keeps its time in integer nanoseconds (libcosim) hands the FMU t_k+1 − t_k, which
#: for 1 ms steps is 1e-3 give or take a few units in the last place, and the models are
#: discretized per step, so a closed loop through the encoder's counts would otherwise
#: follow the host's rounding. The same step on every host, the same results.
STEP_JITTER = 1e-12
#: Fastest mode (rad/s) or decay rate (1/s) of a motor–spring–mass chain the models
#: integrate; a stiffer or more damped chain is refused at initialization.
FASTEST_RATE = 1e6


def range_problems(
    value: Callable[[str], float],
    *,
    positive: Iterable[str] = (),
    non_negative: Iterable[str] = (),
    finite: Iterable[str] = (),
) -> list[str]:
    """Sentences for every parameter outside its allowed range.

    Parameters
    ----------
    value : callable
        Looks a parameter's value up by name.
    positive : Iterable[str]
        Names that must be finite and > 0.
    non_negative : Iterable[str]
        Names that must be finite and ≥ 0.
    finite : Iterable[str]
        Names that must be finite numbers.

    Returns
    -------
    list of str
        One sentence per parameter out of range, in the order given (positive, then
        non-negative, then finite).
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


def number_problem(name: str, x: float) -> str | None:
    """A sentence if a Real parameter is not a finite number within ±:data:`LARGEST`.

    Parameters
    ----------
    name : str
        The parameter's name.
    x : float
        Its value (SI units).

    Returns
    -------
    str or None
        The sentence, or None when ``x`` is fine.
    """
    if not math.isfinite(x):
        return f"parameter {name} = {x!r} is not a finite number"
    if abs(x) > LARGEST:
        return (
            f"parameter {name} = {x!r} is beyond ±{LARGEST:g}, the range the FMU computes "
            "in (SI units)"
        )
    return None


def chain_rate_problems(
    value: Callable[[str], float],
    motor: str | None,
    inertias: Sequence[str],
    springs: Sequence[str],
    dampers: Sequence[str],
) -> list[str]:
    """Sentences for a chain whose fastest mode or decay is beyond :data:`FASTEST_RATE`.

    Body 0 is the motor (inertia ``motor``; None: held still, as in a model driven by
    the motor's angle), bodies 1 … n the load masses; spring i joins body i − 1 and
    body i. Gershgorin's bound on the eigenvalues of M⁻¹K: every mode ω satisfies
    ω² ≤ max_i 2 (k_i + k_{i+1}) / J_i (and every decay rate ≤ the same with the B_i),
    so a chain within the bound is one the models integrate. Called after the ranges
    are checked (every value finite and > 0 or ≥ 0).

    Parameters
    ----------
    value : callable
        Looks a parameter's value up by name.
    motor : str or None
        Name of the motor inertia; None when the motor is held still.
    inertias, springs, dampers : Sequence[str]
        Names of ``J_1 … J_n``, ``k_1 … k_n`` and ``B_1 … B_n``, shape ``(n,)`` each.

    Returns
    -------
    list of str
        One sentence per body whose bound exceeds :data:`FASTEST_RATE`.
    """
    names = ([motor] if motor else []) + list(inertias)
    first = 0 if motor else 1  # the body of names[0]
    problems = []
    for gains, what, unit, square in (
        (springs, "a mode", "rad/s", True),
        (dampers, "a decay", "1/s", False),
    ):
        for j, inertia in enumerate(names):
            body = first + j
            joined = [gains[i] for i in (body - 1, body) if 0 <= i < len(gains)]
            sum_ = sum(value(g) for g in joined)
            bound = 2.0 * sum_ / value(inertia)
            rate = math.sqrt(bound) if square else bound
            if rate > FASTEST_RATE:
                parts = ", ".join(f"{g} = {value(g):g}" for g in joined)
                problems.append(
                    f"parameters {parts} on {inertia} = {value(inertia):g} make {what} of up "
                    f"to {rate:.3g} {unit}; the FMU integrates up to {FASTEST_RATE:g} {unit} "
                    "(soften or lighten the chain, or add inertia)"
                )
    return problems
