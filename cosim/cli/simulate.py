"""``arcosim simulate``: run one scenario with any parameter overridden.

    arcosim simulate [--scenario NAME] [--masses N] [--set plant.k[2]=0.2]
                     [--set observer.g_dist=200] [--ideal] [--ordering jacobi]
                     [--step H] [--duration S] [--out FILE.csv] [--json]

The CSV holds ``time``, the measured ``i_a``, ``omega_m``, ``theta_m`` (so it is a
log that ``arcosim identify`` accepts) and every recorded signal as
``plant.<name>`` / ``observer.<name>``. The closed-loop scenarios ``move`` and
``move-load`` run the controller FMU with the plant instead (``--set controller.NAME=…``;
``--ordering gauss-seidel`` is the sequential master, ``jacobi`` the parallel one, a
step late) and print how the move went. An existing ``--out`` file is replaced only
with ``--force``, and never with one of the FMUs the run reads.

The run is refused (exit 2) when its step and duration give no step or more than
10⁷, and its result when a recorded signal is not finite or the plant moves
faster than a passive chain driven by its current can (:func:`check_passive`), the
check behind the FMUs' own limits on their parameters (before them,
``--set plant.k[1]=1e12`` gave such numbers at 1 ms).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from arcosim import (
    SCENARIOS,
    Recording,
    Scenario,
    UserError,
    check_output,
    run_scenario,
    tool_keys,
    write_csv,
)
from arcosim.build import MAX_MASSES, MIN_MASSES, fmu_variables
from arcosim.cli.options import (
    MAX_TIME,
    add_command,
    add_fmus_option,
    check_steps,
    fmu_folder,
    fmu_inputs,
    force_option,
    number,
    step_option,
    whole_number,
)
from arcosim.experiments import (
    CONTROL_SCENARIOS,
    IDEAL_SENSORS,
    move_summary,
    recording_columns,
    run_control_scenario,
)
from arcosim.host import ORDERINGS, split_overrides


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim simulate``."""
    p = add_command(
        subparsers,
        "simulate",
        summary="run one scenario (plant + observer)",
        description="""
Run one scenario of the plant and observer FMUs and print the observer's final
outputs; any parameter of either FMU can be changed with --set FMU.NAME=VALUE. The
CSV written by --out is also a log that arcosim identify accepts (time, i_a,
omega_m, theta_m, then every recorded signal).""",
        examples="""
arcosim simulate --scenario identification --out identification.csv
arcosim simulate --masses 2 --set plant.k[1]=0.5 --set observer.g_dist=200 --json""",
    )
    names = ", ".join(
        f"{s.name} ({s.description})" for s in (*SCENARIOS.values(), *CONTROL_SCENARIOS.values())
    )
    p.add_argument("--scenario", default="flexible", help=f"one of: {names}")
    p.add_argument(
        "--masses",
        type=whole_number(MIN_MASSES, MAX_MASSES),
        default=3,
        metavar="N",
        help=f"number of load masses, {MIN_MASSES} to {MAX_MASSES} (default 3)",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="FMU.NAME=VALUE",
        help="parameter of plant or observer (controller in move, move-load), repeatable",
    )
    p.add_argument(
        "--ideal", action="store_true", help="ideal sensors: exact angle, true velocity, no noise"
    )
    p.add_argument("--ordering", choices=ORDERINGS, default="gauss-seidel")
    step_option(p)
    p.add_argument(
        "--duration",
        type=number(0.0, MAX_TIME, low_open=True, unit="s"),
        metavar="S",
        help=f"length in s, up to {MAX_TIME:g} (default: the scenario's)",
    )
    p.add_argument(
        "--out", type=Path, metavar="FILE", help="CSV of every recorded signal (a log for identify)"
    )
    force_option(p)
    p.add_argument("--json", action="store_true", help="print the final observer outputs as JSON")
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if args.scenario in CONTROL_SCENARIOS:
        return _execute_control(args)
    if args.scenario not in SCENARIOS:
        known = ", ".join([*SCENARIOS, *CONTROL_SCENARIOS])
        raise UserError(f"--scenario {args.scenario!r}: use one of {known}")
    scenario = SCENARIOS[args.scenario]
    if args.duration is not None:
        scenario = dataclasses.replace(scenario, duration=args.duration)
    check_steps("--step", scenario.duration, args.step)
    warn_coarse_step(scenario, args.step)
    n = args.masses  # checked by its option type
    if args.out:
        check_output(args.out, force=args.force, inputs=fmu_inputs(args.fmus) if args.fmus else ())
    folder = fmu_folder(args, n)
    if args.out:
        check_output(args.out, force=args.force, inputs=fmu_inputs(folder))
    variables = fmu_variables(folder)
    overrides = split_overrides(args.set, variables)
    recording = run_scenario(
        scenario,
        n,
        overrides["plant"],
        overrides["observer"],
        h=args.step,
        ordering=args.ordering,
        ideal=args.ideal,
        fmu_dir=folder,
    )
    plant = {name: v.start for name, v in variables["plant"].items() if v.causality == "parameter"}
    plant.update({**scenario.plant, **(IDEAL_SENSORS if args.ideal else {}), **overrides["plant"]})
    check_passive(recording, scenario, plant, n, args.step, args.set)
    if args.out:
        write_csv(
            args.out,
            recording_columns(recording),
            units=recording.units,
            tool_names=args.tool_names,
            force=args.force,
        )
    final = {
        key.split(".", 1)[1]: float(series[-1])
        for key, series in recording.signals.items()
        if key.startswith("observer.")
    }
    if args.json:
        print(json.dumps(tool_keys(final) if args.tool_names else final, indent=2))
    else:
        print(
            f"{scenario.name}: {len(recording.time) - 1} steps of {args.step:g} s ({args.ordering})"
        )
        for key, value in final.items():
            if value:
                print(f"  observer.{key:22s} {value:.6g}")
        if _recursion_reported(final, scenario, variables["observer"], overrides["observer"]):
            print(RECURSION_NOTE)
        if args.out:
            print(f"wrote {args.out}")
    return 0


#: Steps a period of the excitation's top frequency needs at least. The current is held
#: over each step (a zero-order hold): a sine of ω reaches the plant delayed by ωh/2 and
#: scaled by sinc(ωh/2), and above the Nyquist frequency π/h it is another frequency
#: altogether. At 10 steps a period (ω = π/h / 5) the delay is 18° and the loss 1.6 %;
#: with fewer the run answers for another excitation than the one named.
STEPS_PER_PERIOD = 10


def warn_coarse_step(scenario: Scenario, h: float) -> None:
    """Warn when the step ``h`` (s) gives the scenario's top frequency fewer than
    :data:`STEPS_PER_PERIOD` steps a period (above a fifth of the Nyquist frequency π/h)."""
    top = scenario.top_frequency
    if top is None or top <= 2.0 * math.pi / (STEPS_PER_PERIOD * h):
        return
    warnings.warn(
        f"--step {h:g} s is coarse for the {scenario.name} scenario's top frequency "
        f"{top:g} rad/s: {2.0 * math.pi / (top * h):.1f} steps a period (the Nyquist "
        f"frequency is {math.pi / h:.4g} rad/s); the held current follows it only with "
        f"{STEPS_PER_PERIOD} or more: use --step {2.0 * math.pi / (STEPS_PER_PERIOD * top):.2g} "
        "s or less",
        stacklevel=2,
    )


#: The note after a report of the paper's recursion's estimates beyond the first mass.
RECURSION_NOTE = (
    "note: theta_hat[2] … and omega_hat[2] … come from the paper's recursion (the "
    "default estimator, observer.estimator=0), which diverges from the second mass on by "
    "design (each stage subtracts J_i times the acceleration of the one before, which "
    "amplifies errors above the first mode: docs/method.md); the model-based "
    "estimator does not: --set observer.estimator=1"
)


def _recursion_reported(
    final: Mapping[str, float],
    scenario: Scenario,
    declared: Mapping[str, object],
    overrides: Mapping[str, object],
) -> bool:
    """Whether ``final`` reports the recursion's estimates of mass 2 or later."""

    def setting(name: str) -> int:
        value = overrides.get(name, scenario.observer.get(name, declared[name].start))
        return int(float(value))

    later = any(k.startswith("theta_hat[") and k != "theta_hat[1]" and v for k, v in final.items())
    return later and setting("mode") == 2 and setting("estimator") == 0


def _execute_control(args: argparse.Namespace) -> int:
    """``simulate`` for a closed-loop scenario: controller and plant FMUs."""
    from fmpy import read_model_description  # deferred, as fmu_variables does

    scenario = CONTROL_SCENARIOS[args.scenario]
    if args.duration is not None:
        scenario = dataclasses.replace(scenario, duration=args.duration)
    check_steps("--step", scenario.duration, args.step)
    n = args.masses
    if args.out:
        check_output(args.out, force=args.force, inputs=fmu_inputs(args.fmus) if args.fmus else ())
    folder = fmu_folder(args, n)
    if args.out:
        check_output(args.out, force=args.force, inputs=fmu_inputs(folder))
    variables = {
        prefix: {v.name: v for v in read_model_description(str(folder / stem)).modelVariables}
        for prefix, stem in (
            ("plant", "MotorChainPlant.fmu"),
            ("controller", "ActionReactionController.fmu"),
        )
    }
    overrides = split_overrides(args.set, variables)
    plant = {**(IDEAL_SENSORS if args.ideal else {}), **overrides["plant"]}
    controller = {**({"encoder_cpr": 0} if args.ideal else {}), **overrides["controller"]}
    ordering = "sequential" if args.ordering == "gauss-seidel" else "parallel"
    recording = run_control_scenario(scenario, n, folder, plant, controller, args.step, ordering)
    if args.out:
        write_csv(
            args.out,
            recording_columns(recording),
            units=recording.units,
            tool_names=args.tool_names,
            force=args.force,
        )
    summary = move_summary(recording, n, scenario.target)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{scenario.name}: {len(recording.time) - 1} steps of {args.step:g} s ({ordering})")
        for key, value in summary.items():
            print(f"  {key:16s} {value:.6g}")
        if args.out:
            print(f"wrote {args.out}")
    return 0


def check_passive(
    recording: Recording,
    scenario: Scenario,
    plant: Mapping[str, object],
    n: int,
    h: float,
    settings: list[str],
) -> None:
    """Refuse a recording a passive chain cannot produce.

    The chain stores and dissipates energy but makes none: with the motor torque
    ``|k_t i| <= τ`` its energy obeys ``dE/dt <= τ |ω_m| <= τ sqrt(2 E / J_m)``, so from
    rest ``E(T) <= (τ T)² / (2 J_m)`` and every velocity ``|ω_i| <= sqrt(2 E / J_i)``.
    ``τ`` is taken with twice the largest current command (the current loop's
    overshoot), so a plant that integrates correctly is orders of magnitude inside;
    one whose numbers blow up (a chain too stiff for the step) is far outside.

    Raises
    ------
    UserError
        When a signal is not finite or a velocity exceeds the bound.
    """
    given = f" (settings: {' '.join(settings)})" if settings else ""
    hint = (
        f"{given}: the model cannot be integrated at --step {h:g} s with these "
        "parameters; use other values or a smaller step"
    )
    for name, series in recording.signals.items():
        bad = np.flatnonzero(~np.isfinite(series))
        if bad.size:
            t = float(recording.time[bad[0]])
            raise UserError(f"{name} is not finite from t = {t:g} s{hint}")
    steps = max(round(scenario.duration / h), 1)
    i_max = float(np.max(np.abs(scenario.current(np.arange(steps) * h))))
    torque = 2.0 * abs(float(plant["k_t"])) * i_max
    J_m = float(plant["J_m"])
    energy = (torque * scenario.duration) ** 2 / (2.0 * J_m)
    checks = [("omega_m_true", J_m)]
    checks += [(f"omega[{i}]", float(plant[f"J[{i}]"])) for i in range(1, n + 1)]
    for name, inertia in checks:
        series = recording.signals.get(f"plant.{name}")
        if series is None or not inertia > 0:
            continue
        bound = math.sqrt(2.0 * energy / inertia)
        fastest = int(np.argmax(np.abs(series)))
        if abs(series[fastest]) > bound:
            t = float(recording.time[fastest])
            raise UserError(
                f"plant.{name} reached {float(series[fastest]):.3g} rad/s at t = {t:g} s, more "
                f"than a passive chain driven by at most {torque:.3g} N.m can reach in "
                f"{scenario.duration:g} s ({bound:.3g} rad/s){hint}"
            )
