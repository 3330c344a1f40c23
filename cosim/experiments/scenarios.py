"""Scenarios: an excitation, a duration and the FMUs' settings, run as one co-simulation.

:func:`run_scenario` is the Python API behind ``arcosim simulate`` and
``arcosim reproduce``::

    from arcosim.experiments.scenarios import SCENARIOS, run_scenario
    result = run_scenario(SCENARIOS["rigid"], plant={"seed": 3}, observer={"mode": 1})
    print(result["observer.k_hat"][-1])
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from arcosim.build.builder import ensure_built
from arcosim.build.recipes import OBSERVER, PLANT
from arcosim.experiments import current_commands
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.defaults import STEP
from arcosim.host.instance import FmuInstance
from arcosim.host.master import Recording, cosimulate

#: Plant outputs recorded by default (truth included, for scoring).
PLANT_SIGNALS = (
    "i_a",
    "omega_m",
    "theta_m",
    "theta_m_true",
    "omega_m_true",
    "tau_reac",
    "tau_reac_mean",
    "twist",
)
#: Sensors switched off (``--ideal``): exact angle, true velocity, no current noise.
IDEAL_SENSORS = {"encoder_cpr": 0, "i_noise_std": 0.0}


@dataclass(frozen=True)
class Scenario:
    """One co-simulation setup: a current command, a duration and FMU settings.

    Parameters
    ----------
    name : str
        Short name (``arcosim simulate --scenario NAME``).
    description : str
        One line for the user.
    current : callable
        The current command: step times (s, shape ``(N,)``) → current held over
        each step (A, shape ``(N,)``).
    duration : float
        Length (s).
    plant, observer : mapping of str to value
        Start values of the plant's and the observer's variables by FMU name (in
        each variable's unit, as the FMU declares it).
    inputs : callable, optional
        The plant's other inputs: step times (s, shape ``(N,)``) → values by name
        (``tau_ext[i]``, N·m, shape ``(N,)`` each), each held over its step like the
        current; None: none.
    top_frequency : float, optional
        The highest frequency in the current command and the other inputs (rad/s), for
        the check that the step can follow it; None: not stated.

    Examples
    --------
    >>> import dataclasses
    >>> short = dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=0.5)
    >>> short.name, short.duration
    ('flexible', 0.5)
    """

    name: str
    description: str
    current: Callable[[np.ndarray], np.ndarray]
    duration: float
    plant: Mapping[str, float | int | bool] = field(default_factory=dict)
    observer: Mapping[str, float | int | bool] = field(default_factory=dict)
    inputs: Callable[[np.ndarray], Mapping[str, np.ndarray]] | None = None
    top_frequency: float | None = None


def _self_identification_current(t: np.ndarray) -> np.ndarray:
    """Forward rotation with a varying speed: offset plus three sines (A)."""
    return 0.12 + 0.05 * np.sin(3 * t) + 0.04 * np.sin(11 * t + 1) + 0.03 * np.sin(29 * t + 2)


def _flexible_current(t: np.ndarray) -> np.ndarray:
    """Energy across the bench's three modes: multi-sine from 3 to 120 rad/s, 0.48 A."""
    return current_commands.multisine(
        t, 0.48, np.array([3, 7, 13, 17, 22, 30, 41, 60, 90, 120.0]), 1
    )


#: Lines of the whole-chain identification multi-sine (rad/s): 40, log-spaced over 3 … 150.
#: The subspace start needs many lines: with 11 it takes excitation lines for modes.
IDENTIFICATION_LINES = np.geomspace(3.0, 150.0, 40)
#: Its peak current (A): at 1 A the motor sticks 18 % of the time and the five-mass chain's
#: J_i, k_i come out 0.4–1.5 % off; at 3 A within 0.1 % (docs/identification.md, "What a
#: log needs").
IDENTIFICATION_AMPLITUDE = 3.0
#: Its length (s).
IDENTIFICATION_DURATION = 20.0


def identification_current(t: np.ndarray) -> np.ndarray:
    """The whole-chain identification multi-sine at the step times ``t``.

    :data:`IDENTIFICATION_LINES` (rad/s) at a peak of 3 A, phases of seed 1.

    Parameters
    ----------
    t : ndarray
        Step times (s), shape ``(N,)``.

    Returns
    -------
    ndarray
        The current command (A), shape ``(N,)``.

    Examples
    --------
    >>> t = np.arange(0.0, IDENTIFICATION_DURATION, 1e-3)
    >>> current = identification_current(t)
    >>> current.shape, bool(np.max(np.abs(current)) <= 3.0 + 1e-12)
    ((20000,), True)
    """
    return current_commands.multisine(t, IDENTIFICATION_AMPLITUDE, IDENTIFICATION_LINES, 1)


#: The maneuver's length: 8 periods at 2.1 rad/s.
RIGID_DURATION = 8 * 2 * np.pi / 2.1

#: Lines of the broadband multi-sine (rad/s): the flexible scenario's plus 150 (the
#: accuracy benchmark's, and the load torque scenario's).
BROADBAND_LINES = np.array([3, 7, 13, 17, 22, 30, 41, 60, 90, 120, 150.0])


@dataclass(frozen=True)
class LoadProfile:
    """The load torque scenario's external torque on one mass, over a flexible maneuver.

    Nothing acts until ``step_time``; then a step of ``fraction`` of the drive's peak
    torque (k_t of the bench times the maneuver's peak current); from ``sine_time`` the
    torque goes on as that size times cos(``frequency`` (t − sine_time)), continuous at
    the switch. The maneuver is the broadband multi-sine of ``amplitude`` A. Measured on
    the bench with this load: at 1 A the 2000-count encoder sees no new count within a
    step (ω_m = 0, so the DOB knows the reaction torque only to within ±f_c) in 3 % of
    the samples; at the flexible scenario's 0.48 A in 35 %, and the settled estimate
    comes out 11 % low (docs/identification.md, "Sensorless load torque").

    Parameters
    ----------
    mass : int
        The load mass the torque acts on (1 … n, an index).
    amplitude : float
        Peak current argument of the multi-sine (A).
    fraction : float
        Step size over the drive's peak torque (dimensionless).
    step_time, sine_time : float
        When the step, then the sine, starts (s).
    frequency : float
        Frequency of the sine (rad/s).
    duration : float
        Length of the run (s).

    Examples
    --------
    >>> profile = LoadProfile(mass=2)
    >>> profile.step_time, profile.sine_time, profile.duration
    (1.0, 7.0, 15.0)
    >>> [round(float(v), 6) for v in profile.torque(np.array([0.5, 2.0]))]  # N·m
    [0.0, 0.002639]
    """

    mass: int = 3
    amplitude: float = 1.0
    fraction: float = 0.1
    step_time: float = 1.0
    sine_time: float = 7.0
    frequency: float = 2.0
    duration: float = 15.0

    def current(self, t: np.ndarray) -> np.ndarray:
        """The maneuver's current command (A) at the step times ``t`` (s), shape ``(N,)``."""
        return current_commands.multisine(t, self.amplitude, BROADBAND_LINES, 1)

    def size(self) -> float:
        """The step (N·m): ``fraction`` of the bench drive's peak torque over the run."""
        return self._size

    @functools.cached_property
    def _size(self) -> float:  # the whole run's multi-sine: computed once per profile
        t = np.arange(round(self.duration / STEP)) * STEP
        return self.fraction * defaults.K_T * float(np.max(np.abs(self.current(t))))

    def torque(self, t: np.ndarray) -> np.ndarray:
        """The external torque (N·m) held over the step starting at each of ``t`` (s),
        shape ``(N,)``."""
        size = self.size()
        tau = np.where(t >= self.step_time, size, 0.0)
        sine = size * np.cos(self.frequency * (t - self.sine_time))
        return np.where(t >= self.sine_time, sine, tau)

    @property
    def settled_from(self) -> float:
        """Start of the step's scoring window (s): half-way from the step to the sine."""
        return 0.5 * (self.step_time + self.sine_time)

    @property
    def sine_from(self) -> float:
        """Start of the sine's scoring window (s): its last two whole periods."""
        return self.duration - 2.0 * (2.0 * np.pi / self.frequency)

    def inputs(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """The plant inputs at the step times ``t`` (s): ``tau_ext[mass]`` (N·m), shape ``(N,)``."""
        return {f"tau_ext[{self.mass}]": self.torque(t)}

    def scenario(self, name: str = "load-torque") -> Scenario:
        """The co-simulation: observer in mode 2, estimator 1, estimating ``mass``."""
        return Scenario(
            name,
            f"load torque on mass {self.mass}: a step of a tenth of the drive's peak torque "
            f"at {self.step_time:g} s, a {self.frequency:g} rad/s sine from {self.sine_time:g} s, "
            f"during a {self.amplitude:g} A multi-sine 3–150 rad/s (mode 2, estimator 1)",
            self.current,
            self.duration,
            {},
            {"mode": 2, "estimator": 1, "load_mass": self.mass},
            self.inputs,
            float(max(BROADBAND_LINES.max(), self.frequency)),
        )


#: Experiment 5's load: on the bench's last mass.
LOAD_PROFILE = LoadProfile()

SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario(
            "selfid",
            "actuator self-identification: load detached, forward rotation at varying speed",
            _self_identification_current,
            10.0,
            {"attached": False},
            {"mode": 0},
            top_frequency=29.0,
        ),
        Scenario(
            "rigid",
            "rigid maneuver: 3 A at 2.1 rad/s under raised-cosine ramps, no drift (mode 1)",
            lambda t: current_commands.rigid_maneuver(t),
            RIGID_DURATION,
            {},
            {"mode": 1},
            top_frequency=2.1 * (1.0 + 1.0 / 3.0),  # the sine times its 3-period ramps
        ),
        Scenario(
            "flexible",
            "flexible maneuver: multi-sine 3–120 rad/s, energy at all three modes (mode 2)",
            _flexible_current,
            10.0,
            {},
            {"mode": 2},
            top_frequency=120.0,
        ),
        Scenario(
            "identification",
            "whole-chain identification: multi-sine of 40 lines 3–150 rad/s, 3 A peak, 20 s",
            identification_current,
            IDENTIFICATION_DURATION,
            {},
            {"mode": 2},
            top_frequency=float(IDENTIFICATION_LINES.max()),
        ),
        LOAD_PROFILE.scenario(),
        Scenario(
            "chirp",
            "chirp 1 → 150 rad/s over 10 s, 0.2 A (mode 2)",
            lambda t: current_commands.chirp(t, 0.2, 1.0, 150.0, 10.0),
            10.0,
            {},
            {"mode": 2},
            top_frequency=150.0,
        ),
        Scenario(
            "random",
            "filtered random current, 0.15 A rms below 150 rad/s (mode 2)",
            lambda t: current_commands.filtered_random(t, 0.15, 150.0, seed=7),
            10.0,
            {},
            {"mode": 2},
            top_frequency=150.0,  # the low-pass's corner
        ),
    )
}


def run_scenario(
    scenario: Scenario,
    n: int = 3,
    plant: Mapping[str, float | int | bool] | None = None,
    observer: Mapping[str, float | int | bool] | None = None,
    h: float = STEP,
    ordering: str = "gauss-seidel",
    ideal: bool = False,
    record_plant: Sequence[str] | None = None,
    record_observer: Sequence[str] | None = None,
    fmu_dir: Path | None = None,
    progress: Callable[[int], None] | None = None,
    record_every: int = 1,
) -> Recording:
    """Co-simulate the plant and observer FMUs through a scenario.

    The FMUs are built first if needed (:func:`arcosim.ensure_built`); settings given
    here override the scenario's own.

    Parameters
    ----------
    scenario : Scenario
        What to run (e.g. ``SCENARIOS["flexible"]``).
    n : int
        Number of load masses (a count, 1 to 20).
    plant, observer : mapping of str to value, optional
        Start values by FMU variable name (in the variable's unit), applied after
        the scenario's: ``{"k[2]": 0.2}``, ``{"mode": 1, "g_dist": 200.0}``.
    h : float
        Communication step (s).
    ordering : {"gauss-seidel", "jacobi"}
        Master ordering (``docs/method.md``, timing contract).
    ideal : bool
        Switch the plant's sensors off (exact angle, true velocity, no current
        noise), before ``plant`` overrides. The observer is told the plant's
        ``encoder_cpr`` unless ``observer`` sets it.
    record_plant, record_observer : sequence of str, optional
        Outputs to record (default: the plant's measured and true signals, every
        observer output).
    fmu_dir : Path, optional
        Folder of the FMUs (default: the per-user cache).
    progress : callable, optional
        Called with the number of steps done since its last call.
    record_every : int
        Record after every this many steps, and after the last (a count).

    Returns
    -------
    Recording
        ``time`` (s, shape ``(N + 1,)``) and each signal as ``"plant.<name>"`` /
        ``"observer.<name>"``, in the FMU's units.

    Examples
    --------
    >>> import dataclasses
    >>> scenario = dataclasses.replace(arcosim.SCENARIOS["flexible"], duration=0.2)
    >>> run = arcosim.run_scenario(scenario, observer={"mode": 2})
    >>> run.time.shape, float(run.time[-1])
    ((201,), 0.2)
    >>> bool(abs(run.signals["observer.tau_reac_hat"][-1]) < 1.0)  # N·m
    True
    """
    folder = fmu_dir if fmu_dir is not None else ensure_built(n)
    t = np.arange(round(scenario.duration / h)) * h
    current = scenario.current(t)
    plant_values = {**scenario.plant, **(IDEAL_SENSORS if ideal else {}), **(plant or {})}
    observer_values = {**scenario.observer, **(observer or {})}
    if "encoder_cpr" in plant_values and "encoder_cpr" not in observer_values:
        observer_values["encoder_cpr"] = plant_values["encoder_cpr"]  # same sensor
    with (
        FmuInstance(folder / f"{PLANT.name}.fmu", "plant") as p,
        FmuInstance(folder / f"{OBSERVER.name}.fmu", "observer") as o,
    ):
        if record_plant is None:
            record_plant = [
                *PLANT_SIGNALS,
                *(f"theta[{i}]" for i in range(1, n + 1)),
                *(f"omega[{i}]" for i in range(1, n + 1)),
            ]
        if record_observer is None:
            record_observer = o.output_names()
        return cosimulate(
            p,
            o,
            current,
            h,
            record_plant,
            record_observer,
            plant_values,
            observer_values,
            ordering=ordering,
            progress=progress,
            record_every=record_every,
            plant_inputs=scenario.inputs(t) if scenario.inputs is not None else None,
        )


def recording_columns(recording: Recording, log_only: bool = False) -> dict[str, np.ndarray]:
    """Columns for a CSV: ``time``, the log columns (plant's measured signals under
    the observer's input names), then, unless ``log_only``, every signal by its
    qualified name.

    Parameters
    ----------
    recording : Recording
        A run's time (s) and signals by qualified name (``plant.i_a`` in A, …).
    log_only : bool
        Only ``time`` and the log columns ``i_a`` (A), ``omega_m`` (rad/s), ``theta_m`` (rad).

    Returns
    -------
    dict of str to ndarray
        Column name → values, each of shape (samples,), in the order a CSV takes them.

    Examples
    --------
    >>> from arcosim import Recording
    >>> run = Recording(np.array([0.0, 1e-3]), {"plant.i_a": np.array([0.1, 0.2])})
    >>> list(recording_columns(run, log_only=True))
    ['time', 'i_a']
    """
    columns = {"time": recording.time}
    for name in ("i_a", "omega_m", "theta_m"):
        key = f"plant.{name}"
        if key in recording.signals:
            columns[name] = recording.signals[key]
    if not log_only:
        columns.update(recording.signals)
    return columns
