"""Scenarios: an excitation, a duration and the FMUs' settings, run as one co-simulation.

:func:`run_scenario` is the Python API behind ``arcosim simulate`` and
``arcosim reproduce``::

    from arcosim.experiments.scenarios import SCENARIOS, run_scenario
    result = run_scenario(SCENARIOS["rigid"], plant={"seed": 3}, observer={"mode": 1})
    print(result["observer.k_hat"][-1])
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from arcosim.build.builder import ensure_built
from arcosim.build.recipes import OBSERVER, PLANT
from arcosim.experiments import excitation
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


def _self_identification_current(t: np.ndarray) -> np.ndarray:
    """Forward rotation with a varying speed: offset plus three sines (A)."""
    return 0.12 + 0.05 * np.sin(3 * t) + 0.04 * np.sin(11 * t + 1) + 0.03 * np.sin(29 * t + 2)


def _flexible_current(t: np.ndarray) -> np.ndarray:
    """Energy across the bench's three modes: multi-sine from 3 to 120 rad/s, peak 0.3 A."""
    return excitation.multisine(t, 0.48, np.array([3, 7, 13, 17, 22, 30, 41, 60, 90, 120.0]), 1)


#: Lines of the whole-chain identification multi-sine (rad/s): 40, log-spaced over 3 … 150.
#: The subspace start needs many lines: with 11 it takes excitation lines for modes.
IDENTIFICATION_LINES = np.geomspace(3.0, 150.0, 40)
#: Its peak current (A): at 1 A the motor's Coulomb friction and the encoder's counts
#: bias every J_i and k_i by 1.5–3 % on the five-mass chain; at 3 A by ≤ 1.3 % (README).
IDENTIFICATION_AMPLITUDE = 3.0
#: Its length (s).
IDENTIFICATION_DURATION = 20.0


def identification_current(t: np.ndarray) -> np.ndarray:
    """The whole-chain identification multi-sine (A)."""
    return excitation.multisine(t, IDENTIFICATION_AMPLITUDE, IDENTIFICATION_LINES, 1)


#: The maneuver's length: 8 periods at 2.1 rad/s.
RIGID_DURATION = 8 * 2 * np.pi / 2.1

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
        ),
        Scenario(
            "rigid",
            "rigid maneuver: 2 A at 2.1 rad/s under raised-cosine ramps, no drift (mode 1)",
            lambda t: excitation.rigid_maneuver(t),
            RIGID_DURATION,
            {},
            {"mode": 1},
        ),
        Scenario(
            "flexible",
            "flexible maneuver: multi-sine 3–120 rad/s, energy at all three modes (mode 2)",
            _flexible_current,
            10.0,
            {},
            {"mode": 2},
        ),
        Scenario(
            "identification",
            "whole-chain identification: multi-sine of 40 lines 3–150 rad/s, 3 A peak, 20 s",
            identification_current,
            IDENTIFICATION_DURATION,
            {},
            {"mode": 2},
        ),
        Scenario(
            "chirp",
            "chirp 1 → 150 rad/s over 10 s, 0.2 A (mode 2)",
            lambda t: excitation.chirp(t, 0.2, 1.0, 150.0, 10.0),
            10.0,
            {},
            {"mode": 2},
        ),
        Scenario(
            "random",
            "filtered random current, 0.15 A rms below 150 rad/s (mode 2)",
            lambda t: excitation.filtered_random(t, 0.15, 150.0, seed=7),
            10.0,
            {},
            {"mode": 2},
        ),
    )
}


def run_scenario(
    scenario: Scenario,
    n: int = 3,
    plant: Mapping[str, float | int | bool] | None = None,
    observer: Mapping[str, float | int | bool] | None = None,
    h: float = 1e-3,
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
            record_observer = [
                v.name for v in o.description.modelVariables if v.causality == "output"
            ]
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
        )


def recording_columns(recording: Recording) -> dict[str, np.ndarray]:
    """Columns for a CSV: ``time``, the log columns (plant's measured signals under
    the observer's input names), then every signal by its qualified name."""
    columns = {"time": recording.time}
    for name in ("i_a", "omega_m", "theta_m"):
        key = f"plant.{name}"
        if key in recording.signals:
            columns[name] = recording.signals[key]
    columns.update(recording.signals)
    return columns
