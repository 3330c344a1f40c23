"""Identification and sensorless motion control on a plant we did not write.

The plant: a motor and two load masses, each an instance of Dymola's ``edrive_mass.fmu``
(:mod:`benchmarks.simulators.thirdparty_plant`), joined by our springs and dampers, driven by our
actuator (k_t·i) and read by our sensors (2000-count encoder, 5 mA current noise). The
chain is :mod:`benchmarks.control_accuracy`'s first (J = 5e-4, 1.5e-3 kg·m², k = 0.3,
0.15 N·m/rad, B = 1e-5 N·m·s/rad; lowest mode 19.7 rad/s, damped at about 0.1 %), the
motor the bench's (J_m, k_t, D_m = 2e-5 N·m·s/rad, no Coulomb friction).

1. Coupling: the assembled chain against the project's exact plant FMU
   (``MotorChainPlant``, matrix exponential, f_c = 0) with ideal sensors: the modes of
   the linear map through the FMUs against the model's, and a current step (0.2 A for
   0.5 s, then free ringing to 2 s): the largest angle difference of every mass.
2. Identification: a 20 s log of the ``identification`` multi-sine, then
   :func:`arcosim.identify_drive` with n and the friction found from the log (k_t and J_m
   given): n, every J_i, k_i, B_i error with its σ, and the friction.
3. Control, per seed (the plant's noise seed and the identification's log): the chain
   identified, then a 1 rad move of the last mass in 6 s by the drive's cascade, the
   sensorless controller (``MotionController``) and its full-state upper bound, designed
   on the identified chain, on it with every J_i, k_i scaled by uniform factors in
   [0.9, 1.1] (seeded with the seed) and, on the first seed, the two corners. Scored by
   :func:`arcosim.experiments.motion.findings.score_move` and ``done_when`` (the controller's four
   criteria), as :mod:`benchmarks.control_accuracy` does.

The FMU is not in the repository: ``--fmus DIR`` names the folder that holds
``edrive_mass.fmu``; absent, the benchmark says where to get it and exits 0.

Run: ``python -m benchmarks.thirdparty_chain --fmus DIR [--seeds N] [--out DIR]
[--identification-only]``.
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from arcosim import DriveIdentification, UserError, ensure_built, identify_drive, write_csv
from arcosim.experiments import (
    DISTANCE,
    I_MAX,
    IDENTIFICATION_DURATION,
    MOTION_DURATION,
    MOVE_TIME,
    CascadeController,
    LoopRun,
    OpenLoop,
    cascade_gains,
    chain_modes,
    design_parameters,
    done_when,
    identification_current,
    markdown_table,
    model_errors,
    run_closed_loop,
    scaled,
    sensorless,
)
from arcosim.fmu.flexchain import ENCODER_CPR, I_NOISE_STD, STEP, defaults
from benchmarks import control_accuracy, progress
from benchmarks.simulators.thirdparty_plant import FMU_FILE, ThirdPartyChain, where

#: The chain: control_accuracy's first (lowest mode 19.7 rad/s).
NAME, CHAIN = next(iter(control_accuracy.CHAINS.items()))
#: The motor's viscous friction (N·m·s/rad, the motor instance's damper); no Coulomb.
D_M = defaults.D_M
#: Runge–Kutta steps per 1 ms step in the runs (a count).
SUBSTEPS = 1
#: The same chain on the project's plant FMU (its start values).
OWN_PLANT = {**CHAIN.parameters(), "D_m": D_M, "f_c": 0.0}
#: The coupling check's current step (A) and its length (s), and the run's length (s).
STEP_CURRENT, STEP_LENGTH, FREE_RUN = 0.2, 0.5, 2.0


def open_plant(folder: Path, seed: int, ideal: bool = False, substeps: int = SUBSTEPS):
    """The assembled chain :data:`CHAIN` with the bench's sensors (or ideal ones)."""
    return ThirdPartyChain(
        folder, defaults.J_M, D_M, CHAIN.J, CHAIN.k, CHAIN.B, defaults.K_T,
        0 if ideal else ENCODER_CPR, 0.0 if ideal else I_NOISE_STD, seed, STEP, substeps,
    )  # fmt: skip


def run_loop(
    plant: ThirdPartyChain,
    controller: object,
    reference: float,
    duration: float,
    full_state: bool = False,
) -> LoopRun:
    """``controller`` on the assembled ``plant`` under the sequential master of
    :func:`arcosim.experiments.closed_loop.run_closed_loop` (zero delay): the sample of
    t_k in, the command held over [t_k, t_k + h]."""
    steps = round(duration / plant.h)
    n = plant.n
    theta, meas = np.empty((n + 1, steps + 1)), np.empty((3, steps + 1))
    commands = np.empty(steps)
    takes_current = full_state and len(
        inspect.signature(controller.step_full_state).parameters) >= 5  # fmt: skip
    for k in range(steps + 1):
        angles = plant.angles()
        theta[:, k] = angles
        meas[:, k] = plant.i_a, plant.omega_m, plant.theta_m
        if k == steps:
            break
        if full_state:
            extra = (plant.i_a,) if takes_current else ()
            command = controller.step_full_state(plant.h, reference, angles, plant.speeds(),
                                                 *extra)  # fmt: skip
        else:
            command = controller.step(plant.h, reference, plant.i_a, plant.omega_m,
                                      plant.theta_m)  # fmt: skip
        commands[k] = command
        plant.step(command)
    return LoopRun(time=np.arange(steps + 1) * plant.h, theta=theta, theta_m=meas[2],
                   omega_m=meas[1], i_a=meas[0], i_ref=commands)  # fmt: skip


def coupling(
    folder: Path, substeps: int = SUBSTEPS, duration: float = FREE_RUN
) -> dict[str, object]:
    """The assembled chain against ``MotorChainPlant`` (same chain, f_c = 0, ideal
    sensors): modes and a current step's angles over ``duration`` (s)."""
    truth = {"J_mo": defaults.J_M, "D_m": D_M, **CHAIN.parameters()}
    modes, zeta = chain_modes(truth)
    with open_plant(folder, 1, ideal=True, substeps=substeps) as plant:
        A, _ = plant.jacobian()
        t = np.arange(round(duration / STEP)) * STEP
        current = np.where(t < STEP_LENGTH, STEP_CURRENT, 0.0)
        ours = run_loop(plant, OpenLoop(current), 0.0, duration)
    eig = np.linalg.eigvals(A)
    eig = eig[eig.imag > 1e-9]
    order = np.argsort(np.abs(eig))
    fmu_modes, fmu_zeta = np.abs(eig[order]), -eig[order].real / np.abs(eig[order])
    exact = run_closed_loop(
        ensure_built(CHAIN.n), CHAIN.n, OpenLoop(current), 0.0, duration,
        plant={**OWN_PLANT, "encoder_cpr": 0, "i_noise_std": 0.0},
    )  # fmt: skip
    scale = np.max(np.abs(exact.theta), axis=1)
    error = np.max(np.abs(ours.theta - exact.theta), axis=1)
    return {
        "modes": [float(w) for w in modes],
        "zeta": [float(z) for z in zeta],
        "fmu_modes": [float(w) for w in fmu_modes],
        "fmu_zeta": [float(z) for z in fmu_zeta],
        "step_error": [float(e) for e in error],
        "step_error_relative": [float(e) for e in error / scale],
        "substeps": substeps,
        "duration": duration,
        "omega_s": float(max(modes) * STEP / substeps),
    }


def identification_log(folder: Path | None, seed: int) -> LoopRun:
    """A 20 s log of the ``identification`` multi-sine on the assembled plant (seed
    ``seed``); with ``folder`` None, on the project's plant with the same chain
    (:data:`OWN_PLANT`)."""
    t = np.arange(round(IDENTIFICATION_DURATION / STEP)) * STEP
    excitation = OpenLoop(identification_current(t))
    if folder is None:
        own = {**OWN_PLANT, "seed": seed}
        return run_closed_loop(
            ensure_built(CHAIN.n), CHAIN.n, excitation, 0.0, IDENTIFICATION_DURATION, plant=own
        )
    with open_plant(folder, seed) as plant:
        return run_loop(plant, excitation, 0.0, IDENTIFICATION_DURATION)


def identify(folder: Path | None, seed: int) -> DriveIdentification:
    """:data:`CHAIN` identified from :func:`identification_log`, n and the friction found
    from the log (k_t and J_m given)."""
    log = identification_log(folder, seed)
    return identify_drive(log.time, log.i_a, log.omega_m, log.theta_m, k_t=defaults.K_T,
                          J_m=defaults.J_M, encoder_cpr=ENCODER_CPR)  # fmt: skip


def write_log(run: LoopRun, path: Path) -> Path:
    """``run`` as a log in the project's format (CSV and ``.units.json``: ``time``,
    ``i_a``, ``omega_m``, ``theta_m`` and the masses' true angles), for ``arcosim
    identify``."""
    columns = {"time": run.time, "i_a": run.i_a, "omega_m": run.omega_m, "theta_m": run.theta_m}
    columns.update({f"theta_{i}_true": run.theta[i] for i in range(1, len(run.theta))})
    units = {f"theta_{i}_true": "rad" for i in range(1, len(run.theta))}
    return write_csv(path, columns, units=units, force=True, option="--log")


def identification_errors(result: DriveIdentification) -> dict[str, object]:
    """n, and every J_i, k_i, B_i and the friction: value, σ (or the upper bound of a
    parameter at its bound), error (%), error / σ (a bound counts as covering the truth,
    0, when the truth lies within it)."""
    p, s = {**result.friction, **result.parameters}, result.std
    bounds = dict(result.report().get("bounds", {}))
    truth = {"D_m": D_M, "f_c": 0.0, **CHAIN.parameters()}
    rows = {}
    for name, true in truth.items():
        if name not in p:
            continue
        value, sigma = float(p[name]), float(s.get(name, math.nan))
        bound = bounds.get(name)
        if sigma > 0:
            off = (value - true) / sigma
        elif bound is not None:
            off = 0.0 if 0.0 <= true <= float(bound) else math.inf
        else:
            off = _off(value, true)
        rows[name] = {
            "true": true,
            "value": value,
            "sigma": sigma,
            "bound": bound,
            "error_percent": 100.0 * (value / true - 1.0) if true else math.nan,
            "error_sigmas": off,
        }
    return {"masses": result.masses, "parameters": rows, "warnings": list(result.warnings)}


def _off(value: float, true: float) -> float:
    """A parameter without σ (a friction form left out, the value 0): 0 when it is exact."""
    return 0.0 if value == true else math.inf


def score_seed(
    folder: Path,
    seed: int,
    corners: bool,
    control: bool = True,
    without: frozenset[str] = frozenset(),
) -> dict[str, object]:
    """One seed: the identification's errors and (``control``) every model's moves,
    scored; the controller's parts in ``without`` switched off."""
    result = identify(folder, seed)
    found = {"identification": identification_errors(result)}
    if result.masses != CHAIN.n or not control:
        return found
    params = design_parameters(result, False)

    def move(controller: object, full_state: bool = False):
        with open_plant(folder, seed) as plant:
            run = run_loop(plant, controller, DISTANCE, MOTION_DURATION, full_state)
        return control_accuracy.score(run)

    cascade = move(CascadeController(cascade_gains(params), MOVE_TIME, I_MAX))
    models = {"identified": (np.ones(CHAIN.n), np.ones(CHAIN.n))}
    errors = model_errors(CHAIN.n, (seed,))
    models.update(list(zip(control_accuracy.MODELS[1:], errors.values()))[: 3 if corners else 1])
    found["models"] = {}
    for label, (fJ, fk) in models.items():
        wrong = scaled(params, fJ, fk)
        moving = move(sensorless(wrong, without=without))
        upper = move(sensorless(wrong, without=without), full_state=True)
        found["models"][label] = {
            "sensorless": moving.as_dict(),
            "upper_bound": upper.as_dict(),
            "cascade": cascade.as_dict(),
            "criteria": done_when(moving, cascade, upper),
        }
    return found


def run(
    folder: Path,
    out: Path,
    seeds: range,
    progress: Callable[[str], None],
    control: bool = True,
    without: frozenset[str] = frozenset(),
) -> dict:
    """Coupling, then every seed (``control``: the moves too, else the identification
    only); the tables and the results (written into ``out``)."""
    started = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    progress("coupling against MotorChainPlant")
    check = coupling(folder)
    progress(f"the same chain on MotorChainPlant: identification, seed {seeds[0]}")
    own = identification_errors(identify(None, seeds[0]))
    per_seed: dict[str, dict] = {}
    for seed in seeds:
        progress(f"seed {seed}")
        per_seed[str(seed)] = score_seed(folder, seed, seed == seeds[0], control, without)
        partial = {"coupling": check, "own_plant": own, "seeds": per_seed}
        (out / "thirdparty.json").write_text(json.dumps(partial, indent=1, default=str), "utf-8")
    lowest = check["modes"][0]
    controlled = {s: r["models"] for s, r in per_seed.items() if "models" in r}
    moves = {f"third-party FMU chain, {NAME}": {"lowest_mode": lowest,
                                                      "seeds": controlled}}  # fmt: skip
    tables = {
        "coupling": coupling_table(check),
        "identification": identification_table(per_seed)
        + f"\nThe same chain on MotorChainPlant, seed {seeds[0]}:\n\n"
        + identification_table({"own": {"identification": own}}),
        "control": control_accuracy.markdown(moves)
        if controlled
        else "(moves skipped: --identification-only)\n"
        if not control
        else "(no seed found n = 2)\n",
    }
    summary = {"coupling": check, "own_plant": own, "seeds": per_seed,
               "seconds": time.perf_counter() - started}  # fmt: skip
    (out / "thirdparty.md").write_text("\n".join(tables.values()), encoding="utf-8")
    (out / "thirdparty.json").write_text(json.dumps(summary, indent=1, default=str), "utf-8")
    return {"tables": tables, **summary}


def coupling_table(check: dict) -> str:
    """Modes through the FMUs against the model's, and the step's largest differences."""
    rows = [
        [f"mode {i + 1}", f"{w:.4f}", f"{wf:.4f}", f"{z:.5f}", f"{zf:.5f}"]
        for i, (w, wf, z, zf) in enumerate(
            zip(check["modes"], check["fmu_modes"], check["zeta"], check["fmu_zeta"])
        )
    ]
    modes = markdown_table(["", "model (rad/s)", "FMU chain (rad/s)", "ζ model", "ζ FMU"], rows)
    names = ["motor", *(f"mass {i}" for i in range(1, CHAIN.n + 1))]
    steps = markdown_table(
        ["", "largest abs. Δθ (rad)", "relative to the swing"],
        [[m, f"{e:.2e}", f"{r:.2e}"] for m, e, r in
         zip(names, check["step_error"], check["step_error_relative"])],
    )  # fmt: skip
    return f"{modes}\n\n{steps}\n"


def identification_table(per_seed: dict) -> str:
    """Per parameter over the seeds: the median and worst error (%), and how many seeds'
    2σ cover the truth; the n found."""
    ids = [r["identification"] for r in per_seed.values()]
    right = sum(i["masses"] == CHAIN.n for i in ids)
    rows = []
    for name in ids[0]["parameters"]:
        got = [i["parameters"][name] for i in ids if name in i["parameters"]]
        err = [abs(g["error_percent"]) for g in got]
        covered = sum(abs(g["error_sigmas"]) <= 2.0 for g in got)
        rows.append([name, f"{got[0]['true']:.4g}", _pct(np.median(err)), _pct(max(err)),
                     f"{np.median([g['error_sigmas'] for g in got]):+.1f}",
                     f"{covered}/{len(got)}"])  # fmt: skip
    head = ["parameter", "true", "median abs. error (%)", "worst (%)", "median err/σ", "in 2σ"]
    return f"n found = {CHAIN.n} on {right}/{len(ids)} seeds\n\n{markdown_table(head, rows)}\n"


def _pct(value: float) -> str:
    """A percentage, or a dash for a true value of 0 (then the value is 0 exactly or not)."""
    return "—" if math.isnan(value) else f"{value:.3f}"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register the benchmark ``thirdparty``."""
    p = subparsers.add_parser(
        "thirdparty",
        help="identification and motion control on a chain of Dymola-exported FMUs",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--fmus", type=Path, required=True, help=f"folder holding {FMU_FILE}")
    p.add_argument("--seeds", type=int, default=5, help="plant seeds (default 5)")
    p.add_argument("--out", type=Path, default=Path("reports"), help="folder for the tables")
    p.add_argument("--log", type=Path, help="also write the first seed's identification log "
                   "(CSV) for `arcosim identify`")  # fmt: skip
    p.add_argument("--identification-only", action="store_true",
                   help="skip the moves: the coupling and the identification (about 5 s "
                   "a seed)")  # fmt: skip
    control_accuracy.add_without(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.seeds < 1:
        raise UserError(f"--seeds must be >= 1, got {args.seeds}")
    if not (args.fmus / FMU_FILE).is_file():
        print(f"skip: {where(args.fmus)}")
        return 0
    if args.log:
        print(f"wrote {write_log(identification_log(args.fmus, 1), args.log)}")
    seeds = range(1, args.seeds + 1)
    result = run(args.fmus, args.out, seeds, progress, not args.identification_only,
                 args.without)  # fmt: skip
    for table in result["tables"].values():
        print(table)
    print(f"wrote {args.out / 'thirdparty.md'} and {args.out / 'thirdparty.json'} "
          f"({result['seconds']:.0f} s)")  # fmt: skip
    return 0


if __name__ == "__main__":
    import sys

    from benchmarks import main

    sys.exit(main("thirdparty", add_parser, sys.argv[1:]))
