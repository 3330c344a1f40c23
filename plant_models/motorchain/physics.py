"""Motor and load chain, integrated exactly over each communication step.

State vector ``x`` (length ``2n + 5``)::

    x[0 … n]        θ_0 … θ_n   angles of motor (0) and load masses (rad)
    x[n+1 … 2n+1]   ω_0 … ω_n   velocities (rad/s)
    x[2n+2]         i           actual motor current (A)
    x[2n+3]         ∫ i dt      over the current step (A·s), for the step-average current
    x[2n+4]         ∫ τ_1 dt    over the current step (N·m·s), for the step-average reaction torque

Inputs, constant over a step: ``u = [i_ref, τ_fric, τ_ext,1 … τ_ext,n]`` (A, N·m, N·m).
Between friction events the system is linear, so a step is ``x ← Φ x + Γ u`` with
``[[Φ, Γ], [0, I]] = expm([[A, B], [0, 0]] τ)`` (exact for any τ). Coulomb friction
switches between three linear regimes: moving forward, moving backward (friction
is a constant input ``∓f_c``) and stuck (the motor row is frozen). A step is split
where the motor velocity crosses zero or the drive torque of a stuck motor
exceeds ``f_c``; the switching time comes from the cubic Hermite interpolant of the
event function between the two ends of the sub-step.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ...fmu.flexchain.chain import spring_matrix
from ...fmu.flexchain.linalg import Matrix, Vector, hold, zeros

_MAX_EVENTS_PER_STEP = 16
_CACHE_SIZE = 16


class PlantPhysics:
    """The plant's equations of motion and their exact step.

    ``_cache`` (discretized matrices by step size) is derived data, left out of the
    FMU state and rebuilt on demand.

    Parameters
    ----------
    J_m : float
        Motor inertia (kg·m²), > 0.
    k_t : float
        Torque constant (N·m/A).
    D_m : float
        Motor viscous friction (N·m·s/rad), ≥ 0.
    f_c : float
        Motor Coulomb friction (N·m), ≥ 0; the motor sticks while the drive torque on
        it stays within ±f_c.
    J : Sequence[float]
        Load inertias ``J_1 … J_n`` (kg·m²), each > 0, shape ``(n,)``.
    k : Sequence[float]
        Spring stiffnesses ``k_1 … k_n`` (N·m/rad), each ≥ 0, shape ``(n,)``.
    B : Sequence[float]
        Spring dampings ``B_1 … B_n`` (N·m·s/rad), each ≥ 0, shape ``(n,)``.
    attached : bool
        False decouples spring 1, so the motor runs free.
    current_bandwidth : float
        Current-loop bandwidth (rad/s); 0 = ideal (i = i_ref).
    """

    _transient = ("_cache",)

    def __init__(
        self,
        J_m: float,
        k_t: float,
        D_m: float,
        f_c: float,
        J: Sequence[float],
        k: Sequence[float],
        B: Sequence[float],
        attached: bool = True,
        current_bandwidth: float = 0.0,
    ) -> None:
        n = len(J)
        self.n = n
        self.k_t = k_t
        self.f_c = f_c
        self.k1 = k[0] if attached else 0.0
        self.B1 = B[0] if attached else 0.0
        self.ideal_current = current_bandwidth == 0.0
        self.I = 2 * n + 2
        self.size = 2 * n + 5
        self.a, self.b = _continuous_matrices(
            J_m, k_t, D_m, [J_m, *J], [self.k1, *k[1:]], [self.B1, *B[1:]], current_bandwidth
        )
        self.a_stuck = [row[:] for row in self.a]
        self.b_stuck = [row[:] for row in self.b]
        w0 = n + 1
        self.a_stuck[w0] = [0.0] * self.size
        self.b_stuck[w0] = [0.0] * (n + 2)
        self.x: Vector = [0.0] * self.size
        self.stuck = f_c > 0.0
        self.direction = 0.0
        self._cache: dict[tuple[float, bool], tuple[Matrix, Matrix]] = {}

    # -- public --------------------------------------------------------------------

    def advance(self, h: float, i_ref: float, tau_ext: Sequence[float]) -> None:
        """Integrate the plant from t to t + h with the inputs held constant.

        Parameters
        ----------
        h : float
            Step (s), > 0.
        i_ref : float
            Current command (A).
        tau_ext : Sequence[float]
            External torques on masses 1 … n (N·m), shape ``(n,)``.
        """
        x = self.x
        if self.ideal_current:
            x[self.I] = i_ref
        x[self.I + 1] = 0.0
        x[self.I + 2] = 0.0
        if self.f_c == 0.0:
            self.x = self._propagate(x, [i_ref, 0.0, *tau_ext], h, False)
            return
        t = 0.0
        for _ in range(_MAX_EVENTS_PER_STEP):
            tau = h - t
            if tau <= 1e-12 * h:
                break
            if self.stuck:
                drive = self.drive_torque(x)
                if abs(drive) > self.f_c:
                    self.stuck = False
                    self.direction = math.copysign(1.0, drive)
                    continue
                u = [i_ref, 0.0, *tau_ext]
                end = self._propagate(x, u, tau, True)
                s = self._first_breakaway(x, end, u, tau)
            else:
                u = [i_ref, -self.f_c * self.direction, *tau_ext]
                end = self._propagate(x, u, tau, False)
                s = self._first_reversal(x, end, u, tau)
            if s is None:
                self.x = end
                return
            x = self._propagate(x, u, s, self.stuck)
            t += s
            if self.stuck:
                drive = self.drive_torque(x)
                self.stuck = False
                self.direction = math.copysign(1.0, drive)
            else:
                x[self.n + 1] = 0.0
                drive = self.drive_torque(x)
                if abs(drive) <= self.f_c:
                    self.stuck = True
                else:
                    self.direction = math.copysign(1.0, drive)
        else:  # pathological chatter: finish the step in the current regime
            u = [i_ref, 0.0 if self.stuck else -self.f_c * self.direction, *tau_ext]
            x = self._propagate(x, u, h - t, self.stuck)
        self.x = x

    def drive_torque(self, x: Vector) -> float:
        """Torque on the motor other than friction: ``k_t i − τ_1`` (N·m)."""
        n = self.n
        return self.k_t * x[self.I] - (self.k1 * (x[0] - x[1]) + self.B1 * (x[n + 1] - x[n + 2]))

    def reaction_torque(self) -> float:
        """τ_1 = k_1 (θ_m − θ_1) + B_1 (θ̇_m − θ̇_1) (N·m); 0 when detached."""
        x, n = self.x, self.n
        return self.k1 * (x[0] - x[1]) + self.B1 * (x[n + 1] - x[n + 2])

    def step_average_current(self, h: float) -> float:
        """Current averaged over the step just taken (A)."""
        return self.x[self.I + 1] / h

    def step_average_reaction(self, h: float) -> float:
        """Reaction torque τ_1 averaged over the step just taken (N·m)."""
        return self.x[self.I + 2] / h

    # -- internals -----------------------------------------------------------------

    def _propagate(self, x: Vector, u: Vector, tau: float, stuck: bool) -> Vector:
        phi, gamma = self._discrete(tau, stuck)
        return [
            sum(p * xi for p, xi in zip(prow, x)) + sum(g * ui for g, ui in zip(grow, u))
            for prow, grow in zip(phi, gamma)
        ]

    def _discrete(self, tau: float, stuck: bool) -> tuple[Matrix, Matrix]:
        key = (tau, stuck)
        found = self._cache.get(key)
        if found is None:
            if len(self._cache) >= _CACHE_SIZE:
                self._cache.clear()
            a, b = (self.a_stuck, self.b_stuck) if stuck else (self.a, self.b)
            found = hold(a, b, tau)
            self._cache[key] = found
        return found

    def _derivative(self, x: Vector, u: Vector, stuck: bool) -> Vector:
        a, b = (self.a_stuck, self.b_stuck) if stuck else (self.a, self.b)
        return [
            sum(p * xi for p, xi in zip(arow, x)) + sum(q * ui for q, ui in zip(brow, u))
            for arow, brow in zip(a, b)
        ]

    def _first_reversal(self, x0: Vector, x1: Vector, u: Vector, tau: float) -> float | None:
        w = self.n + 1
        d0 = self._derivative(x0, u, False)[w]
        d1 = self._derivative(x1, u, False)[w]
        sign = self.direction
        return _first_root(lambda s: sign * _hermite(x0[w], d0, x1[w], d1, tau, s) < 0.0, tau)

    def _first_breakaway(self, x0: Vector, x1: Vector, u: Vector, tau: float) -> float | None:
        n = self.n
        f0 = self._derivative(x0, u, True)
        f1 = self._derivative(x1, u, True)

        def drive_rate(x: Vector, f: Vector) -> float:
            return self.k_t * f[self.I] - (
                self.k1 * (x[n + 1] - x[n + 2]) + self.B1 * (f[n + 1] - f[n + 2])
            )

        g0, g1 = self.drive_torque(x0), self.drive_torque(x1)
        r0, r1 = drive_rate(x0, f0), drive_rate(x1, f1)
        f_c = self.f_c
        return _first_root(lambda s: abs(_hermite(g0, r0, g1, r1, tau, s)) > f_c, tau)


def _continuous_matrices(
    J_m: float,
    k_t: float,
    D_m: float,
    inertias: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    current_bandwidth: float,
) -> tuple[Matrix, Matrix]:
    """A (size × size) and B (size × (n+2)) of the augmented linear system."""
    bodies = len(inertias)
    n = bodies - 1
    size = 2 * n + 5
    stiffness = spring_matrix(k)
    damping = spring_matrix(B)
    damping[0][0] += D_m
    a = zeros(size, size)
    b = zeros(size, n + 2)
    cur, q_i, q_tau = 2 * n + 2, 2 * n + 3, 2 * n + 4
    for j in range(bodies):
        a[j][n + 1 + j] = 1.0
        row = a[n + 1 + j]
        for col in range(bodies):
            row[col] = -stiffness[j][col] / inertias[j]
            row[n + 1 + col] = -damping[j][col] / inertias[j]
        if j == 0:
            row[cur] = k_t / J_m
            b[n + 1][1] = 1.0 / J_m
        else:
            b[n + 1 + j][1 + j] = 1.0 / inertias[j]
    a[cur][cur] = -current_bandwidth
    b[cur][0] = current_bandwidth
    a[q_i][cur] = 1.0
    a[q_tau][0], a[q_tau][1] = k[0], -k[0]
    a[q_tau][n + 1], a[q_tau][n + 2] = B[0], -B[0]
    return a, b


def _hermite(y0: float, d0: float, y1: float, d1: float, tau: float, s: float) -> float:
    """Cubic Hermite interpolant at ``s`` ∈ [0, τ] from end values and slopes."""
    r = s / tau
    h00 = (1 + 2 * r) * (1 - r) ** 2
    h10 = r * (1 - r) ** 2
    h01 = r * r * (3 - 2 * r)
    h11 = r * r * (r - 1)
    return h00 * y0 + h10 * tau * d0 + h01 * y1 + h11 * tau * d1


def _first_root(event, tau: float, samples: int = 32) -> float | None:
    """Smallest s ∈ (0, τ] where ``event(s)`` becomes true, or None (bisection on a grid)."""
    lo = 0.0
    for j in range(1, samples + 1):
        hi = tau * j / samples
        if event(hi):
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if event(mid):
                    hi = mid
                else:
                    lo = mid
                if hi - lo <= 1e-15 * tau:
                    break
            return hi
        lo = hi
    return None
