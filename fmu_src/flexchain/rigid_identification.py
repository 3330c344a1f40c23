"""Chain identification from a rigid maneuver (eq. 17–21), with docs/method.md's κ.

The rigid motion is the double integral of the reaction torque over ΣJ plus
``c_4 t + c_5`` (eq. 20). Substituting it into eq. 21 makes the fit linear in
(k, B, β_3, β_4); every regressor passes through the DOB's ``G(s)``, as τ̂ did:

    τ̂ ≈ k (G[θ_m] − G[I₂]/ΣJ) + B (G[θ̇_m] − G[I₁]/ΣJ) + β_3 G[t] + β_4 G[1]

with ``I₁ = ∫τ``, ``I₂ = ∫∫τ`` of the observer's unfiltered per-step reaction
torque, ``β_3 = −k c_4`` and ``β_4 = −(k c_5 + B c_4)``. The integrals take the
torque piecewise linear between samples (exact for such a signal).

Sticking. Over a step that starts or ends with the motor at rest (or below one
encoder count per step) the Coulomb friction is unknown within ±f_c, and with it
the reaction torque ``drive − friction``; an error there would stay in the double
integral and grow into drift, and leaving those rows out biases k (the rows near
reversals, where the twist peaks, carry most of the information). So the
identifier holds such steps back and, when the motor moves again, fills their
friction linearly between the mean friction of the step before and of the step
after, then replays them; the drive part (current, inertia, viscous terms) is
used exactly, so the ``J Δω`` terms still telescope in the integral. With
``f_c = 0`` nothing is held. Memory is constant except for that hold-back,
bounded by :data:`MAX_HELD` steps (past it, the friction is held at its last
known value).

The integrals use the per-step mean torque: ``I₁ += h τ̄``,
``I₂ += h I₁ + h² τ̄ / 2`` (exact for a torque constant over each step).

Multi-mass correction. For n > 1 the rigid motion is the centre of mass, not
θ_1; in quasi-static motion ``θ_m − θ_CoM = (τ_reac / k) κ`` with
``κ = Σ_i S_i² / S_1²``, ``S_i = Σ_{j≥i} J_j``, so the literal eq. 21 gives
``k/κ``. :func:`kappa` computes κ; ``k̂ = κ k̂_eq21`` and ``B̂ = κ B̂_eq21``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .dob import sign
from .filters import LowPassBank
from .least_squares import MIN_ROWS, RCOND_MIN, NormalEquations

#: Rows start this many filter time constants (1/g) after the start.
SETTLE = 10.0
#: Most samples of one stuck interval held back for interpolation.
MAX_HELD = 20000


def kappa(J: Sequence[float]) -> float:
    """The multi-mass correction κ = Σ S_i² / S_1², ``S_i = Σ_{j≥i} J_j``.

    Parameters
    ----------
    J : Sequence[float]
        Load inertias ``J_1 … J_n`` (kg·m²), shape ``(n,)``.

    Returns
    -------
    float
        κ ≥ 1 (dimensionless); 1 for one mass.
    """
    tails = [math.fsum(J[i:]) for i in range(len(J))]
    return math.fsum(s * s for s in tails) / (tails[0] * tails[0])


class RigidChainIdentifier:
    """Online least squares for (k, B) from the reaction torque of a rigid maneuver.

    Parameters
    ----------
    J : Sequence[float]
        Load inertias ``J_1 … J_n`` (kg·m²), shape ``(n,)``.
    g : float
        ``g_dist`` (rad/s).
    correct : bool
        Apply κ (True) or give the literal eq. 21 (False).
    theta0 : float
        Motor angle at start (rad).
    f_c : float
        The motor's Coulomb friction (N·m) that the observer removes.

    Attributes
    ----------
    k, B : float
        After :meth:`estimate`: stiffness (N·m/rad) and damping (N·m·s/rad) estimates.
    theta_rigid : float
        Rigid-motion estimate Θ̂ (rad), through G(s), at the last sample processed
        (samples of a stuck interval are processed when it ends).
    valid : bool
        At least :data:`~arcosim.fmu.flexchain.least_squares.MIN_ROWS` rows, a
        well-conditioned fit and k > 0.
    rows : int
        Rows used so far (a count).
    """

    def __init__(
        self, J: Sequence[float], g: float, correct: bool, theta0: float, f_c: float = 0.0
    ) -> None:
        self.total_inertia = math.fsum(J)
        self.kappa = kappa(J) if correct else 1.0
        self.g = g
        self.f_c = f_c
        self.t = 0.0
        self.i1 = self.i2 = 0.0
        self.sign_last = 0.0  # mean friction sign of the last step processed
        self.theta_last = theta0  # motor angle at the last step processed
        self.h_last = 0.0  # its length (s)
        self.held: list[tuple[float, float, float, float]] = []  # (h, drive, ω, θ)
        self.filtered = LowPassBank(g, 7)  # G[θ_m], G[θ̇_m], G[I₁], G[I₂], G[t], G[1], G[τ]
        self.filtered.y[0] = theta0
        self.equations = NormalEquations(4)
        self.rows = 0
        self.k = self.B = self.theta_rigid = 0.0
        self.valid = False

    def step(
        self,
        h: float,
        drive: float,
        friction_sign: float,
        omega: float,
        theta: float,
        sticking: bool,
    ) -> None:
        """Add the sample that ends a step.

        Parameters
        ----------
        h : float
            Step (s).
        drive : float
            Torque on the motor other than Coulomb friction over the step (N·m).
        friction_sign : float
            Mean sign of the velocity over the step, −1 … 1 (dimensionless).
        omega, theta : float
            Measured motor velocity (rad/s) and angle (rad).
        sticking : bool
            The motor was at rest at one end of the step (friction unknown).
        """
        if sticking and self.f_c > 0.0:
            if len(self.held) >= MAX_HELD:
                self._replay(self.sign_last)
            self.held.append((h, drive, omega, theta))
            return
        if self.held:
            self._replay(friction_sign, h)
        self._process(h, drive - self.f_c * friction_sign, omega, theta)
        self.sign_last, self.h_last = friction_sign, h

    def _replay(self, sign_after: float, h_after: float = 0.0) -> None:
        """Process the held steps with their friction filled in.

        A held step whose angle changed moved in that direction (kinetic friction
        of that sign). The others take the sign of their nearest moving
        neighbours when both agree (slow motion between encoder counts), and the
        linear interpolation between them, by step mid-point, across a reversal.
        """
        held = self.held
        mids, elapsed = [], 0.0
        for h, *_ in held:
            mids.append(elapsed + 0.5 * h)
            elapsed += h
        known = [
            sign(th - prev) if th != prev else None
            for (_, _, _, th), prev in zip(held, [self.theta_last] + [x[3] for x in held[:-1]])
        ]
        before: list[tuple[float, float]] = []
        last = (-0.5 * self.h_last, self.sign_last)
        for mid, k in zip(mids, known):
            if k is not None:
                last = (mid, k)
            before.append(last)
        after: list[tuple[float, float]] = [(0.0, 0.0)] * len(held)
        nxt = (elapsed + 0.5 * h_after, sign_after)
        for j in range(len(held) - 1, -1, -1):
            if known[j] is not None:
                nxt = (mids[j], known[j])
            after[j] = nxt
        for j, (h, drive, omega, theta) in enumerate(held):
            (p1, s1), (p2, s2) = before[j], after[j]
            if known[j] is not None:
                friction = known[j]
            elif s1 == s2 or p2 <= p1:
                friction = s1
            else:
                friction = s1 + (s2 - s1) * (mids[j] - p1) / (p2 - p1)
            self._process(h, drive - self.f_c * friction, omega, theta)
        self.held = []

    def _process(self, h: float, torque: float, omega: float, theta: float) -> None:
        self.theta_last = theta
        self.t += h
        self.i2 += h * self.i1 + 0.5 * h * h * torque
        self.i1 += h * torque
        f = self.filtered.step(h, [theta, omega, self.i1, self.i2, self.t, 1.0, torque])
        if self.t < SETTLE / self.g:
            return
        m = self.total_inertia
        self.equations.add((f[0] - f[3] / m, f[1] - f[2] / m, f[4], f[5]), f[6])
        self.rows += 1

    def estimate(self) -> None:
        """Solve the accumulated normal equations; update k, B and Θ̂."""
        beta, rcond = self.equations.solve()
        self.valid = rcond >= RCOND_MIN and self.rows >= MIN_ROWS and beta[0] > 0.0
        if not self.valid:
            self.k = self.B = self.theta_rigid = 0.0
            return
        k21, b21, b3, b4 = beta
        c4 = -b3 / k21
        c5 = -(b4 + b21 * c4) / k21
        f = self.filtered.y
        self.k = self.kappa * k21
        self.B = self.kappa * b21
        self.theta_rigid = f[3] / self.total_inertia + c4 * f[4] + c5 * f[5]
