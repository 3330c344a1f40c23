"""What a controller part does to the sensorless loop's margins under model errors.

``arcosim bench control`` scores moves against four criteria; this asks the linearized
question beside it: with one of the controller's parts switched off (``--without PART``),
does the sensorless loop still decay when the model is off? For the five-mass chain of
``benchmarks.control_margins`` it prints the slowest decay (1/s; negative: growing) and
its frequency, with every part on and with the named parts off, at the two corners
(every J +E %, every k −E %, and the reverse) and on random models (each J_i, k_i scaled
by an independent factor in [1 − E, 1 + E]). The model is given to the controller, the
plant keeps the chain (``arcosim.control.sensorless_decay``: an exact encoder, no Coulomb
friction, so that the loop is linear).

Run::

    python -m benchmarks.part_margins --without move_refit [--error 0.3] [--seeds 6]

About 2 s per model on the 2-core machine.
"""

from __future__ import annotations

import argparse
import dataclasses
import random

from arcosim.control import sensorless_decay
from arcosim.experiments import markdown_table
from arcosim.fmu.flexchain import PARTS, defaults
from benchmarks.control_margins import CHAINS, params

#: The five-mass chain of ``benchmarks.control_margins``.
FIVE = CHAINS["five masses"]
#: The control step (s): the project's.
H = defaults.STEP


def chain(j_scale: list[float], k_scale: list[float]) -> dict[str, float]:
    """The five-mass chain by the observer's names, each J_i and k_i scaled."""
    J = [j * f for j, f in zip(FIVE.J, j_scale)]
    return params(dataclasses.replace(FIVE, J=J, k=[k * f for k, f in zip(FIVE.k, k_scale)]))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--without", required=True, help=f"parts, comma-separated: {PARTS}")
    parser.add_argument("--error", type=float, default=0.1, help="model error E (default 0.1)")
    parser.add_argument("--seeds", type=int, default=6, help="random models (default 6)")
    args = parser.parse_args(argv)
    without = frozenset(p.strip() for p in args.without.split(","))
    unknown = sorted(without - set(PARTS))
    if unknown:
        parser.error(f"unknown part(s) {unknown}: name them from {PARTS}")
    e, n = args.error, FIVE.n
    models = {
        f"J +{e:.0%}, k −{e:.0%}": chain([1 + e] * n, [1 - e] * n),
        f"J −{e:.0%}, k +{e:.0%}": chain([1 - e] * n, [1 + e] * n),
    }
    for seed in range(args.seeds):
        rng = random.Random(seed)
        scale = [[rng.uniform(1 - e, 1 + e) for _ in range(n)] for _ in range(2)]
        models[f"random ±{e:.0%}, seed {seed}"] = chain(*scale)
    truth = chain([1.0] * n, [1.0] * n)
    rows = []
    for name, model in models.items():
        cells = [name]
        for parts_off in (frozenset(), without):
            decay, at = sensorless_decay(truth, model, h=H, without=parts_off)
            cells.append(f"{decay:.2f} at {at:.0f} rad/s")
        rows.append(cells)
        print(" | ".join(cells), flush=True)
    header = ["model (five masses)", "every part on", f"without {', '.join(sorted(without))}"]
    print()
    print(markdown_table(header, rows))


if __name__ == "__main__":
    main()
