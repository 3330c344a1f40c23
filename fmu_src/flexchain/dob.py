"""Disturbance observer (eq. 8–9) and reaction torque observer (eq. 16).

Sign convention of docs/method.md. The nominal motor model is
``J_mo θ̈_m = k_to i_a − d``; the discrete form pairs the velocity change over a
step with the current that acted over that same step (docs/method.md: low-passing
``k_to i + g J_mo θ̇`` and subtracting ``g J_mo θ̇`` leaves ~10 % error):

    α_k = (ω_k − ω_{k−1}) / h                      (rad/s²)
    v_k = (θ_k − θ_{k−1}) / h                      (rad/s, mean velocity over the step)
    d̂  = G[k_to i_k − J_mo α_k]
    τ̂_reac = G[(k_to + Δk_t) i_k − (J_mo + ΔJ) α_k − D v_k − f_c sgn(v_k)]

so ``τ̂_reac = d̂ − G[D θ̇ + f_c sgn θ̇ − Δk_t i + ΔJ θ̈]`` (eq. 16).

Coulomb friction over a step uses the mean sign of the velocity, taken linear
between the two samples (:func:`mean_sign`), so a reversal inside a step counts
for the fraction of the step on each side. Over a step that starts or ends with
the motor standing still (``ω_{k−1} = 0`` or ``ω_k = 0``) static friction hides
the reaction torque: it is only known to lie within ``±f_c`` of the drive torque, and the
observer keeps the value in that interval closest to its previous estimate
(a motor stuck at rest with the chain at rest gives exactly 0, not ``k_t i``); with a
chain model at hand, :func:`settle_sticking` takes that model's prediction instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .filters import lowpass_pole

if TYPE_CHECKING:  # the chain's estimator, which only settle_sticking takes
    from .load_observer import LoadTorqueObserver


@dataclass(frozen=True)
class Actuator:
    """The motor's terms: nominal values and the identified corrections.

    The disturbance observer uses the nominal model ``J_mo θ̈_m = k_to i_a − d``; the
    reaction torque observer removes the identified terms (eq. 16).

    Parameters
    ----------
    J_mo : float
        Nominal motor inertia (kg·m²), e.g. from the datasheet.
    k_to : float
        Nominal torque constant (N·m/A).
    dkt : float
        k_t − k_to (N·m/A).
    dJm : float
        J_m − J_mo (kg·m²).
    D_m : float
        Motor viscous friction (N·m·s/rad).
    f_c : float
        Motor Coulomb friction (N·m).

    Examples
    --------
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406, D_m=2e-5, f_c=2e-3)
    >>> motor.J_mo + motor.dJm, motor.k_to + motor.dkt
    (2.09e-05, 0.0406)
    """

    J_mo: float
    k_to: float
    dkt: float = 0.0
    dJm: float = 0.0
    D_m: float = 0.0
    f_c: float = 0.0


def sign(x: float) -> float:
    """−1, 0 or +1."""
    return (x > 0.0) - (x < 0.0)


def mean_sign(w0: float, w1: float) -> float:
    """Mean of sgn ω over a step where ω goes linearly from ``w0`` to ``w1`` (rad/s)."""
    if w0 >= 0.0 and w1 >= 0.0:
        return 1.0 if (w0 > 0.0 or w1 > 0.0) else 0.0
    if w0 <= 0.0 and w1 <= 0.0:
        return -1.0
    r = w0 / (w0 - w1)  # fraction of the step before the reversal
    return sign(w0) * (2.0 * r - 1.0)


def clamp(x: float, bound: float) -> float:
    """``x`` limited to ``[−bound, bound]``."""
    return -bound if x < -bound else (bound if x > bound else x)


class ReactionObserver:
    """DOB and reaction torque observer on one filter bank ``G(s) = g/(s+g)``.

    Parameters
    ----------
    actuator : Actuator
        Nominal and identified actuator terms.
    g : float
        Observer bandwidth ``g_dist`` (rad/s).
    theta0 : float
        Motor angle at start (rad).
    omega0 : float
        Motor velocity at start (rad/s).

    Attributes
    ----------
    d_hat : float
        After :meth:`step`: disturbance estimate (N·m).
    tau_reac_hat : float
        Reaction torque estimate (N·m).
    alpha_hat : float
        Low-passed motor acceleration (rad/s²).
    accel : float
        Unfiltered velocity change over the last step / h (rad/s²).
    velocity : float
        Mean velocity over the last step (rad/s).
    friction_sign : float
        Mean of sgn θ̇ over the last step, −1 … 1 (:func:`mean_sign`; dimensionless).
    sticking : bool
        The motor stood still at one end of the last step, so static friction
        (unknown within ±f_c) may have acted during it.
    torque : float
        The unfiltered reaction torque of the last step (N·m).
    drive : float
        The torque on the motor other than Coulomb friction over the last step,
        ``k_t i − J_m α − D v`` (N·m): the reaction torque is
        ``drive − f_c · friction_sign`` when the motor moved throughout.
    """

    def __init__(self, actuator: Actuator, g: float, theta0: float, omega0: float) -> None:
        self.actuator = actuator
        self.g = g
        self.theta = theta0
        self.omega = omega0
        self.d_hat = 0.0
        self.tau_reac_hat = 0.0
        self.alpha_hat = 0.0
        self.accel = 0.0
        self.velocity = omega0
        self.torque = 0.0
        self.drive = 0.0
        self.friction_sign = 0.0
        self.sticking = False
        # constants of the step, looked up once (the step runs at the control rate)
        self._kt = actuator.k_to + actuator.dkt
        self._jm = actuator.J_mo + actuator.dJm
        self._k_to, self._J_mo = actuator.k_to, actuator.J_mo
        self._D, self._f_c = actuator.D_m, actuator.f_c
        self._h = 0.0  # step size the filter coefficient below was computed for
        self._a = 1.0  # e^{−g h}

    def step(self, h: float, i_a: float, omega: float, theta: float, heading: float = 0.0) -> None:
        """Take the sample (i_a, ω, θ) that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        i_a : float
            Current that acted over the step (A).
        omega : float
            Motor velocity at the sample (rad/s).
        theta : float
            Motor angle at the sample (rad).
        heading : float
            The motor's direction over the step when the caller knows it (−1 or +1):
            the motor is then taken as sliding that way throughout, with kinetic
            friction, even where the encoder read no new count (a motor slower than a
            count per step reads ω = 0); 0 (default): from the samples.
        """
        if h != self._h:
            self._h = h
            self._a = lowpass_pole(self.g, h)
        a = self._a
        b = 1.0 - a
        w0 = self.omega
        accel = (omega - w0) / h
        velocity = (theta - self.theta) / h
        self.d_hat = a * self.d_hat + b * (self._k_to * i_a - self._J_mo * accel)
        self.drive = drive = self._kt * i_a - self._jm * accel - self._D * velocity
        if heading != 0.0:  # the caller knows the direction
            friction_sign = heading
        elif w0 > 0.0 and omega > 0.0:  # moving one way throughout: the common case, inline
            friction_sign = 1.0
        elif w0 < 0.0 and omega < 0.0:
            friction_sign = -1.0
        else:
            friction_sign = mean_sign(w0, omega)
        self.friction_sign = friction_sign
        self.sticking = sticking = heading == 0.0 and (omega == 0.0 or w0 == 0.0)
        if sticking:
            torque = drive - clamp(drive - self.torque, self._f_c)
        else:
            torque = drive - self._f_c * friction_sign
        self.torque = torque
        self.tau_reac_hat = a * self.tau_reac_hat + b * torque
        self.alpha_hat = a * self.alpha_hat + b * accel
        self.accel = accel
        self.velocity = velocity
        self.omega = omega
        self.theta = theta


def settle_sticking(
    dob: ReactionObserver, est: LoadTorqueObserver, h: float, theta_m: float
) -> None:
    """Over a step where the motor stood still, take the reaction torque the chain model
    predicts, as far as the friction band allows.

    Static friction hides the reaction torque within ±f_c of the drive torque; the DOB
    alone keeps the value closest to its previous one, which the load torque state
    would then take for a load (a phantom of up to f_c that the controller would hold
    against). The model's prediction, clamped into the band, is the value that does not
    contradict the chain model: the DOB's torque of the step and its output are moved
    there, in place.

    Parameters
    ----------
    dob : ReactionObserver
        The DOB, just stepped over a step with ``sticking`` set.
    est : LoadTorqueObserver
        The chain's estimator, not yet stepped.
    h : float
        The step (s).
    theta_m : float
        The motor angle the estimator takes at the sample (rad).
    """
    a = lowpass_pole(dob.g, h)
    predicted = (est.predict(h, theta_m, est.s)[-1] - a * est.s[-1]) / (1.0 - a)
    f_c = dob.actuator.f_c
    torque = min(max(predicted, dob.drive - f_c), dob.drive + f_c)
    dob.tau_reac_hat += (1.0 - a) * (torque - dob.torque)
    dob.torque = torque
