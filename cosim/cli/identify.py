"""``arcosim identify LOG.csv``: a drive from its log — the observer FMU replayed, the
chain fitted offline (output error, whole chain), or the torque on a load mass.

Contract (scripts rely on it)::

    arcosim identify LOG.csv [--masses N] [--mode 0|1|2] [--set NAME=VALUE ...]
                             [--scale COLUMN=FACTOR ...] [--json] [--out FILE]
                             [--method observer|output-error|whole-chain|load-torque]
                             [--fit-inertia-scale] [--start-k K] [--chain FIT.json]

* the log's columns ``time``, ``i_a``, ``omega_m``, ``theta_m`` (SI; ``--scale``
  converts, e.g. ``--scale i_a=0.001`` for mA), one row per sample (timing contract
  of docs/method.md); the step may vary, and the observer gets the step taken;
* ``--set NAME=VALUE``: an observer parameter, e.g. ``--set "J[1]=5e-4"``;
* ``--json``: one JSON object, the final value of every observer output keyed by its
  FMU name (Booleans as true/false);
* ``--out FILE``: every output over time as CSV (``time`` first); with
  ``--method output-error`` or ``whole-chain``, the report ``--json`` prints, as a
  JSON file (its name must end in ``.json``; the observer's CSV may not). An
  existing file is replaced only with ``--force``; the log itself never.
* ``--method output-error``: instead of replaying the observer FMU, fit the uniform
  chain's k and B (``--fit-inertia-scale``: and a common scale on the J_i) to τ̂_reac
  from any excitation rich enough to ring the chain (``arcosim.identification.uniform_fit``). The
  observer's parameters (``--set``: J_mo, k_to, dkt, dJm, D_m, f_c, g_dist, J[i]) say
  what is known; ``--json`` prints ``k_hat``, ``B_hat`` (and ``J_scale``), their
  standard errors under ``std``, and the evidence (start, residual, velocity used).
  Needs a constant sample step.
* ``--method whole-chain [--masses N|auto]``: fit every load inertia, stiffness and
  damping (``arcosim.identification.whole_chain``); only the actuator terms are known (``--set``:
  J_mo, k_to, dkt, dJm, g_dist, encoder_cpr; D_m and f_c when known, else they are
  fitted with the chain; with counts the fit is the prediction-error fit from the
  current to the encoder). ``--load constant|slow``: a load torque on the last mass is
  part of the model (fitted, reported as ``tau_load``). ``--masses auto`` reads the
  number of masses from the record. The report's ``assumptions`` say what the result
  is conditional on (and any drive parameter left at the bench's default). ``--json``
  prints ``J[i]``, ``k[i]``, ``B[i]``, ``D_m``, ``f_c`` (the observer's own parameter
  names; the text output ends with the ``--set`` line, ``estimator=1`` included, that
  estimates every load angle with them), their standard errors under ``std``, the evidence
  (modes seen and their residue t values, weak modes, criterion per n tried).
  Needs a constant sample step and an excitation that rings every mode (``arcosim
  simulate --scenario identification``: 40 lines 3–150 rad/s, 3 A, 20 s).
* ``--method load-torque [--chain FIT.json]``: the external torque on one load mass over
  time, from the motor alone (``arcosim.identification.load_torque``: the observer FMU's estimator 1
  with ``load_mass``, run offline). The chain (``J[i]``, ``k[i]``, ``B[i]``) and the
  friction (``D_m``, ``f_c``) come from ``--chain`` (the JSON that ``--method
  whole-chain --json`` prints; it sets ``--masses`` too) and ``--set`` (which wins), the
  actuator terms, ``load_mass`` (required) and
  ``load_torque_bandwidth`` from ``--set``; ``--out`` writes ``time``,
  ``tau_load_hat``, ``tau_reac_hat``, ``theta_hat[i]``, ``omega_hat[i]`` and the
  innovation; ``--json`` prints a summary. The step may vary.

Every method names, on a line ``assumption, defaults``, the drive's parameters (J_mo,
k_to, D_m, f_c, encoder_cpr, the chain) it left at the paper bench's default.

A bad log (missing column, non-increasing time, NaN, empty file, not UTF-8) gives a
one-line error naming the row or column, and exit status 2. So does a ``--start-k``
outside the band the log can show (the first clamped mode between one period in the
record and the Nyquist frequency π/h), and a fit that ends on non-finite numbers.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from arcosim.build.recipes import OBSERVER, check_masses
from arcosim.cli.options import (
    add_fmus_option,
    fmu_folder,
    fmu_inputs,
    force_option,
    log_options,
    number,
)
from arcosim.errors import UserError
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.fmu.flexchain.observer import MODEL_BASED, STATE_ESTIMATION, ObserverSettings
from arcosim.host.instance import FmuInstance
from arcosim.host.overrides import parse_assignment
from arcosim.host.replay import final_values, observer_parameters, parameter_sets, replay_log
from arcosim.identification import load_torque
from arcosim.identification.drive import identify_drive
from arcosim.identification.output_error import ParameterFit
from arcosim.identification.records import MotorRecord, motor_record
from arcosim.identification.uniform_fit import clamped_frequencies, uniform_chain
from arcosim.logs import DriveLog, parse_scales, read_log, read_text_file, write_csv
from arcosim.outputs import check_output, write_text

#: Methods whose result is a report (``--out`` writes it as JSON), not a time series.
OFFLINE = ("output-error", "whole-chain")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim identify``."""
    p = subparsers.add_parser(
        "identify",
        help="a drive from its log: replay the observer FMU, fit the chain, or the load torque",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    log_options(p, "observer parameter, repeatable")
    p.add_argument(
        "--masses",
        default="3",
        help="number of load masses (default 3); with --method whole-chain also 'auto'",
    )
    p.add_argument(
        "--mode", type=int, choices=(0, 1, 2), help="observer mode (default: the FMU's, 2)"
    )
    p.add_argument("--json", action="store_true", help="print the final outputs as one JSON object")
    p.add_argument(
        "--out",
        type=Path,
        help="observer, load-torque: every output over time as CSV; output-error, "
        "whole-chain: the report as a .json file",
    )
    force_option(p)
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
        type=number(0.0, low_open=True, unit="N.m/rad"),
        help="output-error: start from this stiffness (N.m/rad) instead of the cost scan; "
        "it must put the chain's first mode in the band the log shows",
    )
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    for given, option in (
        (args.start_k is not None, "--start-k"),
        (args.fit_inertia_scale, "--fit-inertia-scale"),
    ):
        if given and args.method != "output-error":
            raise UserError(f"{option} is for --method output-error (not {args.method})")
    if args.mode is not None and args.method != "observer":
        raise UserError(f"--mode is for --method observer (not {args.method})")
    _check_out(args, [])
    log = read_log(args.log, parse_scales(args.scale))
    if args.method == "whole-chain":
        masses = args.masses if args.masses == "auto" else _masses(args.masses)
        return _whole_chain(args, log, masses)
    if args.method == "load-torque":
        chain = read_chain(args.chain) if args.chain else {}
        n = int(chain.pop("masses")) if "masses" in chain else _masses(args.masses)  # checked
        return _load_torque(args, log, n, chain)
    if args.chain:
        raise UserError("--chain is for --method load-torque")
    n = _masses(args.masses)
    if args.method == "output-error":
        return _output_error(args, log, n)
    folder = fmu_folder(args, n)
    _check_out(args, fmu_inputs(folder))
    defaults = defaults_note(
        known_parameters(n, args.set),
        drive_parameters(n, chain=args.mode in (None, STATE_ESTIMATION)),
        set_names(args.set),
    )
    with FmuInstance(folder / f"{OBSERVER.name}.fmu", "observer") as observer:
        parameters = observer_parameters(observer, args.set, args.mode)
        recording = replay_log(observer, log, parameters)
        final = final_values(observer, recording)
    if args.out:
        columns = {"time": recording.time}
        columns.update({k.split(".", 1)[1]: v for k, v in recording.signals.items()})
        write_csv(args.out, columns, force=args.force)
    if args.json:
        print(json.dumps(final, indent=2))
        if defaults:
            print(f"arcosim identify: assumption, defaults: {defaults}", file=sys.stderr)
    else:
        _print_summary(final, len(log), args.out)
        if defaults:
            print(f"assumption, defaults: {defaults}")
    return 0


def _check_out(args: argparse.Namespace, fmus: Sequence[Path]) -> None:
    """Refuse ``--out`` before any work: a name that does not fit the method's format,
    an existing file without ``--force``, the log or an FMU."""
    if args.out is None:
        return
    is_json = args.out.suffix.lower() == ".json"
    if args.method in OFFLINE and not is_json:
        raise UserError(
            f"--out {args.out}: --method {args.method} writes its report as JSON; name a .json file"
        )
    if args.method not in OFFLINE and is_json:
        raise UserError(
            f"--out {args.out}: --method {args.method} writes its outputs over time as CSV; "
            "name a .csv file (--json prints a summary)"
        )
    chain = [args.chain] if args.chain else []
    check_output(args.out, inputs=[args.log, *chain, *fmus], force=args.force)


def _write_report(args: argparse.Namespace, report: Mapping[str, object]) -> None:
    """Refuse a report with a non-finite estimate; write it to ``--out`` if given."""
    bad = [
        key
        for key, value in [*report.items(), *dict(report.get("std") or {}).items()]
        if isinstance(value, float) and not math.isfinite(value)
    ]
    if bad:
        raise UserError(
            f"{args.log}: the fit ended on non-finite numbers ({', '.join(bad[:6])}): the log "
            "does not determine them; check --set and the excitation"
        )
    if args.out:
        write_text(args.out, json.dumps(report, indent=2) + "\n", force=args.force)


def check_start_k(k: float, J: Sequence[float], record: MotorRecord) -> None:
    """Refuse a ``--start-k`` whose uniform chain's first clamped mode lies outside the
    band the record can show: from one period in its length to the Nyquist frequency."""
    unit = float(clamped_frequencies([float(x) for x in J], [1.0] * len(J))[0])
    low_w, high_w = 2.0 * math.pi / record.duration, math.pi / record.h
    low, high = (low_w / unit) ** 2, (high_w / unit) ** 2
    if not low <= k <= high:
        raise UserError(
            f"--start-k {k:g}: give a stiffness from {low:.3g} to {high:.3g} N.m/rad for this "
            f"log and J (the chain's first mode between one period in {record.duration:g} s, "
            f"{low_w:.3g} rad/s, and the Nyquist frequency, {high_w:.3g} rad/s)"
        )


def _print_summary(final: dict, samples: int, out: Path | None) -> None:
    print(f"{samples} samples; final observer outputs (0 where the mode does not run them):")
    for key, value in final.items():
        print(f"  {key:24s} {value}")
    if out:
        print(f"wrote {out}")


def known_parameters(n: int, assignments: Sequence[str]) -> dict[str, float]:
    """The observer's parameter defaults for ``n`` masses with ``--set`` applied, from the
    observer FMU's own declaration (the offline methods need no built FMU)."""
    from arcosim.fmu.arobserver.fmu import ReactionTorqueObserver

    variables = ReactionTorqueObserver.interface(n)
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
            raise UserError(f"{name} = {float(values[name]):g} must be > 0")
    return Actuator(
        values["J_mo"], values["k_to"], values["dkt"], values["dJm"], values["D_m"], values["f_c"]
    )


def _output_error(args: argparse.Namespace, log: DriveLog, n: int) -> int:
    values = known_parameters(n, args.set)
    J = [values[f"J[{i}]"] for i in range(1, n + 1)]
    if any(not x > 0 for x in J):
        raise UserError(f"the load inertias must be > 0, got J = {J}")
    c = log.columns
    record = motor_record(
        log.time, c["i_a"], c["omega_m"], c["theta_m"], actuator_of(values), values["g_dist"]
    )
    if args.start_k is not None:
        check_start_k(args.start_k, J, record)
    result = uniform_chain(record, J, args.fit_inertia_scale, args.start_k)
    names = {"k": "k_hat", "B": "B_hat", "J_scale": "J_scale"}
    report = {names[k]: v for k, v in result.as_dict().items()}
    report["std"] = {names[k]: v for k, v in result.std_dict().items()}
    report.update(evidence(result, record))
    known = ["J_mo", "k_to", "D_m", "f_c", *(f"J[{i}]" for i in range(1, n + 1))]
    defaults = defaults_note(values, known, set_names(args.set))
    if defaults:
        report["assumptions"] = {"defaults": defaults}
    _write_report(args, report)
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(f"{len(log)} samples, output-error fit of the uniform chain ({n} masses):")
        for key in (k for k in report if k in names.values()):
            print(f"  {key:8s} {report[key]:.6g}  ± {report['std'][key]:.2g}")
        for key in ("start", "velocity", "rms_residual", "rms_data", "newey_west_lag"):
            print(f"  {key}: {report[key]}")
        if defaults:
            print(f"  assumption, defaults: {defaults}")
    return 0


def _masses(text: str) -> int:
    """``--masses`` as a supported number of masses."""
    try:
        n = int(text)
    except ValueError:
        what = " ('auto' needs --method whole-chain)" if text == "auto" else ""
        raise UserError(f"--masses {text}: not a whole number{what}") from None
    return check_masses(n)


def _whole_chain(args: argparse.Namespace, log: DriveLog, masses: int | str) -> int:
    values = known_parameters(masses if isinstance(masses, int) else 3, args.set)
    given = set_names(args.set)
    friction = {"D_m": values["D_m"], "f_c": values["f_c"]} if {"D_m", "f_c"} <= given else {}
    actuator = actuator_of(values)
    c = log.columns
    result = identify_drive(
        log.time,
        c["i_a"],
        c["omega_m"],
        c["theta_m"],
        k_t=actuator.k_to + actuator.dkt,
        J_m=actuator.J_mo + actuator.dJm,
        encoder_cpr=int(values["encoder_cpr"]),
        masses=masses,
        load=args.load,
        g_dist=values["g_dist"],
        **friction,
    )
    note = defaults_note(values, ("J_mo", "k_to", "encoder_cpr"), given)
    if note:
        result.assumptions["defaults"] = note
    report = result.report()
    _write_report(args, report)
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    print(f"{len(log)} samples, whole-chain fit ({result.masses} masses):")
    for key, value in result.parameters.items():
        print(f"  {key:8s} {value:.6g}  ± {result.std[key]:.2g}")
    for key in ("start", "modes_rad_s", "residue_t_values", "weak_modes", "refused"):
        print(f"  {key}: {report[key]}")
    for key, text in result.assumptions.items():
        print(f"  assumption, {key}: {text}")
    for text in result.warnings:
        print(f"  warning: {text}")
    settings = " ".join(f'--set "{k}={v:.6g}"' for k, v in result.observer_parameters().items())
    print(f"every load angle, the observer with this chain: --masses {result.masses} {settings}")
    return 0


def read_chain(path: Path) -> dict[str, float]:
    """``J[i]``, ``k[i]``, ``B[i]`` (and ``masses``, and the friction ``D_m``, ``f_c`` when
    there) from a whole-chain JSON report.

    Raises
    ------
    UserError
        When the file is not UTF-8 JSON, or a value is missing, not a finite number,
        or ``masses`` not a supported number of masses.
    """
    try:
        data = json.loads(read_text_file(path, "chain"))
    except ValueError as error:
        raise UserError(f"--chain {path}: cannot read it as JSON ({error})") from None
    if not isinstance(data, dict):
        raise UserError(f"--chain {path}: expected a JSON object with J[i], k[i], B[i]")
    chain = {
        k: v
        for k, v in data.items()
        if (k.split("[")[0] in ("J", "k", "B") and k.endswith("]")) or k in ("masses", "D_m", "f_c")
    }
    for key, value in chain.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise UserError(f"--chain {path}: {key} = {value!r:.40} is not a number")
        if not math.isfinite(value):
            raise UserError(f"--chain {path}: {key} = {value} is not a finite number")
    masses = chain.get("masses", sum(k.startswith("J[") for k in chain))
    if masses != int(masses):
        raise UserError(f"--chain {path}: masses = {masses} is not a whole number")
    n = check_masses(int(masses))
    missing = [f"{p}[{i}]" for p in "JkB" for i in range(1, n + 1) if f"{p}[{i}]" not in chain]
    if missing:
        raise UserError(f"--chain {path}: missing {', '.join(missing)}")
    return {**{k: float(v) for k, v in chain.items()}, "masses": n}


def _load_torque(args: argparse.Namespace, log: DriveLog, n: int, chain: dict[str, float]) -> int:
    values = known_parameters(n, args.set)
    given = set_names(args.set)
    values.update({k: v for k, v in chain.items() if k not in given})
    defaults = defaults_note(values, drive_parameters(n), given | set(chain))
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
    try:
        result = load_torque.estimate_load_torque(
            settings, log.time, c["i_a"], c["omega_m"], c["theta_m"]
        )
    except (ValueError, ZeroDivisionError, OverflowError) as error:  # the Kalman design
        raise UserError(
            f"--method load-torque: no estimator for these settings ({error}); check "
            "torque_noise_std, tau_noise_std, load_torque_bandwidth and the chain"
        ) from None
    if args.out:
        write_csv(args.out, result.columns(), force=args.force)
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
    if defaults:
        report["assumptions"] = {"defaults": defaults}
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    print(
        f"{len(log)} samples, load torque on mass {load_mass} of {n} "
        f"(bandwidth {settings.load_torque_bandwidth:g} rad/s):"
    )
    print(f"  final              {report['final']:.6g} N·m")
    print(
        f"  last second        {report['mean_last_second']:.6g} ± "
        f"{report['std_last_second']:.2g} N·m (mean ± std)"
    )
    print(f"  rms innovation     {report['rms_innovation']:.3g} N·m")
    if defaults:
        print(f"  assumption, defaults: {defaults}")
    if args.out:
        print(f"wrote {args.out}")
    return 0


def set_names(assignments: Sequence[str]) -> set[str]:
    """The parameter names of ``--set NAME=VALUE`` assignments."""
    return {parse_assignment(text)[0] for text in assignments}


def drive_parameters(n: int, chain: bool = True) -> list[str]:
    """The observer parameters that describe the drive (and, with ``chain``, its n-mass
    chain): the ones whose default is the paper bench's, not a tuning choice."""
    names = ["J_mo", "k_to", "D_m", "f_c", "encoder_cpr"]
    if chain:
        names += [f"{p}[{i}]" for p in "JkB" for i in range(1, n + 1)]
    return names


def defaults_note(values: Mapping[str, float], names: Sequence[str], given: set[str]) -> str | None:
    """One sentence naming the parameters among ``names`` left at their default (None when
    every one was given); a chain left whole at its default is named as one.

    Examples
    --------
    >>> defaults_note({"k_to": 0.0406, "D_m": 0.0}, ["k_to", "D_m"], {"k_to"})
    "not given, so the paper bench's value was used: D_m = 0 (give your drive's with --set)"
    """
    missing = [name for name in names if name not in given]
    if not missing:
        return None
    chain = [name for name in names if "[" in name]
    parts = [f"{name} = {values[name]:g}" for name in missing if "[" not in name]
    if chain and set(chain) <= set(missing):
        kinds = dict.fromkeys(f"{name.split('[')[0]}[i]" for name in chain)
        parts.append(f"the bench's chain ({', '.join(kinds)})")
    else:
        parts += [f"{name} = {values[name]:g}" for name in missing if "[" in name]
    return (
        "not given, so the paper bench's value was used: "
        + ", ".join(parts)
        + " (give your drive's with --set)"
    )


def evidence(result: ParameterFit, record: MotorRecord) -> dict[str, object]:
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
