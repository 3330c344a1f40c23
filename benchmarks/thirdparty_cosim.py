"""One-off: why :mod:`benchmarks.simulators.thirdparty_plant` couples through model exchange.

The same chain as :mod:`benchmarks.thirdparty_chain` (motor and two load masses, each a
co-simulation instance of Dymola's ``edrive_mass.fmu``), coupled explicitly the usual
way: at every coupling step the master reads each mass's flange angle and speed, sets
the spring torques from them and steps every FMU (a Jacobi master), so each spring's
torque is held over the step. Against the project's exact plant FMU under the coupling
check's current step (0.2 A for 0.5 s, then free ringing to 2 s): the largest angle
difference of every mass, and the rms of each spring's twist over the last second
against the exact one.

Run: ``python -m benchmarks.thirdparty_cosim --fmus DIR [--substeps 1 20]`` (coupling
steps per 1 ms).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from arcosim import ensure_built
from arcosim.experiments import OpenLoop, run_closed_loop
from arcosim.fmu.flexchain import STEP, defaults
from benchmarks import thirdparty_chain as chain
from benchmarks.simulators.thirdparty_plant import FMU_FILE, where


def explicit(folder: Path, substeps: int, duration: float = chain.FREE_RUN) -> np.ndarray:
    """Every mass's angle (rad), shape ``(n + 1, N + 1)``, under the current step, with the
    springs coupled explicitly every ``STEP / substeps`` s."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    path = folder / FMU_FILE
    description = read_model_description(str(path))
    unzipped = extract(str(path))
    vr = {v.name: v.valueReference for v in description.modelVariables}
    inertias, dampers = [defaults.J_M, *chain.CHAIN.J], [chain.D_M, *[0.0] * chain.CHAIN.n]
    k, B = chain.CHAIN.k, chain.CHAIN.B
    fmus = []
    for j, (J, d) in enumerate(zip(inertias, dampers)):
        fmu = FMU2Slave(guid=description.guid, unzipDirectory=unzipped,
                        modelIdentifier="edrive_mass", instanceName=f"mass{j}")  # fmt: skip
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.setReal([vr["inertia.J"], vr["damper.d"]], [J, d])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmus.append(fmu)
    steps, s, t = round(duration / STEP), STEP / substeps, 0.0
    inputs, outputs = [vr["M_A"], vr["M_B"]], [vr["phiA"], vr["wA"]]
    theta = np.empty((len(fmus), steps + 1))
    for step in range(steps + 1):
        theta[:, step] = [f.getReal(outputs)[0] for f in fmus]
        if step == steps:
            break
        torque = defaults.K_T * (chain.STEP_CURRENT if step * STEP < chain.STEP_LENGTH else 0.0)
        for _ in range(substeps):
            y = [f.getReal(outputs) for f in fmus]
            tau = [k[i] * (y[i][0] - y[i + 1][0]) + B[i] * (y[i][1] - y[i + 1][1])
                   for i in range(len(k))] + [0.0]  # fmt: skip
            left = torque
            for j, fmu in enumerate(fmus):
                fmu.setReal(inputs, [left, -tau[j]])
                left = tau[j]
            for fmu in fmus:
                fmu.doStep(t, s)
            t += s
    for fmu in fmus:
        fmu.terminate()
        fmu.freeInstance()
    return theta


def main(argv: list[str] | None = None) -> int:
    """Print, per coupling step, the angle errors and the twists' rms ratios."""
    p = argparse.ArgumentParser(prog="python -m benchmarks.thirdparty_cosim")
    p.add_argument("--fmus", type=Path, required=True, help=f"folder holding {FMU_FILE}")
    p.add_argument("--substeps", type=int, nargs="+", default=[1, 20])
    args = p.parse_args(argv)
    if not (args.fmus / FMU_FILE).is_file():
        print(f"skip: {where(args.fmus)}")
        return 0
    t = np.arange(round(chain.FREE_RUN / STEP)) * STEP
    current = np.where(t < chain.STEP_LENGTH, chain.STEP_CURRENT, 0.0)
    exact = run_closed_loop(
        ensure_built(chain.CHAIN.n), chain.CHAIN.n, OpenLoop(current), 0.0, chain.FREE_RUN,
        plant={**chain.OWN_PLANT, "encoder_cpr": 0, "i_noise_std": 0.0},
    ).theta  # fmt: skip
    last = round(1.0 / STEP)
    for substeps in args.substeps:
        started = time.perf_counter()
        theta = explicit(args.fmus, substeps)
        error = np.max(np.abs(theta - exact), axis=1)
        twist = [np.std(np.diff(-theta[:, -last:], axis=0)[i])
                 / np.std(np.diff(-exact[:, -last:], axis=0)[i])
                 for i in range(chain.CHAIN.n)]  # fmt: skip
        print(f"coupling step {1e3 * STEP / substeps:g} ms "
              f"({time.perf_counter() - started:.1f} s): largest |Δθ| motor, masses = "
              + ", ".join(f"{e:.3g}" for e in error) + " rad; twist rms / exact over the "
              "last second = " + ", ".join(f"{r:.3g}" for r in twist))  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
