"""Closed loops of the motion controller on the Python reference plant, for the tests.

The plant is :class:`arcosim.plant.motorchain.physics.PlantPhysics` (exact over each
step, Coulomb friction with sticking) read by the plant FMU's sensors: the encoder
floors the angle to whole counts, the velocity is the backward difference of the
measured angle, the current carries white noise. ``delay = 1`` applies each command one
step late, as a parallel (Jacobi) master does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control.controller import MotionController, design_controller
from arcosim.fmu.flexchain.noise import quantize
from arcosim.plant.motorchain.physics import PlantPhysics

#: The bench's first two masses: clamped modes 11.0 and 28.7 rad/s.
BENCH_2 = dict(J=(5.15299e-4, 5.15299e-4), k=(0.1627, 0.1627), B=(8.88e-6, 8.88e-6))
#: Five unequal masses (the accuracy benchmark's), modes from about 14 rad/s.
FIVE = dict(
    J=(2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4),
    k=(0.4, 0.3, 0.5, 0.35, 0.45),
    B=(1.5e-5,) * 5,
)
ACTUATOR = dict(J_m=defaults.J_M, k_t=defaults.K_T, D_m=defaults.D_M, f_c=defaults.F_C)


def observer_params(
    J, k, B, J_m=defaults.J_M, k_t=defaults.K_T, D_m=defaults.D_M, f_c=defaults.F_C
) -> dict[str, float]:
    """The chain under the observer FMU's parameter names."""
    params = {"J_mo": J_m, "k_to": k_t, "D_m": D_m, "f_c": f_c}
    for name, values in (("J", J), ("k", k), ("B", B)):
        params.update({f"{name}[{i + 1}]": v for i, v in enumerate(values)})
    return params


@dataclass
class Run:
    """One closed-loop run: time (s), every body's angle (rad), the motor's measured
    angle (rad) and the commands (A), one row per sample."""

    time: np.ndarray
    angles: np.ndarray  # (samples, n + 1)
    theta_m: np.ndarray
    i_ref: np.ndarray
    i_ff: np.ndarray
    i_fb: np.ndarray
    theta_hat: np.ndarray
    extra: dict = field(default_factory=dict)

    def settling_time(self, target: float, band: float, mass: int = -1) -> float:
        """Last time the mass was outside ``target ± band`` (s)."""
        outside = np.abs(self.angles[:, mass] - target) > band
        return float(self.time[np.nonzero(outside)[0][-1]]) if outside.any() else 0.0

    def residual_rms(self, target: float, last: float = 2.0, mass: int = -1) -> float:
        """rms of the mass's angle about the target over the last ``last`` s (rad)."""
        tail = self.time >= self.time[-1] - last
        return float(np.sqrt(np.mean((self.angles[tail, mass] - target) ** 2)))


def closed_loop(
    plant: dict,
    model: dict | None = None,
    *,
    stop: float = 6.0,
    h: float = 1e-3,
    target: float = 1.0,
    delay: int = 0,
    full_state: bool = False,
    encoder_cpr: int = defaults.ENCODER_CPR,
    i_noise_std: float = defaults.I_NOISE_STD,
    load_step: tuple[float, float] | None = None,
    seed: int = 1,
    without: frozenset[str] = frozenset(),
    **goals,
) -> Run:
    """Run the controller designed from ``model`` (default: the plant) on ``plant``.

    Parameters
    ----------
    plant, model : dict
        ``J``, ``k``, ``B`` (and actuator terms ``J_m``, ``k_t``, ``D_m``, ``f_c``).
    stop, h : float
        Duration and step (s).
    target : float
        theta_ref from t = 0 on (rad).
    delay : int
        Steps between a command's computation and its application (0 or 1).
    full_state : bool
        Feed the true state (:meth:`MotionController.step_full_state`).
    encoder_cpr, i_noise_std
        The sensors.
    load_step : tuple of float or None
        (time s, torque N·m) on the last mass from that time on.
    seed : int
        Current noise seed.
    without : frozenset of str
        The controller's parts switched off (``controller.PARTS``).
    goals
        Passed to :func:`design_controller` (move_time, bandwidth, i_max, control_mass).
    """
    plant = {**ACTUATOR, **plant}
    model = {**ACTUATOR, **(model or plant)}
    params = observer_params(**model)
    params["encoder_cpr"] = encoder_cpr
    ctrl = MotionController(design_controller(params, h=h, **goals), without)
    physics = PlantPhysics(
        plant["J_m"], plant["k_t"], plant["D_m"], plant["f_c"], plant["J"], plant["k"], plant["B"]
    )
    n = len(plant["J"])
    rng = np.random.default_rng(seed)
    steps = round(stop / h)
    rows = []
    pending = [0.0] * (delay + 1)
    theta_meas = quantize(0.0, encoder_cpr)
    i_a = 0.0
    omega_meas = 0.0
    for k in range(steps + 1):
        t = k * h
        x = physics.x
        if full_state:
            cmd = ctrl.step_full_state(h, target, x[: n + 1], x[n + 1 : 2 * n + 2], i_a)
        else:
            cmd = ctrl.step(h, target, i_a, omega_meas, theta_meas)
        rows.append((t, *x[: n + 1], theta_meas, cmd, ctrl.i_ff, ctrl.i_fb, ctrl.theta_hat_ctrl))
        pending.append(cmd)
        applied = pending.pop(0)
        tau = [0.0] * n
        if load_step is not None and t >= load_step[0]:
            tau[-1] = load_step[1]
        physics.advance(h, applied, tau)
        i_a = physics.step_average_current(h) + i_noise_std * rng.standard_normal()
        new = quantize(physics.x[0], encoder_cpr)
        omega_meas = (new - theta_meas) / h if encoder_cpr else physics.x[n + 1]
        theta_meas = new
    a = np.array(rows)
    return Run(
        a[:, 0],
        a[:, 1 : n + 2],
        a[:, n + 2],
        a[:, n + 3],
        a[:, n + 4],
        a[:, n + 5],
        a[:, n + 6],
        extra={"controller": ctrl},
    )


#: The paper's bench (n = 3, the FMUs' defaults): clamped modes 7.5, 21.5, 31.8 rad/s.
BENCH_3 = dict(J=tuple(defaults.J), k=(defaults.K,) * 3, B=(defaults.B,) * 3)
