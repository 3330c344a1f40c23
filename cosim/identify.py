"""``arcosim identify LOG.csv``: drive the observer FMU with a recorded log.

Contract (scripts rely on it)::

    arcosim identify LOG.csv [--masses N] [--mode 0|1|2] [--set NAME=VALUE ...]
                             [--scale COLUMN=FACTOR ...] [--json] [--out FILE]
                             [--method observer|output-error|whole-chain]
                             [--fit-inertia-scale] [--start-k K]

* the log's columns ``time``, ``i_a``, ``omega_m``, ``theta_m`` (SI; ``--scale``
  converts, e.g. ``--scale i_a=0.001`` for mA), one row per sample (timing contract
  of shared/METHOD.md); the step may vary, and the observer gets the step taken;
* ``--set NAME=VALUE``: an observer parameter, e.g. ``--set "J[1]=5e-4"``;
* ``--json``: one JSON object, the final value of every observer output keyed by its
  FMU name (Booleans as true/false);
* ``--out FILE``: every output over time as CSV (``time`` first).
* ``--method output-error``: instead of replaying the observer FMU, fit the uniform
  chain's k and B (``--fit-inertia-scale``: and a common scale on the J_i) to τ̂_reac
  from any excitation rich enough to ring the chain (``cosim/output_error.py``). The
  observer's parameters (``--set``: J_mo, k_to, dkt, dJm, D_m, f_c, g_dist, J[i]) say
  what is known; ``--json`` prints ``k_hat``, ``B_hat`` (and ``J_scale``), their
  standard errors under ``std``, and the evidence (start, residual, velocity used).
  Needs a constant sample step.
* ``--method whole-chain [--masses N|auto]``: fit every load inertia, stiffness and
  damping (``cosim/whole_chain.py``); only the actuator terms are known (``--set``:
  J_mo, k_to, dkt, dJm, g_dist, encoder_cpr; D_m and f_c when known, else they are
  fitted with the chain; with counts the fit is the prediction-error fit from the
  current to the encoder). ``--load constant|slow``: a load torque on the last mass is
  part of the model (fitted, reported as ``tau_load``). ``--masses auto`` reads the
  number of masses from the record. The report's ``assumptions`` say what the result
  is conditional on (and any drive parameter left at the bench's default). ``--json``
  prints ``J[i]``, ``k[i]``, ``B[i]`` (the observer's own parameter names: pass them
  back with ``--set`` in mode 2), their standard errors under ``std``, and the evidence
  (modes seen and their residue t values, weak modes, criterion per n tried).
  Needs a constant sample step and an excitation that rings every mode (``arcosim
  simulate --scenario identification``: 40 lines 3–150 rad/s, 3 A, 20 s).

A bad log (missing column, non-increasing time, NaN, empty file) gives a one-line
error naming the row or column, and exit status 2.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from cosim.build import OBSERVER, check_masses, ensure_built, fmu_variables
from cosim.encoder_fit import encoder_record
from cosim.errors import UserError
from cosim.instance import FmuInstance
from cosim.logs import DriveLog, parse_scales, read_log, write_csv
from cosim.master import MEASURED, Recording
from cosim.output_error import Fit, MotorRecord, motor_record, uniform_chain
from cosim.overrides import check_name, parse_assignment, typed_value
from cosim.whole_chain import identify as identify_chain
from flexchain.dob import Actuator


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


def parameter_sets(variables: Mapping[str, object], assignments: Sequence[str]) -> dict:
    """``--set`` texts (observer parameters, no prefix) as typed values, checked against
    the observer's variables (anything with ``causality`` and ``type``, by name)."""
    parameters: dict[str, float | int | bool] = {}
    for text in assignments:
        name, value = parse_assignment(text)
        check_name(name, variables, "the observer")
        var = variables[name]
        if var.causality != "parameter":
            raise UserError(f"--set {text!r}: {name} is an {var.causality}, not a parameter")
        parameters[name] = typed_value(name, value, var.type)
    return parameters


def observer_parameters(fmu: FmuInstance, assignments: Sequence[str], mode: int | None) -> dict:
    """``--set`` texts (observer parameters, no prefix) and ``--mode`` as typed values."""
    parameters = parameter_sets(fmu.variables, assignments)
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
    p.add_argument(
        "--masses",
        default="3",
        help="number of load masses (default 3); with --method whole-chain also 'auto'",
    )
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
    p.add_argument(
        "--method",
        choices=("observer", "output-error", "whole-chain"),
        default="observer",
        help="observer: replay the observer FMU (default); output-error: fit k and B "
        "offline; whole-chain: fit every J[i], k[i], B[i] offline",
    )
    p.add_argument(
        "--fit-inertia-scale",
        action="store_true",
        help="output-error: also fit a common scale on the load inertias J[i]",
    )
    p.add_argument(
        "--load",
        choices=("none", "constant", "slow"),
        default="none",
        help="whole-chain: model a load torque on the last mass (constant, or constant "
        "plus a slow drift), fitted and reported",
    )
    p.add_argument(
        "--start-k",
        type=float,
        help="output-error: start from this stiffness (N.m/rad) instead of the cost scan",
    )
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    log = read_log(args.log, parse_scales(args.scale))
    if args.method == "whole-chain":
        masses = args.masses if args.masses == "auto" else _masses(args.masses)
        return _whole_chain(args, log, ensure_built(), masses)
    n = _masses(args.masses)
    folder = ensure_built(n)
    if args.method == "output-error":
        return _output_error(args, log, folder, n)
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


def known_parameters(folder: Path, assignments: Sequence[str]) -> dict[str, float]:
    """The observer FMU's parameter defaults with ``--set`` applied (offline methods)."""
    variables = fmu_variables(folder)["observer"]
    values: dict[str, float] = {
        name: float(v.start)
        for name, v in variables.items()
        if v.causality == "parameter" and v.type in ("Real", "Integer")
    }
    values.update({k: float(v) for k, v in parameter_sets(variables, assignments).items()})
    return values


def actuator_of(values: Mapping[str, float]) -> Actuator:
    """The actuator terms among the observer's parameters."""
    for name in ("J_mo", "k_to", "g_dist"):
        if not values[name] > 0:
            raise UserError(f"{name} = {values[name]!r} must be > 0")
    return Actuator(
        values["J_mo"], values["k_to"], values["dkt"], values["dJm"], values["D_m"], values["f_c"]
    )


def _output_error(args: argparse.Namespace, log: DriveLog, folder: Path, n: int) -> int:
    values = known_parameters(folder, args.set)
    J = [values[f"J[{i}]"] for i in range(1, n + 1)]
    if any(not x > 0 for x in J):
        raise UserError(f"the load inertias must be > 0, got J = {J}")
    c = log.columns
    record = motor_record(
        log.time, c["i_a"], c["omega_m"], c["theta_m"], actuator_of(values), values["g_dist"]
    )
    result = uniform_chain(record, J, args.fit_inertia_scale, args.start_k)
    names = {"k": "k_hat", "B": "B_hat", "J_scale": "J_scale"}
    report = {names[k]: v for k, v in result.as_dict().items()}
    report["std"] = {names[k]: v for k, v in result.std_dict().items()}
    report.update(evidence(result, record))
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(f"{len(log)} samples, output-error fit of the uniform chain ({n} masses):")
        for key in (k for k in report if k in names.values()):
            print(f"  {key:8s} {report[key]:.6g}  ± {report['std'][key]:.2g}")
        for key in ("start", "velocity", "rms_residual", "rms_data", "newey_west_lag"):
            print(f"  {key}: {report[key]}")
    return 0


def _masses(text: str) -> int:
    """``--masses`` as a supported number of masses."""
    try:
        n = int(text)
    except ValueError:
        what = " ('auto' needs --method whole-chain)" if text == "auto" else ""
        raise UserError(f"--masses {text}: not a whole number{what}") from None
    return check_masses(n)


def _whole_chain(args: argparse.Namespace, log: DriveLog, folder: Path, masses: int | str) -> int:
    values = known_parameters(folder, args.set)
    given = {parse_assignment(text)[0] for text in args.set}
    friction_given = {"D_m", "f_c"} <= given
    if not friction_given:  # fitted: the DOB's τ̂ (the modal start) is computed without
        values["D_m"] = values["f_c"] = 0.0
    actuator = actuator_of(values)
    c = log.columns
    g_dist = values["g_dist"]
    record = motor_record(log.time, c["i_a"], c["omega_m"], c["theta_m"], actuator, g_dist)
    cpr = int(values["encoder_cpr"])
    encoder = None
    if cpr > 0:
        encoder = encoder_record(
            log.time, c["i_a"], c["theta_m"], actuator, cpr, friction_given, args.load
        )
    elif not friction_given or args.load != "none":
        raise UserError(
            "without encoder counts (encoder_cpr = 0) the fit needs the motor friction "
            "(--set D_m=… --set f_c=…) and no load torque (--load none)"
        )
    choice = identify_chain(record, masses, encoder)
    result = choice.fit
    report: dict[str, object] = {"masses": choice.n, **result.as_dict()}
    report["std"] = result.std_dict()
    report.update(evidence(result, record), method="whole-chain")
    report.update(
        modes_rad_s=result.extra["modes_rad_s"],
        damping_ratios=result.extra["damping_ratios"],
        residue_t_values=result.extra["residue_t_values"],
        weak_modes=result.extra["weak_modes"],
        refused={str(n): why for n, why in choice.refused.items()},
        assumptions=result.extra["assumptions"],
        warnings=result.extra["warnings"],
        criterion={str(n): v for n, v in choice.criterion.items()},
        masses_seen=choice.seen,
    )
    defaults = [name for name in ("J_mo", "k_to", "encoder_cpr") if name not in given]
    if defaults:
        result.extra["assumptions"]["defaults"] = (
            "not given, so the paper bench's value was used: "
            + ", ".join(f"{name} = {values[name]:g}" for name in defaults)
            + " (give your drive's with --set)"
        )
    if choice.singular_values is not None:
        report["singular_values"] = [float(x) for x in choice.singular_values[:16]]
    if "load_torque_range" in result.extra:
        report["load_torque_range"] = result.extra["load_torque_range"]
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    print(f"{len(log)} samples, whole-chain fit ({choice.n} masses):")
    for key in result.names:
        print(f"  {key:8s} {report[key]:.6g}  ± {report['std'][key]:.2g}")
    for key in ("start", "modes_rad_s", "residue_t_values", "weak_modes", "refused"):
        print(f"  {key}: {report[key]}")
    for key, text in result.extra["assumptions"].items():
        print(f"  assumption, {key}: {text}")
    for text in result.extra["warnings"]:
        print(f"  warning: {text}")
    chain = {k: v for k, v in result.as_dict().items() if k[0] in "JkB" and "[" in k}
    settings = " ".join(f'--set "{k}={v:.6g}"' for k, v in chain.items())
    print(f"observer in mode 2 with this chain: --masses {choice.n} {settings}")
    return 0


def evidence(result: Fit, record: MotorRecord) -> dict[str, object]:
    """What an output-error fit rests on, for the JSON report."""
    return {
        "method": "output-error",
        "start": result.start_note,
        "velocity": record.velocity_source,
        "rms_residual": result.rms_residual,
        "rms_data": result.rms_data,
        "newey_west_lag": result.lag,
        "duration": record.duration,
        "evaluations": result.evaluations,
    }
