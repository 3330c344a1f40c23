"""``arcosim identify LOG.csv``: a drive from its log — the observer FMU replayed, the
chain fitted offline (output error, whole chain), or the torque on a load mass.

Contract (scripts rely on it)::

    arcosim identify LOG.csv [--masses N] [--mode 0|1|2] [--set NAME=VALUE ...]
                             [--scale COLUMN=FACTOR ...] [--json] [--out FILE]
                             [--method observer|output-error|whole-chain|load-torque|beam]
                             [--fit-inertia-scale] [--start-k K] [--chain FIT.json]

* the log's columns ``time``, ``i_a``, ``omega_m``, ``theta_m`` (SI; ``--scale``
  converts, e.g. ``--scale i_a=0.001`` for mA), one row per sample (timing contract
  of docs/method.md); the step may vary, and the observer gets the step taken;
* ``--set NAME=VALUE``: an observer parameter, e.g. ``--set "J[1]=5e-4"``;
* ``--chain FIT.json`` (observer, output-error, load-torque; refused with whole-chain):
  the chain ``J[i]``, ``k[i]``, ``B[i]``, the friction ``D_m``, ``f_c`` and ``--masses``
  from a whole-chain report (:func:`arcosim.read_chain`), as if given with ``--set``
  before the user's own (which win);
* ``--json``: one JSON object, the final value of every observer output keyed by its
  FMU name (Booleans as true/false);
* ``--out FILE``: every output over time as CSV (``time`` first); with
  ``--method output-error`` or ``whole-chain``, the report ``--json`` prints, as a
  JSON file (its name must end in ``.json``; the observer's CSV may not). An
  existing file is replaced only with ``--force``; the log itself never.
* ``--method output-error``: instead of replaying the observer FMU, fit the uniform
  chain's k and B (``--fit-inertia-scale``: and a common scale on the J_i) to τ̂_reac
  from any excitation rich enough to ring the chain
  (``arcosim.identification.fit.uniform_fit``). The observer's parameters (``--set``:
  J_mo, k_to, dkt, dJm, D_m, f_c, g_dist, J[i]) say
  what is known; ``--json`` prints ``k_hat``, ``B_hat`` (and ``J_scale``), their
  standard errors under ``std``, and the evidence (start, residual, velocity used).
  Needs a constant sample step.
* ``--method whole-chain [--masses N|auto]``: fit every load inertia, stiffness and
  damping (``arcosim.identification.fit.whole_chain``); only the actuator terms are known
  (``--set``:
  J_mo, k_to, dkt, dJm, g_dist, encoder_cpr; D_m and f_c when known, else they are
  fitted with the chain; with counts the fit is the prediction-error fit from the
  current to the encoder). ``--load none|constant|slow``: a load torque on the last mass
  is part of the model (fitted, reported as ``tau_load``); not given, the selection rule
  chooses it and says so (``selection.load``). ``--masses auto`` (the default here, as
  ``check`` assumes) reads the number of masses from the record. The report's
  ``assumptions`` say what the result is conditional on (and any drive parameter left at
  the bench's default). ``--json``
  prints ``J[i]``, ``k[i]``, ``B[i]``, ``D_m``, ``f_c`` (the observer's own parameter
  names; the text output ends with the ``--set`` line, ``estimator=1`` included, that
  estimates every load angle with them), their standard errors under ``std`` and SI
  units under ``units``, the evidence (modes seen and their residue t values, weak
  modes, criterion per n tried).
  Needs a constant sample step and an excitation that rings every mode (``arcosim
  simulate --scenario identification``: 40 lines 3–150 rad/s, 3 A, 20 s); it refuses
  exactly when ``arcosim check`` says not ok (one set of decisions).
  ``--plot FILE.png [--reference COLUMN]``: the measured response torque → motor speed
  under the model's, and ``FILE.csv`` (``arcosim.cli.identify.plot``). The report
  starts with the verdict (``"verdict": "trusted" | "untrusted"`` and ``"reasons"`` in
  the JSON; :mod:`arcosim.identification.checks.verdict`); exit status 0 when trusted, 3 when
  the fit was made but is not trusted (printed and written all the same), 1 when it
  refuses. ``--verbose`` adds the structure choice's evidence to the text.
* ``--method load-torque [--chain FIT.json]``: the external torque on one load mass over
  time, from the motor alone (``arcosim.identification.load_torque``: the observer FMU's estimator 1
  with ``load_mass``, run offline). The chain (``J[i]``, ``k[i]``, ``B[i]``) and the
  friction (``D_m``, ``f_c``) come from ``--chain`` (the JSON that ``--method
  whole-chain --json`` prints; it sets ``--masses`` too) and ``--set`` (which wins), the
  actuator terms, ``load_mass`` (required) and
  ``load_torque_bandwidth`` from ``--set``; ``--out`` writes ``time``,
  ``tau_load_hat``, ``tau_reac_hat``, ``theta_hat[i]``, ``omega_hat[i]`` and the
  innovation; ``--json`` prints a summary. The step may vary.

* ``--method beam --set L=M --set m_tip=KG [--set J_tip=… --set r_hub=…]``: a flexible
  link on the hub (``arcosim.identification.link.beam_fit``): EI, ρA, the modal damping and,
  unless given, the hub's friction, from the current and the encoder (``encoder_cpr``
  needed); without ``L``, the link's modal model (frequencies, damping, hub
  participation). ``--json`` prints ``EI``, ``rhoA``, ``modes_rad_s`` (hub-locked),
  ``std``, the assumptions and the equivalent lumped chain; ``--out FILE.json`` writes
  the report (``--chain`` reads its chain), ``--out FILE.csv`` the tip's motion over
  time (``alpha_tip_hat``, ``w_tip_hat``, ``tau_reac_hat``).

Every method names, on a line ``assumption, defaults``, the drive's parameters (J_mo,
k_to, D_m, f_c, encoder_cpr, the chain) it left at the paper bench's default.

A bad log (missing column, non-increasing time, NaN, empty file, not UTF-8) gives a
one-line error naming the row or column, and exit status 2. So does a ``--start-k``
outside the band the log can show (the first clamped mode between one period in the
record and the Nyquist frequency π/h), and a fit that ends on non-finite numbers.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from arcosim import UserError, parse_scales, read_log
from arcosim.cli.identify.beam import run_beam
from arcosim.cli.identify.load_torque import run_load_torque
from arcosim.cli.identify.observer import run_observer
from arcosim.cli.identify.options import (
    chain_assignments,
    chain_option,
    check_method_options,
    check_out,
    masses_option,
)
from arcosim.cli.identify.output_error import run_output_error
from arcosim.cli.identify.plot import check_plot
from arcosim.cli.identify.whole_chain import run_whole_chain
from arcosim.cli.options import add_command, add_fmus_option, force_option, log_options, number
from arcosim.cli.parameters import set_names


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim identify``."""
    p = add_command(
        subparsers,
        "identify",
        summary="a drive from its log: replay the observer FMU, fit the chain, or the load torque",
        description="""
Identify a drive from a log of its motor: columns time (s), i_a (A), omega_m
(rad/s), theta_m (rad), one row per sample. --method chooses what to do:
  observer      replay the observer FMU over the log (default)
  whole-chain   fit every load inertia, stiffness and damping, and n (--masses auto)
  output-error  fit the uniform chain's k and B, the J[i] known
  load-torque   the torque on one load mass over time (--set load_mass=I)
  beam          a flexible link: EI, rhoA, its modes and the tip (--set L=, m_tip=)

Give first what you know of the motor (anything not given takes the paper bench's
value, and the output names it on a line "assumption, defaults"):
  --set k_to=VALUE        torque constant, N.m/A
  --set J_mo=VALUE        motor inertia, kg.m2
  --set encoder_cpr=N     encoder counts per revolution, after quadrature
  --set D_m=, --set f_c=  motor friction (N.m.s/rad, N.m) if known, else fitted
  --scale COLUMN=FACTOR   the log's units to SI: --scale i_a=0.001 for mA
  --chain chain.json      the chain a whole-chain fit wrote (--out chain.json):
                          J[i], k[i], B[i], D_m, f_c and --masses; --set wins""",
        examples="""
M="--set k_to=0.0406 --set J_mo=2.09e-5 --set encoder_cpr=2000"
arcosim identify log.csv $M --method whole-chain --masses auto --out chain.json
arcosim identify log.csv $M --chain chain.json --set estimator=1 --out states.csv
arcosim identify log.csv $M --chain chain.json --method load-torque --set load_mass=2""",
    )
    log_options(p, "observer parameter, repeatable")
    p.add_argument(
        "--masses",
        metavar="N",
        help="number of load masses (default 3; with --method whole-chain default 'auto', "
        "as check assumes); with --method whole-chain also 0 (a rigid drive) and 'auto'",
    )
    p.add_argument(
        "--mode", type=int, choices=(0, 1, 2), help="observer mode (default: the FMU's, 2)"
    )
    p.add_argument("--json", action="store_true", help="print the final outputs as one JSON object")
    p.add_argument(
        "--out",
        type=Path,
        metavar="FILE",
        help="observer, load-torque: every output over time as CSV; output-error, "
        "whole-chain: the report as a .json file",
    )
    force_option(p)
    p.add_argument(
        "--method",
        choices=("observer", "output-error", "whole-chain", "load-torque", "beam"),
        default="observer",
        help="observer: replay the observer FMU (default); output-error: fit k and B "
        "offline; whole-chain: fit every J[i], k[i], B[i] offline; load-torque: estimate "
        "the torque on load mass load_mass over time, offline; beam: a flexible link's EI, "
        "rhoA, damping and tip motion (--set L=M --set m_tip=KG), offline",
    )
    p.add_argument(
        "--chain",
        type=Path,
        metavar="FILE",
        help="observer, output-error, load-torque: the chain J[i], k[i], B[i], the friction "
        "D_m, f_c and --masses from the JSON of --method whole-chain --out FILE (--set wins)",
    )
    p.add_argument(
        "--fit-inertia-scale",
        action="store_true",
        help="output-error: also fit a common scale on the load inertias J[i]",
    )
    p.add_argument(
        "--load",
        choices=("none", "constant", "slow"),
        default=None,
        help="whole-chain: model a load torque on the last mass (constant, or constant "
        "plus a slow drift), fitted and reported; not given: chosen by the selection rule",
    )
    p.add_argument(
        "--start-k",
        type=number(0.0, low_open=True, unit="N.m/rad"),
        metavar="K",
        help="output-error: start from this stiffness (N.m/rad) instead of the cost scan; "
        "it must put the chain's first mode in the band the log shows",
    )
    p.add_argument(
        "--plot",
        type=Path,
        metavar="FILE.png",
        help="whole-chain: the measured response torque → motor speed with its coherence, "
        "the model's over it, the residual against the noise floor; and FILE.csv. "
        "Observer, tracking=1: the tracked chain",
    )
    p.add_argument(
        "--reference",
        metavar="COLUMN",
        help="whole-chain with --plot: a logged reference or added excitation (a closed "
        "loop's): the measured response estimated indirectly through it",
    )
    p.add_argument(
        "--verbose",
        action="store_true",
        help="whole-chain: also print the structure choice's evidence (modes seen, the "
        "candidates and their scores)",
    )
    add_fmus_option(p)
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    """Check the options that do not need the log, read it, and run the method."""
    check_method_options(args)
    check_out(args, [])
    tracking = args.method == "observer" and "tracking" in set_names(args.set)
    if args.plot is not None and args.method != "whole-chain" and not tracking:
        raise UserError(
            "--plot is for --method whole-chain, or the observer with --set tracking=1 "
            f"(not {args.method} without it)"
        )
    check_plot(args)
    if args.chain and args.method in ("whole-chain", "beam"):
        raise UserError(
            "--chain is for the methods that use a chain (observer, output-error, "
            f"load-torque); --method {args.method} fits it"
        )
    chain = chain_option(args.chain) if args.chain else None
    log = read_log(args.log, parse_scales(args.scale))
    if args.method == "beam":
        return run_beam(args, log)
    if args.method == "whole-chain":
        # whole-chain also fits the rigid drive, n = 0, and reads n from the record by
        # default: the n `arcosim check` judges when it is not given
        text = (args.masses or "auto").strip()
        masses = {"auto": "auto", "0": 0}.get(text)
        return run_whole_chain(args, log, masses if masses is not None else masses_option(text))
    n = chain.n if chain else masses_option(args.masses or "3")
    args.set = chain_assignments(chain, args.set) + list(args.set)  # --set wins
    if args.method == "load-torque":
        return run_load_torque(args, log, n)
    if args.method == "output-error":
        return run_output_error(args, log, n)
    return run_observer(args, log, n)
