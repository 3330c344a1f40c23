"""The controller FMU's cost per step through fmpy: ``python -m benchmarks.controller_speed``.

For n masses (default 1, 3 and 5) the controller FMU (``ActionReactionController``) closes
the loop around the C plant FMU, both with their defaults (the bench chain of n masses,
realistic sensors), for a 1 rad move of the last mass held for the rest of the run, as
:func:`arcosim.host.control_loop.control_loop` runs it. Only the controller's
``fmi2DoStep`` is timed, each step apart, in the CPU time of the calling thread
(``time.thread_time_ns`` around the raw ctypes call; the Python FMU runs in that thread),
so that other processes on a shared machine do not count: the mean over the run after
its first step (what a host's budget must hold on average), the median (a typical
step), the slowest step (the refit from the move, ``REFINE_AT`` move times after its
start, falls into one ``doStep``) and the first step (the estimators' step models
designed on first use). Each figure is the median over ``--runs`` runs. Writes
``controller_speed.md`` and ``controller_speed.json`` into ``--out``.

Timings are this machine's; the CPU time still grows with a loaded machine's cache and
memory traffic, so compare two versions of the controller one after the other.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from ctypes import c_double
from pathlib import Path

from arcosim import FmuInstance, UserError, ensure_built
from arcosim.build import CONTROLLER, PLANT
from arcosim.experiments import markdown_table
from arcosim.host import MEASURED

#: The control period (s): the project's 1 ms step.
H = 1e-3
#: The target (rad): the move of ``arcosim simulate --scenario move``.
TARGET = 1.0
#: The table's figures and their decimals: µs to the µs, the slowest step to 0.1 ms.
COLUMNS = (("mean_us", 0), ("median_us", 0), ("max_ms", 1), ("first_ms", 0))


def controller_steps(n: int, seconds: float) -> list[float]:
    """Each controller ``fmi2DoStep`` of one closed-loop run of n masses (µs), in order.

    Parameters
    ----------
    n : int
        Masses of the chain (plant and controller, each with its defaults), ≥ 1.
    seconds : float
        The run's length (s); the move starts at 0 and takes 1 s.

    Returns
    -------
    list of float
        µs per step, shape ``(round(seconds / H),)``.
    """
    folder = ensure_built(n)
    clock = time.thread_time_ns  # CPU time: a step preempted by other work is not charged
    times = []
    with (
        FmuInstance(folder / f"{CONTROLLER.name}.fmu", "controller") as controller,
        FmuInstance(folder / f"{PLANT.name}.fmu", "plant") as plant,
    ):
        plant.initialize()
        measured = plant.real_port(MEASURED)
        sensors = controller.real_port(["theta_ref", *MEASURED])
        measured.get()
        sensors.values[0] = TARGET
        sensors.values[1:] = list(measured.values)
        sensors.send()
        controller.initialize()
        command = controller.real_port(["i_ref"])
        drive = plant.real_port(["i_ref"])
        plant_step, plant_c = plant.step_call()
        ctrl_step, ctrl_c = controller.step_call()
        t_c, h_c = c_double(0.0), c_double(H)
        for k in range(round(seconds / H)):
            t_c.value = k * H
            measured.get()
            sensors.values[1:] = list(measured.values)
            sensors.send()
            started = clock()
            status = ctrl_step(ctrl_c, t_c, h_c, 1)
            times.append((clock() - started) * 1e-3)
            command.get()
            drive.values[0] = command.values[0]
            drive.send()
            if status > 1 or plant_step(plant_c, t_c, h_c, 1) > 1:
                raise UserError(f"the closed loop of {n} masses failed at t = {k * H:.3f} s")
    return times


def run(out: Path, masses: list[int], seconds: float, runs: int) -> dict:
    """Every n of ``masses`` over ``runs`` runs of ``seconds`` s; the table and figures."""
    found = {}
    for n in masses:
        per_run = [controller_steps(n, seconds) for _ in range(runs)]
        found[n] = {
            "first_ms": statistics.median(r[0] for r in per_run) * 1e-3,
            "mean_us": statistics.median(statistics.fmean(r[1:]) for r in per_run),
            "median_us": statistics.median(statistics.median(r[1:]) for r in per_run),
            "max_ms": statistics.median(max(r[1:]) for r in per_run) * 1e-3,
        }
    rows = [[str(n), *(f"{f[key]:.{d}f}" for key, d in COLUMNS)] for n, f in found.items()]
    header = ["masses", "mean µs/step", "median µs/step", "slowest step (ms)", "first step (ms)"]
    table = markdown_table(header, rows) + "\n"
    out.mkdir(parents=True, exist_ok=True)
    (out / "controller_speed.md").write_text(table, encoding="utf-8")
    summary = {"seconds": seconds, "runs": runs, "figures": found}
    (out / "controller_speed.json").write_text(json.dumps(summary, indent=1), "utf-8")
    return {"table": table, **summary}


def main(argv: list[str] | None = None) -> int:
    """The command line: ``--masses``, ``--seconds``, ``--runs``, ``--out``."""
    p = argparse.ArgumentParser(prog="python -m benchmarks.controller_speed", description=__doc__)
    p.add_argument("--masses", type=int, nargs="+", default=[1, 3, 5], help="default 1 3 5")
    p.add_argument("--seconds", type=float, default=3.0, help="run length (s, default 3)")
    p.add_argument("--runs", type=int, default=3, help="runs per figure (default 3)")
    p.add_argument("--out", type=Path, default=Path("reports"), help="folder for the table")
    args = p.parse_args(argv)
    if args.runs < 1 or args.seconds <= 0.0 or min(args.masses) < 1:
        raise UserError("--runs and every --masses must be >= 1 and --seconds > 0")
    print(run(args.out, args.masses, args.seconds, args.runs)["table"])
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(main())
