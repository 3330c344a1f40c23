"""The action-reaction observer: DOB and reaction torque observer, plus one of
three modes, advanced one sample at a time.

* mode 0 — actuator self-identification, load detached
  (:mod:`~arcosim.fmu.flexchain.self_identification`)
* mode 1 — chain identification from a rigid maneuver
  (:mod:`~arcosim.fmu.flexchain.rigid_identification`)
* mode 2 — state estimation: the paper's recursion (:mod:`~arcosim.fmu.flexchain.recursion`)
  or the model-based observer (:mod:`~arcosim.fmu.flexchain.model_observer`)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .dob import Actuator, ReactionObserver
from .load_observer import LOAD_TORQUE_BANDWIDTH, LoadTorqueObserver
from .model_observer import ModelObserver, NoiseModel
from .recursion import ChainRecursion
from .rigid_identification import RigidChainIdentifier
from .self_identification import ActuatorIdentifier

SELF_IDENTIFICATION, RIGID_IDENTIFICATION, STATE_ESTIMATION = 0, 1, 2
RECURSION, MODEL_BASED = 0, 1


@dataclass(frozen=True)
class ObserverSettings:
    """Everything the observer is configured with: its FMU parameters as one value.

    Parameters
    ----------
    mode : int
        0, 1 or 2, an index (see the module doc); 2 estimates the states.
    actuator : Actuator
        Nominal and identified actuator terms (J_mo, k_to, Δk_t, ΔJ, D_m, f_c).
    g_dist : float
        DOB bandwidth (rad/s).
    g_lpf : float
        Bandwidth of the recursion's extra filter (rad/s).
    J, k, B : tuple of float
        Load inertias (kg·m²), spring stiffnesses (N·m/rad) and dampings (N·m·s/rad),
        mass 1 (next to the motor) first, shape ``(n,)`` each.
    kappa_correction : bool
        Mode 1: apply the multi-mass correction κ.
    estimator : int
        Mode 2, an index: 0 = the paper's recursion (eq. 22–26); 1 = the model-based
        observer (use it: the recursion diverges from the second mass on).
    omega_min : float
        Speed below which mode 0 treats the motor as stopped (rad/s).
    g_id : float
        Bandwidth of mode 0's extra filter on target and regressors (rad/s); 0 = none.
    encoder_cpr : int
        Counts per revolution of the motor encoder (a count; 0: not quantized). Mode 2
        takes the motor angle at the middle of its count (an encoder that reports
        whole counts reads half a count low on average), and the model-based observer
        takes its quantization noise, 2π/cpr/√12 rad, into its gain.
    torque_noise_std : float
        Model-based observer: unmodelled torque on each mass (N·m).
    tau_noise_std : float
        Model-based observer: noise on τ̂_reac (N·m).
    load_mass : int
        Model-based observer: 0, or the index (1 … n) of the load mass whose external
        torque is estimated too (:mod:`arcosim.fmu.flexchain.load_observer`).
    load_torque_bandwidth : float
        Bandwidth of that estimate (rad/s), > 0.

    Examples
    --------
    >>> actuator = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406)
    >>> settings = arcosim.ObserverSettings(mode=2, actuator=actuator, g_dist=100.0, g_lpf=100.0,
    ...                                     J=(1e-3,), k=(0.5,), B=(1e-4,), estimator=1)
    >>> settings.estimator, settings.load_mass
    (1, 0)
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
    encoder_cpr: int = 0
    torque_noise_std: float = 1e-4
    tau_noise_std: float = 1.5e-3
    load_mass: int = 0
    load_torque_bandwidth: float = LOAD_TORQUE_BANDWIDTH

    def angle_offset(self) -> float:
        """Half a count of the encoder (rad), 0 when the angle is not quantized."""
        return math.pi / self.encoder_cpr if self.encoder_cpr > 0 else 0.0

    def noise(self) -> NoiseModel:
        """The model-based observer's noise model."""
        quantum = 2.0 * math.pi / self.encoder_cpr if self.encoder_cpr > 0 else 0.0
        return NoiseModel(quantum / math.sqrt(12.0), self.torque_noise_std, self.tau_noise_std)


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
        if s.load_mass and not (s.mode == STATE_ESTIMATION and s.estimator == MODEL_BASED):
            raise ValueError(
                f"load_mass = {s.load_mass} needs mode 2 and estimator 1 (the model-based "
                "observer); use load_mass = 0 otherwise"
            )
        self.dob = ReactionObserver(s.actuator, s.g_dist, theta0, omega0)
        self.identifier: ActuatorIdentifier | RigidChainIdentifier | None = None
        self.estimator: ChainRecursion | ModelObserver | LoadTorqueObserver | None = None
        self.offset = s.angle_offset() if s.mode == STATE_ESTIMATION else 0.0
        if s.mode == SELF_IDENTIFICATION:
            self.identifier = ActuatorIdentifier(s.g_dist, s.omega_min, s.actuator.k_to, s.g_id)
        elif s.mode == RIGID_IDENTIFICATION:
            self.identifier = RigidChainIdentifier(
                s.J, s.g_dist, s.kappa_correction, theta0, s.actuator.f_c
            )
        elif s.estimator == MODEL_BASED and s.load_mass > 0:
            self.estimator = LoadTorqueObserver(
                s.J,
                s.k,
                s.B,
                s.g_dist,
                s.noise(),
                theta0 + self.offset,
                s.load_mass,
                s.load_torque_bandwidth,
            )
        elif s.estimator == MODEL_BASED:
            self.estimator = ModelObserver(s.J, s.k, s.B, s.g_dist, s.noise(), theta0 + self.offset)
        else:
            self.estimator = ChainRecursion(s.J, s.k, s.B, s.g_dist, s.g_lpf, theta0 + self.offset)

    def step(self, h: float, i_a: float, omega: float, theta: float) -> None:
        """Take the sample (i_a, ω, θ) that ends a step of ``h`` s (A, rad/s, rad)."""
        dob = self.dob
        dob.step(h, i_a, omega, theta)
        estimator = self.estimator
        if estimator is not None:  # mode 2, the one that runs in control loops: test it first
            estimator.step(h, dob.tau_reac_hat, theta + self.offset)
        elif self.settings.mode == SELF_IDENTIFICATION:
            self.identifier.step(h, i_a, dob.velocity, dob.accel, dob.friction_sign, dob.d_hat)
        else:
            self.identifier.step(h, dob.drive, dob.friction_sign, omega, theta, dob.sticking)

    def estimate(self) -> None:
        """Solve the identification's normal equations (modes 0 and 1)."""
        if self.identifier is not None:
            self.identifier.estimate()
