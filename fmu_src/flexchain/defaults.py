"""Every default of the project, in one place (SI units).

The plant's defaults are the paper's bench (Khalil & Sabanovic) in SI units: its linear
springs mapped to rotary values at a 10 mm lever, the motor friction assumed for the
EC-motor class (``docs/method.md``). The sensors, the observer's bandwidths and the
co-simulation step follow. The FMUs declare these as their parameters' start values,
and the offline tools (identification, scenarios, benchmarks) read them from here.
"""

from __future__ import annotations

# -- the plant: the paper's bench ---------------------------------------------------
J_M = 2.09e-5  #: motor inertia (kg·m²)
K_T = 0.0406  #: torque constant (N·m/A)
D_M = 2e-5  #: motor viscous friction (N·m·s/rad), assumed
F_C = 2e-3  #: motor Coulomb friction (N·m), assumed
J = (5.15299e-4, 5.15299e-4, 6.192707e-4)  #: load inertias J_1 … J_3 (kg·m²)
K = 0.1627  #: spring stiffness (N·m/rad)
B = 8.88e-6  #: spring damping (N·m·s/rad)
MODES = (16.8, 30.2, 90.1)  #: flexible modes of motor + chain (rad/s)

# -- the sensors ----------------------------------------------------------------------
ENCODER_CPR = 2000  #: encoder counts per revolution after quadrature (0 = ideal)
I_NOISE_STD = 0.005  #: current-sensor noise, standard deviation (A)

# -- the observer -----------------------------------------------------------------------
G_DIST = 100.0  #: bandwidth of the disturbance observer G(s) = g/(s + g) (rad/s)
G_LPF = 100.0  #: bandwidth of the filter on the recursion's later stages (rad/s)
#: Offline, the motor velocity is the angle's derivative smoothed without lag at this
#: many times g_dist (G(s) has removed most of what it cuts there).
VELOCITY_SMOOTHING = 4.0

# -- the co-simulation ----------------------------------------------------------------
STEP = 1e-3  #: communication step (s)


def inertias(n: int) -> list[float]:
    """Load inertias (kg·m²) for n masses: the bench's for n = 3, else J_1 for each."""
    return list(J) if n == 3 else [J[0]] * n
