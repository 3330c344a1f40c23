"""The flexible link, for the tests: its FMUs built for a few element counts, runs of them
through fmpy, the continuous Euler–Bernoulli beam's frequencies from its boundary-value
problem (independent of the finite elements), and modes read off a free response."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from arcosim.host.instance import FmuInstance

#: The link of the defaults, without friction, noise or encoder: the physics alone.
IDEAL = {"f_c": 0.0, "i_noise_std": 0.0, "encoder_cpr": 0, "D_m": 0.0}


def states(elements: int) -> list[str]:
    """The FMU's outputs that make up its whole mechanical state."""
    arrays = ("w", "w_slope", "w_rate", "w_slope_rate")
    nodal = [f"{a}[{k}]" for a in arrays for k in range(1, elements + 1)]
    return ["theta_m_true", "omega_m_true", *nodal]


def run(fmu: Path, parameters: dict, current: np.ndarray, h: float, names: list[str]) -> np.ndarray:
    """The outputs ``names`` after each step of ``h`` s with the current command ``current``
    (A, one value per step), shape ``(len(current), len(names))``."""
    rows = []
    with FmuInstance(fmu, "link") as link:
        link.initialize(parameters)
        for k, i_ref in enumerate(current):
            link.set({"i_ref": float(i_ref)})
            assert link.do_step(k * h, h) == 0, link.messages
            rows.append(link.get(names))
    return np.array(rows)


def modes_of_free_response(x: np.ndarray, h: float) -> np.ndarray:
    """Undamped frequencies (rad/s, ascending, the rigid motion left out) of the linear
    system whose free response is the state sequence ``x`` (rows: samples): the one-step
    map fitted by least squares on the response's own subspace, its eigenvalues e^{λh}."""
    past, future = x[:-1].T, x[1:].T
    u, s, vt = np.linalg.svd(past, full_matrices=False)
    keep = s > 1e-9 * s[0]
    u, s, vt = u[:, keep], s[keep], vt[keep]
    step_map = u.T @ future @ vt.T / s
    lam = np.log(np.linalg.eigvals(step_map).astype(complex)) / h
    omega = np.abs(lam)
    return np.unique(np.round(np.sort(omega[(lam.imag > 0) & (omega > 1e-3)]), 6))


def beam_frequencies(EI, rhoA, L, m_tip=0.0, J_tip=0.0, r=0.0, J_m=None, count=3) -> np.ndarray:
    """The first ``count`` natural frequencies (rad/s) of the continuous beam: clamped at
    the root (``J_m`` None: the hub locked) or clamped to a free hub of inertia ``J_m`` at
    radius ``r``; tip mass and tip inertia at x = L. The roots in β of the determinant of
    the boundary conditions on y = A cosh βx + B sinh βx + C cos βx + D sin βx, the
    absolute deflection (y'''' = β⁴ y, ω = β² sqrt(EI/ρA))."""

    def basis(x, b):  # rows: y, y', y'', y''' of the four functions at x
        ch, sh, c, s = np.cosh(b * x), np.sinh(b * x), np.cos(b * x), np.sin(b * x)
        return np.array(
            [
                [ch, sh, c, s],
                [b * sh, b * ch, -b * s, b * c],
                [b**2 * ch, b**2 * sh, -(b**2) * c, -(b**2) * s],
                [b**3 * sh, b**3 * ch, b**3 * s, -(b**3) * c],
            ]
        )

    def determinant(beta):
        w2 = beta**4 * EI / rhoA
        root, tip = basis(0.0, beta), basis(L, beta)
        if J_m is None:
            rows = [root[0], root[1]]  # y(0) = y'(0) = 0
        else:  # y(0) = r y'(0); -ω² J_m y'(0) = EI y''(0) - r EI y'''(0)
            rows = [root[0] - r * root[1], w2 * J_m * root[1] + EI * (root[2] - r * root[3])]
        rows += [EI * tip[2] - w2 * J_tip * tip[1], EI * tip[3] + w2 * m_tip * tip[0]]
        m = np.array(rows)
        return np.linalg.det(m / np.abs(m).max(axis=1, keepdims=True))

    grid = np.linspace(0.05, 60.0, 24000) / L
    values = [determinant(b) for b in grid]
    roots = [
        brentq(determinant, grid[k], grid[k + 1], xtol=1e-14)
        for k in range(len(grid) - 1)
        if values[k] * values[k + 1] < 0
    ]
    return np.array(roots[:count]) ** 2 * np.sqrt(EI / rhoA)
