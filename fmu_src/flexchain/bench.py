"""The paper's bench in SI units (shared/METHOD.md): the project's default plant.

Linear springs of the paper are mapped to rotary values at a 10 mm lever; the motor
friction values are assumptions of the EC-motor class.
"""

from __future__ import annotations

J_M = 2.09e-5  #: motor inertia (kg·m²)
K_T = 0.0406  #: torque constant (N·m/A)
D_M = 2e-5  #: motor viscous friction (N·m·s/rad), assumed
F_C = 2e-3  #: motor Coulomb friction (N·m), assumed
J = (5.15299e-4, 5.15299e-4, 6.192707e-4)  #: load inertias J_1 … J_3 (kg·m²)
K = 0.1627  #: spring stiffness (N·m/rad)
B = 8.88e-6  #: spring damping (N·m·s/rad)
MODES = (16.8, 30.2, 90.1)  #: flexible modes (rad/s)


def inertias(n: int) -> list[float]:
    """Load inertias (kg·m²) for n masses: the bench's for n = 3, else J_1 for each."""
    return list(J) if n == 3 else [J[0]] * n
