"""The paper's own results (Khalil & Sabanovic, Table II), in the project's SI units.

The bench's springs are linear (kN/m, N·s/m); docs/method.md maps them to rotary values
at a 10 mm lever: ``k_rot = k_lin · r²``, ``B_rot = B_lin · r²``.
"""

LEVER = 0.010  # m
K_TRUE_PAPER = 1.627e3 * LEVER**2  # N·m/rad (the paper's "actual" 1.627 kN/m)
B_TRUE_PAPER = 0.0888 * LEVER**2  # N·m·s/rad

#: Table II, five rigid maneuvers: (k̂ in kN/m, B̂ in N·s/m).
TABLE_II = (
    (1.5796, 0.0888),
    (1.5336, 0.0878),
    (1.6459, 0.0887),
    (1.5116, 0.0889),
    (1.5625, 0.0893),
)


def table_ii_si() -> list[tuple[float, float]]:
    """Table II in N·m/rad and N·m·s/rad."""
    return [(k * 1e3 * LEVER**2, b * LEVER**2) for k, b in TABLE_II]
