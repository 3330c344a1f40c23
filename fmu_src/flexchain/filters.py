"""First-order low-pass filters discretized exactly for the step actually taken.

``G(s) = g / (s + g)`` with its input held over each step (the timing contract of
docs/method.md: a sample carries what acted over the step that ends there):

    y_k = e^{−g h} y_{k−1} + (1 − e^{−g h}) u_k

is exact for any step ``h``, so steps may vary from one sample to the next.
"""

from __future__ import annotations

import math


def lowpass_pole(g: float, h: float) -> float:
    """``e^{−g h}``: the pole of ``G(s) = g / (s + g)`` over a step with the input held.

    The one discretization of G(s) in the project: the DOB, the observers and the
    offline fits all take it from here.

    Parameters
    ----------
    g : float
        Bandwidth (rad/s).
    h : float
        Step (s).

    Returns
    -------
    float
        The pole, in (0, 1] for g ≥ 0 (dimensionless).
    """
    return math.exp(-g * h)


class LowPassBank:
    """Several filters with one corner frequency, advanced together.

    Parameters
    ----------
    g : float
        Corner frequency (rad/s), > 0.
    size : int
        Number of channels (a count).

    Attributes
    ----------
    y : list of float
        Outputs, one per channel, shape ``(size,)``.
    """

    __slots__ = ("g", "y")

    def __init__(self, g: float, size: int) -> None:
        self.g = g
        self.y = [0.0] * size

    def step(self, h: float, u: list[float]) -> list[float]:
        """Advance every channel by one step.

        Parameters
        ----------
        h : float
            Step (s).
        u : list of float
            Inputs held over the step, shape ``(size,)``.

        Returns
        -------
        list of float
            The outputs :attr:`y`, shape ``(size,)``.
        """
        a = lowpass_pole(self.g, h)
        b = 1.0 - a
        self.y = [a * y + b * x for y, x in zip(self.y, u)]
        return self.y
