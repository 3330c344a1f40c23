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

from arcosim import controller_margins
from arcosim.fmu.flexchain import defaults

H = 1e-3
MOTOR = {"J_mo": defaults.J_M, "k_to": defaults.K_T, "D_m": defaults.D_M, "f_c": defaults.F_C}
CHAINS = {
    "bench, two masses": (defaults.J[:2], (defaults.K,) * 2, (defaults.B,) * 2),
    "bench, three masses": (defaults.J, (defaults.K,) * 3, (defaults.B,) * 3),
    "five masses": ((2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4), (0.4, 0.3, 0.5, 0.35, 0.45), (1.5e-5,) * 5),
}


def params(J, k, B) -> dict[str, float]:
    """The chain under the observer's names, the bench's motor."""
    out = dict(MOTOR)
    for name, values in (("J", J), ("k", k), ("B", B)):
        out.update({f"{name}[{i + 1}]": v for i, v in enumerate(values)})
    return out


def margins(J, k, B) -> dict[str, object]:
    """One row of the table."""
    chain = params(J, k, B)
    found = controller_margins(chain, h=H)
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
        row = margins(*chain)
        print(name, {key: np.round(np.asarray(v, float), 2).tolist() for key, v in row.items()})


if __name__ == "__main__":
    main()
