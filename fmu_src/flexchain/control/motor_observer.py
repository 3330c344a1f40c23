"""The controller's motor observer: the motor's angle, velocity and friction from its
current and encoder, the first spring pulling towards the estimated mass 1.

The controller's state feedback needs the motor's velocity, and the encoder's backward
difference carries a count per step of noise (3 rad/s at 2000 counts and 1 ms); its
friction compensation needs what the friction model f_c · sgn misses. Both come from a
three-state observer with its poles placed (Ackermann), standard library only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from operator import mul

from .. import defaults, linalg
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
    """The motor's angle, velocity and friction from its current and encoder.

    State ``s = [d_m, ω_m, θ_m]`` (N·m, rad/s, rad relative to the start), the motor on
    the first spring, whose far end follows the estimated mass 1:
    ``J_m ω̇ = k_t i − D_m ω − k_1 (θ − θ̂_1) − B_1 (ω − ω̂_1) − d_m``, ``ḋ_m = 0``; the
    inputs ``[i, θ̂_1, ω̂_1]`` held over the step, corrected by the measured angle with
    all three poles of the error at ``e^{−ω_o h}``.

    Parameters
    ----------
    design : ControllerDesign
        The motor's terms and the first spring.
    bandwidth : float
        ω_o (rad/s).
    spring : bool
        True (default): the model above. False: the motor alone (``k_1 = B_1 = 0``), the
        spring's torque taken into d_m, whose pole then sits at ω_o too: what the hold's
        dither needs (:mod:`~arcosim.fmu.flexchain.control.hold_dither`), no load parameter in it.
    """

    _transient = ("_models",)  # derived from the settings; rebuilt after an FMU state restore

    def __init__(self, design: ControllerDesign, bandwidth: float, spring: bool = True) -> None:
        self.design = design
        self.bandwidth = bandwidth
        self.spring = spring
        self.friction_bandwidth = defaults.MOTOR_FRICTION_BANDWIDTH if spring else bandwidth
        self.s = [0.0, 0.0, 0.0]
        self._models: dict[float, tuple[Matrix, Matrix, list[float]]] = {}

    def model(self, h: float) -> tuple[Matrix, Matrix, list[float]]:
        """``F``, ``Γ`` and the gain for a step of ``h`` s (cached)."""
        found = self._models.get(h)
        if found is None:
            d = self.design
            k1, B1 = (d.k[0], d.B[0]) if self.spring else (0.0, 0.0)
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
            found = (F, Gamma, observer_gain(F, (p, p, math.exp(-self.friction_bandwidth * h))))
            self._models[h] = found
        return found

    def step(
        self,
        h: float,
        i_a: float,
        theta: float,
        theta_1: float,
        omega_1: float,
        friction: float = 0.0,
    ) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        i_a : float
            Current that acted over the step (A).
        theta : float
            Measured motor angle at the sample, relative to the start (rad).
        theta_1, omega_1 : float
            Estimated angle (rad, relative to the start) and velocity (rad/s) of mass 1
            at the previous sample.
        friction : float
            The friction the controller's feedforward assumed over the step (N·m): the
            model's known part, so that d_m is what it missed.
        """
        F, Gamma, gain = self.model(h)
        w = (i_a, theta_1, omega_1, friction)
        s = self.s
        pred = [math.fsum(map(mul, row, s)) + math.fsum(map(mul, g, w)) for row, g in zip(F, Gamma)]
        e = theta - pred[2]
        self.s = [p + k * e for p, k in zip(pred, gain)]
