"""A fixed-step master for the closed loop controller → plant → controller.

Connections: the plant's measured ``i_a``, ``omega_m``, ``theta_m`` feed the
controller's inputs of the same names, the controller's ``i_ref`` the plant's; the
target ``theta_ref`` and the plant's external torques come from the caller, one value
per step. Time is ``t0 + k h``, never accumulated.

Orderings (the controller's timing contract, docs/fmus/controller.md):

* ``"sequential"`` (default): at t_k the controller takes the plant's sample at t_k and
  steps first; its ``i_ref`` drives the plant over [t_k, t_k + h] (zero delay).
* ``"parallel"``: both FMUs step from the values at t_k, so the plant holds the command
  the controller computed one step earlier (one step of delay).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from ctypes import c_double

import numpy as np

from arcosim.errors import UserError
from arcosim.host import stepping
from arcosim.host.instance import FmuInstance
from arcosim.host.master import MEASURED, Recording

ORDERINGS = ("sequential", "parallel")
#: The controller's outputs a run records.
CONTROLLER_OUTPUTS = ("i_ref", "theta_hat_ctrl", "i_ff", "i_fb")


def control_loop(
    controller: FmuInstance,
    plant: FmuInstance,
    theta_ref: Sequence[float],
    h: float,
    record_plant: Sequence[str] = (),
    plant_parameters: Mapping[str, float | int | bool] | None = None,
    controller_parameters: Mapping[str, float | int | bool] | None = None,
    ordering: str = "sequential",
    plant_inputs: Mapping[str, Sequence[float]] | None = None,
    t0: float = 0.0,
) -> Recording:
    """Run controller and plant for ``len(theta_ref)`` steps of ``h`` seconds.

    Parameters
    ----------
    controller, plant : FmuInstance
        Freshly instantiated FMUs (``ActionReactionController``, ``MotorChainPlant``),
        not yet initialized.
    theta_ref : sequence of float
        The target of the controlled mass at each step (rad), shape ``(N,)``.
    h : float
        Communication step (s), finite and > 0.
    record_plant : sequence of str
        Plant outputs to record after every step; the controller's
        :data:`CONTROLLER_OUTPUTS` are always recorded.
    plant_parameters, controller_parameters : mapping of str to value, optional
        Start values by FMU variable name (in the variable's unit).
    ordering : {"sequential", "parallel"}
        See the module doc.
    plant_inputs : mapping of str to sequence of float, optional
        Other Real inputs of the plant (``"tau_ext[3]"``, N·m), one value per step,
        shape ``(N,)`` each, held over the step.
    t0 : float
        Start time (s).

    Returns
    -------
    Recording
        Sample k is the state at ``t0 + k h``: the plant's outputs and the command the
        controller computed from them (``controller.i_ref``, held over the next step in
        sequential order; at the last sample, which no step took, the command last
        computed); signals ``"plant.<name>"`` and ``"controller.<name>"``.

    Raises
    ------
    UserError
        Bad arguments, or an FMU refused its parameters or a step (its log is the message).

    Examples
    --------
    >>> folder = arcosim.ensure_built(3)
    >>> from arcosim.host.control_loop import control_loop
    >>> with (
    ...     arcosim.FmuInstance(folder / "ActionReactionController.fmu", "controller") as c,
    ...     arcosim.FmuInstance(folder / "MotorChainPlant.fmu", "plant") as p,
    ... ):
    ...     run = control_loop(c, p, [1.0] * 200, 1e-3, ["theta[3]"])
    >>> run.time.shape, float(run["controller.i_ref"][1]) > 0  # the move has started
    ((201,), True)
    """
    if ordering not in ORDERINGS:
        raise UserError(f"ordering {ordering!r}: use one of {', '.join(ORDERINGS)}")
    stepping.check_step(h)
    targets = [float(x) for x in theta_ref]
    steps = len(targets)
    extra = stepping.plant_inputs(plant, plant_inputs or {}, steps)
    plant.initialize(plant_parameters, t0)
    measured = plant.real_port(MEASURED)
    sensors = controller.real_port(["theta_ref", *MEASURED])
    stepping.check_status(measured.get(), plant, "reading the sensors", t0)
    sensors.values[0] = targets[0] if targets else 0.0
    sensors.values[1:] = list(measured.values)
    stepping.check_status(sensors.send(sensors.values), controller, "taking the sensors", t0)
    controller.initialize(controller_parameters, t0)
    command = controller.real_port(["i_ref"])
    drive = plant.real_port(["i_ref", *extra])
    read_plant, read_controller = (
        stepping.recorder(plant, record_plant),
        stepping.recorder(controller, CONTROLLER_OUTPUTS),
    )
    plant_log = np.empty((steps + 1, len(record_plant)))
    controller_log = np.empty((steps + 1, len(CONTROLLER_OUTPUTS)))
    plant_log[0] = read_plant()
    plant_step, plant_c = plant.step_call()
    ctrl_step, ctrl_c = controller.step_call()
    t_c, h_c = c_double(t0), c_double(h)
    rows = list(zip(*extra.values())) if extra else None
    held = 0.0  # the command the plant holds over the next step
    for k in range(steps):
        t_c.value = t = t0 + k * h
        stepping.check_status(measured.get(), plant, "reading the sensors", t)
        sensors.values[0] = targets[k]
        sensors.values[1:] = list(measured.values)
        stepping.check_status(sensors.send(sensors.values), controller, "taking the sensors", t)
        if ordering == "parallel":  # the plant steps on the command read before this step
            drive.values[0] = held
        if ctrl_step(ctrl_c, t_c, h_c, 1) > 1:
            stepping.check_status(2, controller, "stepping", t)
        stepping.check_status(command.get(), controller, "reading i_ref", t)
        controller_log[k] = read_controller()
        if ordering == "sequential":
            drive.values[0] = command.values[0]
        if rows is not None:
            drive.values[1:] = list(rows[k])
        stepping.check_status(drive.send(drive.values), plant, "taking i_ref", t)
        if plant_step(plant_c, t_c, h_c, 1) > 1:
            stepping.check_status(2, plant, "stepping", t)
        held = command.values[0]
        plant_log[k + 1] = read_plant()
    controller_log[steps] = controller_log[steps - 1] if steps else 0.0
    plant.time = controller.time = t0 + steps * h
    recording = Recording(time=t0 + np.arange(steps + 1) * h)
    recording.signals.update(stepping.signals("plant", record_plant, plant_log))
    recording.signals.update(stepping.signals("controller", CONTROLLER_OUTPUTS, controller_log))
    recording.units.update({f"plant.{name}": plant.unit(name) for name in record_plant})
    recording.units.update(
        {f"controller.{name}": controller.unit(name) for name in CONTROLLER_OUTPUTS}
    )
    return recording
