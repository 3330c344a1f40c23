"""The closed-loop scenarios: the controller FMU moving the plant FMU's last mass.

``move`` is a 1 rad step of the target at t = 0, which the controller shapes into a move
of ``move_time``; ``move-load`` adds a load torque step on the last mass during the hold.
:func:`run_control_scenario` runs one (``arcosim simulate --scenario move``) and
:func:`move_summary` says how it went.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from arcosim.fmu.flexchain.defaults import STEP
from arcosim.host.control_loop import control_loop
from arcosim.host.instance import FmuInstance
from arcosim.host.master import Recording


@dataclass(frozen=True)
class ControlScenario:
    """A move of the last mass, with or without a load torque step.

    Parameters
    ----------
    name : str
        Short name (``arcosim simulate --scenario NAME``).
    description : str
        One line for the user.
    duration : float
        Length (s).
    target : float
        The target of the last mass from t = 0 (rad).
    load_time : float or None
        When the load torque steps on (s); None: no load.
    load_torque : float
        The torque on the last mass from ``load_time`` on (N·m; positive accelerates it).

    Examples
    --------
    >>> from arcosim.experiments.control_scenarios import CONTROL_SCENARIOS
    >>> CONTROL_SCENARIOS["move-load"].load_torque  # N·m
    -0.005
    """

    name: str
    description: str
    duration: float = 6.0
    target: float = 1.0
    load_time: float | None = None
    load_torque: float = 0.0


CONTROL_SCENARIOS = {
    s.name: s
    for s in (
        ControlScenario("move", "a 1 rad move of the last mass, controller FMU + plant FMU"),
        ControlScenario(
            "move-load",
            "the move, then a -5 mN.m load torque step on the last mass at 4 s",
            duration=8.0,
            load_time=4.0,
            load_torque=-5e-3,
        ),
    )
}
#: What the plant records besides its sensors, for n masses: the truth to score against.
TRUTH = ("theta_m_true", "omega_m_true", "tau_reac")


def run_control_scenario(
    scenario: ControlScenario,
    n: int,
    fmu_dir: Path,
    plant: Mapping[str, float | int | bool] | None = None,
    controller: Mapping[str, float | int | bool] | None = None,
    h: float = STEP,
    ordering: str = "sequential",
) -> Recording:
    """Run the controller and plant FMUs of ``fmu_dir`` through a scenario.

    Parameters
    ----------
    scenario : ControlScenario
        What to run.
    n : int
        Number of load masses the FMUs were built for (a count).
    fmu_dir : Path
        Folder of the built FMUs.
    plant, controller : mapping of str to value, optional
        Start values by FMU variable name (in the variable's unit).
    h : float
        Communication step (s).
    ordering : {"sequential", "parallel"}
        The master's order (:mod:`arcosim.host.control_loop`).

    Returns
    -------
    Recording
        ``plant.<name>`` (sensors, the truth, every mass's angle and velocity) and
        ``controller.<name>`` signals, sample k at k h.

    Examples
    --------
    >>> import dataclasses
    >>> from arcosim import ensure_built
    >>> short = dataclasses.replace(CONTROL_SCENARIOS["move"], duration=0.1)
    >>> run = run_control_scenario(short, 3, ensure_built(3))
    >>> run.time.shape, "controller.i_ref" in run.signals
    ((101,), True)
    """
    steps = round(scenario.duration / h)
    time = np.arange(steps) * h
    inputs = {}
    if scenario.load_time is not None:
        inputs[f"tau_ext[{n}]"] = np.where(time >= scenario.load_time, scenario.load_torque, 0.0)
    record = ["i_a", "omega_m", "theta_m", *TRUTH]
    record += [f"theta[{i}]" for i in range(1, n + 1)] + [f"omega[{i}]" for i in range(1, n + 1)]
    with (
        FmuInstance(fmu_dir / "ActionReactionController.fmu", "controller") as control,
        FmuInstance(fmu_dir / "MotorChainPlant.fmu", "plant") as plant_fmu,
    ):
        return control_loop(
            control,
            plant_fmu,
            np.full(steps, scenario.target),
            h,
            record,
            plant_parameters=plant,
            controller_parameters=controller,
            ordering=ordering,
            plant_inputs=inputs,
        )


def move_summary(recording: Recording, n: int, target: float, hold: float = 2.0) -> dict:
    """How a move went: the last mass's settling and residual, the current's peak.

    Parameters
    ----------
    recording : Recording
        A run of :func:`run_control_scenario`.
    n : int
        Number of load masses (a count).
    target : float
        The last mass's target (rad).
    hold : float
        The residual is taken over the last ``hold`` s (s).

    Returns
    -------
    dict
        ``settling_1pct`` and ``settling_0.5pct`` (s: the last time outside ± 1 %, 0.5 %
        of the target), ``residual_rms`` (rad, about the target over the last ``hold``
        s), ``final_error`` (rad), ``peak_current`` (A), ``motor_p2p`` (rad, the measured
        motor angle's range over the last ``hold`` s).

    Examples
    --------
    >>> from arcosim import Recording
    >>> t = np.arange(0.0, 3.0, 1e-3)
    >>> run = Recording(t, {"plant.theta[1]": np.minimum(t, 1.0), "plant.theta_m": 0 * t,
    ...                     "controller.i_ref": 0.5 * np.sin(t)})
    >>> round(move_summary(run, 1, target=1.0, hold=1.0)["settling_1pct"], 3)  # s
    0.99
    """
    t = recording.time
    last = recording[f"plant.theta[{n}]"]
    tail = t >= t[-1] - hold

    def settling(band: float) -> float:
        outside = np.flatnonzero(np.abs(last - target) > band * abs(target))
        return float(t[outside[-1]]) if outside.size else 0.0

    return {
        "settling_1pct": settling(0.01),
        "settling_0.5pct": settling(0.005),
        "residual_rms": float(np.sqrt(np.mean((last[tail] - target) ** 2))),
        "final_error": float(last[-1] - target),
        "peak_current": float(np.max(np.abs(recording["controller.i_ref"]))),
        "motor_p2p": float(np.ptp(recording["plant.theta_m"][tail])),
    }
