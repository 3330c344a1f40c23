"""State estimation by the paper's recursion along the chain (eq. 22–26).

From the torque τ_i entering spring i and the angle θ_{i−1} before it, the spring's
deflection is ``δ_i = τ_i / (B_i s + k_i)`` (pole at −k_i/B_i, stable; the paper's
printed exponents have the wrong sign), so ``θ_i = θ_{i−1} − δ_i``, and the next
spring carries ``τ_{i+1} = τ_i − J_i θ̈_i``. Start: ``τ_1 = τ̂_reac`` and
``θ_0 = G[θ_m]`` (the motor angle through the DOB's own ``G(s)``, so that both
carry the same lag). Each later stage passes its torque and angle through one
more ``G_lpf(s) = g_lpf / (s + g_lpf)``, as the paper filters θ̈.

Expect stage 1 to work and later stages to amplify errors (docs/method.md: J_i ω²/k ≫ 1
above the first mode).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .filters import lowpass_pole

#: Per step size: e^{−g_dist h}, e^{−g_lpf h}, and per stage (i, e^{−k_i h/B_i}, gain, J_i).
Coefficients = tuple[float, float, list[tuple[int, float, float, float]]]


class ChainRecursion:
    """Angles and velocities of the n load masses from τ̂_reac and θ_m.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Per mass / spring inertia (kg·m²), stiffness (N·m/rad, > 0) and damping
        (N·m·s/rad, ≥ 0), shape ``(n,)`` each.
    g_dist : float
        DOB bandwidth (rad/s), for ``G[θ_m]``.
    g_lpf : float
        Bandwidth of the filter on later stages (rad/s).
    theta0 : float
        Motor angle at start (rad); the chain starts at rest, aligned.

    Attributes
    ----------
    theta : list of float
        After :meth:`step`: estimated angles θ̂_1 … θ̂_n (rad), shape ``(n,)``.
    omega : list of float
        Estimated velocities (rad/s), backward differences of ``theta``, shape ``(n,)``.
    """

    def __init__(
        self,
        J: Sequence[float],
        k: Sequence[float],
        B: Sequence[float],
        g_dist: float,
        g_lpf: float,
        theta0: float,
    ) -> None:
        n = len(J)
        self.J, self.k, self.B = list(J), list(k), list(B)
        self.g_dist, self.g_lpf = g_dist, g_lpf
        self.theta_m_filtered = theta0
        self.deflection = [0.0] * n
        self.theta = [theta0] * n
        self.omega = [0.0] * n
        self.torque_next = [0.0] * n  # G_lpf[τ_i − J_i θ̈_i], feeds stage i+1
        self.angle_next = [theta0] * n  # G_lpf[θ̂_i], feeds stage i+1
        self._h = 0.0  # step size the coefficients below were computed for
        self._coefficients: Coefficients = (1.0, 1.0, [])

    def _coefficients_for(self, h: float) -> Coefficients:
        """e^{−g_dist h}, e^{−g_lpf h}, and per stage ``(i, e, (1 − e)/k_i, J_i)`` with
        e = e^{−k_i/B_i h} (0 when B_i = 0)."""
        decay = [math.exp(-k / B * h) if B > 0.0 else 0.0 for k, B in zip(self.k, self.B)]
        stages = [
            (i, e, (1.0 - e) / k, J) for i, (e, k, J) in enumerate(zip(decay, self.k, self.J))
        ]
        self._h = h
        self._coefficients = (lowpass_pole(self.g_dist, h), lowpass_pole(self.g_lpf, h), stages)
        return self._coefficients

    def step(self, h: float, tau_reac_hat: float, theta_m: float) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        tau_reac_hat : float
            The reaction torque observer's estimate τ̂_reac (N·m).
        theta_m : float
            The measured motor angle (rad).
        """
        a0, a, stages = self._coefficients if h == self._h else self._coefficients_for(h)
        self.theta_m_filtered = angle_before = a0 * self.theta_m_filtered + (1.0 - a0) * theta_m
        b = 1.0 - a
        torque = tau_reac_hat
        deflection, thetas, omegas = self.deflection, self.theta, self.omega
        torque_next, angle_next = self.torque_next, self.angle_next
        last = len(stages) - 1
        for i, e, gain, J in stages:
            deflection[i] = d = e * deflection[i] + gain * torque
            theta = angle_before - d
            omega = (theta - thetas[i]) / h
            thetas[i] = theta
            if i < last:  # the next stage's torque: this one's minus J_i θ̈_i, filtered
                torque = a * torque_next[i] + b * (torque - J * ((omega - omegas[i]) / h))
                torque_next[i] = torque
                angle_next[i] = angle_before = a * angle_next[i] + b * theta
            omegas[i] = omega
