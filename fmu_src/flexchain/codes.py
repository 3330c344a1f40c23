"""The integer codes of the FMUs' choice parameters, as enums: one home for each code.

The observer's ``mode`` and ``estimator`` and the excitation source's ``signal`` are
Integer parameters of the FMUs; the members below are those integers (``IntEnum``: a
member equals its value, so ``settings.mode == Mode.STATE_ESTIMATION`` holds for a
plain ``2`` read from an FMU variable). Where a code is written out (a start value, a
message, JSON), write ``int(member)``: ``str()`` of a member differs between Python
versions (``"Mode.STATE_ESTIMATION"`` before 3.11, ``"2"`` from 3.11 on).

The ``*_NAMES`` tables say what each code means, in the words of the FMUs' messages,
and :func:`choice_problem` is the one sentence for a code outside its table.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping


class Mode(enum.IntEnum):
    """What the observer runs besides the DOB (its parameter ``mode``).

    Examples
    --------
    >>> Mode(2) is Mode.STATE_ESTIMATION, int(Mode.STATE_ESTIMATION)
    (True, 2)
    """

    SELF_IDENTIFICATION = 0  #: actuator self-identification, load detached (eq. 13–15)
    RIGID_IDENTIFICATION = 1  #: chain identification from a rigid maneuver (eq. 17–21)
    STATE_ESTIMATION = 2  #: load angles and velocities (eq. 22–26, or the model-based one)


class Estimator(enum.IntEnum):
    """The state estimator of mode 2 (the observer's parameter ``estimator``).

    Examples
    --------
    >>> Estimator(1).name, int(Estimator.RECURSION)
    ('MODEL_BASED', 0)
    """

    RECURSION = 0  #: the paper's recursion along the chain (eq. 22–26)
    MODEL_BASED = 1  #: the chain model driven by θ_m, Kalman-corrected by τ̂_reac


class Signal(enum.IntEnum):
    """The excitation source's current command (its parameter ``signal``)."""

    RIGID = 0  #: the drift-free rigid maneuver of mode 1
    MULTISINE = 1  #: a sum of log-spaced sines
    CHIRP = 2  #: a linear chirp
    RANDOM = 3  #: Gaussian noise through a 4th-order Butterworth low-pass


MODE_NAMES = {
    Mode.SELF_IDENTIFICATION: "actuator self-identification",
    Mode.RIGID_IDENTIFICATION: "rigid-maneuver chain identification",
    Mode.STATE_ESTIMATION: "state estimation",
}
ESTIMATOR_NAMES = {
    Estimator.RECURSION: "the paper's recursion",
    Estimator.MODEL_BASED: "model-based observer",
}
SIGNAL_NAMES = {
    Signal.RIGID: "rigid maneuver",
    Signal.MULTISINE: "multi-sine",
    Signal.CHIRP: "chirp",
    Signal.RANDOM: "filtered random",
}


def choice_problem(name: str, value: int, allowed: Mapping[int, str]) -> str | None:
    """A sentence if ``value`` is not a code of ``allowed``, else None.

    Parameters
    ----------
    name : str
        The parameter's name, as the FMU declares it.
    value : int
        Its value.
    allowed : Mapping[int, str]
        Code → meaning, e.g. :data:`MODE_NAMES`.

    Returns
    -------
    str or None
        ``"parameter NAME = VALUE is not allowed (use 0 = …, 1 = …)"``, or None.

    Examples
    --------
    >>> choice_problem("gear", 3, {1: "low", 2: "high"})
    'parameter gear = 3 is not allowed (use 1 = low, 2 = high)'
    >>> choice_problem("gear", 2, {1: "low", 2: "high"}) is None
    True
    """
    if value in allowed:
        return None
    options = ", ".join(f"{int(k)} = {v}" for k, v in allowed.items())
    return f"parameter {name} = {value} is not allowed (use {options})"
