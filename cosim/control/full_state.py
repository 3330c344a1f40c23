"""The state feedback's own loop: the true angles and velocities of every mass fed back.

From a :class:`~arcosim.fmu.flexchain.control.design.ControllerDesign`: ``x ← F x + g u``
with ``u = −K x``, broken at the current for the margins (the loop gain
``L(z) = K (zI − F)⁻¹ g``), and the same gain on the plant a model error makes of the
chain. The upper bound the sensorless loop is measured against.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from arcosim.fmu.flexchain.chain import state_space
from arcosim.fmu.flexchain.control.design import (
    ControllerDesign,
    hold_discretize,
    indexed_values,
)

#: Frequencies the loop gain is evaluated at, log-spaced up to Nyquist (a count).
FREQUENCIES = 20000


def slowest(poles: np.ndarray, h: float) -> tuple[float, float]:
    """The slowest of discrete poles: its decay rate (1/s; negative: growing) and its
    frequency (rad/s).

    Examples
    --------
    >>> [round(x, 2) for x in slowest(np.array([0.99, 0.5]), 1e-3)]
    [10.05, 0.0]
    """
    worst = poles[np.argmax(np.abs(poles))]
    return -math.log(float(abs(worst))) / h, abs(float(np.angle(worst))) / h


def decay(poles: np.ndarray, h: float) -> float:
    """The slowest decay rate of discrete poles (1/s; negative: growing).

    Examples
    --------
    >>> round(decay(np.array([0.99, 0.5]), 1e-3), 2)
    10.05
    """
    return slowest(poles, h)[0]


def closed_loop(design: ControllerDesign, truth: Mapping[str, float] | None = None) -> np.ndarray:
    """``F − g K`` on the chain ``truth`` (the design's own model when None).

    Parameters
    ----------
    design : ControllerDesign
        The gain K and the step h.
    truth : mapping of str to float, optional
        The plant under the observer's names (``J_mo``, ``k_to``, ``D_m``, ``J[i]``,
        ``k[i]``, ``B[i]``).

    Returns
    -------
    numpy.ndarray
        Shape ``(2n + 2, 2n + 2)``.
    """
    if truth is None:
        F, g = np.array(design.F), np.array(design.g)
    else:
        J, k, B = (indexed_values(truth, name) for name in ("J", "k", "B"))
        A, b = state_space(truth["J_mo"], truth["k_to"], truth["D_m"], J, k, B)
        F_, g_ = hold_discretize(A, b, design.h)
        F, g = np.array(F_), np.array(g_)
    return F - np.outer(g, design.K)


def loop_gain(design: ControllerDesign, w: np.ndarray) -> np.ndarray:
    """``L(e^{jωh}) = K (e^{jωh} I − F)⁻¹ g`` at the frequencies ``w`` (rad/s), shape
    ``(len(w),)``."""
    F, g, K = np.array(design.F), np.array(design.g), np.array(design.K)
    eye = np.eye(len(F))
    return np.array([K @ np.linalg.solve(np.exp(1j * x * design.h) * eye - F, g) for x in w])


def margins(design: ControllerDesign) -> dict[str, float]:
    """The full-state loop's margins, broken at the current.

    Parameters
    ----------
    design : ControllerDesign
        From :func:`~arcosim.fmu.flexchain.control.design.design_controller`.

    Returns
    -------
    dict of str to float
        ``slowest_decay`` (1/s), ``phase_margin`` (degrees) at ``crossover`` (rad/s),
        ``delay_margin`` (s: the smallest phase margin over its crossover frequency),
        ``max_sensitivity`` (max |1/(1 + L)|, dimensionless) and ``decay_one_step_late``
        (1/s: the command applied one step later, as a parallel master does).

    Examples
    --------
    >>> from arcosim.fmu.flexchain.control.design import design_controller
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> m = margins(design_controller(chain, h=1e-3))
    >>> m["phase_margin"] > 45.0
    True
    """
    h = design.h
    low = min(0.1, 0.01 * design.bandwidth)  # rad/s, well below any crossover
    w = np.logspace(math.log10(low), math.log10(math.pi / h), FREQUENCIES)
    L = loop_gain(design, w)
    cross = np.flatnonzero(np.diff(np.sign(np.abs(L) - 1.0)))
    pm = [(180.0 - abs(math.degrees(np.angle(L[i]))), float(w[i])) for i in cross]
    phase, at = min(pm) if pm else (math.inf, math.nan)
    F, g, K = np.array(design.F), np.array(design.g), np.array(design.K)
    delayed = np.block([[F, g[:, None]], [-K[None, :], np.zeros((1, 1))]])
    return {
        "slowest_decay": decay(np.linalg.eigvals(closed_loop(design)), h),
        "phase_margin": phase,
        "crossover": at,
        "delay_margin": min((math.radians(p) / x for p, x in pm), default=math.inf),
        "max_sensitivity": float(np.abs(1.0 / (1.0 + L)).max()),
        "decay_one_step_late": decay(np.linalg.eigvals(delayed), h),
    }


def decay_on(design: ControllerDesign, truth: Mapping[str, float]) -> tuple[float, float]:
    """The full-state loop's slowest pole with the design's gain on the plant ``truth``:
    its decay (1/s) and frequency (rad/s) (:func:`slowest`)."""
    return slowest(np.linalg.eigvals(closed_loop(design, truth)), design.h)
