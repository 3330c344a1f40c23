"""The controller's margins as docs/control.md quotes them (``-m benchmarks.control_margins``).

For the bench's two- and three-mass chains and a five-mass chain, the design at
T = 1 s (ω_c = 8 rad/s), h = 1 ms: the chain's modes, the closed loop's slowest decay,
the full-state loop broken at the current (phase margin, delay margin, peak of the
sensitivity), the slowest decay with every J_i, k_i scaled by independent factors in
[0.9, 1.1] (20 seeds) and the two corners, and with one step of delay.

Then the same decays of the *sensorless* loop, the estimator in it: the controller's own
code (:class:`~arcosim.fmu.flexchain.motion_control.MotionController`) on the plant's
(:class:`~arcosim.plant.motorchain.physics.PlantPhysics`), with an exact encoder and no
Coulomb friction, so that the loop is linear; its one-step map is differentiated by
finite differences over every float the two objects hold (:func:`sensorless_jacobian`).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control_design import design_controller, hold_discretize, plant_matrices
from arcosim.fmu.flexchain.motion_control import MotionController
from arcosim.plant.motorchain.physics import PlantPhysics

H = 1e-3
MOTOR = {"J_mo": defaults.J_M, "k_to": defaults.K_T, "D_m": defaults.D_M, "f_c": defaults.F_C}
CHAINS = {
    "bench, two masses": (defaults.J[:2], (defaults.K,) * 2, (defaults.B,) * 2),
    "bench, three masses": (defaults.J, (defaults.K,) * 3, (defaults.B,) * 3),
    "five masses": ((2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4), (0.4, 0.3, 0.5, 0.35, 0.45), (1.5e-5,) * 5),
}


def params(J, k, B) -> dict[str, float]:
    """The chain under the observer's names."""
    out = dict(MOTOR)
    for name, values in (("J", J), ("k", k), ("B", B)):
        out.update({f"{name}[{i + 1}]": v for i, v in enumerate(values)})
    return out


#: Attributes the linearization leaves alone: caches and settings (constant over a run)
#: and clocks (times and the step, which no state feeds back into).
UNPERTURBED = frozenset(
    {"_models", "_designs", "design", "settings", "a", "b", "a_stuck", "b_stuck"}
    | {"t", "_moved", "_h"}
)
#: When the sensorless loop is linearized: after the 1 rad move, at rest (s).
AT_REST = 1.6


@dataclass
class SensorlessLoop:
    """The controller, the plant and what passes between them at the next sample.

    ``signals`` = [i_a (A), ω_m (rad/s), θ_m (rad), the command still pending (A)].
    """

    controller: MotionController
    plant: PlantPhysics
    signals: list[float]
    delay: int


def sensorless_loop(chain: Sequence, model: Sequence, delay: int = 0) -> SensorlessLoop:
    """The controller designed on ``model`` = (J, k, B) driving the plant ``chain``, exact
    encoder, no Coulomb friction, run through a 1 rad move to :data:`AT_REST`.

    Examples
    --------
    >>> loop = sensorless_loop(CHAINS["bench, two masses"], CHAINS["bench, two masses"])
    >>> round(loop.plant.x[2], 3)  # the last mass (rad)
    1.0
    """
    design = design_controller({**params(*model), "f_c": 0.0, "encoder_cpr": 0}, h=H)
    J, k, B = chain
    plant = PlantPhysics(defaults.J_M, defaults.K_T, defaults.D_M, 0.0, J, k, B)
    loop = SensorlessLoop(MotionController(design), plant, [0.0, 0.0, 0.0, 0.0], delay)
    for _ in range(round(AT_REST / H)):
        advance(loop)
    return loop


def advance(loop: SensorlessLoop) -> None:
    """One sample of the loop: the controller's step, then the plant's over h."""
    i_a, omega, theta, pending = loop.signals
    command = loop.controller.step(H, 1.0, i_a, omega, theta)
    applied = pending if loop.delay else command
    n = loop.plant.n
    loop.plant.advance(H, applied, [0.0] * n)
    x = loop.plant.x
    loop.signals = [loop.plant.step_average_current(H), x[n + 1], x[0], command]


def _leaves(obj, path: tuple = (), seen: set | None = None) -> list[tuple]:
    """Paths to every float the object holds (attributes, dict entries, list items)."""
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return []
    seen.add(id(obj))
    items = obj.items() if isinstance(obj, dict) else vars(obj).items()
    found = []
    for key, value in items:
        frozen = getattr(getattr(type(value), "__dataclass_params__", None), "frozen", False)
        if key in UNPERTURBED or frozen:
            continue
        if isinstance(value, float):
            found.append((*path, key))
        elif isinstance(value, list):
            found += [(*path, key, i) for i, v in enumerate(value) if isinstance(v, float)]
        elif isinstance(value, dict) or hasattr(value, "__dict__"):
            found += _leaves(value, (*path, key), seen)
    return found


def _holder(root, path: tuple):
    for key in path[:-1]:
        root = root[key] if isinstance(root, (dict, list)) else getattr(root, key)
    return root


def _get(root, path: tuple) -> float:
    holder = _holder(root, path)
    return holder[path[-1]] if isinstance(holder, (dict, list)) else getattr(holder, path[-1])


def _put(root, path: tuple, value: float) -> None:
    holder = _holder(root, path)
    if isinstance(holder, (dict, list)):
        holder[path[-1]] = value
    else:
        setattr(holder, path[-1], value)


def sensorless_jacobian(loop: SensorlessLoop) -> np.ndarray:
    """The loop's one-step map differentiated at its present state, shape ``(m, m)``.

    Every float of the controller, the plant and the signals is perturbed by a relative
    1e-6; those the step leaves exactly as they were (parameters) are dropped, so the
    eigenvalues are the loop's poles (an exact model puts the state feedback's among them).
    """
    paths = _leaves(loop)
    z0 = np.array([_get(loop, p) for p in paths])

    def stepped(path=None, value=0.0) -> np.ndarray:
        copied = copy.deepcopy(loop)
        if path is not None:
            _put(copied, path, value)
        advance(copied)
        return np.array([_get(copied, p) for p in paths])

    z1 = stepped()
    jac = np.empty((len(paths), len(paths)))
    for j, path in enumerate(paths):
        eps = 1e-6 * max(1.0, abs(z0[j]))
        jac[:, j] = (stepped(path, float(z0[j] + eps)) - z1) / eps
    unit = np.eye(len(paths))
    keep = [i for i in range(len(paths)) if not np.allclose(jac[i], unit[i], atol=1e-7)]
    return jac[np.ix_(keep, keep)]


def sensorless_decay(chain: Sequence, model: Sequence, delay: int = 0) -> tuple[float, float]:
    """The sensorless loop's slowest decay (1/s, negative: growing) and its frequency (rad/s)."""
    poles = np.linalg.eigvals(sensorless_jacobian(sensorless_loop(chain, model, delay)))
    worst = poles[np.argmax(np.abs(poles))]
    return -math.log(abs(worst)) / H, abs(np.angle(worst)) / H


def loop(J, k, B, K) -> np.ndarray:
    """``F − g K`` of the plant (J, k, B) under the gain K."""
    A, b = plant_matrices(defaults.J_M, defaults.K_T, defaults.D_M, J, k, B)
    F, g = hold_discretize(A, b, H)
    return np.array(F) - np.outer(g, K)


def margins(J, k, B) -> dict[str, float]:
    """One row of the table."""
    d = design_controller(params(J, k, B), h=H)
    F, g, K = np.array(d.F), np.array(d.g), np.array(d.K)
    w = np.logspace(-1, math.log10(math.pi / H), 20000)
    eye = np.eye(len(F))
    L = np.array([K @ np.linalg.solve(np.exp(1j * x * H) * eye - F, g) for x in w])
    cross = np.flatnonzero(np.diff(np.sign(np.abs(L) - 1)))
    pm = [(180 - abs(math.degrees(np.angle(L[i]))), w[i]) for i in cross]
    phase, at = min(pm)
    A, _ = plant_matrices(defaults.J_M, defaults.K_T, defaults.D_M, J, k, B)
    ev = np.linalg.eigvals(np.array(A))
    n = len(J)
    rng = np.random.default_rng(29)
    factors = [rng.uniform(0.9, 1.1, (2, n)) for _ in range(20)]
    factors += [np.array([[1.1] * n, [0.9] * n]), np.array([[0.9] * n, [1.1] * n])]
    worst = max(
        np.abs(np.linalg.eigvals(loop(np.array(J) * fj, np.array(k) * fk, B, K))).max()
        for fj, fk in factors
    )
    delayed = np.block([[F, g[:, None]], [-K[None, :], np.zeros((1, 1))]])
    chain = (J, k, B)
    late, _ = sensorless_decay(chain, chain, delay=1)
    models = [(np.array(J) * fj, np.array(k) * fk, B) for fj, fk in factors]
    sensorless = [sensorless_decay(chain, model) for model in models]
    low, at_low = min(sensorless)
    return {
        "modes": sorted({round(float(abs(e)), 1) for e in ev if abs(e.imag) > 1e-6}),
        "slowest_decay": -math.log(np.abs(np.linalg.eigvals(F - np.outer(g, K))).max()) / H,
        "phase_margin_deg": phase,
        "crossover": at,
        "delay_margin_ms": 1e3 * min(math.radians(p) / x for p, x in pm),
        "max_sensitivity": float(np.abs(1 / (1 + L)).max()),
        "worst_decay_10pct": -math.log(worst) / H,
        "decay_one_step_late": -math.log(np.abs(np.linalg.eigvals(delayed)).max()) / H,
        "sensorless_decay": sensorless_decay(chain, chain)[0],
        "sensorless_worst_10pct": low,
        "sensorless_worst_at": at_low,
        "sensorless_corners": [sensorless[-2][0], sensorless[-1][0]],
        "sensorless_one_step_late": late,
    }


def main() -> None:
    """Print the table."""
    for name, chain in CHAINS.items():
        row = margins(*chain)
        print(name, {key: np.round(np.asarray(v, float), 2).tolist() for key, v in row.items()})


if __name__ == "__main__":
    main()
