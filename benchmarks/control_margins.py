"""The controller's margins as docs/control.md quotes them (``-m benchmarks.control_margins``).

For the bench's two- and three-mass chains and a five-mass chain, the design at
T = 1 s (ω_c = 8 rad/s), h = 1 ms: the chain's modes, the closed loop's slowest decay,
the full-state loop broken at the current (phase margin, delay margin, peak of the
sensitivity), the slowest decay with every J_i, k_i scaled by independent factors in
[0.9, 1.1] (20 seeds) and the two corners, and with one step of delay.
"""

from __future__ import annotations

import math

import numpy as np

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control_design import design_controller, hold_discretize, plant_matrices

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
    return {
        "modes": sorted({round(float(abs(e)), 1) for e in ev if abs(e.imag) > 1e-6}),
        "slowest_decay": -math.log(np.abs(np.linalg.eigvals(F - np.outer(g, K))).max()) / H,
        "phase_margin_deg": phase,
        "crossover": at,
        "delay_margin_ms": 1e3 * min(math.radians(p) / x for p, x in pm),
        "max_sensitivity": float(np.abs(1 / (1 + L)).max()),
        "worst_decay_10pct": -math.log(worst) / H,
        "decay_one_step_late": -math.log(np.abs(np.linalg.eigvals(delayed)).max()) / H,
    }


def main() -> None:
    """Print the table."""
    for name, chain in CHAINS.items():
        row = margins(*chain)
        print(name, {k: v if isinstance(v, list) else round(v, 2) for k, v in row.items()})


if __name__ == "__main__":
    main()
