"""``arcosim identify --method whole-chain``: every load inertia, stiffness and damping
(and n) fitted offline from the motor's current and encoder, only the actuator terms
known; the report, and the ``--set`` line that gives the observer this chain.
"""

from __future__ import annotations

import argparse
import json
import sys

from arcosim import DriveIdentification, DriveLog, identify_drive, tool_keys
from arcosim.cli.identify.options import EXIT_UNTRUSTED, write_report
from arcosim.cli.identify.plot import write_plot
from arcosim.cli.parameters import actuator_of, defaults_note, set_names
from arcosim.host import observer_values
from arcosim.identification import MAX_AUTO_MASSES, search_band


def run_whole_chain(args: argparse.Namespace, log: DriveLog, masses: int | str) -> int:
    """Identify the whole chain from ``log``; print and write the report.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``arcosim identify`` arguments (``set``, ``load``, ``out``,
        ``force``, ``json``, ``log``).
    log : DriveLog
        The checked log, SI units, at a constant step.
    masses : int or "auto"
        Number of load masses (a count), or ``"auto"``: read it from the record.

    Returns
    -------
    int
        The exit status: 0 when the fit is trusted, :data:`EXIT_UNTRUSTED` (3) when it
        was made but is not (the result is printed and written all the same, marked
        untrusted, with the reasons).

    Raises
    ------
    UserError
        A bad ``--set``, a record the fit cannot work with, a fit that ends on
        non-finite numbers.
    """
    values = observer_values(masses if isinstance(masses, int) else 3, args.set)
    given = set_names(args.set)
    friction = {"D_m": values["D_m"], "f_c": values["f_c"]} if {"D_m", "f_c"} <= given else {}
    actuator = actuator_of(values)
    c = log.columns
    print(_status(masses, len(log)), file=sys.stderr, flush=True)
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
    view = None
    if getattr(args, "plot", None):
        band = search_band(values["g_dist"], float(log.time[1] - log.time[0]))
        k_t, J_m = actuator.k_to + actuator.dkt, actuator.J_mo + actuator.dJm
        view = write_plot(args, log, result, k_t, J_m, int(values["encoder_cpr"]), band)
        result.warnings.extend(w for w in view if w not in result.warnings)
    report = result.report()
    if view is not None:
        report["frf"] = {"plot": str(args.plot), "csv": str(args.plot.with_suffix(".csv"))}
    write_report(args, report)
    if args.json:
        print(json.dumps(tool_keys(report) if args.tool_names else report, indent=2))
    else:
        _print_report(result, report, len(log), verbose=getattr(args, "verbose", False))
    return 0 if result.verdict.trusted else EXIT_UNTRUSTED


def _status(masses: int | str, samples: int) -> str:
    """The line on stderr before the fit, which takes seconds (stdout stays the report's).

    Examples
    --------
    >>> _status("auto", 20001)
    'arcosim identify: fitting the whole chain to 20001 samples, n = 0 … 8 tried (seconds)…'
    """
    tried = f"n = 0 … {MAX_AUTO_MASSES} tried" if masses == "auto" else f"n = {masses}"
    return f"arcosim identify: fitting the whole chain to {samples} samples, {tried} (seconds)…"


def _print_report(
    result: DriveIdentification, report: dict, samples: int, verbose: bool = False
) -> None:
    """The report as text: the verdict first, the parameters with their standard errors,
    the reasons, what the result rests on; the selection's evidence with ``verbose``;
    last the ``--set`` line for the observer."""
    verdict = result.verdict
    print(f"verdict: {verdict.word}" + ("" if verdict.trusted else " (exit status 3)"))
    for reason in verdict.reasons:
        print(f"  reason: {reason}")
    print(f"{samples} samples, whole-chain fit ({result.masses} masses):")
    bounds = report.get("bounds", {})
    units = result.units
    for key, value in result.parameters.items():
        if key in bounds:
            print(
                f"  {key:8s} ≤ {bounds[key]:.2g} {units[key]}  (at its bound 0: the record does "
                "not resolve it)"
            )
        else:
            print(f"  {key:8s} {value:.6g} ± {result.std[key]:.2g} {units[key]}")
    for key in sorted(set(bounds) - set(result.parameters)):
        print(f"  {key:8s} ≤ {bounds[key]:.2g} {units[key]}  (left out by the selection rule)")
    for key, text in result.assumptions.items():
        print(f"  assumption, {key}: {text}")
    for text in result.warnings:
        if text not in verdict.reasons:
            print(f"  warning: {text}")
    if verbose:
        _print_selection(report)
    settings = " ".join(f'--set "{k}={v:.6g}"' for k, v in result.observer_parameters().items())
    if result.masses == 0:  # no chain, no --masses 0 (the observer needs 1 to 20)
        print(f"the load torque (tau_reac_hat), the observer with this rigid drive: {settings}")
    else:
        print(
            f"every load angle, the observer with this chain: --masses {result.masses} {settings}"
        )


def _print_selection(report: dict) -> None:
    """The structure choice's evidence (``--verbose``): modes, candidates, scores."""
    modes = ", ".join(f"{w:.4g}" for w in report["modes_rad_s"])
    t_values = ", ".join(f"{t:.3g}" for t in report["residue_t_values"])
    print(f"  start: {report['start']}")
    print(f"  modes seen (rad/s): {modes or 'none'}; their residue t values: {t_values or '-'}")
    for mode in report["weak_modes"]:
        print(f"  weak mode: {mode['rad_s']:.4g} rad/s (t = {mode['t']:.3g})")
    for n, why in report["refused"].items():
        print(f"  {n} masses refused: {why}")
    selection = report.get("selection", {})
    if selection:
        print(f"  selection rule: {selection['rule']}")
        for what in ("masses", "friction", "load"):
            scores = selection.get(what) or {}
            chosen = scores.get("chosen") if isinstance(scores, dict) else None
            for name, score in scores.get("candidates", scores).items():
                taken = " (chosen)" if name == chosen else ""
                print(f"  selection, {what}, {name}{taken}: {_score_text(score)}")


def _score_text(score: object) -> str:
    """One candidate's score as text (a number, or its named figures).

    Examples
    --------
    >>> _score_text({"parameters": 7, "rms_innovation": 1.02, "bic": -3.5})
    'parameters 7, rms_innovation 1.02, bic -3.5'
    >>> _score_text(12.5)
    '12.5'
    """
    if isinstance(score, dict):
        return ", ".join(
            f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in score.items()
        )
    return f"{score:.4g}" if isinstance(score, float) else str(score)
