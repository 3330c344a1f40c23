"""The hold's motor observer: the motor's angle and velocity below a count, from its
current and the de-dithered encoder reading.

At rest the hold's dither (:mod:`~arcosim.fmu.flexchain.control.hold_dither`) takes its
known path out of the encoder's reading; what is left has a quantization error that
changes from sample to sample, and this observer of the motor alone averages it into the
motor's angle and velocity: a three-state observer with its poles placed (Ackermann),
the torque on the motor other than the current (the spring's, the friction) taken as a
slow disturbance, standard library only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from operator import mul

from .. import linalg
from ..linalg import Matrix
from .design import ControllerDesign


def observer_gain(F: Matrix, poles: Sequence[float]) -> list[float]:
    """Gain L of ``s ← F s + L (y − c F s)`` (c = [0, 0, 1]) that puts the three poles of
    the estimation error at ``poles`` (Ackermann's formula for the current estimator).

    Parameters
    ----------
    F : Matrix
        Shape ``(3, 3)``.
    poles : Sequence[float]
        The three poles, each in [0, 1) (dimensionless).

    Returns
    -------
    list of float
        L, shape ``(3,)``.
    """
    c = [0.0, 0.0, 1.0]
    rows, power = [], F
    for _ in range(3):
        rows.append(linalg.matvec(linalg.transpose(power), c))  # c Fʲ
        power = linalg.matmul(power, F)
    phi = linalg.identity(3)
    for p in poles:
        phi = linalg.matmul(phi, linalg.add(F, linalg.identity(3), -p))
    column = [row[0] for row in linalg.solve(rows, [[0.0], [0.0], [1.0]])]
    return linalg.matvec(phi, column)


class MotorObserver:
    """The motor's angle and velocity from its current and encoder, the motor alone.

    State ``s = [d_m, ω_m, θ_m]`` (N·m, rad/s, rad relative to the start):
    ``J_m ω̇ = k_t i − D_m ω − d_m``, ``ḋ_m = 0``, d_m every other torque on the motor
    (the first spring's, the friction); the current held over the step, corrected by the
    measured angle with all three poles of the error at ``e^{−ω_o h}``.

    Parameters
    ----------
    design : ControllerDesign
        The motor's terms.
    bandwidth : float
        ω_o (rad/s).
    """

    _transient = ("_models",)  # derived from the settings; rebuilt after an FMU state restore

    def __init__(self, design: ControllerDesign, bandwidth: float) -> None:
        self.design = design
        self.bandwidth = bandwidth
        self.s = [0.0, 0.0, 0.0]
        self._models: dict[float, tuple[Matrix, Matrix, list[float]]] = {}

    def model(self, h: float) -> tuple[Matrix, Matrix, list[float]]:
        """``F``, ``Γ`` and the gain for a step of ``h`` s (cached)."""
        found = self._models.get(h)
        if found is None:
            d = self.design
            k1 = B1 = 0.0  # the motor alone: the spring's torque is in d_m
            Jm = d.J_m
            A = [
                [0.0, 0.0, 0.0],
                [-1.0 / Jm, -(d.D_m + B1) / Jm, -k1 / Jm],
                [0.0, 1.0, 0.0],
            ]
            E = [
                [0.0, 0.0, 0.0, 0.0],
                [d.k_t / Jm, k1 / Jm, B1 / Jm, -1.0 / Jm],
                [0.0, 0.0, 0.0, 0.0],
            ]
            F, Gamma = linalg.hold(A, E, h)
            p = math.exp(-self.bandwidth * h)
            found = (F, Gamma, observer_gain(F, (p, p, p)))
            self._models[h] = found
        return found

    def step(self, h: float, i_a: float, theta: float) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        i_a : float
            Current that acted over the step (A).
        theta : float
            Measured motor angle at the sample, relative to the start (rad).
        """
        F, Gamma, gain = self.model(h)
        w = (i_a, 0.0, 0.0, 0.0)  # the current; the model's other inputs are the spring's
        s = self.s
        pred = [math.fsum(map(mul, row, s)) + math.fsum(map(mul, g, w)) for row, g in zip(F, Gamma)]
        e = theta - pred[2]
        self.s = [p + k * e for p, k in zip(pred, gain)]
