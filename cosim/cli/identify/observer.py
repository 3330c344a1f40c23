"""``arcosim identify --method observer`` (the default): the observer FMU replayed over
the log, sample by sample; its final outputs printed, every output over time written.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from arcosim.build.recipes import OBSERVER
from arcosim.cli.identify.options import check_out
from arcosim.cli.options import fmu_folder, fmu_inputs
from arcosim.cli.parameters import defaults_note, drive_parameters, known_parameters, set_names
from arcosim.fmu.flexchain.codes import Mode
from arcosim.host.instance import FmuInstance
from arcosim.host.replay import final_values, observer_parameters, replay_log
from arcosim.logs import DriveLog, tool_keys, write_csv


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
        known_parameters(n, args.set),
        drive_parameters(n, chain=args.mode in (None, Mode.STATE_ESTIMATION)),
        set_names(args.set),
    )
    with FmuInstance(folder / f"{OBSERVER.name}.fmu", "observer") as observer:
        parameters = observer_parameters(observer, args.set, args.mode)
        recording = replay_log(observer, log, parameters)
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


def _print_summary(final: dict, samples: int, out: Path | None) -> None:
    """The final outputs, one a line, and the file written."""
    print(f"{samples} samples; final observer outputs (0 where the mode does not run them):")
    for key, value in final.items():
        print(f"  {key:24s} {value}")
    if out:
        print(f"wrote {out}")
