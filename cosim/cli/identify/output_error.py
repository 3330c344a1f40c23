"""``arcosim identify --method output-error``: the paper's uniform chain, k and B (and a
common scale on the J_i) fitted offline to τ̂_reac (:func:`arcosim.identify_uniform_chain`),
and the report of the fit.
"""

from __future__ import annotations

import argparse
import json

from arcosim import DriveLog, identify_uniform_chain, tool_keys
from arcosim.cli.identify.options import write_report
from arcosim.cli.parameters import actuator_of, defaults_note, set_names
from arcosim.host import observer_values


def run_output_error(args: argparse.Namespace, log: DriveLog, n: int) -> int:
    """Fit the uniform chain of ``n`` masses to ``log``; print and write the report.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``set``, ``start_k``,
        ``fit_inertia_scale``, ``out``, ``force``, ``json``, ``log``).
    log : DriveLog
        The checked log, SI units, at a constant step.
    n : int
        Number of load masses (a count).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    IdentificationError
        Load inertias not > 0, a ``--start-k`` out of the log's band, a fit that ends
        on non-finite numbers.
    """
    values = observer_values(n, args.set)
    c = log.columns
    result = identify_uniform_chain(
        log.time,
        c["i_a"],
        c["omega_m"],
        c["theta_m"],
        actuator_of(values),
        [values[f"J[{i}]"] for i in range(1, n + 1)],
        g_dist=values["g_dist"],
        fit_inertia_scale=args.fit_inertia_scale,
        k_start=args.start_k,
    )
    known = ["J_mo", "k_to", "D_m", "f_c", *(f"J[{i}]" for i in range(1, n + 1))]
    defaults = defaults_note(values, known, set_names(args.set))
    if defaults:
        result = result.with_assumption("defaults", defaults)
    report = result.to_json()
    write_report(args, report)
    if args.json:
        print(json.dumps(tool_keys(report) if args.tool_names else report, indent=2))
    else:
        print(result.text())
    return 0
