"""A fixed-step co-simulation master for the plant and the observer FMUs.

Connections: the plant's measured ``i_a``, ``omega_m``, ``theta_m`` feed the
observer's inputs of the same names. Time is ``t0 + k h``, never accumulated.

Orderings (both honour the timing contract of docs/method.md):

* ``"gauss-seidel"`` (default): the plant steps first, and the observer's
  ``doStep(t_k, h)`` receives the sample at ``t_k + h``; after step k every output
  refers to ``t_k + h``.
* ``"jacobi"``: both FMUs step from the values at ``t_k``, so the observer's
  ``doStep(t_k, h)`` receives the sample at ``t_k``; its estimates after step k are
  those of the sample at ``t_k`` (one step behind the plant's outputs).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from ctypes import c_double
from dataclasses import dataclass, field

import numpy as np

from arcosim.errors import UserError
from arcosim.fmu.fmukit.checks import SMALLEST_STEP
from arcosim.host import stepping
from arcosim.host.instance import FmuInstance

MEASURED = ("i_a", "omega_m", "theta_m")
ORDERINGS = ("gauss-seidel", "jacobi")
#: Most communication steps a run of the command line (or a sweep) may take: 10⁷,
#: 10⁴ s at 1 ms. Every recorded signal is kept in memory, 8 bytes a step: 10⁷ steps of
#: the ~50 signals ``arcosim simulate`` records are 4 GB.
MAX_STEPS = 10_000_000
#: Largest time or length (s) the command line accepts: a day.
MAX_TIME = 86_400.0
#: Smallest communication step (s): the FMUs' own limit.
MIN_STEP = SMALLEST_STEP


@dataclass
class Recording:
    """Recorded signals of a run: ``time`` and one array per ``"fmu.variable"`` name.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    signals : dict of str to ndarray
        ``"plant.theta[1]"``, ``"observer.tau_reac_hat"`` … → values (in the FMU
        variable's unit), each of shape ``(N,)``.
    units : dict of str to str
        Signal name → its unit as the FMU declares it (``"rad"``, ``"N.m"``; ``"1"``
        for a count, a code or a flag); filled by the runs that record.

    Examples
    --------
    >>> run = arcosim.Recording(np.array([0.0, 0.001]), {"plant.i_a": np.array([0.0, 0.5])})
    >>> float(run["plant.i_a"][-1])
    0.5
    """

    time: np.ndarray
    signals: dict[str, np.ndarray] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.signals[name]


def cosimulate(
    plant: FmuInstance,
    observer: FmuInstance,
    i_ref: Sequence[float],
    h: float,
    record_plant: Sequence[str] = (),
    record_observer: Sequence[str] = (),
    plant_parameters: Mapping[str, float | int | bool] | None = None,
    observer_parameters: Mapping[str, float | int | bool] | None = None,
    ordering: str = "gauss-seidel",
    t0: float = 0.0,
    progress: Callable[[int], None] | None = None,
    record_every: int = 1,
    plant_inputs: Mapping[str, Sequence[float]] | None = None,
) -> Recording:
    """Run plant and observer for ``len(i_ref)`` steps of ``h`` seconds.

    The plant's measured ``i_a``, ``omega_m``, ``theta_m`` feed the observer's inputs
    of the same names; time is ``t0 + k h``, never accumulated. One FMI call per FMU
    per step on the hot path (bare ctypes, arguments made once).

    Parameters
    ----------
    plant, observer : FmuInstance
        Freshly instantiated FMUs, not yet initialized.
    i_ref : sequence of float
        Current command for each step (A), held over the step; shape ``(N,)``.
    plant_inputs : mapping of str to sequence of float, optional
        Other Real inputs of the plant by name (e.g. ``"tau_ext[3]"``, N·m), one
        value per step like ``i_ref`` (shape ``(N,)``) and held over the step; inputs
        not named keep their start values.
    h : float
        Communication step (s), finite and > 0.
    record_plant, record_observer : sequence of str
        Outputs to record after every step (as floats).
    plant_parameters, observer_parameters : mapping of str to value, optional
        Start values by FMU variable name (in the variable's unit).
    ordering : {"gauss-seidel", "jacobi"}
        Gauss–Seidel: the plant steps first and the observer's ``doStep(t_k, h)``
        receives the sample at ``t_k + h``; Jacobi: both step from the values at
        ``t_k`` (the observer one step behind).
    t0 : float
        Start time (s).
    progress : callable, optional
        Called with the number of steps done, every 1000 steps and at the end.
    record_every : int
        Record after every this many steps, and always after the last (a count);
        reading outputs costs time, and some (identification) cost a solve.

    Returns
    -------
    Recording
        Sample 0 is the values after initialization at ``t0``; signals are named
        ``"plant.<name>"`` and ``"observer.<name>"``.

    Raises
    ------
    UserError
        Bad arguments, or an FMU refused a step (its log is in the message).

    Examples
    --------
    >>> folder = arcosim.ensure_built(3)
    >>> with (
    ...     arcosim.FmuInstance(folder / "MotorChainPlant.fmu", "plant") as plant,
    ...     arcosim.FmuInstance(folder / "ReactionTorqueObserver.fmu", "observer") as observer,
    ... ):
    ...     run = arcosim.cosimulate(plant, observer, [0.5] * 100, 1e-3, ["theta[1]"], ["d_hat"])
    >>> run.time.shape, sorted(run.signals)
    ((101,), ['observer.d_hat', 'plant.theta[1]'])
    """
    _check_arguments(ordering, h, record_every)
    currents = [float(x) for x in i_ref]
    steps = len(currents)
    extra = stepping.plant_inputs(plant, plant_inputs or {}, steps)
    plant.initialize(plant_parameters, t0)
    measured = plant.real_port(MEASURED)
    observer_in = observer.real_port(MEASURED)
    stepping.check_status(
        measured.get() | observer_in.send(measured.values), plant, "reading the sensors", t0
    )
    observer.initialize(observer_parameters, t0)
    recorded = stepping.record_points(steps, record_every)
    plant_log = np.empty((len(recorded), len(record_plant)))
    observer_log = np.empty((len(recorded), len(record_observer)))
    read_plant, read_observer = (
        stepping.recorder(plant, record_plant),
        stepping.recorder(observer, record_observer),
    )
    plant_log[0], observer_log[0] = read_plant(), read_observer()
    # The hot loop: bare ctypes calls with ctypes arguments made once, no allocation.
    i_port = plant.real_port(["i_ref", *extra])
    set_i, i_vr, i_value, one = i_port.set_real, i_port.vrs, i_port.values, i_port.count
    rows = list(zip(currents, *extra.values())) if extra else None
    plant_step, plant_c = plant.step_call()
    observer_step, observer_c = observer.step_call()
    get_sensors, sensors_in = measured.get_real, observer_in.set_real
    vrs_out, vrs_in, count, values = measured.vrs, observer_in.vrs, measured.count, measured.values
    t_c, h_c = c_double(t0), c_double(h)
    gauss_seidel = ordering == "gauss-seidel"
    next_record, row = recorded[1] if len(recorded) > 1 else -1, 1
    for k in range(steps):
        t_c.value = t = t0 + k * h
        if (
            not gauss_seidel
            and (
                get_sensors(plant_c, vrs_out, count, values)
                | sensors_in(observer_c, vrs_in, count, values)
            )
            > 1
        ):
            stepping.check_status(2, plant, "passing the sensors on", t)
        if rows is None:
            i_value[0] = currents[k]
        else:
            i_value[:] = rows[k]
        if set_i(plant_c, i_vr, one, i_value) > 1 or plant_step(plant_c, t_c, h_c, 1) > 1:
            stepping.check_status(2, plant, "stepping", t)
        if (
            gauss_seidel
            and (
                get_sensors(plant_c, vrs_out, count, values)
                | sensors_in(observer_c, vrs_in, count, values)
            )
            > 1
        ):
            stepping.check_status(2, plant, "passing the sensors on", t)
        if observer_step(observer_c, t_c, h_c, 1) > 1:
            stepping.check_status(2, observer, "stepping", t)
        if k + 1 == next_record:
            plant_log[row], observer_log[row] = read_plant(), read_observer()
            row += 1
            next_record = recorded[row] if row < len(recorded) else -1
        if progress is not None and (k + 1) % 1000 == 0:
            progress(1000)
    if progress is not None and steps % 1000:
        progress(steps % 1000)
    plant.time = observer.time = t0 + steps * h
    recording = Recording(time=t0 + np.array(recorded) * h)
    recording.signals.update(stepping.signals("plant", record_plant, plant_log))
    recording.signals.update(stepping.signals("observer", record_observer, observer_log))
    recording.units.update({f"plant.{name}": plant.unit(name) for name in record_plant})
    recording.units.update({f"observer.{name}": observer.unit(name) for name in record_observer})
    return recording


def _check_arguments(ordering: str, h: float, record_every: int) -> None:
    """Refuse an unknown ordering, a step ``h`` (s) that is not finite and > 0
    (:func:`~arcosim.host.stepping.check_step`), and a ``record_every`` below 1."""
    if ordering not in ORDERINGS:
        raise UserError(f"ordering {ordering!r}: use one of {', '.join(ORDERINGS)}")
    stepping.check_step(h)
    if record_every < 1:
        raise UserError(f"record_every = {record_every}: record at least every step (>= 1)")
