"""An independent drive simulator for testing identification (numpy/scipy only).

Written apart from the project's plant (it imports nothing of ``flexchain`` or the
FMUs), so that identification is tested on logs the project's own physics did not
make. A motor (inertia J_m, viscous D_m, Coulomb f_c with sticking) drives a chain of
n masses (J_i, springs k_i with dampers B_i, k_1 from the motor to J_1). Between
friction events the dynamics are linear and are advanced by the exact zero-order-hold
discretization (matrix exponential) over each sample step; a step in which the motor
velocity reverses, or a stuck motor breaks away, is redone in sub-steps and the event
is placed by a secant step inside the sub-step where it happens. While stuck the
motor is held still and the chain rings against it, until the torque on the motor
other than friction exceeds f_c.

Drive: a first-order current loop (bandwidth ``current_bandwidth``) follows the
reference held over each sample step; the reference is either an open-loop current
(A, a function of time) or the output of a PI speed loop on the encoder's speed,
optionally inside a P position loop on the encoder's angle. The
log records, per sample k: the mean current over the step ending at sample k plus a
sensor offset and Gaussian noise (A); the encoder angle (whole counts, rad); its
backward difference (rad/s). An optional load torque (constant plus a slow sine) acts
on one load mass.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg


@dataclass(frozen=True)
class Drive:
    """A motor and its load chain, the drive electronics and the sensors.

    Attributes:
        J_m: motor inertia (kg·m²).
        k_t: torque constant (N·m/A).
        J: load inertias (kg·m²), shape (n,).
        k: springs (N·m/rad), k[0] from the motor to J[0].
        B: spring dampers (N·m·s/rad).
        D_m: motor viscous friction (N·m·s/rad).
        f_c: motor Coulomb friction (N·m); the static friction equals it.
        current_bandwidth: current loop bandwidth (rad/s); ``inf`` for none.
        current_offset: current sensor offset (A).
        current_noise: current sensor noise, standard deviation (A).
        counts: encoder counts per revolution (0: exact angle).
        load_torque: constant load torque (N·m), braking positive motion (a positive
            value acts on the load mass in the negative direction).
        load_sine: (amplitude N·m, frequency rad/s) of a sine load torque.
        load_mass: index (1…n) of the mass the load torque acts on.
        star: each mass hangs on its own spring and damper from the motor (k[i], B[i]
            between the motor and J[i]: a flexible link's modes) instead of the chain.
    """

    J_m: float
    k_t: float
    J: tuple[float, ...]
    k: tuple[float, ...]
    B: tuple[float, ...]
    D_m: float = 0.0
    f_c: float = 0.0
    current_bandwidth: float = np.inf
    current_offset: float = 0.0
    current_noise: float = 0.0
    counts: int = 2000
    load_torque: float = 0.0
    load_sine: tuple[float, float] = (0.0, 0.0)
    load_mass: int = 0  # 0: the last mass
    star: bool = False  # each mass on its own spring to the motor (a flexible link's modes)

    @property
    def n(self) -> int:
        return len(self.J)


@dataclass(frozen=True)
class SpeedLoop:
    """A PI speed controller on the encoder's backward-difference speed.

    Attributes:
        kp: proportional gain (A·s/rad).
        ki: integral gain (A/rad).
        reference: speed reference (rad/s) as a function of time (s); with
            ``position_gain``, the position reference (rad) instead.
        limit: current limit (A).
        position_gain: gain (1/s) of a P position loop around the speed loop, on the
            encoder angle: speed reference = position_gain · (reference − angle); 0:
            no position loop.
    """

    kp: float
    ki: float
    reference: Callable[[np.ndarray], np.ndarray]
    limit: float = np.inf
    position_gain: float = 0.0


@dataclass
class Log:
    """What the drive recorded, and the truth."""

    time: np.ndarray
    i_a: np.ndarray
    omega_m: np.ndarray
    theta_m: np.ndarray
    theta_true: np.ndarray  # motor and load angles, shape (N, n + 1)
    omega_true: np.ndarray  # motor velocity (rad/s), shape (N,)
    i_true: np.ndarray  # mean current over each step (A), shape (N,)
    load_torque: np.ndarray  # N·m, shape (N,)
    stuck_fraction: float = 0.0


class _Model:
    """Continuous linear model, state ``[θ_0…θ_n, ω_0…ω_n, i, ∫i]``, inputs
    ``[i_ref, friction torque on the motor, load torque]``; moving or stuck."""

    def __init__(self, drive: Drive) -> None:
        n = drive.n
        m = n + 1
        J = np.array([drive.J_m, *drive.J], dtype=float)
        K = np.zeros((m, m))
        C = np.zeros((m, m))
        for j, (kj, bj) in enumerate(zip(drive.k, drive.B)):
            a = 0 if drive.star else j  # the spring's motor-side end
            for M, v in ((K, kj), (C, bj)):
                M[a, a] += v
                M[j + 1, j + 1] += v
                M[a, j + 1] -= v
                M[j + 1, a] -= v
        C[0, 0] += drive.D_m
        size = 2 * m + 2
        A = np.zeros((size, size))
        A[:m, m : 2 * m] = np.eye(m)
        A[m : 2 * m, :m] = -K / J[:, None]
        A[m : 2 * m, m : 2 * m] = -C / J[:, None]
        Bu = np.zeros((size, 3))
        wc = drive.current_bandwidth
        if np.isfinite(wc):
            A[2 * m, 2 * m] = -wc
            Bu[2 * m, 0] = wc
            A[m, 2 * m] = drive.k_t / J[0]
        else:
            # ideal current loop: i follows i_ref at once (i kept equal to i_ref as a state)
            Bu[m, 0] = drive.k_t / J[0]
        A[2 * m + 1, 2 * m] = 1.0
        if not np.isfinite(wc):
            Bu[2 * m + 1, 0] = 1.0
        Bu[m, 1] = 1.0 / J[0]
        load = (drive.load_mass or n) if n else 0
        Bu[m + load, 2] = -1.0 / J[load]  # the load torque brakes positive motion
        stuck = A.copy()
        stuck[m, :] = 0.0  # motor held: no acceleration
        stuck[0, :] = 0.0  # and no motion
        stuck_B = Bu.copy()
        stuck_B[m, :] = 0.0
        self.m, self.size, self.J, self.K, self.C = m, size, J, K, C
        self.k_t, self.ideal = drive.k_t, not np.isfinite(wc)
        self.modes = {False: (A, Bu), True: (stuck, stuck_B)}
        self._cache: dict[tuple[bool, float], tuple[np.ndarray, np.ndarray]] = {}

    def step(self, stuck: bool, dt: float) -> tuple[np.ndarray, np.ndarray]:
        key = (stuck, round(dt, 15))
        if key not in self._cache:
            A, Bu = self.modes[stuck]
            big = np.zeros((self.size + 3, self.size + 3))
            big[: self.size, : self.size] = A
            big[: self.size, self.size :] = Bu
            X = scipy.linalg.expm(big * dt)
            self._cache[key] = (X[: self.size, : self.size], X[: self.size, self.size :])
        return self._cache[key]

    def motor_torque(self, x: np.ndarray, i_ref: float) -> float:
        """Torque on the motor other than Coulomb friction (N·m)."""
        m = self.m
        current = i_ref if self.ideal else x[2 * m]
        springs = -(self.K[0] @ x[:m]) - (self.C[0] @ x[m : 2 * m])
        return self.k_t * current + springs


SUBSTEPS = 16


def simulate(
    drive: Drive,
    h: float,
    duration: float,
    current: Callable[[np.ndarray], np.ndarray] | None = None,
    speed_loop: SpeedLoop | None = None,
    seed: int = 0,
    drift: Callable[[float], Drive] | None = None,
    drift_interval: float = 0.1,
) -> Log:
    """Simulate ``duration`` s sampled every ``h`` s; open loop (``current``: reference
    current, A, of time) or closed loop (``speed_loop``). The motor starts at rest.

    ``drift``: the drive at time t (s), taken every ``drift_interval`` s (its springs,
    dampers, friction and constant load torque may change; its masses and sensors may
    not), for a plant that wears or is loaded while it runs; None: ``drive`` throughout."""
    if (current is None) == (speed_loop is None):
        raise ValueError("give either a current reference or a speed loop")
    model = _Model(drive)
    every = max(1, round(drift_interval / h)) if drift is not None else 0
    load_step = 0.0  # the drift's change of the constant load torque (N·m)
    m = model.m
    count = round(duration / h) + 1
    time = np.arange(count) * h
    rng = np.random.default_rng(seed)
    noise = drive.current_offset + drive.current_noise * rng.standard_normal(count)
    amplitude, w_load = drive.load_sine
    load = drive.load_torque + amplitude * np.sin(w_load * (time - h / 2))
    load[0] = drive.load_torque
    q = 2 * np.pi / drive.counts if drive.counts else 0.0
    f_c = drive.f_c

    def encoder(angle: float) -> float:
        return float(np.floor(angle / q) * q) if q else angle

    x = np.zeros(model.size)
    stuck = f_c > 0.0
    theta = np.zeros((count, m))
    omega = np.zeros(count)
    i_mean = np.zeros(count)
    enc = np.zeros(count)
    enc[0] = encoder(0.0)
    refs = None if current is None else np.asarray(current(time), dtype=float)
    integral = 0.0
    stuck_steps = 0
    speed_ref = None if speed_loop is None else np.asarray(speed_loop.reference(time), float)
    for k in range(1, count):
        if every and (k - 1) % every == 0:
            worn = drift(float(time[k - 1]))
            model, f_c = _Model(worn), worn.f_c
            load_step = worn.load_torque - drive.load_torque
        if refs is not None:
            i_ref = float(refs[k - 1])
        else:
            w_meas = (enc[k - 1] - enc[k - 2]) / h if k >= 2 else 0.0
            target = speed_ref[k - 1]
            if speed_loop.position_gain:
                target = speed_loop.position_gain * (target - enc[k - 1])
            error = target - w_meas
            unclamped = speed_loop.kp * error + integral + speed_loop.ki * h * error
            i_ref = float(np.clip(unclamped, -speed_loop.limit, speed_loop.limit))
            if i_ref == unclamped:
                integral += speed_loop.ki * h * error
        start_integral = x[-1]
        x, stuck = _advance(model, x, stuck, i_ref, float(load[k]) + load_step, f_c, h)
        stuck_steps += stuck
        theta[k] = x[:m]
        omega[k] = x[m]
        i_mean[k] = (x[-1] - start_integral) / h
        enc[k] = encoder(float(x[0]))
    omega_m = np.concatenate([[0.0], np.diff(enc) / h])
    i_mean[0] = 0.0
    return Log(
        time=time,
        i_a=i_mean + noise,
        omega_m=omega_m,
        theta_m=enc,
        theta_true=theta,
        omega_true=omega,
        i_true=i_mean,
        load_torque=load,
        stuck_fraction=stuck_steps / max(count - 1, 1),
    )


def _advance(
    model: _Model, x: np.ndarray, stuck: bool, i_ref: float, load: float, f_c: float, h: float
) -> tuple[np.ndarray, bool]:
    """One sample step; friction events are located in sub-steps."""
    trial, ok = _try(model, x, stuck, i_ref, load, f_c, h)
    if ok:
        return trial, stuck
    dt = h / SUBSTEPS
    remaining = h
    for _ in range(4 * SUBSTEPS + 8):
        if remaining <= 1e-15 * h:
            break
        step = min(dt, remaining)
        trial, ok = _try(model, x, stuck, i_ref, load, f_c, step)
        if ok:
            x, remaining = trial, remaining - step
            continue
        # event inside this sub-step: place it by a secant step, switch mode there
        fraction = _event_fraction(model, x, trial, stuck, i_ref, f_c)
        part = max(fraction * step, 0.0)
        if part > 0.0:
            x = _move(model, x, stuck, i_ref, load, f_c, part)
        remaining -= part
        stuck = _new_mode(model, x, stuck, i_ref, f_c)
    if remaining > 1e-15 * h:  # events bunched closer than the secant resolves
        x = _move(model, x, stuck, i_ref, load, f_c, remaining)
    return x, stuck


def _friction(model: _Model, x: np.ndarray, stuck: bool, i_ref: float, f_c: float) -> float:
    if stuck or f_c == 0.0:
        return 0.0
    w = x[model.m]
    if w != 0.0:
        return -f_c * np.sign(w)
    return -f_c * np.sign(model.motor_torque(x, i_ref))


def _move(model, x, stuck, i_ref, load, f_c, dt) -> np.ndarray:
    F, G = model.step(stuck, dt)
    u = np.array([i_ref, _friction(model, x, stuck, i_ref, f_c), load])
    out = F @ x + G @ u
    if stuck:
        out[model.m] = 0.0
    return out


def _try(model, x, stuck, i_ref, load, f_c, dt) -> tuple[np.ndarray, bool]:
    out = _move(model, x, stuck, i_ref, load, f_c, dt)
    if f_c == 0.0:
        return out, True
    m = model.m
    if stuck:
        return out, abs(model.motor_torque(out, i_ref)) <= f_c
    w0, w1 = x[m], out[m]
    if w0 == 0.0:
        w0 = -_friction(model, x, stuck, i_ref, f_c)  # the direction it starts moving
    return out, (w0 > 0.0) == (w1 > 0.0) or w1 == 0.0


def _event_fraction(model, x0, x1, stuck, i_ref, f_c) -> float:
    m = model.m
    if stuck:
        a = abs(model.motor_torque(x0, i_ref)) - f_c
        b = abs(model.motor_torque(x1, i_ref)) - f_c
    else:
        a, b = x0[m], x1[m]
    if a == b:
        return 1.0
    return float(np.clip(a / (a - b), 0.0, 1.0))


def _new_mode(model, x, stuck, i_ref, f_c) -> bool:
    """At an event: stick when the motor torque cannot overcome static friction."""
    if stuck:
        return False  # broke away
    x[model.m] = 0.0
    return abs(model.motor_torque(x, i_ref)) <= f_c


def multisine(
    lines: np.ndarray, amplitude: float, seed: int = 1, slope: float = 0.0
) -> Callable[[np.ndarray], np.ndarray]:
    """Sum of sines at ``lines`` (rad/s) with random phases; line j's amplitude is
    ∝ lines_j^slope, scaled so that they add up to ``amplitude`` (slope 0: each
    ``amplitude / len(lines)``)."""
    phases = np.random.default_rng(seed).uniform(0, 2 * np.pi, len(lines))
    lines = np.asarray(lines, dtype=float)
    weights = lines**slope
    weights = amplitude * weights / weights.sum()

    def signal(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        return np.sin(np.outer(t, lines) + phases) @ weights

    return signal
