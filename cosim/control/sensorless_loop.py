"""The sensorless loop's poles, from the controller's and the plant's own code.

The controller (:class:`~arcosim.fmu.flexchain.control.controller.MotionController`, designed
on a model) drives the plant (:class:`~arcosim.plant.motorchain.physics.PlantPhysics`, the
true chain) with an exact encoder and no Coulomb friction, so that the loop is linear
(the encoder's counts, the friction and the hold's dither, which need both, are left
out: they add a limit cycle of a few counts, not an instability). After a 1 rad move the
loop's one-step map is differentiated by finite differences over every float the two
objects hold (caches, frozen settings and clocks left alone; what the step leaves exactly
as it was, a parameter, dropped). With the model exact the state feedback's poles
``eig(F − g K)`` are among the result to 1e-6 (separation; ``tests/test_control_margins.py``).
"""

from __future__ import annotations

import copy
import math
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from arcosim.control.full_state import slowest
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control.controller import MotionController
from arcosim.fmu.flexchain.control.design import design_controller, indexed_values
from arcosim.plant.motorchain.physics import PlantPhysics

#: Attributes the linearization leaves alone: caches and settings (constant over a run)
#: and clocks (times and the step, which no state feeds back into).
UNPERTURBED = frozenset(
    {"_models", "_designs", "design", "settings", "a", "b", "a_stuck", "b_stuck"}
    | {"t", "_moved", "_h", "still"}
    | {"elapsed", "_trusted_for"}  # the move's record's clocks (kept with the refit off)
    | {"_other"}  # the estimator's other gain's designs: a cache
)
#: When the loop is linearized: this long after the move ends (s).
AFTER_MOVE = 0.6
#: With ``hold``: the target, which the step compares with ``theta_ref`` to start a move
#: (a switch, not a state), is left alone too, and so is the dither's own path (a signal
#: generator: its floats follow the step count, whatever the loop does), all but its
#: observer, and the hold's edge keeper (``hold_edge``: a switch between edges of the
#: encoder, which the exact angle here does not have; its low-pass would show as a pole).
HOLD_UNPERTURBED = frozenset({"target"})
#: With ``hold``: how much longer the run may go on for the estimator to take the hold's
#: gain (s; the controller switches once the controlled mass is still).
QUIET_WAIT = 2.0
#: The loop counts as come to rest when, over this last stretch of the run (s), the command
#: stayed below i_max and the controlled mass ends within SETTLE_ANGLE of its target.
SETTLE_WINDOW = 0.1
#: … within this angle of the 1 rad target (rad).
SETTLE_ANGLE = 0.1
#: The finite differences' relative step (dimensionless).
RELATIVE_STEP = 1e-6


@dataclass
class SensorlessLoop:
    """The controller, the plant and what passes between them at the next sample.

    ``signals`` = [i_a (A), ω_m (rad/s), θ_m (rad), the command still pending (A)];
    ``delay`` 1 applies each command one step late (a parallel master), 0 at once;
    ``hold``: linearized with the hold's dither running (:func:`sensorless_loop`);
    ``settled``: whether the run came to rest (:data:`SETTLE_WINDOW`), without which its
    linearization means nothing (a loop pinned at ±i_max shows only the plant's poles).
    """

    controller: MotionController
    plant: PlantPhysics
    signals: list[float]
    delay: int
    hold: bool = False
    settled: bool = True

    @property
    def h(self) -> float:
        """The step (s)."""
        return self.controller.design.h


def sensorless_loop(
    truth: Mapping[str, float],
    model: Mapping[str, float],
    *,
    h: float,
    delay: int = 0,
    hold: bool = False,
    without: frozenset[str] = frozenset(),
    **goals,
) -> SensorlessLoop:
    """The controller designed on ``model`` driving the plant ``truth``, through a 1 rad
    move of the controlled mass to :data:`AFTER_MOVE` after it ends.

    With ``hold`` the controller is designed with the model's encoder (``encoder_cpr``,
    default ``defaults.ENCODER_CPR``) so that its hold's dither runs at rest
    (:mod:`~arcosim.fmu.flexchain.control.hold_dither`: the feedback's motor angle and velocity from
    the dither's observer, as in the runs), while the plant's angle stays exact and
    friction stays out; the loop is run to :data:`AFTER_MOVE` after the dither starts and
    then, up to :data:`QUIET_WAIT` more, until the estimator runs the hold's gain (if it
    never does, it is linearized with the move's, as the FMU would run on).

    Parameters
    ----------
    truth, model : mapping of str to float
        The plant and the controller's model under the observer's names: ``J_mo``
        (kg·m²), ``k_to`` (N·m/A), ``D_m`` (N·m·s/rad), ``J[i]``, ``k[i]``, ``B[i]``;
        the controller's ``g_dist`` (rad/s) from ``model`` when given. Coulomb friction
        and the encoder are left out of both.
    h : float
        The control step (s).
    delay : int
        0: each command acts over the next step; 1: one step later.
    hold : bool
        Linearize at rest with the hold's dither running (above).
    without : frozenset of str
        The controller's parts switched off (``PARTS`` of
        :mod:`~arcosim.fmu.flexchain.control.controller`; none by default, as the FMU runs).
    **goals
        ``control_mass``, ``move_time``, ``bandwidth``, ``i_max``, ``hold_dither`` for
        :func:`~arcosim.fmu.flexchain.control.design.design_controller`.

    Returns
    -------
    SensorlessLoop
        At rest after the move.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> loop = sensorless_loop(chain, chain, h=1e-3)
    >>> round(loop.plant.x[1], 3)  # the load mass (rad)
    1.0
    """
    cpr = model.get("encoder_cpr", defaults.ENCODER_CPR) if hold else 0
    design = design_controller({**model, "f_c": 0.0, "encoder_cpr": cpr}, h=h, **goals)
    if hold and not design.dither_current > 0.0:
        raise ValueError(
            "hold: the design has no dither (give encoder_cpr > 0 and hold_dither > 0)"
        )
    J, k, B = (indexed_values(truth, name) for name in ("J", "k", "B"))
    plant = PlantPhysics(truth["J_mo"], truth["k_to"], truth["D_m"], 0.0, J, k, B)
    loop = SensorlessLoop(
        MotionController(design, without), plant, [0.0, 0.0, 0.0, 0.0], delay, hold
    )
    wait = (1.0 + defaults.HOLD_DITHER_AFTER) * design.move_time if hold else design.move_time
    steps = round((wait + AFTER_MOVE) / h)
    within = deque(maxlen=max(1, round(SETTLE_WINDOW / h)))  # the command below i_max
    for k in range(steps + (round(QUIET_WAIT / h) if hold else 0)):
        if k >= steps and loop.controller.estimator.quiet:
            break
        advance(loop)
        within.append(abs(loop.signals[3]) < design.i_max)
    if not all(within):
        loop.settled = False
    L = design.control_mass
    if not abs(loop.plant.x[L] - 1.0) < SETTLE_ANGLE:
        loop.settled = False
    return loop


def advance(loop: SensorlessLoop) -> None:
    """One sample of the loop: the controller's step, then the plant's over h."""
    h = loop.h
    i_a, omega, theta, pending = loop.signals
    command = loop.controller.step(h, 1.0, i_a, omega, theta)
    applied = pending if loop.delay else command
    n = loop.plant.n
    loop.plant.advance(h, applied, [0.0] * n)
    x = loop.plant.x
    loop.signals = [loop.plant.step_average_current(h), x[n + 1], x[0], command]


def _leaves(
    obj, path: tuple = (), seen: set | None = None, skip: frozenset = UNPERTURBED
) -> list[tuple]:
    """Paths to every float the object holds (attributes, dict entries, list items),
    those named in ``skip`` left out."""
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return []
    seen.add(id(obj))
    if isinstance(obj, dict):
        items = obj.items()
    else:
        items = enumerate(obj) if isinstance(obj, list) else vars(obj).items()
    found = []
    for key, value in items:
        frozen = getattr(getattr(type(value), "__dataclass_params__", None), "frozen", False)
        if key in skip or frozen:
            continue
        if isinstance(value, float):
            found.append((*path, key))
        elif isinstance(value, (list, dict)) or hasattr(value, "__dict__"):
            found += _leaves(value, (*path, key), seen, skip)
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
    :data:`RELATIVE_STEP`; those the step leaves exactly as they were (parameters) are
    dropped, so the eigenvalues are the loop's poles.
    """
    paths = _leaves(loop, skip=UNPERTURBED | (HOLD_UNPERTURBED if loop.hold else frozenset()))
    if loop.hold:
        paths = [p for p in paths if p[:2] != ("controller", "dither") or p[2] == "observer"]
        paths = [p for p in paths if p[:2] != ("controller", "edge")]
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
        eps = RELATIVE_STEP * max(1.0, abs(z0[j]))
        jac[:, j] = (stepped(path, float(z0[j] + eps)) - z1) / eps
    unit = np.eye(len(paths))
    keep = [i for i in range(len(paths)) if not np.allclose(jac[i], unit[i], atol=1e-7)]
    return jac[np.ix_(keep, keep)]


def sensorless_decay(
    truth: Mapping[str, float],
    model: Mapping[str, float],
    *,
    h: float,
    delay: int = 0,
    hold: bool = False,
    without: frozenset[str] = frozenset(),
    **goals,
) -> tuple[float, float]:
    """The sensorless loop's slowest decay and where it is.

    Parameters
    ----------
    truth, model, h, delay, hold, without, **goals
        As :func:`sensorless_loop`.

    Returns
    -------
    tuple of float
        The slowest decay rate (1/s; negative: growing) and that pole's frequency (rad/s);
        (−inf, nan) when the run did not come to rest (``SensorlessLoop.settled``): it
        diverged or saturated, and no pole describes it.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> decay, at = sensorless_decay(chain, chain, h=1e-3)
    >>> decay > 0.0  # 1/s: every pole of the linearized loop decays
    True
    """
    loop = sensorless_loop(truth, model, h=h, delay=delay, hold=hold, without=without, **goals)
    if not loop.settled:
        return -math.inf, math.nan
    return slowest(np.linalg.eigvals(sensorless_jacobian(loop)), h)
