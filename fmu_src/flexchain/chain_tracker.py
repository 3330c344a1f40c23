"""Tracking the chain in service: a recursive prediction-error estimator of the springs,
the dampers and the motor friction, with their standard deviations and a drift alarm.

The predictor is the model-based observer's (:mod:`~arcosim.fmu.flexchain.model_observer`):
the chain driven by the measured motor angle, its reaction torque through the DOB's
``G(s)``, corrected by a Kalman gain. Here the measured output is the torque on the motor
before friction, ``z = G[k_t i − J_m α]``, and the model adds the motor's friction and a
constant torque to the chain's:

    ŷ_k = y_k(k, B) + f_c · G[sgn θ̇_m] + D_m · G[θ̇_m] + τ_0

(τ_0: a constant load through the chain and any current-sensor offset, estimated and not
reported). The parameters ``p = [k_1…k_n, B_1…B_n, f_c, D_m, τ_0]``, each in units of its
scale (its commissioning value, or a floor where that is zero), follow a recursive
prediction-error method (Ljung & Söderström, 1983): the gradient ``ψ = ∂ŷ/∂p`` comes from
the predictor's sensitivity equations,

    S_j ← (I − K eᵀ) (F S_j + ∂F/∂p_j s + ∂Γ/∂p_j w)        (∂K/∂p neglected)

and a recursive least squares with exponential forgetting updates ``p`` and its
covariance ``P``:

    λ = 1 − h / tracking_time,   L = P ψ̃ / (λ + ψ̃ᵀ P ψ̃),   p ← p + L ẽ,   P ← (P − L ψ̃ᵀ P) / λ

with ψ̃ and ẽ prefiltered (:data:`PREFILTER_RATIO`), and in units of the innovation's
running standard deviation, so ``P`` is the covariance of ``p`` for white innovations. A
sample weighs ``λ^age``: the memory's time constant is ``tracking_time``, in time. A
step that teaches nothing (the motor may stand still) forgets too, ``P ← P / λ``:
a position loop's moves teach on fewer than a third of the steps, and a memory counted in
steps that teach spanned minutes of operation. The prior (the commissioning values,
σ :data:`PRIOR_STD`; τ_0, 0 with σ :data:`OFFSET_PRIOR_STD`) is forgotten and renewed
at the same rate
(stabilized forgetting, Kulhavý 1987): ``p ← p + (1 − λ) P P₀⁻¹ (p₀ − p)`` each step,
so a parameter the operation does not resolve returns to its commissioning value over
``tracking_time`` instead of wandering on the errors of the others, and ``P``'s diagonal
is capped at the prior's. ``P`` starts tighter than the prior for the stiffnesses and the
Coulomb friction (:data:`INITIAL_STD`, the commissioning identification's certainty), so
the first moves cannot carry them out of the region where the predictor leads back.
Dampers and frictions are kept ≥ 0, stiffnesses within
:data:`STIFFNESS_RANGE` of their scale.
``F``, ``Γ`` and their derivatives (central differences of the exact discretization) are
designed at a point ``p_d`` and redesigned when a chain parameter has moved
:data:`REDESIGN_STEP` from it, one discretization a step (a design's 4n + 1 spread over
as many steps); in between the predictor uses the first-order expansion
``F(p) ≈ F(p_d) + Σ ∂F/∂p_j (p_j − p_d,j)``. The Kalman gain stays the commissioning
chain's: the gradient neglects ∂K/∂p, which is then exact (a gain redesigned with the
parameters took the two-mass chain's k_1 to 1.10 of its true value, 1.03 with it held).

Each step costs a fixed number of operations (one discretization, a matrix exponential of
the chain's size, at most), and the state is a fixed set of numbers: constant memory,
bounded cost.

What it reports:

* the standard deviations ``σ_j``, from the sandwich covariance
  ``P (P₀⁻¹ + Ω / (1 − λ²)) P`` of the weighted least squares: Ω the long-run
  covariance of the score ``ψ̃ ẽ`` per step, measured by batch means over blocks of
  :data:`SCORE_BLOCK` of the memory (a Newey–West-like estimate in constant memory),
  ``1 / (1 − λ²)`` the forgetting weights' sum of squares, ``P₀⁻¹`` the prior's share.
  The DOB's filter, the prefilter, the encoder and what the model leaves out colour the
  score for far longer than a step, and ``P`` alone, the covariance for white
  innovations, counts each sample as new. The cubic-cost sandwich is formed once a
  block; between, σ_j² is ``P_jj`` times its ratio to it then;
* ``valid``: the motion is persistently exciting for every stiffness and the Coulomb
  friction: each one's information ``1 / P_jj``, less what is left of the start's
  beyond the prior (:data:`INITIAL_STD`, forgotten as the data), is at least
  ``1 / (EXCITED_SHARE · PRIOR_STD)²``, so what the motion taught about it outweighs
  the prior (:data:`EXCITED_SHARE`). ``P_jj``
  is the marginal variance, what remains after the others, τ_0 among them, are
  accounted for; τ_0's prior is loose (:data:`OFFSET_PRIOR_STD`), so a constant load
  can stand in for any constant torque. At constant speed ``sgn θ̇_m`` and ``θ̇_m``
  are constants like ``τ_0``, so f_c is not taught, and a spring's steady deflection
  is the load's; at rest nothing is;
* ``alarm``: while ``valid``, some stiffness or the Coulomb friction, or a damper or
  the viscous friction resolved to ``3 σ_j`` within ``drift_threshold``, differs from
  its commissioning value by more than ``drift_threshold`` of its scale (the value, or
  the floor where the value is smaller: a drift of a value near zero is taken against
  the floor, as its resolution is) and by more than 3 σ_j. A damper the operation does
  not resolve that finely raises no alarm: a damper
  of a lightly damped chain is seldom resolved in ordinary operation, and with σ capped
  at the prior its estimate would otherwise alarm on any model error. The alarm also waits
  until the memory is full (``tracking_time`` after the start: before, the first
  seconds' estimates, biased while the predictor settles, weigh most) and needs
  ``valid`` (at constant speed with load steps a stiffness can look resolved while the
  friction, and a load torque it stands in for, are not).

Which way the motor slides comes from the encoder's edges
(:meth:`~arcosim.fmu.flexchain.control.encoder_edge.CrossedEdge.sliding`): below a count per step
its backward difference reads 0 on most steps, and a move of 1 rad in 1 s on 2000 counts
at 1 ms is mostly there; the next edge may come up to :data:`EDGE_LATENESS` steps later
than the last interval (the samples' rounding of each edge's time). While the edges
show no slide the motor may stand still, and
static friction (unknown within ±f_c) acts; the G-filtered measurement remembers it for
:data:`SETTLE` / g_dist s. Over such a step the friction input is the one that makes
the step's torque the predictor's, clamped to the band (as
:func:`~arcosim.fmu.flexchain.dob.settle_sticking`), and neither the parameters nor the
states are corrected until the memory has passed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from operator import mul

from . import defaults
from .control.encoder_edge import CrossedEdge
from .filters import lowpass_pole
from .linalg import Matrix
from .model_observer import NoiseModel, filtered_chain, step_model

#: The prior's standard deviation of each parameter in units of its scale
#: (dimensionless): the commissioning chain is known to 10 % (an identification's own σ is
#: well below). A larger prior lets the first samples, whose errors are coloured, move the
#: parameters so far that the predictor leaves the region where its sensitivities hold
#: (measured: at 0.5 the two-mass chain's k went to 1.1–1.2 of a true 1.0 within 2 s of
#: moves; at 0.1 it stayed within 1 %). Also the cap of ``P``'s diagonal: with forgetting
#: and no information (the motor at rest), ``P`` grows as λ^−t; capped there, the
#: estimator never becomes less certain than before it had seen any data.
PRIOR_STD = 0.1
#: The stiffnesses' and the Coulomb friction's standard deviation at the start, in units
#: of their scales (dimensionless): the commissioning identification's, which resolves
#: them to well under 1 % (the whole-chain fit of 40 s of moves: k within 0.2 %, σ 0.1 %),
#: taken at 1 %, inside the region where the prediction error leads back to the truth
#: (on the two-mass chain's 20 s of moves with the 2000-count encoder, the error at fixed
#: stiffnesses rises from the truth to each point ±7 % off in k_1 and k_2, and is no
#: longer monotonic at ±15 %). Started at :data:`PRIOR_STD` instead, the first move's
#: samples, whose quantization error is systematic while the speed sweeps through
#: fractions of a count per step, took k_1 20 % high within a second, out of that region,
#: where it stayed (false alarms on every healthy run's full memory). The information
#: beyond the prior's is forgotten as the data's, so after a few memories the estimate
#: is the data's; ``valid`` counts the data's information only.
INITIAL_STD = 0.01
#: The prior's standard deviation of τ_0, the constant torque through the chain, in units of
#: its scale (the torque noise's σ): a load the drive carries is not part of the
#: commissioning chain, so its prior must teach nothing: 1e3 noise levels, a millionth
#: of one sample's information. A tight prior here (it was :data:`PRIOR_STD`) pinned τ_0,
#: and at constant speed a load's steady deflection then taught the stiffnesses and a
#: constant friction torque taught f_c, the confounding the offset is there to absorb
#: (measured on the conveyor: ``valid`` on 25 % of its samples).
OFFSET_PRIOR_STD = 1e3
#: The chain's parameters are kept within these factors of their scale (a stiffness a
#: quarter or four times the commissioning one is no drift but a different machine;
#: the projection keeps the predictor stable, as the recursive prediction-error method
#: requires, Ljung & Söderström 1983, sec. 6.6).
STIFFNESS_RANGE = (0.25, 4.0)
#: Dampers, friction and viscous friction between 0 and this many scales.
DISSIPATION_MAX = 100.0
#: A damper's scale where its commissioning value is smaller: the damping of a 1 %
#: damping ratio of the spring against its own mass, 2 · 0.01 · √(k_i J_i) (N·m·s/rad).
#: Structural damping ratios lie well below it, so the alarm's relative test is taken
#: against this, not against a value near zero.
DAMPING_RATIO_FLOOR = 0.01
#: The motor speed (rad/s) at which the viscous friction's scale equals the Coulomb
#: friction's: D_m's scale where it is smaller is (f_c's scale) / this.
VISCOUS_SPEED = 10.0
#: The relative move (in units of the scale) of a chain parameter from the design point
#: after which ``F``, ``Γ`` and their derivatives are redesigned: the first-order
#: expansion in between errs by the square of it (1e-4, far below the 3 % sought).
REDESIGN_STEP = 0.01
#: Relative step of the central differences of the discretization (dimensionless): their
#: truncation error is of its square, their rounding of 1e-16 over it.
DIFFERENCE_STEP = 1e-4
#: The prediction error and its gradient pass a first-order low-pass at this share of
#: g_dist before the least squares (the prefilter L(q) of the prediction-error method,
#: Ljung 1999, sec. 14.4): the criterion weighs the band of the chain's modes, which the
#: DOB passes, over the encoder's quantization noise above it, which the DOB's acceleration
#: and the predictor's input speed share (errors in variables: without it the two-mass
#: chain's k_1 crept to 1.04 in 60 s of moves and f_c to 1.06; with it both within 0.5 %).
PREFILTER_RATIO = 0.5
#: How many steps later than the last interval between two edges the next may come while
#: the motor is still taken as sliding: a sample sees an edge up to a step after the motor
#: crosses it, so the intervals the samples read at a steady speed differ by a step; two
#: allow that and as much again for a slide that slows. The edge's own rule (the next
#: edge no later than the last interval) compares two sums of steps, and where they held
#: the same number of steps, a log's steps, a few ulps apart, put the time since on
#: either side of the interval: the motor was taken as stuck at random within a slide,
#: and each stuck step stops the learning for :data:`SETTLE` / g_dist. The tracker
#: followed those last bits (the two-mass healthy run's k_1 ended 0.5 % off with every
#: step exactly 1 ms, 10 % off with the steps of the log's time column).
EDGE_LATENESS = 2.0
#: Steps that differ by less than this (relative) share a design: a log's time column
#: read back gives steps a few ulps apart, and the discrete model differs by as little.
STEP_TOLERANCE = 1e-9
#: Innovations beyond this many running standard deviations are clipped in the update
#: (Huber's robust least squares): a load step or a missed count moves the parameters by
#: at most this much evidence.
CLIP = 4.0
#: Settling of the DOB's filter after a stuck step, in time constants 1/g_dist: e^−5 of
#: the static friction left (the self-identification's rule).
SETTLE = 5.0
#: The viscous friction's regressor is the motor speed over this many steps (the angle's
#: difference across them over their time; a count): the encoder's quantization enters
#: the measured torque through the DOB's acceleration, the difference of two one-step
#: speeds, and a one-step speed as regressor shares that noise (errors in variables:
#: on the two-mass chain D_m went to −10 times its value and f_c 20 % high). Over 20 steps
#: the shared part is a twentieth, and at 1 ms the 10 ms lag is far below a move's time.
SPEED_STEPS = 20
#: ``valid`` when each stiffness's and the Coulomb friction's ``P_jj`` is at most this
#: share of the prior's σ, squared: the motion's information on it (1/P_jj less the
#: prior's 1/PRIOR_STD²) is at least 1/0.5² − 1 = 3 times the prior's, so its estimate
#: is the data's, not the commissioning value's (a test of persistent excitation on the
#: information; the noise's size enters the alarm's 3σ instead). Measured on the
#: two-mass chain in moves: the former test, 3σ within drift_threshold, held on none of
#: the friction row's samples and on 44 % of the k row's (f_c's 3σ near the threshold),
#: so neither drift had its alarm at the end.
EXCITED_SHARE = 0.5
#: The score's long-run covariance is measured on blocks of this share of the memory
#: (batch means): a block, 3 s at the default minute, is long beside the correlation of
#: the prefiltered score (the prefilter's 20 ms, the chain's modes, a 1-s move), and the
#: memory holds 2/this = 40 blocks' worth of weight, so the covariance is known to
#: about √(1/40) ≈ 16 %. The AR(1) inflation of the innovation at lag one it replaces
#: saw the prefilter's colour, not a score correlated over seconds.
SCORE_BLOCK = 0.05


def scales(
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    f_c: float,
    D_m: float,
    torque_floor: float,
) -> list[float]:
    """Each tracked parameter's scale: its commissioning value, or a floor.

    Parameters
    ----------
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape
        ``(n,)`` each.
    f_c, D_m : float
        Commissioning Coulomb friction (N·m) and viscous friction (N·m·s/rad).
    torque_floor : float
        The least torque the scales resolve (N·m): f_c's and τ_0's floor.

    Returns
    -------
    list of float
        Scales of ``[k_1…k_n, B_1…B_n, f_c, D_m, τ_0]`` in their units, shape ``(2n + 3,)``.

    Examples
    --------
    >>> [round(x, 6) for x in scales((5e-4,), (0.16,), (1e-5,), 0.0, 0.0, 1e-3)]
    [0.16, 0.000179, 0.001, 0.0001, 0.001]
    """
    damping = [max(b, 2.0 * DAMPING_RATIO_FLOOR * math.sqrt(kk * j)) for j, kk, b in zip(J, k, B)]
    friction = max(f_c, torque_floor)
    return [*k, *damping, friction, max(D_m, friction / VISCOUS_SPEED), torque_floor]


class ChainTracker:
    """The chain's springs, dampers and the motor friction, tracked from the motor side.

    Parameters
    ----------
    J, k, B : Sequence[float]
        The commissioning chain: load inertias (kg·m², known), stiffnesses (N·m/rad, > 0),
        dampings (N·m·s/rad, ≥ 0), shape ``(n,)`` each.
    f_c, D_m : float
        The commissioning motor Coulomb friction (N·m) and viscous friction (N·m·s/rad).
    g_dist : float
        The DOB's bandwidth (rad/s).
    noise : NoiseModel
        The noise levels of the model-based observer (its Kalman gain, and the floor of
        the torques: ``tau_noise_std``).
    theta0 : float
        The encoder's reading at start (rad); the chain starts at rest, aligned.
    half_count : float
        Half an encoder count (rad; 0 for an exact angle): the predictor takes the angle
        at the middle of the count, as the model-based observer does.
    tracking_time : float
        The memory's time constant (s), > 0.
    drift_threshold : float
        The relative change that counts as drift (dimensionless), > 0.

    Attributes
    ----------
    p : list of float
        The parameters in units of their scales, shape ``(2n + 3,)``.
    P : list of list of float
        Their covariance for white innovations, shape ``(2n + 3, 2n + 3)``.
    theta, omega : list of float
        The predictor's load angles (rad) and velocities (rad/s), shape ``(n,)``: the
        model-based state estimate on the tracked chain.
    valid, alarm : bool
        See the module doc.

    Examples
    --------
    >>> noise = NoiseModel(1e-3, 1e-4, 1.5e-3)
    >>> tr = ChainTracker((5e-4,), (0.16,), (1e-5,), 2e-3, 2e-5, 100.0, noise, 0.0, 0.0,
    ...                   60.0, 0.05)
    >>> tr.step(1e-3, 0.0, 0.0)  # at rest: nothing learnt
    >>> tr.values()[0], tr.valid, tr.alarm
    (0.16, False, False)
    """

    def __init__(
        self,
        J: Sequence[float],
        k: Sequence[float],
        B: Sequence[float],
        f_c: float,
        D_m: float,
        g_dist: float,
        noise: NoiseModel,
        theta0: float,
        half_count: float,
        tracking_time: float,
        drift_threshold: float,
    ) -> None:
        n = len(J)
        self.n = n
        self.J = tuple(J)
        self.g_dist = g_dist
        self.noise = noise
        self.theta0 = theta0 + half_count
        self.edges = CrossedEdge(theta0, half_count)
        self.tracking_time = tracking_time
        self.drift_threshold = drift_threshold
        self.scale = scales(J, k, B, f_c, D_m, noise.tau_noise_std)
        self.p0 = [x / s for x, s in zip([*k, *B, f_c, D_m, 0.0], self.scale)]
        size = 2 * n + 3
        self.p = self.p0[:]
        self.prior = [*([PRIOR_STD**2] * (size - 1)), OFFSET_PRIOR_STD**2]  # P₀'s diagonal
        # the start: the stiffnesses and the Coulomb friction as certain as commissioning
        # identified them (INITIAL_STD), the rest as the prior; the information beyond the
        # prior's is forgotten as the data's (``anchor``, per those parameters)
        self.anchored = [*([True] * n), *([False] * n), True, False, False]
        start = [INITIAL_STD**2 if a else v for a, v in zip(self.anchored, self.prior)]
        self.P = [[start[i] if i == j else 0.0 for j in range(size)] for i in range(size)]
        self.anchor = 1.0 / INITIAL_STD**2 - 1.0 / PRIOR_STD**2
        m = 2 * n + 1
        self.s = [0.0] * m  # chain state [θ, ω] relative to theta0, and its filtered torque
        self.S = [[0.0] * m for _ in range(size)]  # ∂s/∂p_j
        self.u_prev = 0.0  # motor angle at the previous sample, relative to theta0
        self.g_sign = 0.0  # G[sgn θ̇_m]
        self.g_speed = 0.0  # G[θ̇_m] (rad/s)
        self.readings = [theta0] * (SPEED_STEPS + 1)  # the last encoder readings (rad)
        self.times = [0.0] * SPEED_STEPS  # the steps between them (s)
        self.z = 0.0  # G[k_t i − J_m α] (N·m)
        self.variance = noise.tau_noise_std**2  # running mean square of the innovation
        self.block_score = [0.0] * size  # Σ x e_n over the present block (per scale)
        self.block_time = 0.0  # s in the present block …
        self.block_steps = 0  # … and its steps (a count)
        self.score_covariance = [[0.0] * size for _ in range(size)]  # Ω: per step, weighted
        self.score_weight = 0.0  # the blocks' total weight in Ω (dimensionless, ≤ 1)
        self.e_f = 0.0  # the prefiltered innovation (N·m) …
        self.psi_f = [0.0] * size  # … and gradient (N·m per scale)
        self.quiet = 0.0  # s left before a stuck step's friction has left the filter
        self.learnt = 0.0  # s since start, up to tracking_time (then the memory is full)
        self.theta = [self.theta0] * n
        self.omega = [0.0] * n
        self.valid = False
        self.alarm = False
        self.ratio = [1.0] * (2 * n + 2)  # σ_j² / P_jj for [k…, B…, f_c, D_m], per block
        # the design: F, Γ and their derivatives at p_d, the gain, for step h_d
        self.h_d = 0.0
        self.p_d = self.p[: 2 * n]
        self.F: Matrix = []
        self.Gamma: Matrix = []
        self.dF: list[Matrix] = []
        self.dGamma: list[Matrix] = []
        self.K: list[float] = []
        # a design under way (:meth:`redesign`): its point, its next part (−1: none), the
        # parts done, and the upper side of the parameter being differenced
        self.next_p = self.p_d
        self.part = -1
        self.next_F: Matrix = []
        self.next_Gamma: Matrix = []
        self.next_dF: list[Matrix] = []
        self.next_dGamma: list[Matrix] = []
        self.upper: list[Matrix] = []

    def chain(self, p: Sequence[float]) -> tuple[list[float], list[float]]:
        """Stiffnesses (N·m/rad) and dampings (N·m·s/rad) of ``p``, shape ``(n,)`` each."""
        n, sc = self.n, self.scale
        return (
            [p[i] * sc[i] for i in range(n)],
            [p[n + i] * sc[n + i] for i in range(n)],
        )

    def design(self, h: float) -> None:
        """Discretize at the present parameters for step ``h`` (s), all at once: ``F``,
        ``Γ`` and their derivatives by each chain parameter (central differences); for
        a new step, the Kalman gain, at the commissioning chain. Any redesign under way
        (:meth:`redesign`) is dropped."""
        if not self.K or not same_step(h, self.h_d):
            k, B = self.chain(self.p0)
            self.K = step_model(self.J, k, B, self.g_dist, self.noise, h).K
        self.h_d = h
        self.begin()
        while self.part >= 0:
            self.advance()

    def begin(self) -> None:
        """Start a design at the present chain parameters (for the design's step)."""
        n = self.n
        self.next_p = self.p[: 2 * n]
        self.part = 0

    def redesign(self) -> None:
        """One part of a design under way, or the start of one once a chain parameter has
        moved :data:`REDESIGN_STEP` from the design point: a step pays for one
        discretization at most, and the design, 4n + 1 of them, is in use 4n + 1 steps
        after it began (21 ms at 1 ms for n = 5, against the parameters' drift over
        ``tracking_time``); the first-order expansion about the last design serves
        meanwhile."""
        if self.part < 0 and any(abs(a - b) > REDESIGN_STEP for a, b in zip(self.p, self.p_d)):
            self.begin()
        if self.part >= 0:
            self.advance()

    def advance(self) -> None:
        """The design's next discretization: part 0 the design point itself, parts
        2j + 1 and 2j + 2 the chain parameter j stepped up and down (its derivative, by
        central difference, once both are in); after the last part the design replaces
        the one in use."""
        n, h, q, part = self.n, self.h_d, self.next_p[:], self.part
        j, side = divmod(part - 1, 2)
        delta = DIFFERENCE_STEP * max(q[j], 1.0) if part else 0.0
        if part:
            q[j] += delta if side == 0 else -delta
        F, Gamma = filtered_chain(self.J, *self.chain(q), self.g_dist, h)
        if part == 0:
            self.next_F, self.next_Gamma = F, Gamma
            if not self.next_dF:  # the first design: the slots its successors fill in place
                self.next_dF, self.next_dGamma = [F] * (2 * n), [Gamma] * (2 * n)
        elif side == 0:
            self.upper = [F, Gamma]
        else:
            (Fp, Gp), d = self.upper, 2.0 * delta
            self.next_dF[j] = [[(a - b) / d for a, b in zip(ra, rb)] for ra, rb in zip(Fp, F)]
            self.next_dGamma[j] = [
                [(a - b) / d for a, b in zip(ra, rb)] for ra, rb in zip(Gp, Gamma)
            ]
        self.part = part + 1
        if self.part == 4 * n + 1:  # in use; copies of the lists, whose slots the next fills
            self.F, self.Gamma = self.next_F, self.next_Gamma
            self.dF, self.dGamma = self.next_dF[:], self.next_dGamma[:]
            self.p_d, self.part = self.next_p, -1

    def step(
        self,
        h: float,
        torque: float,
        theta_m: float,
    ) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        torque : float
            The torque on the motor before friction over the step, ``k_t i − J_m α``
            (N·m; the DOB's, unfiltered).
        theta_m : float
            The encoder's reading at the sample (rad).
        """
        n = self.n
        self.edges.step(h, theta_m)
        self.readings = readings = [*self.readings[1:], theta_m]
        self.times = times = [*self.times[1:], h]
        span = math.fsum(times)
        speed = (readings[-1] - readings[0]) / span if times[0] > 0.0 else 0.0
        friction_sign = self.edges.sliding(defaults.SLIDING_INTERVAL, EDGE_LATENESS * h)
        sticking = friction_sign == 0.0
        theta_m += self.edges.half_count
        if not same_step(h, self.h_d):
            self.design(h)
        else:
            self.redesign()
        p, sc = self.p, self.scale
        F, Gamma, K = self.F, self.Gamma, self.K
        u = theta_m - self.theta0
        w0, w1 = self.u_prev, (u - self.u_prev) / h
        s = self.s
        # the chain's step at p: F(p_d) s + Γ(p_d) w + Σ_j (∂F_j s + ∂Γ_j w) Δp_j
        chain_terms = [
            [fsum_dot(row, s) + g[0] * w0 + g[1] * w1 for row, g in zip(dF, dG)]
            for dF, dG in zip(self.dF, self.dGamma)
        ]
        pred = [fsum_dot(row, s) + g[0] * w0 + g[1] * w1 for row, g in zip(F, Gamma)]
        for j, col in enumerate(chain_terms):
            dp = p[j] - self.p_d[j]
            if dp:
                pred = [x + dp * c for x, c in zip(pred, col)]
        a = lowpass_pole(self.g_dist, h)
        b = 1.0 - a
        f_c, D_m, tau_0 = (p[i] * sc[i] for i in range(2 * n, 2 * n + 3))
        if sticking:  # static friction: the value that agrees with the predictor, in band
            chain_torque = (pred[-1] - a * s[-1]) / b
            rest = torque - D_m * speed - tau_0 - chain_torque
            friction_sign = max(-1.0, min(1.0, rest / f_c)) if f_c > 0.0 else 0.0
            self.quiet = SETTLE / self.g_dist
        else:
            self.quiet = max(0.0, self.quiet - h)
        self.z = z = a * self.z + b * torque
        self.g_sign = a * self.g_sign + b * friction_sign
        self.g_speed = a * self.g_speed + b * speed
        e = z - (pred[-1] + f_c * self.g_sign + D_m * self.g_speed + tau_0)
        # sensitivities of the prediction; ψ_j = ∂ŷ/∂p_j
        S = [[fsum_dot(row, Sj) for row in F] for Sj in self.S]
        for j, col in enumerate(chain_terms):
            S[j] = [x + c for x, c in zip(S[j], col)]
        psi = [Sj[-1] for Sj in S]
        psi[2 * n] += sc[2 * n] * self.g_sign
        psi[2 * n + 1] += sc[2 * n + 1] * self.g_speed
        psi[2 * n + 2] += sc[2 * n + 2]
        # the criterion's prefilter (both the error and its gradient)
        ap = lowpass_pole(PREFILTER_RATIO * self.g_dist, h)
        bp = 1.0 - ap
        self.e_f = ap * self.e_f + bp * e
        self.psi_f = [ap * x + bp * y for x, y in zip(self.psi_f, psi)]
        correct = self.quiet == 0.0
        # the memory runs in time: a step that teaches nothing (the motor may stand still)
        # still forgets, so that a sample weighs λ^age however much of the age was spent
        # moving
        self.learn(h, self.e_f, self.psi_f if correct else None)
        if correct:
            self.s = [x + kk * e for x, kk in zip(pred, K)]
            self.S = [[x - kk * q for x, kk in zip(Sj, K)] for Sj, q in zip(S, psi)]
        else:
            self.s, self.S = pred, S
        self.u_prev = u
        t0 = self.theta0
        self.theta = [t0 + x for x in self.s[:n]]
        self.omega = self.s[n : 2 * n]
        self.judge()

    def learn(self, h: float, e: float, psi: list[float] | None) -> None:
        """One recursive least-squares step with forgetting on the innovation ``e`` (N·m)
        and its gradient ``psi`` (N·m per scale), shape ``(2n + 3,)``; ``psi`` None: a
        step without a sample (forgetting and the prior's renewal only)."""
        lam = 1.0 - h / self.tracking_time
        self.learnt = min(self.tracking_time, self.learnt + h)
        self.anchor *= lam
        P = self.P
        size = len(P)
        gain, Px, e_n = [0.0] * size, [0.0] * size, 0.0
        if psi is not None:
            sd = math.sqrt(self.variance)
            self.variance = lam * self.variance + (1.0 - lam) * e * e
            e_n = max(-CLIP, min(CLIP, e / sd))
            x = [q / sd for q in psi]
            Px = [fsum_dot(row, x) for row in P]
            denominator = lam + fsum_dot(x, Px)
            gain = [q / denominator for q in Px]
            if any(P[i][i] - g * q <= 0.0 for i, (g, q) in enumerate(zip(gain, Px))):
                # a variance this sample would take to 0 or below is rounding, not
                # information (P spans the loose τ_0 prior to the well-taught
                # stiffnesses): the step forgets only
                gain, Px, e_n = [0.0] * size, [0.0] * size, 0.0
            self.block_score = [g + q * e_n for g, q in zip(self.block_score, x)]
        self.block_steps += 1
        self.block_time += h
        if self.block_time >= SCORE_BLOCK * self.tracking_time:
            self.close_block(lam)
        p = self.p
        # the prior's information, forgotten as the data's, renewed at the same rate
        # (stabilized forgetting): each step pulls p towards p0 by (1 − λ) P P0⁻¹ (p0 − p)
        prior = self.prior
        offset = [(1.0 - lam) * (a - b) / v for a, b, v in zip(self.p0, p, prior)]
        for i in range(size):
            p[i] += gain[i] * e_n + fsum_dot(P[i], offset)
        self.downdate(gain, Px, lam)
        self.project()

    def downdate(self, gain: list[float], Px: list[float], lam: float) -> None:
        """``P ← (P − gain Pxᵀ) / λ``, kept symmetric and its diagonal capped at the
        prior's; ``gain`` and ``Px`` (per scale, shape ``(2n + 3,)``) from :meth:`learn`,
        ``lam`` the step's forgetting factor (dimensionless)."""
        P, prior, size = self.P, self.prior, len(self.P)
        for i in range(size):
            row, gi = P[i], gain[i]
            for j in range(size):
                row[j] = (row[j] - gi * Px[j]) / lam
        for i in range(size):  # symmetric, as in exact arithmetic (rounding parts the halves)
            row = P[i]
            for j in range(i + 1, size):
                row[j] = P[j][i] = 0.5 * (row[j] + P[j][i])
        shrink = [
            min(1.0, math.sqrt(v / P[i][i])) if P[i][i] > v else 1.0 for i, v in enumerate(prior)
        ]
        if any(f < 1.0 for f in shrink):
            for i in range(size):
                row, fi = P[i], shrink[i]
                for j in range(size):
                    row[j] *= fi * shrink[j]
                if fi < 1.0:
                    row[i] = prior[i]  # exactly: at rest P stays the prior

    def project(self) -> None:
        """Keep every parameter in its physical range (:data:`STIFFNESS_RANGE`,
        :data:`DISSIPATION_MAX`)."""
        n, p = self.n, self.p
        low, high = STIFFNESS_RANGE
        for i in range(n):
            p[i] = min(max(p[i], low * self.p0[i]), high * self.p0[i])
        for i in range(n, 2 * n + 2):
            p[i] = min(max(p[i], 0.0), DISSIPATION_MAX)

    def close_block(self, lam: float) -> None:
        """Fold the present block's score into its long-run covariance Ω (batch means,
        weighted as the memory weighs its samples), start a new block, and take the
        ratio of the sandwich to ``P``'s diagonal at ``lam``, the last step's forgetting
        factor (dimensionless)."""
        decay = max(0.0, 1.0 - self.block_time / self.tracking_time)
        g, steps = self.block_score, self.block_steps
        for row, gi in zip(self.score_covariance, g):
            for j, gj in enumerate(g):
                row[j] = decay * row[j] + (1.0 - decay) * gi * gj / steps
        self.score_weight = decay * self.score_weight + (1.0 - decay)
        self.block_score = [0.0] * len(g)
        self.block_time, self.block_steps = 0.0, 0
        P = self.P
        v = self.variances(lam)
        self.ratio = [v[i] / P[i][i] if P[i][i] > 0.0 else 1.0 for i in range(len(self.ratio))]

    def variances(self, lam: float) -> list[float]:
        """The tracked parameters' variances in units of their scales squared, shape
        ``(2n + 3,)``: the sandwich ``P (P₀⁻¹ + Ω / (1 − λ²)) P``, the prior's share and
        the data's, Ω the score's long-run covariance per step (batch means over
        :data:`SCORE_BLOCK`), ``Σ λ^2age = 1 / (1 − λ²)`` the weights' sum of squares
        at the forgetting factor ``lam`` (dimensionless, < 1). White innovations give
        about P / 2 where the data rule; correlated ones, what their correlation costs;
        at rest, the prior."""
        P, size = self.P, len(self.P)
        w = self.score_weight
        data = 1.0 / ((1.0 - lam * lam) * w) if w > 0.0 else 0.0
        M = [
            [data * c + (1.0 / self.prior[i] if i == j else 0.0) for j, c in enumerate(row)]
            for i, row in enumerate(self.score_covariance)
        ]
        out = []
        for i in range(size):
            Pi = P[i]
            out.append(max(0.0, fsum_dot(Pi, [fsum_dot(row, Pi) for row in M])))
        return out

    def sigma2(self) -> list[float]:
        """The variances of ``[k…, B…, f_c, D_m]`` in scales², shape ``(2n + 2,)``:
        ``P_jj`` times the ratio of the sandwich to it at the last block's end
        (:meth:`variances`, whose cost, cubic in the size, is paid once a block)."""
        return [max(self.P[i][i], 0.0) * r for i, r in enumerate(self.ratio)]

    def stds(self) -> list[float]:
        """Standard deviations of the tracked parameters in their units, shape ``(2n + 2,)``
        (``[k…, B…, f_c, D_m]``)."""
        return [math.sqrt(v) * c for v, c in zip(self.sigma2(), self.scale)]

    def values(self) -> list[float]:
        """The tracked parameters in their units, shape ``(2n + 2,)`` (``[k…, B…, f_c, D_m]``)."""
        return [x * s for x, s in zip(self.p[: 2 * self.n + 2], self.scale)]

    def judge(self) -> None:
        """Set :attr:`valid` and :attr:`alarm` (see the module doc)."""
        n = self.n
        threshold = self.drift_threshold
        size = 2 * n + 2
        sigma = [math.sqrt(v) for v in self.sigma2()]
        # persistence of excitation: the motion has taught more than the prior knew
        least = 1.0 / (EXCITED_SHARE * PRIOR_STD) ** 2
        taught = [
            self.P[i][i] > 0.0
            and 1.0 / self.P[i][i] - (self.anchor if self.anchored[i] else 0.0) >= least
            for i in range(size)
        ]
        watched = [*taught[:n], *([False] * n), taught[2 * n], False]
        self.valid = all(taught[:n]) and taught[2 * n]
        filled = self.learnt >= self.tracking_time
        self.alarm = (filled and self.valid) and any(
            (watched[i] or 3.0 * sigma[i] <= threshold)
            and abs(self.p[i] - self.p0[i]) > max(threshold, 3.0 * sigma[i])  # in scales
            for i in range(size)
        )


def same_step(h: float, h_d: float) -> bool:
    """Whether a step ``h`` (s) is the design's ``h_d`` to within :data:`STEP_TOLERANCE`."""
    return abs(h - h_d) <= STEP_TOLERANCE * h_d


def fsum_dot(a: Sequence[float], b: Sequence[float]) -> float:
    """``Σ a_i b_i`` by :func:`math.fsum` (the same sum on every CPython)."""
    return math.fsum(map(mul, a, b))
