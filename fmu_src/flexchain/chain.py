"""The motor–spring–mass chain as a linear model.

Bodies 0 … n: body 0 is the motor (inertia ``J_m``), bodies 1 … n the load masses.
Spring i (1-based) joins body i−1 and body i with stiffness ``k[i-1]`` (N·m/rad)
and damping ``B[i-1]`` (N·m·s/rad). Sign convention of docs/method.md: the
torque of spring i is ``τ_i = k_i (θ_{i−1} − θ_i) + B_i (θ̇_{i−1} − θ̇_i)``.
"""

from __future__ import annotations

from collections.abc import Sequence

from .linalg import Matrix, zeros


def spring_matrix(gains: Sequence[float]) -> Matrix:
    """The ``(n+1) × (n+1)`` Laplacian of a chain of n springs.

    For stiffnesses it is the stiffness matrix K, for dampings the damping matrix:
    the torque on the bodies is ``−K θ − C θ̇``.

    Parameters
    ----------
    gains : Sequence[float]
        ``k_1 … k_n`` (N·m/rad) or ``B_1 … B_n`` (N·m·s/rad), one per spring, shape
        ``(n,)``.

    Returns
    -------
    Matrix
        The Laplacian, shape ``(n + 1, n + 1)``, in the unit of ``gains``.
    """
    return _laplacian(gains, [(i - 1, i) for i in range(1, len(gains) + 1)])


def star_matrix(gains: Sequence[float]) -> Matrix:
    """The ``(n+1) × (n+1)`` Laplacian of a star of n springs, each from body 0 (the
    hub) to its own body i (a link's modes, :mod:`arcosim.fmu.flexchain.link`).

    Parameters
    ----------
    gains : Sequence[float]
        ``k_1 … k_n`` (N·m/rad) or ``B_1 … B_n`` (N·m·s/rad), one per spring, shape
        ``(n,)``.

    Returns
    -------
    Matrix
        The Laplacian, shape ``(n + 1, n + 1)``, in the unit of ``gains``.

    Examples
    --------
    >>> star_matrix([1.0, 2.0])
    [[3.0, -1.0, -2.0], [-1.0, 1.0, 0.0], [-2.0, 0.0, 2.0]]
    """
    return _laplacian(gains, [(0, i) for i in range(1, len(gains) + 1)])


def _laplacian(gains: Sequence[float], ends: Sequence[tuple[int, int]]) -> Matrix:
    """The ``(n+1) × (n+1)`` Laplacian of n springs, spring j joining bodies ``ends[j]``.

    Parameters
    ----------
    gains : Sequence[float]
        One gain per spring, shape ``(n,)``, in any unit.
    ends : Sequence[tuple[int, int]]
        The two bodies (0 … n) each spring joins, shape ``(n, 2)``.

    Returns
    -------
    Matrix
        The Laplacian, shape ``(n + 1, n + 1)``, in the unit of ``gains``.

    Examples
    --------
    >>> _laplacian([2.0], [(0, 1)])
    [[2.0, -2.0], [-2.0, 2.0]]
    """
    m = zeros(len(gains) + 1, len(gains) + 1)
    for g, (a, b) in zip(gains, ends):
        m[a][a] += g
        m[b][b] += g
        m[a][b] -= g
        m[b][a] -= g
    return m


def spring_torques(
    k: Sequence[float], B: Sequence[float], theta: Sequence[float], omega: Sequence[float]
) -> list[float]:
    """Torques ``τ_1 … τ_n`` carried by the springs.

    Parameters
    ----------
    k, B : Sequence[float]
        Per-spring stiffness (N·m/rad) and damping (N·m·s/rad), shape ``(n,)`` each.
    theta, omega : Sequence[float]
        Angles (rad) and velocities (rad/s) of bodies 0 … n, shape ``(n + 1,)`` each.

    Returns
    -------
    list of float
        The spring torques (N·m), shape ``(n,)``.
    """
    return [
        k[i] * (theta[i] - theta[i + 1]) + B[i] * (omega[i] - omega[i + 1]) for i in range(len(k))
    ]
