"""``arcosim identify LOG.csv``: drive the observer FMU with a recorded log.

Contract (scripts rely on it)::

    arcosim identify LOG.csv [--masses N] [--mode 0|1|2] [--set NAME=VALUE ...]
                             [--scale COLUMN=FACTOR ...] [--json] [--out FILE]
                             [--method observer|output-error|whole-chain|load-torque]
                             [--fit-inertia-scale] [--start-k K] [--chain FIT.json]

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
* ``--method load-torque [--chain FIT.json]``: the external torque on one load mass over
  time, from the motor alone (``cosim/load_torque.py``: the observer FMU's estimator 1
  with ``load_mass``, run offline). The chain (``J[i]``, ``k[i]``, ``B[i]``) comes from
  ``--chain`` (the JSON that ``--method whole-chain --json`` prints; it sets
  ``--masses`` too) and ``--set``, the actuator terms, ``load_mass`` (required) and
  ``load_torque_bandwidth`` from ``--set``; ``--out`` writes ``time``,
  ``tau_load_hat``, ``tau_reac_hat``, ``theta_hat[i]``, ``omega_hat[i]`` and the
  innovation; ``--json`` prints a summary. The step may vary.

A bad log (missing column, non-increasing time, NaN, empty file) gives a one-line
error naming the row or column, and exit status 2.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from arcosim.build.builder import fmu_variables
from arcosim.build.recipes import OBSERVER, check_masses
from arcosim.cli.options import add_fmus_option, fmu_folder
from arcosim.errors import UserError
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.fmu.flexchain.observer import MODEL_BASED, STATE_ESTIMATION, ObserverSettings
from arcosim.host.instance import FmuInstance
from arcosim.host.overrides import parse_assignment
from arcosim.host.replay import final_values, observer_parameters, parameter_sets, replay_log
from arcosim.identification import load_torque
from arcosim.identification.encoder_fit import encoder_record
from arcosim.identification.output_error import Fit, MotorRecord, motor_record, uniform_chain
from arcosim.identification.whole_chain import identify as identify_chain
from arcosim.logs import DriveLog, parse_scales, read_log, write_csv


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
        choices=("observer", "output-error", "whole-chain", "load-torque"),
        default="observer",
        help="observer: replay the observer FMU (default); output-error: fit k and B "
        "offline; whole-chain: fit every J[i], k[i], B[i] offline; load-torque: estimate "
        "the torque on load mass load_mass over time, offline",
    )
    p.add_argument(
        "--chain",
        type=Path,
        help="load-torque: JSON with J[i], k[i], B[i] (the output of --method whole-chain "
        "--json); sets --masses",
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
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    log = read_log(args.log, parse_scales(args.scale))
    if args.method == "whole-chain":
        masses = args.masses if args.masses == "auto" else _masses(args.masses)
        return _whole_chain(args, log, fmu_folder(args, 3), masses)
    if args.method == "load-torque":
        chain = read_chain(args.chain) if args.chain else {}
        n = int(chain.pop("masses")) if "masses" in chain else _masses(args.masses)
        return _load_torque(args, log, fmu_folder(args, check_masses(n)), n, chain)
    if args.chain:
        raise UserError("--chain is for --method load-torque")
    n = _masses(args.masses)
    folder = fmu_folder(args, n)
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


def read_chain(path: Path) -> dict[str, float]:
    """``J[i]``, ``k[i]``, ``B[i]`` (and ``masses``) from a whole-chain JSON report."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise UserError(f"--chain {path}: cannot read it as JSON ({error})") from None
    if not isinstance(data, dict):
        raise UserError(f"--chain {path}: expected a JSON object with J[i], k[i], B[i]")
    chain = {
        k: v
        for k, v in data.items()
        if (k.split("[")[0] in ("J", "k", "B") and k.endswith("]")) or k == "masses"
    }
    n = int(chain.get("masses", sum(k.startswith("J[") for k in chain)))
    missing = [f"{p}[{i}]" for p in "JkB" for i in range(1, n + 1) if f"{p}[{i}]" not in chain]
    if n < 1 or missing:
        raise UserError(f"--chain {path}: missing {', '.join(missing) or 'J[1]'}")
    return {**{k: float(v) for k, v in chain.items()}, "masses": n}


def _load_torque(
    args: argparse.Namespace, log: DriveLog, folder: Path, n: int, chain: dict[str, float]
) -> int:
    values = known_parameters(folder, args.set)
    values.update({k: v for k, v in chain.items() if k not in _set_names(args.set)})
    load_mass = int(values["load_mass"])
    if not 1 <= load_mass <= n:
        raise UserError(
            f"--method load-torque needs the load mass: --set load_mass=I with I in 1 … {n} "
            f"(got {load_mass})"
        )
    settings = ObserverSettings(
        mode=STATE_ESTIMATION,
        actuator=actuator_of(values),
        g_dist=values["g_dist"],
        g_lpf=values["g_lpf"],
        J=tuple(values[f"J[{i}]"] for i in range(1, n + 1)),
        k=tuple(values[f"k[{i}]"] for i in range(1, n + 1)),
        B=tuple(values[f"B[{i}]"] for i in range(1, n + 1)),
        estimator=MODEL_BASED,
        encoder_cpr=int(values["encoder_cpr"]),
        torque_noise_std=values["torque_noise_std"],
        tau_noise_std=values["tau_noise_std"],
        load_mass=load_mass,
        load_torque_bandwidth=values["load_torque_bandwidth"],
    )
    for name in ("J", "k"):
        if any(not x > 0 for x in getattr(settings, name)):
            raise UserError(f"every {name}[i] must be > 0, got {getattr(settings, name)}")
    if not settings.load_torque_bandwidth > 0:
        raise UserError("load_torque_bandwidth must be > 0 (rad/s)")
    c = log.columns
    result = load_torque.estimate(settings, log.time, c["i_a"], c["omega_m"], c["theta_m"])
    if args.out:
        write_csv(args.out, result.columns())
    last = log.time >= log.time[-1] - 1.0
    report = {
        "method": "load-torque",
        "masses": n,
        "load_mass": load_mass,
        "load_torque_bandwidth": settings.load_torque_bandwidth,
        "samples": len(log),
        "final": float(result.tau_load[-1]),
        "mean_last_second": float(np.mean(result.tau_load[last])),
        "std_last_second": float(np.std(result.tau_load[last])),
        "rms_innovation": float(np.sqrt(np.mean(result.innovation**2))),
    }
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    print(
        f"{len(log)} samples, load torque on mass {load_mass} of {n} "
        f"(bandwidth {settings.load_torque_bandwidth:g} rad/s):"
    )
    print(f"  final              {report['final']:.6g} N.m")
    print(
        f"  last second        {report['mean_last_second']:.6g} ± "
        f"{report['std_last_second']:.2g} N.m (mean ± std)"
    )
    print(f"  rms innovation     {report['rms_innovation']:.3g} N.m")
    if args.out:
        print(f"wrote {args.out}")
    return 0


def _set_names(assignments: Sequence[str]) -> set[str]:
    return {parse_assignment(text)[0] for text in assignments}


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
