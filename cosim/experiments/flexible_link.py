"""A flexible link on the hub, identified from the hub alone: ``arcosim reproduce``'s
experiment 6 and the published rig of ``benchmarks/published_link.py``.

:func:`simulate_link` drives the flexible-link plant FMU (``FlexLinkPlant.fmu``, the
C plant of ``plant_models/flexlink_c``, written apart from the identification's modal
model) with a current command and records what a log holds (current, encoder) with the
plant's truth beside it (its root moment ``tau_reac``, eq. 7, and the tip angle
``alpha_tip``). :func:`score_link` gives the fit only k_t, J_m, the friction, the
encoder's counts and the link's L, m_tip, J_tip and r (what a user knows):
:func:`arcosim.identification.link.beam_fit.fit_link` finds EI, ρA and the damping, and
:func:`arcosim.identification.link.beam_motion.tip_motion` the tip angle and eq. 7's reaction
torque over the record. :func:`clamped_frequencies` are the hub-locked modes of the
continuous beam (the roots of its characteristic equation, not finite elements) the
identified modes are scored against.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from arcosim.experiments.current_commands import multisine
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.host.instance import FmuInstance
from arcosim.identification.link.beam_fit import Geometry, fit_link, modal_of
from arcosim.identification.link.beam_motion import tip_motion
from arcosim.identification.records.record import encoder_record, motor_record

#: The FMU file of the flexible-link plant in an FMU folder.
LINK_FMU = "FlexLinkPlant.fmu"
#: Communication step (s) and record length (s) of the experiment.
STEP = defaults.STEP
LINK_DURATION = 20.0
#: Scores skip the record's first second (the smoother's and the excitation's start).
SETTLE = 1.0
#: The plant outputs a run records: the log's columns, then the truth.
RECORDED = ("i_a", "omega_m", "theta_m", "omega_m_true", "tau_reac", "alpha_tip", "w_tip")
#: The units of a run's columns (the FMU's spelling).
LINK_UNITS = {
    "time": "s",
    "i_a": "A",
    "omega_m": "rad/s",
    "theta_m": "rad",
    "omega_m_true": "rad/s",
    "tau_reac": "N.m",
    "alpha_tip": "rad",
    "w_tip": "m",
}


@dataclass(frozen=True)
class LinkRig:
    """A flexible link on a motor, and the multi-sine current that identifies it.

    Attributes
    ----------
    name : str
        Label of the rig.
    plant : dict of str to float
        The plant FMU's parameters (SI units): ``J_m``, ``k_t``, ``D_m``, ``f_c``,
        ``EI``, ``rhoA``, ``L``, ``m_tip``, ``J_tip``, ``r_hub``, ``beta``,
        ``encoder_cpr``, ``i_noise_std``; the FMU's defaults for any left out.
    lines : tuple of float
        The multi-sine's lines (rad/s).
    amplitude : float
        The multi-sine's peak current (A).
    seed : int
        Seed of the multi-sine's phases and of the plant's current noise (an index).

    Examples
    --------
    >>> rig = LinkRig("a strip", {"EI": 0.04, "rhoA": 0.03, "L": 0.3, "m_tip": 0.005})
    >>> rig.value("EI"), rig.value("k_t") == defaults.K_T  # N·m²; the FMU's default k_t
    (0.04, True)
    >>> rig.geometry
    Geometry(L=0.3, m_tip=0.005, J_tip=0.0, r_hub=0.01)
    """

    name: str
    plant: dict[str, float] = field(default_factory=dict)
    lines: tuple[float, ...] = tuple(np.geomspace(3.0, 400.0, 40))
    amplitude: float = 0.3
    seed: int = 1

    def value(self, name: str) -> float:
        """The plant parameter ``name`` (its FMU default when the rig leaves it out)."""
        return float(self.plant.get(name, _PLANT_DEFAULTS[name]))

    @property
    def geometry(self) -> Geometry:
        """What the user knows of the link: L, m_tip, J_tip, r (m, kg, kg·m², m)."""
        return Geometry(*(self.value(p) for p in ("L", "m_tip", "J_tip", "r_hub")))

    @property
    def actuator(self) -> Actuator:
        """The motor as the user gives it: J_m, k_t and the friction."""
        return Actuator(
            self.value("J_m"), self.value("k_t"), 0.0, 0.0, self.value("D_m"), self.value("f_c")
        )


#: The plant FMU's parameter defaults (arcosim.build.clink declares them from these).
_PLANT_DEFAULTS = {
    "J_m": defaults.J_M,
    "k_t": defaults.K_T,
    "D_m": defaults.D_M,
    "f_c": defaults.F_C,
    "EI": defaults.LINK_EI,
    "rhoA": defaults.LINK_RHOA,
    "L": defaults.LINK_L,
    "m_tip": defaults.LINK_M_TIP,
    "J_tip": defaults.LINK_J_TIP,
    "r_hub": defaults.LINK_R_HUB,
    "beta": defaults.LINK_BETA,
    "encoder_cpr": defaults.ENCODER_CPR,
    "i_noise_std": defaults.I_NOISE_STD,
}

#: Experiment 6: a 0.3 m strip (EI 0.04 N·m², ρA 0.03 kg/m) with a 5 g tip mass, clamped
#: at r = 1 cm on the bench's motor and sensors (the link 37 times the rotor's inertia;
#: clamped modes 24.9, 215 and 661 rad/s: two below the record's band of 300 rad/s),
#: driven by a 1 A multi-sine of 30 lines 10–300 rad/s (the hub below 0.3 × the first
#: mode, the linear model's limit: up to 6.1 rad/s on seed 1). (The link FMU's default link,
#: 270 times the rotor's inertia, moves the hub by a few encoder counts only: at 6 A its
#: fitted first mode came out 12 % low.)
EXPERIMENT_RIG = LinkRig(
    "0.3 m strip, 5 g tip mass",
    {"EI": 0.04, "rhoA": 0.03, "L": 0.3, "m_tip": 0.005, "J_tip": 0.0, "r_hub": 0.01},
    tuple(np.geomspace(10.0, 300.0, 30)),
    1.0,
)


@dataclass(frozen=True)
class LinkRun:
    """A run of the link plant: the log's columns and the plant's truth over time.

    Attributes
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    signals : dict of str to ndarray
        :data:`RECORDED` outputs, each shape ``(N,)``: ``i_a`` (A), ``omega_m``
        (rad/s), ``theta_m`` (rad), the hub's true speed ``omega_m_true`` (rad/s),
        ``tau_reac`` (N·m), ``alpha_tip`` (rad), ``w_tip`` (m).

    Examples
    --------
    >>> t = np.arange(3) * STEP
    >>> run = LinkRun(t, {name: np.zeros(3) for name in RECORDED})
    >>> sorted(run.log())  # what a log of the rig holds
    ['i_a', 'omega_m', 'theta_m', 'time']
    """

    time: np.ndarray
    signals: dict[str, np.ndarray]

    def log(self) -> dict[str, np.ndarray]:
        """What a log of the rig holds: ``time``, ``i_a``, ``omega_m``, ``theta_m``."""
        return {"time": self.time, **{c: self.signals[c] for c in ("i_a", "omega_m", "theta_m")}}


def simulate_link(fmu: Path, rig: LinkRig, duration: float = LINK_DURATION) -> LinkRun:
    """Drive the link plant FMU ``fmu`` with ``rig``'s multi-sine for ``duration`` s.

    Parameters
    ----------
    fmu : Path
        ``FlexLinkPlant.fmu``.
    rig : LinkRig
        The plant's parameters and the excitation.
    duration : float
        Length of the run (s), in :data:`STEP` steps.

    Returns
    -------
    LinkRun
        The initial sample and one after each step (the FMU's timing contract: the
        outputs after the step from t to t + h are the sample at t + h).

    Raises
    ------
    RuntimeError
        When the FMU refuses a step (its messages in the text).

    Examples
    --------
    >>> from arcosim import ensure_built
    >>> run = simulate_link(ensure_built(3) / LINK_FMU, EXPERIMENT_RIG, duration=0.5)
    >>> run.time.shape, float(run.time[-1])  # samples, s
    ((501,), 0.5)
    """
    steps = round(duration / STEP)
    current = multisine(np.arange(steps) * STEP, rig.amplitude, np.array(rig.lines), rig.seed)
    rows = np.empty((steps + 1, len(RECORDED)))
    with FmuInstance(fmu, "link") as link:
        link.initialize({**rig.plant, "seed": rig.seed})
        read = link.reader(RECORDED)
        rows[0] = read()
        for k, i_ref in enumerate(current):
            link.set({"i_ref": float(i_ref)})
            if link.do_step(k * STEP, STEP) > 1:
                raise RuntimeError(f"the link plant refused step {k}: {link.messages}")
            rows[k + 1] = read()
    time = np.arange(steps + 1) * STEP
    return LinkRun(time, {name: rows[:, j] for j, name in enumerate(RECORDED)})


@dataclass
class LinkFindings:
    """What the fit from the hub alone found against the plant (SI units).

    Attributes
    ----------
    values, std, truth : dict of str to float
        ``EI`` (N·m²), ``rhoA`` (kg/m): fitted, standard error, the plant's.
    modes, clamped : list of float
        The fitted model's first clamped modes and the continuous beam's (rad/s).
    tau_ratio, alpha_ratio : float
        rms(τ̂_reac − τ_reac) / rms(τ_reac) and rms(α̂ − α) / rms(α) after
        :data:`SETTLE` s (dimensionless).
    peak_speed : float
        The hub's largest true speed over the record (rad/s).
    seconds : float
        The fit's and the smoother's wall time (s).
    estimates : dict of str to ndarray
        ``tau_reac`` (N·m) and ``alpha_tip`` (rad) over the record, for the figure.
    """

    values: dict[str, float]
    std: dict[str, float]
    truth: dict[str, float]
    modes: list[float]
    clamped: list[float]
    tau_ratio: float
    alpha_ratio: float
    peak_speed: float
    seconds: float
    estimates: dict[str, np.ndarray] = field(repr=False, default_factory=dict)

    def errors(self) -> dict[str, float]:
        """Relative errors in % (signed): ``EI``, ``rhoA``, ``mode[1]``, ``mode[2]``, …"""
        out = {p: 100.0 * (self.values[p] / self.truth[p] - 1.0) for p in ("EI", "rhoA")}
        for i, (a, b) in enumerate(zip(self.modes, self.clamped), start=1):
            out[f"mode[{i}]"] = 100.0 * (a / b - 1.0)
        return out

    def as_dict(self) -> dict[str, object]:
        """Everything but the time series, JSON-able."""
        return {
            "EI": self.values["EI"],
            "rhoA": self.values["rhoA"],
            "std": dict(self.std),
            "truth": dict(self.truth),
            "modes_rad_s": list(self.modes),
            "clamped_rad_s": list(self.clamped),
            "errors_percent": self.errors(),
            "tau_ratio": self.tau_ratio,
            "alpha_ratio": self.alpha_ratio,
            "peak_speed_rad_s": self.peak_speed,
            "seconds": self.seconds,
        }


def score_link(run: LinkRun, rig: LinkRig, count: int = 2) -> LinkFindings:
    """Fit the link of ``run`` from its hub's current and encoder alone; score it.

    Parameters
    ----------
    run : LinkRun
        A run of :func:`simulate_link`.
    rig : LinkRig
        The rig it ran (its truth, and what the fit is given: k_t, J_m, the friction,
        the counts, L, m_tip, J_tip, r).
    count : int
        The clamped modes scored (a count).

    Returns
    -------
    LinkFindings
        The fit against the plant.

    Examples
    --------
    >>> from arcosim import ensure_built
    >>> run = simulate_link(ensure_built(3) / LINK_FMU, EXPERIMENT_RIG)
    >>> found = score_link(run, EXPERIMENT_RIG)
    >>> {p: abs(found.values[p] / found.truth[p] - 1.0) < 0.05 for p in ("EI", "rhoA")}
    {'EI': True, 'rhoA': True}
    """
    import time as clock

    c, actuator = run.log(), rig.actuator
    cpr = int(rig.value("encoder_cpr"))
    motor = motor_record(run.time, c["i_a"], c["omega_m"], c["theta_m"], actuator, defaults.G_DIST)
    encoder = encoder_record(run.time, c["i_a"], c["theta_m"], actuator, cpr)
    started = clock.perf_counter()
    result = fit_link(encoder, motor, rig.geometry)
    model = modal_of(result, rig.geometry)
    tip = tip_motion(encoder, model, actuator.D_m, actuator.f_c)
    seconds = clock.perf_counter() - started
    after = run.time >= SETTLE
    truth = run.signals
    return LinkFindings(
        values={p: float(result.as_dict()[p]) for p in ("EI", "rhoA")},
        std={p: float(result.std_dict()[p]) for p in ("EI", "rhoA")},
        truth={p: rig.value(p) for p in ("EI", "rhoA")},
        modes=[float(w) for w in modal_of(result, rig.geometry, count).frequency],
        clamped=[float(w) for w in clamped_frequencies(rig, count)],
        tau_ratio=_ratio(tip.tau_reac[after], truth["tau_reac"][after]),
        alpha_ratio=_ratio(tip.alpha_tip[after], truth["alpha_tip"][after]),
        peak_speed=float(np.max(np.abs(truth["omega_m_true"]))),
        seconds=seconds,
        estimates={"tau_reac": tip.tau_reac, "alpha_tip": tip.alpha_tip},
    )


def _ratio(estimate: np.ndarray, truth: np.ndarray) -> float:
    """rms(estimate − truth) / rms(truth) (dimensionless)."""
    return float(np.sqrt(np.mean((estimate - truth) ** 2) / np.mean(truth**2)))


def clamped_frequencies(rig: LinkRig, count: int = 2) -> np.ndarray:
    """The first ``count`` hub-locked (clamped–free) modes of the continuous beam (rad/s).

    The roots in β of the tip's boundary conditions on the clamped shape
    y = A (cosh βx − cos βx) + B (sinh βx − sin βx): EI y''(L) = ω² J_tip y'(L) and
    EI y'''(L) = −ω² m_tip y(L), with ω = β² √(EI/ρA) (the hub's radius does not
    enter: the hub is held).

    Parameters
    ----------
    rig : LinkRig
        The link (EI, ρA, L, m_tip, J_tip).
    count : int
        Modes wanted (a count).

    Returns
    -------
    ndarray
        Frequencies (rad/s), ascending, shape ``(count,)``.

    Examples
    --------
    >>> rig = LinkRig("bare", {"EI": 1.0, "rhoA": 1.0, "L": 1.0, "m_tip": 0.0})
    >>> [round(float(w), 4) for w in clamped_frequencies(rig, 2)]
    [3.516, 22.0345]
    """
    EI, rhoA, L = rig.value("EI"), rig.value("rhoA"), rig.value("L")
    m_tip, J_tip = rig.value("m_tip"), rig.value("J_tip")

    def determinant(beta: float) -> float:
        x = beta * L
        ch, sh, c, s = np.cosh(x), np.sinh(x), np.cos(x), np.sin(x)
        w2 = beta**4 * EI / rhoA
        # y, y', y'', y''' at L of the two clamped shapes, scaled by 1 / cosh (no overflow)
        a = np.array([ch - c, beta * (sh + s), beta**2 * (ch + c), beta**3 * (sh - s)]) / ch
        b = np.array([sh - s, beta * (ch - c), beta**2 * (sh + s), beta**3 * (ch + c)]) / ch
        rows = [
            [EI * v[2] - w2 * J_tip * v[1] for v in (a, b)],
            [EI * v[3] + w2 * m_tip * v[0] for v in (a, b)],
        ]
        m = np.array(rows)
        return float(np.linalg.det(m / np.abs(m).max(axis=1, keepdims=True)))

    grid = np.linspace(0.05, 4.0 * count + 4.0, 400 * count) / L
    values = [determinant(b) for b in grid]
    roots = [
        brentq(determinant, grid[k], grid[k + 1], xtol=1e-14)
        for k in range(len(grid) - 1)
        if values[k] * values[k + 1] < 0
    ]
    return np.array(roots[:count]) ** 2 * np.sqrt(EI / rhoA)
