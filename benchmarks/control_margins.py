"""The controller's margins as docs/control.md quotes them (``-m benchmarks.control_margins``).

For the bench's two- and three-mass chains and a five-mass chain, the design at
T = 1 s (ω_c = 8 rad/s), h = 1 ms, checked by :func:`arcosim.control.controller_margins`
(what ``arcosim control`` prints for one chain): the chain's modes; the full-state loop's
slowest decay, its margins broken at the current (phase, delay, peak of the sensitivity),
its slowest decay with every J_i, k_i scaled by independent factors in [0.9, 1.1] (20
seeds) and the two corners, and one step late; then the *sensorless* loop's slowest
decays (:mod:`arcosim.control.sensorless_loop`: the controller's and the plant's own
code, exact encoder, no Coulomb friction, linearized) with the model exact, one step
late, and under the same model errors; and at rest with the hold's dither running
(``hold=True``: the dither's observer in the loop, the finest motor velocity there is),
the model exact and at the two corners.
"""

from __future__ import annotations

import numpy as np

from arcosim import Chain, controller_margins
from arcosim.fmu.flexchain import defaults

H = 1e-3
#: The bench's motor under the observer's names (kg·m², N·m/A, N·m·s/rad, N·m).
MOTOR = {"J_mo": defaults.J_M, "k_to": defaults.K_T, "D_m": defaults.D_M, "f_c": defaults.F_C}
#: The chains by their names in the table (kg·m², N·m/rad, N·m·s/rad).
CHAINS = {
    "bench, two masses": Chain(J=defaults.J[:2], k=(defaults.K,) * 2, B=(defaults.B,) * 2),
    "bench, three masses": Chain(J=defaults.J, k=(defaults.K,) * 3, B=(defaults.B,) * 3),
    "five masses": Chain(
        J=(2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4), k=(0.4, 0.3, 0.5, 0.35, 0.45), B=(1.5e-5,) * 5
    ),
}


def params(chain: Chain) -> dict[str, float]:
    """The chain under the observer's names, with the bench's motor."""
    return {**MOTOR, **chain.parameters()}


def margins(chain: Chain) -> dict[str, object]:
    """One row of the table."""
    found = controller_margins(params(chain), h=H)
    fs = found.full_state
    hold = [case.decay for case in found.hold]  # the model exact, the corners, [the worst]
    return {
        "modes": [round(w, 1) for w in found.modes],
        "slowest_decay": fs["slowest_decay"],
        "phase_margin_deg": fs["phase_margin"],
        "crossover": fs["crossover"],
        "delay_margin_ms": 1e3 * fs["delay_margin"],
        "max_sensitivity": fs["max_sensitivity"],
        "worst_decay_10pct": found.full_state_worst.decay,
        "decay_one_step_late": fs["decay_one_step_late"],
        "sensorless_decay": found.sensorless.decay,
        "sensorless_worst_10pct": found.worst.decay,
        "sensorless_worst_at": found.worst.frequency,
        "sensorless_corners": [e.decay for e in found.under_errors[:2]],
        "sensorless_one_step_late": found.sensorless_late.decay,
        "hold_decay": hold[0],
        "hold_corners": hold[1:3],
    }


def main() -> None:
    """Print the table."""
    for name, chain in CHAINS.items():
        row = margins(chain)
        print(name, {key: np.round(np.asarray(v, float), 2).tolist() for key, v in row.items()})


if __name__ == "__main__":
    main()
