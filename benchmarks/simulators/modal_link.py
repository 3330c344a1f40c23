"""A flexible link simulated apart from the plant FMU: the continuous beam's own modes.

The link plant FMU discretizes the beam in Hermite finite elements. This simulator shares
none of that: it takes the exact eigenfunctions of the continuous Euler–Bernoulli beam
clamped (on the axis, r = 0) to a hub of inertia J_m that turns freely, truncated to
the first few, and steps their modal equations exactly over each zero-order-hold step
(scipy's matrix exponential). The motor's viscous friction couples the modes; the
damping is Kelvin–Voigt on the bending, EI(1 + β ∂/∂t), so mode j is damped
ζ_j = β ω_j / 2 as in the plant. Sensors as the plant's documentation states them
(docs/fmus/plant.md), written here again: the current as commanded (an ideal current
loop) plus Gaussian noise, the angle floored to whole encoder counts, the velocity its
backward difference. Without a tip mass and without Coulomb friction (the rig it serves,
Quanser's rotary flexible link, has neither).

Modes. With y(x, t) = x θ(t) + w(x, t) the link's displacement in the inertial frame (w
in the hub's frame, w(0) = w'(0) = 0), the free hub–beam system has ρA ÿ + EI y'''' = 0,
y(0) = 0, J_m θ̈ = EI y''(0) (θ = y'(0)), y''(L) = y'''(L) = 0. A mode φ(x) with
ω² = EI β⁴ / ρA is a sin βx + b cos βx + c e^(−βx) + d e^(−β(L−x)) (every term bounded on
[0, L], so the high modes keep their digits); the four conditions give a 4 × 4 matrix in
β whose determinant's roots are the β_j, its null vector the shape. With the modes
normalized to the system's kinetic energy, ∫ρA φ_i φ_j dx + J_m φ_i'(0) φ_j'(0) = δ_ij
(the rigid mode φ_0 = x included), q̈_j + β ω_j² q̇_j + ω_j² q_j = φ_j'(0) (k_t i −
D_m θ̇), θ = Σ φ_j'(0) q_j, y(L) = Σ φ_j(L) q_j, and the link's torque on the hub is
τ_reac = k_t i − D_m θ̇ − J_m θ̈ (the hub's own balance).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from arcosim import multisine
from arcosim.experiments import LINK_DURATION, LinkRig, LinkRun
from arcosim.fmu.flexchain import STEP

#: Flexible modes kept (besides the rigid one): the sixth of the Quanser link is at
#: 2.3·10³ rad/s, under the 1 kHz record's Nyquist frequency; the fit reads 2–4.
MODES = 6
#: Gauss–Legendre points of the normalizing integrals.
QUADRATURE = 200


@dataclass(frozen=True)
class ModalLink:
    """The hub–beam system's modes, normalized to its kinetic energy.

    Attributes
    ----------
    omega : ndarray
        Natural frequencies (rad/s), shape ``(M + 1,)``, the rigid mode's 0 first.
    hub : ndarray
        Each mode's hub rotation φ_j'(0) (rad per unit modal coordinate), shape ``(M + 1,)``.
    tip : ndarray
        Each mode's tip displacement φ_j(L) (m per unit modal coordinate), shape ``(M + 1,)``.
    orthogonality : float
        Largest off-diagonal entry of the modes' mass matrix (should be ~0; a check).
    """

    omega: np.ndarray
    hub: np.ndarray
    tip: np.ndarray
    orthogonality: float


def _conditions(beta: float, L: float, J_m: float, rhoA: float) -> np.ndarray:
    """The four boundary conditions on (sin βx, cos βx, e^(−βx), e^(−β(L−x))), scaled."""
    s, c, e = np.sin(beta * L), np.cos(beta * L), np.exp(-beta * L)
    mu = J_m * beta**3 / rhoA  # the hub's inertia against the beam's, per β
    return np.array(
        [
            [0.0, 1.0, 1.0, e],  # y(0) = 0
            # EI y''(0) + ω² J_m y'(0) = 0, over EI β² (1 + μ)
            [mu / (1 + mu), -1.0 / (1 + mu), (1.0 - mu) / (1 + mu), e],
            [-s, -c, e, 1.0],  # y''(L) / β² = 0
            [-c, s, -e, 1.0],  # y'''(L) / β³ = 0
        ]
    )


def _shape(beta: float, coefficients: np.ndarray, x: np.ndarray, L: float):
    """φ(x) and φ'(x) of the mode with these coefficients."""
    a, b, c, d = coefficients
    ex, eL = np.exp(-beta * x), np.exp(-beta * (L - x))
    phi = a * np.sin(beta * x) + b * np.cos(beta * x) + c * ex + d * eL
    slope = beta * (a * np.cos(beta * x) - b * np.sin(beta * x) - c * ex + d * eL)
    return phi, slope


def link_modes(EI: float, rhoA: float, L: float, J_m: float, count: int = MODES) -> ModalLink:
    """The rigid mode and the first ``count`` flexible modes of the hub–beam system.

    Parameters
    ----------
    EI : float
        Bending stiffness (N·m²).
    rhoA : float
        Mass per length (kg/m).
    L : float
        Length (m).
    J_m : float
        Everything rigid on the shaft (kg·m²).
    count : int
        Flexible modes (a count).

    Returns
    -------
    ModalLink
        Frequencies, hub and tip participations, normalized.

    Examples
    --------
    >>> m = link_modes(0.1033, 0.1706, 0.381, 2.084e-3, count=2)
    >>> [round(float(w), 1) for w in m.omega]
    [0.0, 29.2, 120.4]
    """
    det = lambda b: np.linalg.det(_conditions(b, L, J_m, rhoA))  # noqa: E731
    grid = np.linspace(1e-3, (count + 2) * np.pi, 4000 * (count + 2)) / L
    values = np.array([det(b) for b in grid])
    roots = [
        brentq(det, grid[i], grid[i + 1], xtol=1e-14, rtol=1e-15)
        for i in np.nonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]
    ][:count]
    if len(roots) < count:
        raise ValueError(f"found {len(roots)} of {count} modes; widen the search")
    nodes, weights = np.polynomial.legendre.leggauss(QUADRATURE)
    x, w = L * (nodes + 1) / 2, weights * L / 2
    shapes = [x]  # the rigid mode, φ = x
    slopes0, tips = [1.0], [L]
    for beta in roots:
        coefficients = np.linalg.svd(_conditions(beta, L, J_m, rhoA))[2][-1]
        phi, _ = _shape(beta, coefficients, x, L)
        shapes.append(phi)
        slopes0.append(float(_shape(beta, coefficients, np.zeros(1), L)[1][0]))
        tips.append(float(_shape(beta, coefficients, np.array([L]), L)[0][0]))
    Phi, hub = np.array(shapes), np.array(slopes0)
    mass = (Phi * (rhoA * w)) @ Phi.T + J_m * np.outer(hub, hub)
    scale = 1.0 / np.sqrt(np.diag(mass))
    normalized = mass * np.outer(scale, scale)
    omega = np.concatenate([[0.0], np.sqrt(EI / rhoA) * np.array(roots) ** 2])
    return ModalLink(
        omega=omega,
        hub=hub * scale,
        tip=np.array(tips) * scale,
        orthogonality=float(np.max(np.abs(normalized - np.eye(len(omega))))),
    )


def simulate_modal_link(rig: LinkRig, duration: float = LINK_DURATION) -> LinkRun:
    """Drive ``rig``'s link, simulated by its continuous modes, with its multi-sine.

    Parameters
    ----------
    rig : LinkRig
        The link, the motor and the sensors (``r_hub``, ``m_tip``, ``J_tip`` and ``f_c``
        must be 0) and the excitation.
    duration : float
        Length of the run (s), in :data:`~arcosim.fmu.flexchain.defaults.STEP` steps.

    Returns
    -------
    LinkRun
        As :func:`~arcosim.experiments.flexible_link.simulate_link` returns it: the
        initial sample and one after each step.

    Raises
    ------
    ValueError
        For a tip mass or inertia, a hub radius or Coulomb friction (not modelled here).
    """
    for name in ("r_hub", "m_tip", "J_tip", "f_c"):
        if rig.value(name) != 0.0:
            raise ValueError(f"{name} = {rig.value(name)}: the modal simulator has none")
    EI, rhoA, L = rig.value("EI"), rig.value("rhoA"), rig.value("L")
    J_m, k_t, D_m = rig.value("J_m"), rig.value("k_t"), rig.value("D_m")
    modes = link_modes(EI, rhoA, L, J_m)
    b, n = modes.hub, len(modes.omega)
    stiffness = np.diag(modes.omega**2)
    damping = rig.value("beta") * stiffness + D_m * np.outer(b, b)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-stiffness, -damping]])
    B = np.concatenate([np.zeros(n), b * k_t])
    augmented = np.zeros((2 * n + 1, 2 * n + 1))
    augmented[: 2 * n, : 2 * n], augmented[: 2 * n, -1] = A * STEP, B * STEP
    step = expm(augmented)
    F, G = step[: 2 * n, : 2 * n], step[: 2 * n, -1]

    steps = round(duration / STEP)
    current = multisine(np.arange(steps) * STEP, rig.amplitude, np.array(rig.lines), rig.seed)
    z = np.zeros((steps + 1, 2 * n))
    for k, i in enumerate(current):
        z[k + 1] = F @ z[k] + G * i
    q, qdot = z[:, :n], z[:, n:]
    held = np.concatenate([[0.0], current])  # the current over the step ending at each sample
    theta, omega = q @ b, qdot @ b
    accel = (-(q @ stiffness) - qdot @ damping + np.outer(held * k_t, b)) @ b
    deflection = q @ modes.tip - L * theta
    rng = np.random.default_rng(rig.seed)
    count = 2 * np.pi / rig.value("encoder_cpr")
    theta_m = np.floor(theta / count + 1e-9) * count
    signals = {
        "i_a": held + rng.normal(0.0, rig.value("i_noise_std"), steps + 1),
        "omega_m": np.concatenate([[0.0], np.diff(theta_m) / STEP]),
        "theta_m": theta_m,
        "omega_m_true": omega,
        "tau_reac": held * k_t - D_m * omega - J_m * accel,
        "alpha_tip": deflection / L,
        "w_tip": deflection,
    }
    return LinkRun(np.arange(steps + 1) * STEP, signals)
