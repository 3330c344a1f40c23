"""The action-reaction observer: DOB and reaction torque observer, plus one of
three modes, advanced one sample at a time.

* mode 0 — actuator self-identification, load detached (:mod:`flexchain.self_identification`)
* mode 1 — chain identification from a rigid maneuver (:mod:`flexchain.rigid_identification`)
* mode 2 — state estimation (:mod:`flexchain.recursion`)
"""

from __future__ import annotations

from dataclasses import dataclass

from flexchain.dob import Actuator, ReactionObserver
from flexchain.recursion import ChainRecursion
from flexchain.rigid_identification import RigidChainIdentifier
from flexchain.self_identification import ActuatorIdentifier

SELF_IDENTIFICATION, RIGID_IDENTIFICATION, STATE_ESTIMATION = 0, 1, 2
RECURSION, MODEL_BASED = 0, 1


@dataclass(frozen=True)
class ObserverSettings:
    """Everything the observer is configured with (units as the FMU parameters).

    Attributes:
        mode: 0, 1 or 2 (see module doc).
        actuator: nominal and identified actuator terms.
        g_dist: DOB bandwidth (rad/s).
        g_lpf: bandwidth of the recursion's extra filter (rad/s).
        J, k, B: load inertias (kg·m²), spring stiffnesses (N·m/rad), dampings (N·m·s/rad).
        kappa_correction: multi-mass correction κ in mode 1.
        estimator: 0 = recursion (eq. 22–26); 1 = model-based (not yet available).
        omega_min: speed below which mode 0 treats the motor as stopped (rad/s).
        g_id: bandwidth of mode 0's extra filter on target and regressors (rad/s); 0 = none.
    """

    mode: int
    actuator: Actuator
    g_dist: float
    g_lpf: float
    J: tuple[float, ...]
    k: tuple[float, ...]
    B: tuple[float, ...]
    kappa_correction: bool = True
    estimator: int = RECURSION
    omega_min: float = 5.0
    g_id: float = 30.0


class Observer:
    """DOB + reaction torque observer + the configured mode.

    Args:
        settings: configuration.
        theta0, omega0: motor angle (rad) and velocity (rad/s) at start.

    The estimates are attributes of :attr:`dob` and of :attr:`identifier` or
    :attr:`estimator` (whichever the mode runs); identification estimates are
    refreshed by :meth:`estimate`.
    """

    def __init__(self, settings: ObserverSettings, theta0: float, omega0: float) -> None:
        self.settings = settings
        s = settings
        self.dob = ReactionObserver(s.actuator, s.g_dist, theta0, omega0)
        self.identifier: ActuatorIdentifier | RigidChainIdentifier | None = None
        self.estimator: ChainRecursion | None = None
        if s.mode == SELF_IDENTIFICATION:
            self.identifier = ActuatorIdentifier(s.g_dist, s.omega_min, s.actuator.k_to, s.g_id)
        elif s.mode == RIGID_IDENTIFICATION:
            self.identifier = RigidChainIdentifier(
                s.J, s.g_dist, s.kappa_correction, theta0, s.actuator.f_c
            )
        elif s.mode == STATE_ESTIMATION:
            self.estimator = ChainRecursion(s.J, s.k, s.B, s.g_dist, s.g_lpf, theta0)

    def step(self, h: float, i_a: float, omega: float, theta: float) -> None:
        """Take the sample (i_a, ω, θ) that ends a step of ``h`` s (A, rad/s, rad)."""
        dob = self.dob
        dob.step(h, i_a, omega, theta)
        mode = self.settings.mode
        if mode == SELF_IDENTIFICATION:
            self.identifier.step(h, i_a, dob.velocity, dob.accel, dob.friction_sign, dob.d_hat)
        elif mode == RIGID_IDENTIFICATION:
            self.identifier.step(h, dob.drive, dob.friction_sign, omega, theta, dob.sticking)
        else:
            self.estimator.step(h, dob.tau_reac_hat, theta)

    def estimate(self) -> None:
        """Solve the identification's normal equations (modes 0 and 1)."""
        if self.identifier is not None:
            self.identifier.estimate()
