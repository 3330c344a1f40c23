"""The action-reaction observer: DOB and reaction torque observer, plus one of
three modes (:class:`~arcosim.fmu.flexchain.codes.Mode`), advanced one sample at a time.

* mode 0 — actuator self-identification, load detached
  (:mod:`~arcosim.fmu.flexchain.self_identification`)
* mode 1 — chain identification from a rigid maneuver
  (:mod:`~arcosim.fmu.flexchain.rigid_identification`)
* mode 2 — state estimation: the paper's recursion (:mod:`~arcosim.fmu.flexchain.recursion`)
  or the model-based observer (:mod:`~arcosim.fmu.flexchain.model_observer`), on a chain
  or on a flexible link's modes (:mod:`~arcosim.fmu.flexchain.link_observer`)

:class:`ObserverSettings` holds the configuration and states its rules
(:meth:`ObserverSettings.problems`), for the FMU, the CLI and the library alike; the
defaults are :mod:`~arcosim.fmu.flexchain.defaults`'.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import defaults
from .chain import Chain
from .chain_tracker import ChainTracker
from .codes import ESTIMATOR_NAMES, MODE_NAMES, Estimator, Mode, choice_problem
from .dob import Actuator, ReactionObserver
from .link_observer import LinkObserver, StarLink
from .load_observer import LoadTorqueObserver
from .model_observer import NOISE_RANGE, NOISE_RATIO, ModelObserver, NoiseModel
from .recursion import ChainRecursion
from .rigid_identification import RigidChainIdentifier
from .self_identification import ActuatorIdentifier


@dataclass(frozen=True)
class ObserverSettings:
    """Everything the observer is configured with: its FMU parameters as one value.

    Parameters
    ----------
    mode : int
        A :class:`~arcosim.fmu.flexchain.codes.Mode` (an index 0, 1 or 2, see the module
        doc); 2 estimates the states.
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
        Mode 2, an :class:`~arcosim.fmu.flexchain.codes.Estimator` (an index): 0 = the
        paper's recursion (eq. 22–26); 1 = the model-based observer (use it: the
        recursion diverges from the second mass on).
    omega_min : float
        Speed below which mode 0 treats the motor as stopped (rad/s).
    g_id : float
        Bandwidth of mode 0's extra filter on target and regressors (rad/s); 0 = none.
    encoder_cpr : int
        Counts per revolution of the motor encoder (a count; 0, the default here: not
        quantized; the FMU's default is the plant's encoder). Mode 2
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
    link : StarLink or None
        Model-based observer: a flexible link's modal model in place of the chain of
        ``J``, ``k``, ``B`` (:mod:`~arcosim.fmu.flexchain.link_observer`); None: the chain.
    tracking : bool
        Model-based observer on a chain: track its springs, dampers and the motor's
        friction while it runs (:mod:`~arcosim.fmu.flexchain.chain_tracker`); the state
        estimates then come from the tracked chain.
    tracking_time : float
        The tracker's memory (s), > 0.
    drift_threshold : float
        The relative change the tracker's alarm counts as drift (dimensionless), > 0.

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
    kappa_correction: bool = defaults.KAPPA_CORRECTION
    estimator: int = defaults.ESTIMATOR
    omega_min: float = defaults.OMEGA_MIN
    g_id: float = defaults.G_ID
    encoder_cpr: int = 0
    torque_noise_std: float = defaults.TORQUE_NOISE_STD
    tau_noise_std: float = defaults.TAU_NOISE_STD
    load_mass: int = defaults.LOAD_MASS
    load_torque_bandwidth: float = defaults.LOAD_TORQUE_BANDWIDTH
    link: StarLink | None = None
    tracking: bool = bool(defaults.TRACKING)
    tracking_time: float = defaults.TRACKING_TIME
    drift_threshold: float = defaults.DRIFT_THRESHOLD

    @classmethod
    def for_chain(
        cls,
        chain: Chain,
        *,
        k_to: float | None = None,
        actuator: Actuator | None = None,
        mode: int = defaults.MODE,
        g_dist: float = defaults.G_DIST,
        g_lpf: float = defaults.G_LPF,
        **settings: object,
    ) -> ObserverSettings:
        """The settings that observe a chain: its J, k, B and its motor.

        Parameters
        ----------
        chain : Chain
            The chain; its ``J_m`` (kg·m²), ``D_m`` (N·m·s/rad) and ``f_c`` (N·m) are
            the actuator's nominal inertia and friction unless ``actuator`` is given
            (an unknown friction is taken as 0).
        k_to : float or None
            The nominal torque constant (N·m/A); needed unless ``actuator`` is given.
        actuator : Actuator or None
            The actuator's terms as they are (J_mo, k_to, Δk_t, ΔJ, D_m, f_c), in place
            of the chain's motor; None: from the chain and ``k_to``.
        mode : int
            A :class:`~arcosim.fmu.flexchain.codes.Mode` (an index).
        g_dist, g_lpf : float
            The DOB's and the recursion filter's bandwidths (rad/s).
        **settings
            Any other field of :class:`ObserverSettings` (``estimator``, ``encoder_cpr``,
            the noise levels, ``load_mass`` …).

        Returns
        -------
        ObserverSettings
            The settings; their :attr:`chain` is ``chain`` without its standard errors.

        Raises
        ------
        ValueError
            Without ``actuator``, when ``k_to`` is not given or the chain's ``J_m`` is
            not known.

        Examples
        --------
        >>> chain = arcosim.Chain(J=(1e-3,), k=(0.5,), B=(1e-4,), J_m=2.09e-5, D_m=0.0, f_c=0.0)
        >>> settings = arcosim.ObserverSettings.for_chain(chain, k_to=0.0406, estimator=1)
        >>> settings.chain == chain, settings.actuator.J_mo  # kg·m²
        (True, 2.09e-05)
        """
        if actuator is None:
            if k_to is None or chain.J_m is None:
                raise ValueError(
                    "give the motor: k_to (N·m/A) and a chain with J_m, or an actuator"
                )
            friction = {name: getattr(chain, name) or 0.0 for name in ("D_m", "f_c")}
            actuator = Actuator(J_mo=chain.J_m, k_to=k_to, **friction)
        return cls(mode, actuator, g_dist, g_lpf, chain.J, chain.k, chain.B, **settings)

    @property
    def chain(self) -> Chain | None:
        """The chain observed: J, k, B, the motor inertia J_mo + ΔJ (kg·m²) and the
        friction D_m (N·m·s/rad), f_c (N·m); None without load masses (a link's modes
        alone)."""
        if not self.J:
            return None
        a = self.actuator
        return Chain(self.J, self.k, self.B, J_m=a.J_mo + a.dJm, D_m=a.D_m, f_c=a.f_c)

    def angle_offset(self) -> float:
        """Half a count of the encoder.

        Returns
        -------
        float
            π / ``encoder_cpr`` (rad), 0 when the angle is not quantized.
        """
        return math.pi / self.encoder_cpr if self.encoder_cpr > 0 else 0.0

    def noise(self) -> NoiseModel:
        """The model-based observer's noise model.

        Returns
        -------
        NoiseModel
            The encoder's quantization noise 2π/cpr/√12 (rad) and the two noise levels
            (N·m).
        """
        quantum = 2.0 * math.pi / self.encoder_cpr if self.encoder_cpr > 0 else 0.0
        return NoiseModel(quantum / math.sqrt(12.0), self.torque_noise_std, self.tau_noise_std)

    @property
    def model_based(self) -> bool:
        """Whether the settings run the model-based observer (mode 2, estimator 1)."""
        return self.mode == Mode.STATE_ESTIMATION and self.estimator == Estimator.MODEL_BASED

    def problems(self, noise: bool = True) -> list[str]:
        """What the observer cannot run with these settings, one sentence each.

        The rules of the settings as a whole, in this order: ``mode`` and ``estimator``
        are codes of :mod:`~arcosim.fmu.flexchain.codes`; the model-based observer's
        noise levels lie where its Kalman design is known to work
        (:func:`noise_problem`); ``load_mass`` names a load mass and only with the
        model-based observer (:func:`load_mass_problem`). Each number is taken to be in
        its range already (finite; > 0 or ≥ 0): the FMU checks those first, by name.

        Parameters
        ----------
        noise : bool
            Check the noise levels too; the FMU passes False when it has refused a
            number already.

        Returns
        -------
        list of str
            One line per problem, naming the parameters and the fix; empty when the
            settings can run.

        Examples
        --------
        >>> actuator = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406)
        >>> settings = arcosim.ObserverSettings(mode=2, actuator=actuator, g_dist=100.0,
        ...                                     g_lpf=100.0, J=(1e-3,), k=(0.5,), B=(1e-4,))
        >>> settings.problems()
        []
        >>> import dataclasses
        >>> dataclasses.replace(settings, load_mass=1).problems()  # doctest: +ELLIPSIS
        ['parameter load_mass = 1 needs mode = 2 and estimator = 1 (the model-based ...']
        """
        found = [
            choice_problem("mode", self.mode, MODE_NAMES),
            choice_problem("estimator", self.estimator, ESTIMATOR_NAMES),
        ]
        if noise and (self.model_based or self.tracking):
            found.append(noise_problem(self.torque_noise_std, self.tau_noise_std))
        found.append(load_mass_problem(self.load_mass, len(self.J), self.model_based))
        found.append(link_problem(self.link is not None, self.model_based, self.load_mass))
        found.append(tracking_problem(self))
        return [problem for problem in found if problem is not None]


def noise_problem(torque_noise_std: float, tau_noise_std: float) -> str | None:
    """A sentence if the model-based observer cannot design its Kalman gain for these
    noise levels (outside :data:`~arcosim.fmu.flexchain.model_observer.NOISE_RANGE`, or
    one more than :data:`~arcosim.fmu.flexchain.model_observer.NOISE_RATIO` times the
    other).

    Parameters
    ----------
    torque_noise_std, tau_noise_std : float
        Unmodelled torque on each mass and noise on τ̂_reac (N·m).

    Returns
    -------
    str or None
        The sentence, naming both parameters, the envelope and the defaults; None when
        the levels are inside the envelope.
    """
    torque, tau = torque_noise_std, tau_noise_std
    low, high = NOISE_RANGE
    inside = low <= torque <= high and low <= tau <= high
    if inside and max(torque / tau, tau / torque) <= NOISE_RATIO:
        return None
    return (
        f"parameters torque_noise_std = {torque!r} and tau_noise_std = {tau!r} N.m: "
        f"the model-based observer (mode {int(Mode.STATE_ESTIMATION)}, estimator "
        f"{int(Estimator.MODEL_BASED)}) designs its Kalman gain for noise on both; give each "
        f"from {low:g} to {high:g} N.m, neither more than {NOISE_RATIO:g} times the other "
        f"(defaults {_short(defaults.TORQUE_NOISE_STD)} and {_short(defaults.TAU_NOISE_STD)})"
    )


def load_mass_problem(load_mass: int, n: int, model_based: bool) -> str | None:
    """A sentence if ``load_mass`` names no load mass, or is set where the observer cannot
    estimate a load torque (anything but mode 2 with estimator 1).

    Parameters
    ----------
    load_mass : int
        0 (off) or the index of a load mass, 1 … n.
    n : int
        Number of load masses (a count).
    model_based : bool
        Whether the observer runs the model-based observer
        (:attr:`ObserverSettings.model_based`).

    Returns
    -------
    str or None
        The sentence, naming the fix; None when ``load_mass`` can run.
    """
    if not 0 <= load_mass <= n:
        return (
            f"parameter load_mass = {load_mass} is not allowed (use 0 = off, or a load "
            f"mass 1 to {n})"
        )
    if load_mass and not model_based:
        return (
            f"parameter load_mass = {load_mass} needs mode = {int(Mode.STATE_ESTIMATION)} and "
            f"estimator = {int(Estimator.MODEL_BASED)} (the model-based observer); set "
            "load_mass = 0 otherwise"
        )
    return None


def link_problem(link: bool, model_based: bool, load_mass: int) -> str | None:
    """A sentence if a link's modal model is set where the observer cannot run it: only
    the model-based observer runs on a link, and without a load torque state.

    Parameters
    ----------
    link : bool
        Whether the settings carry a link (``link_modes`` > 0 in the FMU).
    model_based : bool
        Whether the observer runs the model-based observer
        (:attr:`ObserverSettings.model_based`).
    load_mass : int
        0 (off) or the load mass whose torque is estimated.

    Returns
    -------
    str or None
        The sentence, naming the fix; None when the link (or none) can run.
    """
    if link and not model_based:
        return (
            f"parameter link_modes > 0 needs mode = {int(Mode.STATE_ESTIMATION)} and "
            f"estimator = {int(Estimator.MODEL_BASED)} (the model-based observer); set "
            "link_modes = 0 otherwise"
        )
    if link and load_mass:
        return "parameters link_modes > 0 and load_mass > 0 exclude each other: set load_mass = 0"
    return None


def tracking_problem(settings: ObserverSettings) -> str | None:
    """A sentence if tracking is asked for where the tracker cannot run: in mode 2 on a
    chain, without a load torque state (its own constant torque takes a steady load). It
    is then the state estimator, whatever ``estimator`` says (its predictor is the
    model-based observer's, on the tracked chain).

    Parameters
    ----------
    settings : ObserverSettings
        The settings.

    Returns
    -------
    str or None
        The sentence, naming the fix; None when the settings can track (or do not).
    """
    s = settings
    if not s.tracking:
        return None
    if s.mode != Mode.STATE_ESTIMATION or s.link is not None or s.load_mass:
        return (
            f"parameter tracking = 1 needs mode = {int(Mode.STATE_ESTIMATION)} (state "
            "estimation), link_modes = 0 and load_mass = 0; set tracking = 0 otherwise"
        )
    return None


def _short(x: float) -> str:
    """``x`` in the shortest scientific notation: 1e-4, 1.5e-3."""
    mantissa, exponent = f"{x:e}".split("e")
    return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"


class Observer:
    """DOB + reaction torque observer + the configured mode.

    The estimates are attributes of :attr:`dob` and of :attr:`identifier` or
    :attr:`estimator` (whichever the mode runs); identification estimates are
    refreshed by :meth:`estimate`.

    Parameters
    ----------
    settings : ObserverSettings
        The configuration.
    theta0, omega0 : float
        Motor angle (rad) and velocity (rad/s) at start.

    Raises
    ------
    ValueError
        If ``settings.load_mass`` cannot run (:func:`load_mass_problem`).

    Examples
    --------
    >>> settings = ObserverSettings(mode=2, actuator=Actuator(J_mo=2.09e-5, k_to=0.0406),
    ...                             g_dist=100.0, g_lpf=100.0, J=(1e-3,), k=(0.5,),
    ...                             B=(1e-4,), estimator=1)
    >>> observer = Observer(settings, 0.0, 0.0)
    >>> observer.step(1e-3, 0.0, 0.0, 0.0)  # s, A, rad/s, rad: at rest
    >>> type(observer.estimator).__name__, observer.estimator.theta  # load angles (rad)
    ('ModelObserver', [0.0])
    """

    def __init__(self, settings: ObserverSettings, theta0: float, omega0: float) -> None:
        self.settings = settings
        s = settings
        problem = load_mass_problem(s.load_mass, len(s.J), s.model_based)
        if problem is None:
            problem = link_problem(s.link is not None, s.model_based, s.load_mass)
        if problem is None:
            problem = tracking_problem(s)
        if problem is not None:
            raise ValueError(problem)
        self.dob = ReactionObserver(s.actuator, s.g_dist, theta0, omega0)
        self.identifier: ActuatorIdentifier | RigidChainIdentifier | None = None
        self.estimator: (
            ChainRecursion | ModelObserver | LoadTorqueObserver | ChainTracker | None
        ) = None
        self.rigid = s.link.J_rigid if s.link is not None else 0.0  # off τ̂_reac, on the hub
        self.offset = s.angle_offset() if s.mode == Mode.STATE_ESTIMATION else 0.0
        if s.mode == Mode.SELF_IDENTIFICATION:
            self.identifier = ActuatorIdentifier(s.g_dist, s.omega_min, s.actuator.k_to, s.g_id)
        elif s.mode == Mode.RIGID_IDENTIFICATION:
            self.identifier = RigidChainIdentifier(
                s.J, s.g_dist, s.kappa_correction, theta0, s.actuator.f_c
            )
        elif s.tracking:
            self.estimator = ChainTracker(
                s.J,
                s.k,
                s.B,
                s.actuator.f_c,
                s.actuator.D_m,
                s.g_dist,
                s.noise(),
                theta0,
                self.offset,
                s.tracking_time,
                s.drift_threshold,
            )
        elif s.estimator == Estimator.MODEL_BASED and s.load_mass > 0:
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
        elif s.estimator == Estimator.MODEL_BASED and s.link is not None:
            self.estimator = LinkObserver(s.link, s.g_dist, s.noise(), theta0 + self.offset)
        elif s.estimator == Estimator.MODEL_BASED:
            self.estimator = ModelObserver(s.J, s.k, s.B, s.g_dist, s.noise(), theta0 + self.offset)
        else:
            self.estimator = ChainRecursion(s.J, s.k, s.B, s.g_dist, s.g_lpf, theta0 + self.offset)

    def step(self, h: float, i_a: float, omega: float, theta: float) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        i_a : float
            Current that acted over the step (A).
        omega, theta : float
            Motor velocity (rad/s) and angle (rad) at the sample.
        """
        dob = self.dob
        dob.step(h, i_a, omega, theta)
        estimator = self.estimator
        if self.settings.tracking:  # the torque before friction; the tracker has its own
            estimator.step(h, dob.drive + self.settings.actuator.D_m * dob.velocity, theta)
        elif estimator is not None:  # mode 2, the one that runs in control loops: test it first
            tau = dob.tau_reac_hat - self.rigid * dob.alpha_hat if self.rigid else dob.tau_reac_hat
            estimator.step(h, tau, theta + self.offset)
        elif self.settings.mode == Mode.SELF_IDENTIFICATION:
            self.identifier.step(h, i_a, dob.velocity, dob.accel, dob.friction_sign, dob.d_hat)
        else:
            self.identifier.step(h, dob.drive, dob.friction_sign, omega, theta, dob.sticking)

    @property
    def tracker(self) -> ChainTracker | None:
        """The chain tracker when the settings track (it is then the estimator), else None."""
        return self.estimator if self.settings.tracking else None

    def estimate(self) -> None:
        """Solve the identification's normal equations (modes 0 and 1)."""
        if self.identifier is not None:
            self.identifier.estimate()
