"""``arcosim identify --method observer`` (the default): the observer FMU replayed over
the log, sample by sample; its final outputs printed, every output over time written.
With ``--set tracking=1``: the tracked chain over time written (and drawn with ``--plot``),
its final values with their σ, the alarm and validity printed.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from arcosim import DriveLog, FmuInstance, UserError, replay_log, tool_keys, write_csv
from arcosim.build import OBSERVER
from arcosim.cli.identify.options import check_out
from arcosim.cli.options import fmu_folder, fmu_inputs
from arcosim.cli.parameters import defaults_note, drive_parameters, set_names
from arcosim.fmu.flexchain import Mode
from arcosim.host import (
    TrackedChain,
    final_values,
    observer_parameters,
    observer_values,
    replay_tracking,
    untracked_outputs,
)


def run_observer(args: argparse.Namespace, log: DriveLog, n: int) -> int:
    """Replay the observer FMU for ``n`` masses over ``log``; print and write its outputs.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``set``, ``mode``, ``fmus``, ``out``,
        ``force``, ``json``).
    log : DriveLog
        The checked log, SI units.
    n : int
        Number of load masses (a count).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    UserError
        A bad ``--set`` or ``--out``, an FMU that cannot be built or refuses a step.
    """
    folder = fmu_folder(args, n)
    check_out(args, fmu_inputs(folder))
    defaults = defaults_note(
        observer_values(n, args.set),
        drive_parameters(n, chain=args.mode in (None, Mode.STATE_ESTIMATION)),
        set_names(args.set),
    )
    with FmuInstance(folder / f"{OBSERVER.name}.fmu", "observer") as observer:
        parameters = observer_parameters(observer, args.set, args.mode)
        if parameters.get("tracking"):
            tracked = replay_tracking(observer, log, parameters, n)
            return _report_tracking(args, tracked, defaults)
        if args.plot is not None:
            raise UserError(
                "--plot with the observer draws the tracked chain: add --set tracking=1"
            )
        outputs = untracked_outputs(observer.output_names(), n)
        recording = replay_log(observer, log, parameters, outputs)
        final = final_values(observer, recording)
    if args.out:
        columns = {"time": recording.time}
        columns.update({k.split(".", 1)[1]: v for k, v in recording.signals.items()})
        units = {k.split(".", 1)[1]: v for k, v in recording.units.items()}
        write_csv(args.out, columns, units=units, tool_names=args.tool_names, force=args.force)
    if args.json:
        print(json.dumps(tool_keys(final) if args.tool_names else final, indent=2))
        if defaults:
            print(f"arcosim identify: assumption, defaults: {defaults}", file=sys.stderr)
    else:
        _print_summary(final, len(log), args.out)
        if defaults:
            print(f"assumption, defaults: {defaults}")
    return 0


def _report_tracking(args: argparse.Namespace, tracked: TrackedChain, defaults: str) -> int:
    """Write, draw and print a tracked replay; exit status 0."""
    from arcosim.experiments import draw_tracking

    if args.out:
        columns, units = tracked.columns()
        write_csv(args.out, columns, units=units, tool_names=args.tool_names, force=args.force)
    if args.plot is not None:
        draw_tracking(tracked, args.plot, force=args.force)
    if args.json:
        print(json.dumps(tracked.to_json(), indent=2))
    else:
        print(tracked.text())
        for path in (args.out, args.plot):
            if path:
                print(f"wrote {path}")
    if defaults:
        print(f"assumption, defaults: {defaults}", file=sys.stderr if args.json else sys.stdout)
    return 0


def _print_summary(final: dict, samples: int, out: Path | None) -> None:
    """The final outputs, one a line, and the file written."""
    print(f"{samples} samples; final observer outputs (0 where the mode does not run them):")
    for key, value in final.items():
        print(f"  {key:24s} {value}")
    if out:
        print(f"wrote {out}")
