"""A load chain and its driving-point modes, both ways (pure algebra, offline).

With the motor held still, the load chain (inertias J_1 … J_n, kg·m²; springs k_1 …
k_n, N·m/rad, k_1 from the motor to J_1) rings at its clamped frequencies p_i (rad/s).
Undamped, the reaction torque it puts on a motor that moves by θ_m is

    τ(s) / θ_m(s) = k_1 − Σ_i r_i / (s² + p_i²),   r_i = k_1² φ_{1i}² > 0,

with φ_i the mass-normalized mode shapes. The 2n numbers (p_i, r_i) fix the chain
(k_1 = Σ r_i / p_i², J_1 = k_1² / Σ r_i, and the Lanczos recursion rebuilds the
mass-normalized stiffness matrix from its eigenvalues p_i² and first components;
Gladwell, *Inverse Problems in Vibration*, ch. 4). Any p_i > 0 distinct and r_i > 0
give a physical chain: every J_i and k_i positive.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from arcosim.fmu.flexchain.chain import spring_matrix


def clamped_modes(J: Sequence[float], k: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """The chain's modes with the motor held still: squared frequencies p² (rad²/s²,
    shape (n,), ascending) and mass-normalized shapes φ (shape (n, n); rows: masses,
    columns: modes) of the inertias J (kg·m²) and stiffnesses k (N·m/rad)."""
    root = np.sqrt(np.asarray(J, dtype=float))
    K = np.array(spring_matrix([float(x) for x in k]))[1:, 1:]  # motor held still
    eigenvalues, shapes = np.linalg.eigh(K / root[:, None] / root[None, :])
    return eigenvalues, shapes / root[:, None]


def driving_point_modes(J: Sequence[float], k: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """The clamped frequencies and residues of a chain: what the motor's side shows of it.

    Parameters
    ----------
    J : sequence of float
        Load inertias J_1 … J_n (kg·m²), shape ``(n,)``.
    k : sequence of float
        Stiffnesses k_1 … k_n (N·m/rad), shape ``(n,)``.

    Returns
    -------
    tuple of ndarray
        ``(p, r)``: clamped frequencies (rad/s), ascending, and residues
        (N·m/rad·s⁻²), shape ``(n,)`` each; :func:`chain_from_modes` inverts them.

    Examples
    --------
    >>> p, r = driving_point_modes([1e-3, 2e-3], [0.5, 0.8])
    >>> np.round(p, 4).tolist(), np.round(r, 4).tolist()
    ([11.2765, 39.6591], [47.1821, 202.8179])
    """
    eigenvalues, phi = clamped_modes(J, k)
    return np.sqrt(eigenvalues), float(k[0]) ** 2 * phi[0] ** 2  # φ_{1i}


def chain_from_modes(p: Sequence[float], r: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """The chain with the given clamped frequencies and residues (the Lanczos inverse).

    Parameters
    ----------
    p : sequence of float
        Clamped frequencies (rad/s), distinct, > 0, length n.
    r : sequence of float
        Residues (N·m/rad·s⁻²), > 0, length n.

    Returns
    -------
    tuple of ndarray
        ``(J, k)``: inertias (kg·m²) and stiffnesses (N·m/rad), shape ``(n,)`` each.

    Raises
    ------
    ValueError
        For non-positive or repeated frequencies, or non-positive residues.

    Examples
    --------
    >>> J, k = chain_from_modes(*driving_point_modes([1e-3, 2e-3], [0.5, 0.8]))
    >>> np.round(J, 9).tolist(), np.round(k, 9).tolist()  # kg·m², N·m/rad: back again
    ([0.001, 0.002], [0.5, 0.8])
    """
    p = np.asarray(p, dtype=float)
    r = np.asarray(r, dtype=float)
    if p.shape != r.shape or p.ndim != 1 or len(p) == 0:
        raise ValueError(f"need as many frequencies as residues, got {p.shape} and {r.shape}")
    if np.any(~np.isfinite(p)) or np.any(p <= 0) or np.any(~np.isfinite(r)) or np.any(r <= 0):
        raise ValueError(f"frequencies and residues must be finite and > 0, got {p}, {r}")
    if len(np.unique(p)) < len(p):
        raise ValueError(f"the clamped frequencies must be distinct, got {p}")
    k1 = float(np.sum(r / p**2))
    J1 = k1**2 / float(np.sum(r))
    diagonal, coupling = _lanczos(p**2, np.sqrt(r / np.sum(r)))
    T = np.diag(diagonal) - np.diag(coupling, 1) - np.diag(coupling, -1)
    first = np.zeros(len(p))
    first[0] = 1.0
    root_J = (k1 / np.sqrt(J1)) * np.linalg.solve(T, first)  # √J_i: the static deflection
    k = [k1] + [coupling[i] * root_J[i] * root_J[i + 1] for i in range(len(p) - 1)]
    return root_J**2, np.array(k)


def _lanczos(eigenvalues: np.ndarray, first: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Jacobi matrix (diagonal, shape (n,); off-diagonal magnitudes, shape (n−1,)) with
    the given eigenvalues and unit first-component vector (full reorthogonalization)."""
    n = len(eigenvalues)
    basis = np.zeros((n, n))
    diagonal, coupling = np.zeros(n), np.zeros(n - 1)
    q, previous, beta = first / np.linalg.norm(first), np.zeros(n), 0.0
    for j in range(n):
        basis[:, j] = q
        z = eigenvalues * q
        diagonal[j] = q @ z
        z = z - diagonal[j] * q - beta * previous
        z -= basis[:, : j + 1] @ (basis[:, : j + 1].T @ z)
        if j < n - 1:
            beta = float(np.linalg.norm(z))
            coupling[j] = beta
            previous, q = q, z / beta
    return diagonal, coupling


def driving_point_response(
    J: Sequence[float], k: Sequence[float], B: Sequence[float], w: np.ndarray
) -> np.ndarray:
    """The chain's reaction torque per motor angle, τ_1(jω) / θ_m(jω), with damping.

    With the motor angle prescribed, the load masses obey
    ``(−ω² M + jω C + K)_LL θ_L = −(jω C + K)_L0 θ_m``, and the reaction torque is
    the first spring's, ``τ_1 = (K + jω C)_00 θ_m + (K + jω C)_0L θ_L``.

    Parameters
    ----------
    J : sequence of float
        Load inertias J_1 … J_n (kg·m²).
    k : sequence of float
        Spring stiffnesses k_1 … k_n (N·m/rad), k_1 from the motor to J_1.
    B : sequence of float
        Spring dampings B_1 … B_n (N·m·s/rad).
    w : ndarray
        Angular frequencies (rad/s), shape ``(F,)``.

    Returns
    -------
    ndarray
        Complex response (N·m/rad), shape ``(F,)``: 0 at ω = 0 (the chain follows
        the motor), about −ω² ΣJ_i well below the first mode, and a resonance at each
        clamped frequency p_i.

    Examples
    --------
    >>> z = driving_point_response([1e-3], [0.5], [0.0], np.array([0.0, 10.0]))
    >>> np.round(z.real, 6).tolist()  # one mass: k J ω² / (J ω² − k)
    [0.0, -0.125]
    """
    K = np.array(spring_matrix([float(x) for x in k]))
    C = np.array(spring_matrix([float(x) for x in B]))
    M = np.diag([0.0, *(float(x) for x in J)])
    out = np.empty(len(w), dtype=complex)
    for j, omega in enumerate(np.asarray(w, dtype=float)):
        Z = K + 1j * omega * C
        D = Z - omega**2 * M
        theta_L = np.linalg.solve(D[1:, 1:], -Z[1:, 0])
        out[j] = Z[0, 0] + Z[0, 1:] @ theta_L
    return out
