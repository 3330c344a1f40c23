"""Actuator self-identification with the load detached (eq. 13–15).

With τ_reac = 0 the disturbance is ``d = D θ̇ + f_c sgn θ̇ − Δk_t i + ΔJ θ̈``.
Every regressor is low-passed by the same ``G(s)`` as ``d̂`` (docs/method.md) and
paired as the DOB pairs them (mean velocity and velocity change over the step):

    d̂ ≈ β_0 G[i] + β_1 G[v] + β_2 G[α] + β_3 G[sgn v],
    β = (−Δk_t, D, ΔJ, f_c).

Without load, ``J_m θ̈ = k_t i − D θ̇ − f_c sgn θ̇`` makes the four regressors
linearly dependent: scaling (k_t, J_m, D, f_c) by one factor leaves the
current→velocity response unchanged. And since ``d̂ = G[k_to i − J_mo α]`` by
construction, noisy data (which break the exact dependency) let the full fit
collapse to that identity, ``k_t ≈ 0``. The fit is therefore called rank
deficient when the scaled normal matrix has a reciprocal condition number below
:data:`RANK_RCOND` or the full fit's torque constant ``k_to + Δk_t`` lies outside
``[k_to / 2, 2 k_to]``; then ``k_t = k_to`` (Δk_t = 0) is fixed, and the output
says so (``rank_deficient``). Free-motor data can only determine
(J_m, D, f_c) relative to k_t.

The encoder's quantization makes the acceleration regressor noisy, and that
noise sits in the target too (errors in variables: on the bench with a
2000-count encoder, D came out 5 % low and f_c 9 % high). A second low-pass
``F(s) = g_id / (s + g_id)`` on the target and on every regressor alike removes
most of it (same bench, g_id = 30 rad/s: both within 1 %); ``g_id = 0`` turns it off.

Rows are used only while the motor has kept moving (|v| > ``omega_min``) for the
last ``SETTLE / g + SETTLE / g_id`` seconds (:data:`SETTLE` = 5): a stuck motor's
friction is not ``f_c sgn θ̇``.
"""

from __future__ import annotations

from . import defaults
from .filters import LowPassBank
from .least_squares import MIN_ROWS, RCOND_MIN, NormalEquations

#: Rows start once the motor has moved for this many time constants of each filter,
#: 1/g and 1/g_id (a count).
SETTLE = 5.0
#: A four-regressor fit this close to singular is taken as the rank deficiency
#: that the free motor's equation of motion implies.
RANK_RCOND = 1e-6


class ActuatorIdentifier:
    """Online least squares for (Δk_t, D, ΔJ, f_c).

    Parameters
    ----------
    g : float
        ``g_dist`` (rad/s), the DOB's bandwidth.
    omega_min : float
        Speed below which the motor counts as stopped (rad/s).
    k_to : float
        Nominal torque constant (N·m/A).
    g_id : float
        Bandwidth of the extra filter F(s) (rad/s); 0 = none.

    Attributes
    ----------
    dkt, D_m, dJm, f_c : float
        After :meth:`estimate`: the estimates (N·m/A, N·m·s/rad, kg·m², N·m).
    rank_deficient : bool
        The full fit was singular and k_t was fixed to k_to.
    valid : bool
        At least :data:`~arcosim.fmu.flexchain.least_squares.MIN_ROWS` rows and a
        well-conditioned (reduced) fit.
    """

    def __init__(
        self, g: float, omega_min: float, k_to: float, g_id: float = defaults.G_ID
    ) -> None:
        self.g = g
        self.g_id = g_id
        self.k_to = k_to
        self.omega_min = omega_min
        self.filtered = LowPassBank(g, 4)  # G[i], G[v], G[α], G[sgn]
        self.smoothed = LowPassBank(g_id, 5) if g_id > 0.0 else None  # F[G[…]], F[d̂]
        self.settle = SETTLE / g + (SETTLE / g_id if g_id > 0.0 else 0.0)
        self.moving_time = 0.0
        self.equations = NormalEquations(4)
        self.dkt = self.D_m = self.dJm = self.f_c = 0.0
        self.rank_deficient = False
        self.valid = False

    def step(
        self,
        h: float,
        i_a: float,
        velocity: float,
        accel: float,
        friction_sign: float,
        d_hat: float,
    ) -> None:
        """Add the sample that ends a step (DOB pairing, see module doc).

        Parameters
        ----------
        h : float
            Step (s).
        i_a : float
            Current over the step (A).
        velocity : float
            Mean velocity over the step (rad/s).
        accel : float
            Velocity change over the step / h (rad/s²).
        friction_sign : float
            Mean of sgn θ̇ over the step, −1 … 1 (dimensionless).
        d_hat : float
            The DOB's estimate after this sample (N·m).
        """
        row = self.filtered.step(h, [i_a, velocity, accel, friction_sign])
        target = d_hat
        if self.smoothed is not None:
            *row, target = self.smoothed.step(h, [*row, d_hat])
        self.moving_time = self.moving_time + h if abs(velocity) > self.omega_min else 0.0
        if self.moving_time >= self.settle:
            self.equations.add(row, target)

    def estimate(self) -> None:
        """Solve the accumulated normal equations (full, or with Δk_t fixed at 0)."""
        beta, rcond = self.equations.solve()
        k_t = self.k_to - beta[0]
        plausible = 0.5 * self.k_to <= k_t <= 2.0 * self.k_to
        self.rank_deficient = rcond < RANK_RCOND or not plausible
        if self.rank_deficient:
            beta, rcond = self.equations.solve(columns=(1, 2, 3))
        self.valid = rcond >= RCOND_MIN and self.equations.count >= MIN_ROWS
        if not self.valid:
            beta = [0.0] * 4
        self.dkt, self.D_m, self.dJm, self.f_c = -beta[0], beta[1], beta[2], beta[3]
