"""``arcosim identify LOG.csv``: drive the observer FMU with a recorded log.

Contract (scripts rely on it)::

    arcosim identify LOG.csv [--masses N] [--mode 0|1|2] [--set NAME=VALUE ...]
                             [--scale COLUMN=FACTOR ...] [--json] [--out FILE]

* the log's columns ``time``, ``i_a``, ``omega_m``, ``theta_m`` (SI; ``--scale``
  converts, e.g. ``--scale i_a=0.001`` for mA), one row per sample (timing contract
  of shared/METHOD.md); the step may vary, and the observer gets the step taken;
* ``--set NAME=VALUE``: an observer parameter, e.g. ``--set "J[1]=5e-4"``;
* ``--json``: one JSON object, the final value of every observer output keyed by its
  FMU name (Booleans as true/false);
* ``--out FILE``: every output over time as CSV (``time`` first).

A bad log (missing column, non-increasing time, NaN, empty file) gives a one-line
error naming the row or column, and exit status 2.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from cosim.build import OBSERVER, check_masses, ensure_built
from cosim.errors import UserError
from cosim.instance import FmuInstance
from cosim.logs import DriveLog, parse_scales, read_log, write_csv
from cosim.master import MEASURED, Recording
from cosim.overrides import check_name, parse_assignment, typed_value


def replay_log(
    observer: FmuInstance,
    log: DriveLog,
    parameters: Mapping[str, float | int | bool] | None = None,
    outputs: Sequence[str] | None = None,
) -> Recording:
    """Feed every sample of ``log`` to a fresh observer instance; record ``outputs``.

    The first row is the initial sample (set before initialization); row k ends the
    step from row k−1, so ``doStep(t_{k−1}, t_k − t_{k−1})`` receives it, as with a
    Gauss–Seidel master.

    Returns:
        The recording, one sample per log row, signals named ``"observer.<name>"``.
    """
    if outputs is None:
        outputs = output_names(observer)
    write = observer.real_writer(list(MEASURED))
    read = observer.reader(outputs)
    inputs = np.column_stack([log.columns[c] for c in MEASURED])
    t = log.time
    write(list(inputs[0]))
    observer.initialize(parameters, float(t[0]))
    samples = np.empty((len(t), len(outputs)))
    samples[0] = read()
    for k in range(1, len(t)):
        write(list(inputs[k]))
        status = observer.do_step(float(t[k - 1]), float(t[k] - t[k - 1]))
        if status > 1:
            raise UserError(
                f"{log.path}, sample at t = {t[k]!r} s: the observer refused it: "
                + (observer.messages[-1] if observer.messages else f"status {status}")
            )
        samples[k] = read()
    recording = Recording(time=t.copy())
    for j, name in enumerate(outputs):
        recording.signals[f"observer.{name}"] = samples[:, j]
    return recording


def output_names(fmu: FmuInstance) -> list[str]:
    """Every output of ``fmu``, in value-reference order."""
    return [v.name for v in fmu.description.modelVariables if v.causality == "output"]


def final_values(fmu: FmuInstance, recording: Recording, prefix: str = "observer") -> dict:
    """Last value of every recorded output, typed as JSON likes it."""
    result = {}
    for key, series in recording.signals.items():
        name = key.split(".", 1)[1]
        vtype = fmu.variables[name].type
        x = series[-1]
        result[name] = bool(x) if vtype == "Boolean" else int(x) if vtype == "Integer" else float(x)
    return result


def observer_parameters(fmu: FmuInstance, assignments: Sequence[str], mode: int | None) -> dict:
    """``--set`` texts (observer parameters, no prefix) and ``--mode`` as typed values."""
    parameters: dict[str, float | int | bool] = {}
    for text in assignments:
        name, value = parse_assignment(text)
        check_name(name, fmu.variables, "the observer")
        var = fmu.variables[name]
        if var.causality != "parameter":
            raise UserError(f"--set {text!r}: {name} is an {var.causality}, not a parameter")
        parameters[name] = typed_value(name, value, var.type)
    if mode is not None:
        parameters["mode"] = mode
    return parameters


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim identify``."""
    p = subparsers.add_parser(
        "identify",
        help="run the observer FMU on a recorded log",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("log", type=Path, help="CSV log with time, i_a, omega_m, theta_m")
    p.add_argument("--masses", type=int, default=3, help="number of load masses (default 3)")
    p.add_argument(
        "--mode", type=int, choices=(0, 1, 2), help="observer mode (default: the FMU's, 2)"
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="observer parameter, repeatable",
    )
    p.add_argument(
        "--scale",
        action="append",
        default=[],
        metavar="COLUMN=FACTOR",
        help="multiply a log column to get SI units, repeatable",
    )
    p.add_argument("--json", action="store_true", help="print the final outputs as one JSON object")
    p.add_argument("--out", type=Path, help="write every output over time to this CSV file")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    log = read_log(args.log, parse_scales(args.scale))
    folder = ensure_built(check_masses(args.masses))
    with FmuInstance(folder / f"{OBSERVER.name}.fmu", "observer") as observer:
        parameters = observer_parameters(observer, args.set, args.mode)
        recording = replay_log(observer, log, parameters)
        final = final_values(observer, recording)
    if args.out:
        columns = {"time": recording.time}
        columns.update({k.split(".", 1)[1]: v for k, v in recording.signals.items()})
        write_csv(args.out, columns)
    if args.json:
        print(json.dumps(final, indent=2))
    else:
        _print_summary(final, len(log), args.out)
    return 0


def _print_summary(final: dict, samples: int, out: Path | None) -> None:
    print(f"{samples} samples; final observer outputs (0 where the mode does not run them):")
    for key, value in final.items():
        print(f"  {key:24s} {value}")
    if out:
        print(f"wrote {out}")
