"""The plant FMU with a Python controller in the loop: a sequential master at step h.

At each t_k the master reads the plant's sample of t_k (measured current, velocity and
angle: the observer's timing contract), asks the controller for the current to hold
over [t_k, t_k + h], sets it (and any external torque) and steps the plant: zero delay.
The controller is any object with ``step(h, theta_ref, i_a, omega_m, theta_m) -> i_ref``
(:class:`arcosim.experiments.motion.baselines.CascadeController`, the sensorless
``MotionController``); with ``full_state=True`` the master calls its
``step_full_state(h, theta_ref, angles, velocities[, i_a])`` with the plant's true angles
and velocities of the motor and every mass instead (the upper bound), and the measured
current when the method takes it.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping, Sequence
from ctypes import c_double
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from arcosim.build.recipes import PLANT
from arcosim.errors import UserError
from arcosim.fmu.flexchain.defaults import STEP
from arcosim.host.instance import FmuInstance

#: The plant's measured signals, in the controller's argument order.
MEASURED = ("i_a", "omega_m", "theta_m")
#: What a controller may expose for inspection, recorded when it has them.
INSPECTED = ("i_ff", "i_fb", "theta_hat_ctrl")


@dataclass(frozen=True)
class LoadStep:
    """A constant external torque on one load mass from ``time`` on.

    Attributes
    ----------
    mass : int
        The load mass it acts on (1 … n, an index).
    time : float
        When it starts (s).
    torque : float
        Its size (N·m).
    """

    mass: int
    time: float
    torque: float


@dataclass
class LoopRun:
    """A closed-loop run, sampled at every step.

    Attributes
    ----------
    time : ndarray
        Sample times t_0 … t_N (s), shape ``(N + 1,)``.
    theta : ndarray
        True angles of the motor (row 0) and of masses 1 … n (rad), shape ``(n + 1, N + 1)``.
    theta_m, omega_m, i_a : ndarray
        The measured encoder angle (rad), velocity (rad/s) and current (A), shape ``(N + 1,)``.
    i_ref : ndarray
        The command held over each step (A), shape ``(N,)``.
    inspected : dict of str to ndarray
        The controller's ``i_ff``, ``i_fb``, ``theta_hat_ctrl`` after each step, those
        it has (A, A, rad), shape ``(N,)`` each.

    Examples
    --------
    >>> run = LoopRun(np.array([0.0, 1e-3]), np.zeros((2, 2)), *np.zeros((3, 2)), np.zeros(1))
    >>> run.theta.shape, run.last.shape  # the motor and one mass; the last mass's angle
    ((2, 2), (2,))
    """

    time: np.ndarray
    theta: np.ndarray
    theta_m: np.ndarray
    omega_m: np.ndarray
    i_a: np.ndarray
    i_ref: np.ndarray
    inspected: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def last(self) -> np.ndarray:
        """The last mass's true angle (rad), shape ``(N + 1,)``."""
        return self.theta[-1]


def run_closed_loop(
    folder: Path,
    n: int,
    controller: object,
    reference: float | Callable[[float], float],
    duration: float,
    plant: Mapping[str, float | int | bool] | None = None,
    h: float = STEP,
    load: LoadStep | None = None,
    full_state: bool = False,
) -> LoopRun:
    """Run the plant FMU of ``folder`` (n masses) with ``controller`` in the loop.

    Parameters
    ----------
    folder : Path
        Folder of FMUs built for ``n`` (:func:`arcosim.ensure_built`).
    n : int
        Number of load masses (a count).
    controller : object
        Has ``step(h, theta_ref, i_a, omega_m, theta_m) -> i_ref`` (or, with
        ``full_state``, ``step_full_state``); reset by the caller.
    reference : float or callable
        The target ``theta_ref`` (rad): a constant from t = 0 (a step at the start), or a
        function of t_k (s).
    duration : float
        Length of the run (s).
    plant : mapping of str to value, optional
        The plant's start values by FMU name (``J[2]``, ``k[1]``, ``seed`` …).
    h : float
        The step (s).
    load : LoadStep, optional
        An external torque step on one mass.
    full_state : bool
        Feed the controller the plant's true angles and velocities
        (``step_full_state``) rather than its measurements.

    Returns
    -------
    LoopRun
        Every mass's angle, the measurements and the commands.

    Raises
    ------
    UserError
        When the plant refuses its parameters or a step.

    Examples
    --------
    >>> from arcosim import ensure_built
    >>> push = OpenLoop(np.full(500, 0.2))  # 0.2 A for 0.5 s
    >>> run = run_closed_loop(ensure_built(3), 3, push, 0.0, 0.5)
    >>> run.theta.shape, float(run.time[-1]), bool(run.last[-1] > 0.0)  # rad, s
    ((4, 501), 0.5, True)
    """
    steps = round(duration / h)
    ref = reference if callable(reference) else (lambda _t, r=float(reference): r)
    names = [*MEASURED, "theta_m_true", *(f"theta[{i}]" for i in range(1, n + 1))]
    names += ["omega_m_true", *(f"omega[{i}]" for i in range(1, n + 1))]
    inspected = [a for a in INSPECTED if hasattr(controller, a)]
    takes_current = full_state and _takes_current(controller.step_full_state)
    log = np.empty((steps + 1, len(names)))
    commands, seen = np.empty(steps), np.empty((steps, len(inspected)))
    with FmuInstance(folder / f"{PLANT.name}.fmu", "plant") as fmu:
        fmu.initialize(plant)
        outputs = fmu.real_port(names)
        inputs = fmu.real_port(["i_ref", *([f"tau_ext[{load.mass}]"] if load else [])])
        do_step, component = fmu.step_call()
        t_c, h_c = c_double(0.0), c_double(h)
        _checked(outputs.get(), fmu, 0.0)
        for k in range(steps):
            t = k * h
            log[k] = outputs.array
            row = log[k].tolist()  # Python floats, as an FMU would be given them
            if full_state:
                angles, velocities = row[3 : 4 + n], row[4 + n :]
                measured = (row[0],) if takes_current else ()  # i_a, when it asks for it
                command = controller.step_full_state(h, ref(t), angles, velocities, *measured)
            else:
                command = controller.step(h, ref(t), row[0], row[1], row[2])
            commands[k] = inputs.array[0] = command
            if load is not None:
                inputs.array[1] = load.torque if t >= load.time else 0.0
            t_c.value = t
            _checked(inputs.send() | do_step(component, t_c, h_c, 1), fmu, t)
            _checked(outputs.get(), fmu, t)
            for j, attribute in enumerate(inspected):
                seen[k, j] = getattr(controller, attribute)
        log[steps] = outputs.array
    return LoopRun(
        time=np.arange(steps + 1) * h,
        theta=log[:, 3 : 4 + n].T.copy(),
        theta_m=log[:, 2].copy(),
        omega_m=log[:, 1].copy(),
        i_a=log[:, 0].copy(),
        i_ref=commands,
        inspected={a: seen[:, j].copy() for j, a in enumerate(inspected)},
    )


def _takes_current(method: Callable) -> bool:
    """Whether ``step_full_state`` takes the measured current after the velocities."""
    return len(inspect.signature(method).parameters) >= 5


def _checked(status: int, fmu: FmuInstance, t: float) -> None:
    """Raise when ``status`` is worse than fmi2Warning, naming the time and the FMU's log."""
    if status > 1:
        said = "; ".join(fmu.messages[-3:]) or f"status {status}"
        raise UserError(f"the plant refused a step at t = {t:.6g} s: {said}")


class OpenLoop:
    """A fixed current command as a controller: ``current`` (A) over the step times.

    For the identification log of a chain that is later controlled (the same runner).

    Parameters
    ----------
    current : sequence of float
        The command for each step (A), shape ``(N,)``.

    Examples
    --------
    >>> command = OpenLoop([0.5, -0.5])
    >>> command.step(1e-3, 0.0, 0.0, 0.0, 0.0), command.step(1e-3, 0.0, 0.0, 0.0, 0.0)
    (0.5, -0.5)
    """

    def __init__(self, current: Sequence[float]) -> None:
        self.current = np.asarray(current, dtype=float)
        self.k = 0

    def step(self, h: float, theta_ref: float, i_a: float, omega_m: float, theta_m: float) -> float:
        """The next command (A), whatever the measurements."""
        value = float(self.current[self.k])
        self.k += 1
        return value
