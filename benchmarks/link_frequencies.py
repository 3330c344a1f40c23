"""The flexible link's frequencies against the continuous beam's, for 2, 4 and 8 elements.

The continuous Euler–Bernoulli beam's frequencies from its boundary-value problem
(independent of the finite elements), the link FMU's read off its free responses (hub
held by its friction: clamped; hub free: coupled), and the relative errors; also used by
tests/test_flexlink.py. Prints the table of docs/fmus/link.md:

    python -m benchmarks.link_frequencies            # builds the three links (~1 min)
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from arcosim import FmuInstance
from arcosim.fmu.flexchain import defaults

#: The link of the defaults, without friction, noise or encoder: the physics alone.
IDEAL = {"f_c": 0.0, "i_noise_std": 0.0, "encoder_cpr": 0, "D_m": 0.0}
H = 1e-3  #: the runs' step (s)
LINK = {"EI": defaults.LINK_EI, "rhoA": defaults.LINK_RHOA, "L": defaults.LINK_L}
#: Light damping: it leaves the modes' natural frequencies |λ| exact and removes the
#: element modes above the sampling's Nyquist frequency (π / H) before the fit.
BETA = 5e-5


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

    grid = np.linspace(0.05, 16.0, 1600) / L  # βL to 16: the first three roots and more, 2 apart
    values = [determinant(b) for b in grid]
    roots = [
        brentq(determinant, grid[k], grid[k + 1], xtol=1e-14)
        for k in range(len(grid) - 1)
        if values[k] * values[k + 1] < 0
    ]
    return np.array(roots[:count]) ** 2 * np.sqrt(EI / rhoA)


def clamped_modes(fmu: Path, elements: int, m_tip: float, J_tip: float) -> np.ndarray:
    """The first three modes (rad/s) of the link with its hub held by Coulomb friction: a
    current pulse breaks the hub away, it sticks again, the beam rings on a still hub."""
    current = np.zeros(800)
    current[:15] = 40.0
    parameters = {**IDEAL, "f_c": 1.0, "beta": BETA, "m_tip": m_tip, "J_tip": J_tip}
    x = run(fmu, parameters, current, H, states(elements))
    start = np.flatnonzero(x[:, 1] != 0.0).max() + 150  # stuck for good, element modes gone
    assert len(x) - start >= 300, "the hub did not stay stuck"
    return modes_of_free_response(x[start:, 2:], H)[:3]


def coupled_modes(fmu: Path, elements: int, parameters: dict) -> np.ndarray:
    """The first three modes (rad/s) of hub and link, hub free (no friction): a short
    pulse, then the free response."""
    current = np.zeros(500)
    current[:5] = 1.0
    x = run(fmu, {**IDEAL, "beta": BETA, **parameters}, current, H, states(elements))
    return modes_of_free_response(x[150:], H)[:3]


def eq7_from_the_root_element(x: np.ndarray, elements: int, r: float, beta: float) -> np.ndarray:
    """−EI (w''(0) + β ẇ''(0)) + r EI (w'''(0) + β ẇ'''(0)) of the root element's cubic,
    from the nodal outputs w[1], w_slope[1], w_rate[1], w_slope_rate[1] (columns 0–3)."""
    le, EI = LINK["L"] / elements, LINK["EI"]
    w = x[:, 0] + beta * x[:, 2]
    s = x[:, 1] + beta * x[:, 3]
    curvature = 6.0 * w / le**2 - 2.0 * s / le
    third = -12.0 * w / le**3 + 6.0 * s / le**2
    return -EI * curvature + r * EI * third


def eq7_gaps(fmus: dict[int, Path], r: float = 0.02) -> dict[int, float]:
    """Largest |τ_reac − eq. 7 on the root element's cubic| (N·m) over a 1.5 s two-tone
    run, by number of elements."""
    t = np.arange(1500) * H
    current = 0.4 * np.sin(20.0 * t) + 0.2 * np.sin(150.0 * t)
    names = ["w[1]", "w_slope[1]", "w_rate[1]", "w_slope_rate[1]", "tau_reac"]
    gaps = {}
    for e, fmu in fmus.items():
        x = run(fmu, {**IDEAL, "r_hub": r, "beta": BETA}, current, H, names)
        gaps[e] = float(np.abs(x[:, 4] - eq7_from_the_root_element(x, e, r, BETA)).max())
    return gaps


def main() -> int:
    """Print the relative frequency errors of links of 2, 4 and 8 elements."""
    from arcosim.build import build_link

    tip = {"m_tip": defaults.LINK_M_TIP, "J_tip": 0.0}
    hub = {"r": defaults.LINK_R_HUB, "J_m": defaults.J_M}
    cases = {
        "clamped, no tip mass": ({"m_tip": 0.0, "J_tip": 0.0}, None),
        "clamped, tip mass": (tip, None),
        "coupled (hub free), tip mass": (tip, hub),
    }
    with tempfile.TemporaryDirectory() as tmp:
        fmus = {e: build_link(e, Path(tmp) / f"e{e}" / "FlexLinkPlant.fmu") for e in (2, 4, 8)}
        for name, (ends, free) in cases.items():
            exact = beam_frequencies(**LINK, **ends, **(free or {}))
            print(f"{name}: exact {', '.join(f'{w:.2f}' for w in exact)} rad/s")
            for e, fmu in fmus.items():
                if free is None:
                    got = clamped_modes(fmu, e, **ends)
                else:
                    got = coupled_modes(fmu, e, {"m_tip": ends["m_tip"]})
                errors = [f"{g / w - 1.0:.2e}" for g, w in zip(got, exact, strict=False)]
                print(f"  {e} elements: {', '.join(errors)}")
        gaps = eq7_gaps(fmus)
        print(
            "tau_reac - eq. 7 on the root element (N.m):", {e: f"{g:.2e}" for e, g in gaps.items()}
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
