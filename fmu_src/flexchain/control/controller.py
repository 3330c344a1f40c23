"""Sensorless motion and vibration control of a load mass, one sample at a time.

The controller (:class:`MotionController`) moves the controlled load mass L to the
target ``theta_ref`` and damps the chain, from the motor's current and encoder only:

* **estimates**: the observer's model-based estimator with its load-torque state on mass
  L (:class:`~arcosim.fmu.flexchain.observer.Observer`, mode 2, estimator 1, the same
  code as the observer FMU, its gain designed for ``defaults.CONTROL_TORQUE_NOISE_STD``),
  its chain refitted from each move
  (:class:`~arcosim.fmu.flexchain.control.refined_estimator.RefinedEstimator`), gives every
  load angle and velocity and the torque d̂ on mass L; the motor's angle enters as
  measured (the middle of its count), its velocity,
  where Coulomb friction is cancelled, as the backward difference of the encoder's last
  crossed edge (:class:`~arcosim.fmu.flexchain.control.encoder_edge.CrossedEdge`: 0 for a
  dither across one edge), in the feedback and the DOB alike; the DOB is told the
  motor's heading, the reference's during a move and, as the motor creeps to rest, the
  one its encoder edges show
  (:meth:`~arcosim.fmu.flexchain.control.encoder_edge.CrossedEdge.sliding`);
* **reference shaping**: each change of ``theta_ref`` starts a shaped step of that size
  (:func:`shaped_step`, zero velocity, acceleration and jerk at both ends, lasting
  ``move_time``) whose sum is the target path s(t); a reference model, the design model
  under the same state feedback, follows the rigid inverse of s (the current that
  moves the whole chain along s as one body) and gives the reference state x_r and
  the feedforward current ``i_ff`` — consistent with the model, so with an exact model
  the feedback has nothing to do;
* **feedback**: ``i_fb = −K (x̂ − x_r − x_d(d̂)) − d̂/k_t + f_c sgn(ω̄)/k_t``, the design's
  gain (:mod:`~arcosim.fmu.flexchain.control.design`) on the estimate's deviation from
  the reference, shifted to where the chain rests under d̂ with mass L on target
  (:meth:`~arcosim.fmu.flexchain.control.design.ControllerDesign.load_offset`), the
  current that holds d̂, and the motor's Coulomb friction cancelled (:func:`heading`);
* **the limit**: ``i_ref = clamp(i_ff + i_fb, i_max)``. Anti-windup by construction:
  the only integrator of the loop (the load torque estimate) is
  driven by the *measured* current, the one that acted, so it integrates nothing the
  limit cut off; the reference model keeps its own current within
  ``REFERENCE_SHARE · i_max``.

Timing (the observer's contract): the sample passed to :meth:`MotionController.step`
is the one at t_k (the current that acted over the step ending there, the angle and
velocity at t_k); the returned ``i_ref`` is meant to be held over [t_k, t_k + h].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from operator import mul

from .. import defaults
from ..codes import Estimator, Mode
from ..dob import clamp, settle_sticking, sign
from ..observer import Observer, ObserverSettings
from .design import ControllerDesign, design_controller
from .encoder_edge import CrossedEdge
from .hold_dither import HoldDither
from .hold_edge import hold_edge
from .refined_estimator import RefinedEstimator

__all__ = ["PARTS", "MotionController", "design_controller", "shaped_step"]

#: The controller's parts that ``MotionController(design, without=…)`` switches off, each
#: added to meet the control benchmark's criteria (docs/control.md, "What each part buys"):
#: the hold's dither, the hold near an edge, the hold's estimator gain, the DOB told the
#: heading from the encoder's edges and from the reference, the chain model's torque over
#: a stuck step, the move's refit and the crossed edge's velocity (the plain difference
#: instead). Every part is on by default; switching one off is for measuring what it buys.
PARTS = (
    "hold_dither",
    "hold_edge",
    "hold_gain",
    "edge_heading",
    "sliding_heading",
    "sticking_settle",
    "move_refit",
    "crossed_edge",
)

#: The share of i_max the reference model may use; the rest is the feedback's (dimensionless).
REFERENCE_SHARE = 0.8


def shaped_step(tau: float) -> tuple[float, float, float]:
    """A smooth step from 0 to 1 over τ ∈ [0, 1]: ``35τ⁴ − 84τ⁵ + 70τ⁶ − 20τ⁷``.

    Velocity, acceleration and jerk vanish at both ends.

    Parameters
    ----------
    tau : float
        Time as a fraction of the move (dimensionless); clipped to [0, 1].

    Returns
    -------
    tuple of float
        The value and its first two derivatives with respect to τ.

    Examples
    --------
    >>> shaped_step(0.5)
    (0.5, 2.1875, 0.0)
    """
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0
    t3 = tau**3
    value = t3 * tau * (35.0 + tau * (-84.0 + tau * (70.0 - 20.0 * tau)))
    rate = t3 * (140.0 + tau * (-420.0 + tau * (420.0 - 140.0 * tau)))
    accel = tau * tau * (420.0 + tau * (-1680.0 + tau * (2100.0 - 840.0 * tau)))
    return value, rate, accel


class TargetPath:
    """The target path s(t): the sum of a shaped step per change of the target.

    Parameters
    ----------
    start : float
        The target at t = 0 (rad).
    move_time : float
        Each shaped step's duration (s).
    """

    def __init__(self, start: float, move_time: float) -> None:
        self.move_time = move_time
        self.target = start
        self.base = start  # the sum of the finished steps
        self.moves: list[tuple[float, float]] = []  # (start time, size) of running steps

    def aim(self, t: float, target: float) -> None:
        """Start a shaped step at ``t`` (s) if ``target`` (rad) differs from the last one."""
        if target != self.target:
            self.moves.append((t, target - self.target))
            self.target = target

    def at(self, t: float) -> tuple[float, float]:
        """The path's angle (rad) and velocity (rad/s) at ``t`` (s)."""
        T = self.move_time
        value, rate = self.base, 0.0
        running = []
        for t0, size in self.moves:
            if t - t0 >= T:
                self.base += size
                value += size
                continue
            s, ds, _ = shaped_step((t - t0) / T)
            value += size * s
            rate += size * ds / T
            running.append((t0, size))
        self.moves = running
        return value, rate


class MotionController:
    """Moves the controlled load mass to ``theta_ref`` and damps the chain (module doc).

    Parameters
    ----------
    design : ControllerDesign
        From :func:`~arcosim.fmu.flexchain.control.design.design_controller`.
    without : frozenset of str
        Parts of :data:`PARTS` switched off (default none: the controller as shipped); for
        measuring what each part buys.

    Attributes
    ----------
    theta_hat_ctrl : float
        After :meth:`step`: the estimated angle of the controlled mass (rad).
    i_ff, i_fb : float
        The feedforward and feedback parts of the last command (A), before the limit.
    i_ref : float
        The last command (A), within ±i_max.
    reference : list of float
        The reference state x_r, relative to the start, shape ``(2n + 2,)``.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> controller = arcosim.MotionController(arcosim.design_controller(chain, h=1e-3))
    >>> i_ref = controller.step(1e-3, 1.0, 0.0, 0.0, 0.0)  # a 1 rad move starts, at rest
    >>> round(i_ref, 3), round(controller.i_ff, 6)  # A: the friction cancelled; no feedforward yet
    (0.049, 2e-06)
    """

    _transient = ("_designs",)

    def __init__(self, design: ControllerDesign, without: frozenset[str] = frozenset()) -> None:
        unknown = sorted(set(without) - set(PARTS))
        if unknown:
            raise ValueError(f"unknown controller parts {unknown}; the parts are {PARTS}")
        self.design = design
        # a tuple, not a set: the FMU state (fmukit.state) stores tuples
        self.parts = tuple(part for part in PARTS if part not in without)
        self._designs = {design.h: design}
        self.reset()

    def reset(self, theta_m0: float = 0.0) -> None:
        """Start at rest with the motor and every mass at ``theta_m0`` (rad), target there."""
        d = self.design
        n = d.n
        settings = ObserverSettings.for_chain(
            d.chain,
            k_to=d.k_t,
            mode=Mode.STATE_ESTIMATION,
            g_dist=d.g_dist,
            g_lpf=defaults.G_LPF,
            estimator=Estimator.MODEL_BASED,
            encoder_cpr=d.encoder_cpr,
            load_mass=d.control_mass,
            torque_noise_std=defaults.CONTROL_TORQUE_NOISE_STD,
        )
        self.observer = Observer(settings, theta_m0, 0.0)
        # the observer keeps its DOB and offset; the estimator, refitted from each move,
        # is the controller's (refined_estimator)
        self.estimator = RefinedEstimator(self.observer.estimator, "hold_gain" in self.parts)
        self.observer.estimator = None
        self.offset = settings.angle_offset()
        # the crossed edge's velocity only with an encoder and the friction cancelled:
        # without friction the plain difference's kick at an edge is the motor's only
        # damping there and holds it on the edge (docs/control.md)
        use_edge = self.offset > 0.0 and d.f_c > 0.0
        self.crossed = CrossedEdge(theta_m0, self.offset) if use_edge else None
        # the origin of the relative states: where the estimates start (the encoder's
        # angle at the middle of its count), so the reference starts on them
        self.theta0 = theta_m0 + self.offset
        self.t = 0.0
        self.path = TargetPath(self.theta0, d.move_time)
        self.reference = [0.0] * (2 * n + 2)
        self.theta_hat_ctrl = self.theta0
        self.i_ff = self.i_fb = self.i_ref = 0.0
        self.friction = 0.0  # the friction the feedforward assumed over the next step (N·m)
        self.dither: HoldDither | None = None  # while the hold's dither runs
        # the shift of the hold's target that keeps the motor near an edge (hold_edge)
        self.edge = hold_edge(d.encoder_cpr) if "hold_edge" in self.parts else None
        self._needed = self._any_edge = 0.0  # where the hold needs the motor; an edge (rad)
        self._moved = 0.0  # when the target path last moved (s)
        self._first_move = True
        self._refine_after = defaults.REFINE_AT * d.move_time  # after a move's start (s)

    def step(self, h: float, theta_ref: float, i_a: float, omega_m: float, theta_m: float) -> float:
        """Take the sample at t_k and return the current to hold over the next step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        theta_ref : float
            Target of the controlled mass (rad); a change starts a shaped move.
        i_a : float
            Current that acted over the step ending at t_k (A).
        omega_m, theta_m : float
            Measured motor velocity (rad/s) and angle (rad) at t_k. With an encoder
            (``encoder_cpr`` > 0) and Coulomb friction (``f_c`` > 0) the velocity is
            not used: the controller takes the motor's from the encoder's last crossed
            edge.

        Returns
        -------
        float
            ``i_ref`` (A).
        """
        obs = self.observer
        est = self.estimator.filter
        t0 = self.theta0
        dob = obs.dob
        # the velocity of the last crossed edge, not of the count (a dither across one
        # edge is no motion; encoder_edge), the DOB's too, where reset chose it
        motion = theta_m
        if self.crossed is not None:
            edge_velocity = self.crossed.step(h, theta_m)
            if "crossed_edge" in self.parts:
                omega_m = edge_velocity
                motion = self.crossed.edge - self.offset
        heading = self._heading()
        dob.step(h, i_a, omega_m, motion, heading)
        th_m = theta_m + self.offset - t0
        self._any_edge = theta_m - t0  # the encoder's reading is its count's lower edge
        dither = self.dither
        if dither is not None:  # at rest: the motor's angle and velocity below a count,
            # from the reading less the dither's path (hold_dither's doc); the DOB keeps
            # the crossed edge's
            th_m = dither.measure(h, i_a, th_m)
            omega_m = dither.observer.s[1]
        drive = theta_m + obs.offset if dither is None else th_m + t0 - self.offset + obs.offset
        if dob.sticking and "sticking_settle" in self.parts:
            settle_sticking(dob, est, h, drive)
        estimator = self.estimator
        estimator.step(h, dob.tau_reac_hat, drive, heading)
        record = estimator.record
        if (
            record is not None
            and record.elapsed >= self._refine_after - 0.5 * h
            and "move_refit" in self.parts
        ):
            estimator.refine()  # every J_i and k_i from the move so far (move_fit)
        est = estimator.filter
        # the motor's own states as measured: its observer's (model-based) estimates of
        # them cost the loop its stability under a 10 % model error (docs/control.md)
        x = [th_m, *(a - t0 for a in est.theta), omega_m, *est.omega]
        L = self.design.control_mass
        self.theta_hat_ctrl = est.theta[L - 1]
        self._command(h, theta_ref, x, est.tau_load)
        return self._hold(h, x)

    def _hold(self, h: float, x: Sequence[float]) -> float:
        """Start, run or stop the hold's dither for the next step; return ``i_ref`` (A).

        It runs from ``defaults.HOLD_DITHER_AFTER`` move times after the target path
        stops until the next move, where the design has one (``dither_current`` > 0);
        the estimator takes the hold's gain while mass L is still (``RefinedEstimator.settle``).
        """
        design = self._design_for(h)
        if self.path.moves:
            if self._first_move or self.t - self._moved > 1.5 * h:  # a move starts:
                self.estimator.restart()  # it records the move anew
                self._first_move = False
            self._moved = self.t
        rest = self.t - self._moved >= defaults.HOLD_DITHER_AFTER * design.move_time
        if not (rest and design.dither_current > 0.0 and "hold_dither" in self.parts):
            self.dither = None
            self.estimator.set_quiet(False)
            return self.i_ref
        if self.dither is None or self.dither.design.h != h:
            self.dither = HoldDither(design)
            self.dither.start(x[0], x[design.n + 1])
        self.estimator.settle(h, abs(self.theta_hat_ctrl - self.path.target))
        if self.edge is not None and self.estimator.quiet:  # near an edge once mass L is still
            self.edge.step(h, self._needed, self._any_edge)
        elif self.edge is not None:  # the edge and the low-pass start when it is
            self.edge.reset()
        current, friction = self.dither.command(h)
        # the friction cancelled along the dither's velocity, which the motor follows
        self.i_fb += current + (friction - self.friction) / design.k_t
        self.friction = friction
        self.i_ref = clamp(self.i_ff + self.i_fb, design.i_max)
        return self.i_ref

    def _heading(self) -> float:
        """The motor's heading the DOB is told at this sample (−1, 0 or +1): the reference
        model's while it moves (:meth:`_reference_heading`), weighed against the encoder's
        edges until the hold's dither starts (``CrossedEdge.heading``,
        ``defaults.SLIDING_INTERVAL``); 0 leaves it to the DOB's samples."""
        heading = self._reference_heading() if "sliding_heading" in self.parts else 0.0
        if self.dither is None and self.crossed is not None and "edge_heading" in self.parts:
            heading = self.crossed.heading(heading, defaults.SLIDING_INTERVAL)
        return heading

    def _reference_heading(self) -> float:
        """The reference model's motor heading at this sample (−1, 0 or +1): its sign
        while the reference's motor speed exceeds ``defaults.CONTROL_MOVING_SPEED``."""
        v = self.reference[self.design.n + 1]
        return float(sign(v)) if abs(v) > defaults.CONTROL_MOVING_SPEED else 0.0

    def step_full_state(
        self,
        h: float,
        theta_ref: float,
        angles: Sequence[float],
        velocities: Sequence[float],
        i_a: float,
    ) -> float:
        """:meth:`step` with the true state instead of the estimates (the upper bound).

        The same gains, reference and limit; the motor's Coulomb friction is still
        cancelled; no load torque is estimated.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        theta_ref : float
            Target of the controlled mass (rad).
        angles, velocities : Sequence[float]
            Motor, then masses 1 … n: angles (rad) and velocities (rad/s) at t_k, shape
            ``(n + 1,)`` each.
        i_a : float
            Current that acted over the step ending at t_k (A); not used (the loop's
            signature).

        Returns
        -------
        float
            ``i_ref`` (A).
        """
        t0 = self.theta0
        x = [a - t0 for a in angles] + list(velocities)
        self.theta_hat_ctrl = angles[self.design.control_mass]
        return self._command(h, theta_ref, x, 0.0)

    def _design_for(self, h: float) -> ControllerDesign:
        """The design for a step of ``h`` s (the first one's settings; cached)."""
        found = self._designs.get(h)
        if found is None:
            d = self.design
            found = design_controller(
                d.chain,
                k_t=d.k_t,
                g_dist=d.g_dist,
                encoder_cpr=d.encoder_cpr,
                h=h,
                control_mass=d.control_mass,
                move_time=d.move_time,
                i_max=d.i_max,
                hold_dither=d.hold_dither,
            )
            self._designs[h] = found
        return found

    def _command(self, h: float, theta_ref: float, x: list[float], d: float) -> float:
        """The reference's step and the command from the state ``x`` (relative to the
        start) and the load torque estimate ``d`` (N·m)."""
        design = self._design_for(h)
        t0 = self.theta0
        path = self.path
        t = self.t  # the sample's time; the command acts over [t, t + h]
        self.t += h
        path.aim(t, theta_ref)
        s0, v0 = path.at(t)
        s1, v1 = path.at(t + h)
        n1 = design.n + 1
        # the reference model: rigid inverse of s over the next step, under the feedback
        xr = self.reference
        K = design.K
        deviation = [xr[j] - (s0 - t0 if j < n1 else v0) for j in range(2 * n1)]
        rigid = (design.inertia * (v1 - v0) + design.D_m * (s1 - s0)) / (h * design.k_t)
        i_ff = clamp(rigid - _dot(K, deviation), REFERENCE_SHARE * design.i_max)
        offset, i_hold = design.load_offset(d)
        self._needed = xr[0] + offset[0]
        if self.dither is not None and self.edge is not None:  # the hold near an edge
            offset = [c + self.edge.shift if j < n1 else c for j, c in enumerate(offset)]
        error = [a - b - c for a, b, c in zip(x, xr, offset)]
        i_linear = i_ff - _dot(K, error) + i_hold
        self.friction = design.f_c * heading(design, x, i_linear, h)
        i_fb = i_linear - i_ff + self.friction / design.k_t
        self.reference = [_dot(row, xr) + g * i_ff for row, g in zip(design.F, design.g)]
        self.i_ff, self.i_fb = i_ff, i_fb
        self.i_ref = clamp(i_ff + i_fb, design.i_max)
        return self.i_ref


def heading(design: ControllerDesign, x: Sequence[float], i: float, h: float) -> float:
    """The sign of the motor's mean velocity over the next step under the current ``i``
    (A) with the friction cancelled: −1, 0 or +1.

    ``ω_m + (h / 2) (k_t i − τ_1 − D_m ω_m) / J_m`` from the state ``x`` (relative
    angles and velocities, shape ``(2n + 2,)``), τ_1 the first spring's torque.
    """
    n1 = design.n + 1
    w_m = x[n1]
    tau_1 = design.k[0] * (x[0] - x[1]) + design.B[0] * (w_m - x[n1 + 1])
    mean = w_m + 0.5 * h * (design.k_t * i - tau_1 - design.D_m * w_m) / design.J_m
    return float(sign(mean))


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    """``Σ a_i b_i`` (``math.fsum``, correctly rounded)."""
    return math.fsum(map(mul, a, b))
