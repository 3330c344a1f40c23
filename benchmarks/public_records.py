"""``arcosim check`` and ``arcosim identify`` on public measured records of real drives.

The records are not part of the repository (nothing downloaded is committed): put the
files, as their sources publish them, in one folder and name it with ``--data``. A
record whose file is missing is skipped with a line saying where to get it.

The records (``--records`` name, the file in ``--data``, what was logged):

- ``emps``, ``DATA_EMPS.mat``: the EMPS, a rigid ball-screw axis in a position loop
  (Janot, Gautier, Brunot 2019): controller voltage, motor encoder on the load side
  (m), the reference;
- ``hsm150`` and ``hsm150-command``, ``idf_pos_0.065_2.mat``: the HSM150 motor, rigid,
  turning one way, torque stepped 0.05 → 0.065 N·m: motor current (or, in the second,
  the torque command), encoder angle and speed;
- ``motor-bench``, ``MultisineTypeA.mat``: the KU Leuven motor bench with a flexible
  coupling (FdiTools): q-axis current under a Schroeder multi-sine 11–250 Hz, motor and
  load encoders.

Per record: the log written in the project's format (CSV and ``.units.json``, see
:mod:`benchmarks.public_loaders` for how each record's signals map onto the names),
``arcosim check`` and each ``arcosim identify`` run as a user types them (exit status,
the first line of a refusal), and the identified values beside the published ones
(or, for the motor bench, whose k_t is not published, beside what its load encoder
says: :func:`benchmarks.public_loaders.two_mass_reference`).

Run: ``python -m benchmarks.public_records --data DIR [--records NAME ...] [--work DIR]
[--fmus DIR] [--out FILE.json] [--figure FILE.png]``, or ``arcosim bench public
--data DIR …``. About 3 min for all four on the loaded 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from arcosim import COLUMN_UNITS, write_csv
from arcosim.experiments import markdown_table
from arcosim.fmu.flexchain import G_DIST
from benchmarks import public_loaders as loaders

#: Where each file can be had: the source's page, then a GitHub copy (raw file).
EMPS_URL = (
    "https://www.nonlinearbenchmark.org/benchmarks/emps (EMPS.zip); a copy: "
    "https://github.com/forgi86/sysid-neural-continuous/raw/master/examples/EMPS/data/DATA_EMPS.mat"
)
HSM150_URL = (
    "https://github.com/malik-robert/HSM150-data/raw/main/Data/Identification/idf_pos_0.065_2.mat"
)
BENCH_URL = (
    "https://github.com/HoriFujimotoLab/FdiTools/raw/master/Examples/private/MultisineTypeA.mat"
)


@dataclass(frozen=True)
class Run:
    """One ``arcosim identify`` command on a record.

    Parameters
    ----------
    label : str
        What it is, for the table.
    args : tuple of str
        Its options after the log and the record's ``--set`` values.
    read : callable
        ``read(result, settings)``: the compared quantities from its ``--json`` result
        and the ``--set`` values (name → float).
    """

    label: str
    args: tuple[str, ...]
    read: Callable[[dict, dict[str, float]], dict[str, float]]


@dataclass(frozen=True)
class Record:
    """A public record and what to run on it.

    Parameters
    ----------
    name : str
        Its ``--records`` name.
    file : str
        The file's name in the ``--data`` folder.
    url : str
        Where to get it.
    source : str
        Who published it, and where the published values come from.
    load : callable
        ``load(path)`` → :class:`benchmarks.public_loaders.Converted`.
    settings : tuple of str
        ``--set`` values beyond the record's own (the nominal motor inertia).
    runs : tuple of Run
        The identifications.
    published : dict of str to float
        The published values of the compared quantities (SI, or the record's units).
    """

    name: str
    file: str
    url: str
    source: str
    load: Callable[[Path], loaders.Converted]
    settings: tuple[str, ...]
    runs: tuple[Run, ...]
    published: dict[str, float]


def _observer_mode0(result: dict, values: dict[str, float]) -> dict[str, float]:
    """Mode 0: the total inertia J_mo + ΔJ, the motor's viscous and Coulomb friction."""
    return {
        "J_total": values["J_mo"] + result["dJm_hat"],
        "D_m": result["D_m_hat"],
        "f_c": result["f_c_hat"],
    }


def _whole_rigid(result: dict, values: dict[str, float]) -> dict[str, float]:
    """Whole chain read as a rigid drive: J_mo + the load (``J_load`` of n = 0, or every
    J_i), D_m, f_c and n; a term reported only as a bound under ``NAME (bound)``."""
    n = int(result["masses"])
    load = result.get("J_load", 0.0) + sum(result[f"J[{i}]"] for i in range(1, n + 1))
    out = {"masses": float(n), "J_total": values["J_mo"] + load}
    out.update(_values_or_bounds(result, ("D_m", "f_c")))
    return out


def _values_or_bounds(result: dict, names: tuple[str, ...]) -> dict[str, float]:
    """``names`` from a whole-chain result; one reported as a bound (``bounds``, whatever
    value stands beside it) under ``NAME (bound)``."""
    bounds = result.get("bounds", {})
    out = {}
    for name in names:
        if name in bounds:
            out[f"{name} (bound)"] = bounds[name]
        elif name in result:
            out[name] = result[name]
    return out


def clamped_modes(J: list[float], k: list[float]) -> np.ndarray:
    """The clamped modes (rad/s, ascending) of a chain J_i (kg·m²) on springs k_i
    (N·m/rad), k_1 to the motor held still: √eig(J⁻¹K)."""
    n = len(J)
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k[i]
        if i + 1 < n:
            K[i, i] += k[i + 1]
            K[i, i + 1] = K[i + 1, i] = -k[i + 1]
    return np.sqrt(np.sort(np.linalg.eigvals(K / np.array(J)[:, None]).real))


def _whole_chain(result: dict, values: dict[str, float]) -> dict[str, float]:
    """Whole chain: n, J[1], k[1], B[1] and the fitted chain's clamped mode nearest the
    reference's (rad/s)."""
    n = int(result["masses"])
    out = {"masses": float(n)}
    out.update(_values_or_bounds(result, ("J[1]", "k[1]", "B[1]")))
    if n and all(f"J[{i}]" in result and f"k[{i}]" in result for i in range(1, n + 1)):
        modes = clamped_modes(
            [result[f"J[{i}]"] for i in range(1, n + 1)],
            [result[f"k[{i}]"] for i in range(1, n + 1)],
        )
        out["clamped_mode"] = float(modes[np.argmin(np.abs(modes - values["clamped_mode"]))])
    return out


WHOLE_AUTO = ("--method", "whole-chain", "--masses", "auto")
#: The observer's default bandwidth given again after the record's own (the last wins).
DEFAULT_G_DIST = ("--set", f"g_dist={G_DIST:g}")
MODE0 = ("--mode", "0")
RECORDS = (
    Record(
        "emps",
        "DATA_EMPS.mat",
        EMPS_URL,
        "Janot, Gautier, Brunot, Data set and reference models of EMPS (2019): IDIM-LS, "
        "Script_IDIM_LS.m (M ± 0.11, Fv ± 1.1, Fc ± 0.10; an offset −3.16 N besides)",
        loaders.load_emps,
        ("J_mo=90",),
        (
            Run("whole chain, auto", WHOLE_AUTO, _whole_rigid),
            Run("whole chain, n = 0", ("--method", "whole-chain", "--masses", "0"), _whole_rigid),
            Run("observer mode 0", MODE0, _observer_mode0),
        ),
        {"J_total": 95.1089, "D_m": 203.5034, "f_c": 20.3935},
    ),
    Record(
        "hsm150",
        "idf_pos_0.065_2.mat",
        HSM150_URL,
        "malik-robert/HSM150-data, Parameters_HSM150.m: J0, B0 fitted by the authors "
        "(tfest, input torque → speed); catalog J 1.2e-4, B 7.03e-5 in the file",
        lambda path: loaders.load_hsm150(path, "measured"),
        (),
        (
            Run("whole chain, auto", WHOLE_AUTO, _whole_rigid),
            Run("whole chain, n = 0", ("--method", "whole-chain", "--masses", "0"), _whole_rigid),
            Run("observer mode 0", MODE0, _observer_mode0),
        ),
        {"J_total": 1.2153e-4, "D_m": 6.9498e-5},
    ),
    Record(
        "hsm150-command",
        "idf_pos_0.065_2.mat",
        HSM150_URL,
        "as hsm150, i_a = the input torque / Cu (the signal the authors' fit used)",
        lambda path: loaders.load_hsm150(path, "command"),
        (),
        (Run("observer mode 0", MODE0, _observer_mode0),),
        {"J_total": 1.2153e-4, "D_m": 6.9498e-5},
    ),
    Record(
        "motor-bench",
        "MultisineTypeA.mat",
        BENCH_URL,
        "Beauduin (KU Leuven) / Ohnishi, FdiTools examples; no J, k published (k_t "
        "unknown): reference = the two-encoder fit (two_mass_reference), J_mo from it",
        loaders.load_motor_bench,
        (),
        (
            Run("whole chain, auto", WHOLE_AUTO, _whole_chain),
            Run("whole chain, n = 1", ("--method", "whole-chain", "--masses", "1"), _whole_chain),
            # as a newcomer types it: the default g_dist, its band under the mode
            Run("whole chain, auto, default g_dist", (*WHOLE_AUTO, *DEFAULT_G_DIST), _whole_chain),
        ),
        {},
    ),
)


def arcosim(args: list[str]) -> tuple[int, str, str]:
    """Run ``arcosim ARGS`` as a user does; (exit status, stdout, stderr)."""
    done = subprocess.run(
        [sys.executable, "-m", "arcosim", *args], capture_output=True, text=True, check=False
    )
    return done.returncode, done.stdout, done.stderr


def refusal(stderr: str) -> str:
    """The ``arcosim: error: …`` line of a refused command ('' when none)."""
    lines = [x for x in stderr.splitlines() if x.startswith("arcosim: error:")]
    return lines[0].removeprefix("arcosim: error: ") if lines else ""


def settings_of(texts: tuple[str, ...]) -> dict[str, float]:
    """``("J_mo=90", …)`` → ``{"J_mo": 90.0, …}``."""
    return {k: float(v) for k, _, v in (t.partition("=") for t in texts)}


def run_record(record: Record, data: Path, work: Path, fmus: Path | None) -> dict | None:
    """Convert one record, check it and run its identifications; None when absent.

    Parameters
    ----------
    record : Record
        What to run.
    data : Path
        The folder holding the record's file.
    work : Path
        Where the converted log is written.
    fmus : Path or None
        ``--fmus`` for the observer runs (None: the per-user cache).

    Returns
    -------
    dict or None
        ``check`` (exit status and report), ``runs`` (per run: exit status, refusal,
        quantities, warnings), ``published``, ``reference`` (motor bench), ``log``.
    """
    path = data / record.file
    if not path.is_file():
        print(f"skip {record.name}: {path} not found; get {record.file} from {record.url}")
        return None
    converted = record.load(path)
    reference = loaders.two_mass_reference(converted) if record.name == "motor-bench" else None
    extra = (f"J_mo={reference['J_m']:.6g}",) if reference else ()
    settings = (*converted.settings, *record.settings, *extra)
    log = write_csv(
        work / f"{record.name}.csv", converted.columns, units=converted.units, force=True
    )
    sets = [a for s in settings for a in ("--set", s)]
    # a column the loader keeps in the record's own unit (the EMPS's control voltage in V
    # with k_to in N/V, its axis in m) is taken as it is, and said so: --scale COLUMN=1
    sets += [
        a
        for column, unit in converted.units.items()
        if column in COLUMN_UNITS and unit != COLUMN_UNITS[column]
        for a in ("--scale", f"{column}=1")
    ]
    status, out, err = arcosim(["check", str(log), *sets, "--json"])
    check = json.loads(out) if out.strip().startswith("{") else {}
    result = {"log": str(log), "data_file": str(path), "note": converted.note}
    result["settings"] = list(settings)
    result["check"] = {"status": status, "refusal": refusal(err), **check}
    result["published"], result["reference"], result["runs"] = record.published, reference, []
    values = settings_of(settings)
    if reference:
        values["clamped_mode"] = reference["clamped_mode"]
    for run in record.runs:
        fmu_args = ["--fmus", str(fmus)] if fmus and run.args == MODE0 else []
        status, out, err = arcosim(["identify", str(log), *sets, *run.args, *fmu_args, "--json"])
        # 3: a fit made but not trusted (whole chain); its figures are read all the same
        fitted = status in (0, 3) and out.strip().startswith("{")
        body = json.loads(out) if fitted else {}
        result["runs"].append(
            {
                "label": run.label,
                "command": f"arcosim identify LOG {' '.join(sets + list(run.args))}",
                "status": status,
                "refusal": refusal(err),
                "quantities": run.read(body, values) if body else {},
                "verdict": body.get("verdict", ""),
                "reasons": body.get("reasons", []),
                "warnings": body.get("warnings", []),
                "std": body.get("std", {}),
                "json": body,
            }
        )
    return result


def comparison(name: str, result: dict) -> list[list[str]]:
    """Rows ``record, run, quantity, published/reference, identified, error``."""
    rows = []
    truth = result["reference"] or result["published"]
    for run in result["runs"]:
        if not run["quantities"]:
            rows.append([name, run["label"], "refused", "", run["refusal"][:90], ""])
            continue
        for quantity, value in run["quantities"].items():
            bound = quantity.endswith(" (bound)")
            known = truth.get(quantity.removesuffix(" (bound)"))
            shown = f"{known:.6g}" if known else ""
            if bound:
                verdict = ("covers it" if known <= value else "excludes it") if known else ""
                rows.append([name, run["label"], quantity, shown, f"≤ {value:.6g}", verdict])
                continue
            error = f"{100 * (value / known - 1):+.1f} %" if known else ""
            rows.append([name, run["label"], quantity, shown, f"{value:.6g}", error])
    return rows


def report(results: dict[str, dict]) -> str:
    """The check verdicts, then the comparison table (markdown)."""
    lines = []
    for name, result in results.items():
        check = result["check"]
        verdict = "not ok" if not check.get("ok") else ("doubtful" if check.get("doubts") else "ok")
        lines.append(f"- {name}: check exit {check['status']} ({verdict})")
        lines += [f"  - problem: {p}" for p in check.get("problems", [])]
        lines += [f"  - warning: {w}" for w in check.get("warnings", [])]
        for run in result["runs"]:
            said = f" ({run['verdict']})" if run.get("verdict") else ""
            lines.append(f"  - identify {run['label']}: exit {run['status']}{said}")
            lines += [f"    - refusal: {run['refusal']}"] if run["refusal"] else []
            lines += [f"    - reason: {r}" for r in run.get("reasons", [])]
            reasons = set(run.get("reasons", []))
            lines += [f"    - warning: {w}" for w in run["warnings"] if w not in reasons]
    rows = [row for name, result in results.items() for row in comparison(name, result)]
    header = ["record", "run", "quantity", "published / reference", "identified", "error"]
    return "\n".join(lines) + "\n\n" + markdown_table(header, rows)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim bench public``."""
    p = subparsers.add_parser(
        "public",
        help="check and identify public measured records of real drives",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--data", type=Path, required=True, help="folder holding the records' files")
    names = [r.name for r in RECORDS]
    p.add_argument("--records", nargs="+", choices=names, default=names, help="which records")
    p.add_argument("--work", type=Path, help="folder for the converted logs (default: a temp)")
    p.add_argument("--fmus", type=Path, help="FMU folder for the observer runs (arcosim --fmus)")
    p.add_argument("--out", type=Path, help="write every result as JSON here")
    p.add_argument("--figure", type=Path, help="the motor bench's FRF figure (PNG) and CSV")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    work = args.work or Path(tempfile.mkdtemp(prefix="arcosim-public-"))
    work.mkdir(parents=True, exist_ok=True)
    results = {}
    for record in RECORDS:
        if record.name in args.records:
            result = run_record(record, args.data, work, args.fmus)
            if result is not None:
                results[record.name] = result
    if results:
        print(report(results))
    if args.out:
        args.out.write_text(json.dumps(results, indent=1) + "\n")
    if args.figure and "motor-bench" in results:
        from benchmarks.public_figure import bench_figure

        print(f"wrote {', '.join(map(str, bench_figure(results['motor-bench'], args.figure)))}")
    return 0


if __name__ == "__main__":
    from benchmarks import main

    sys.exit(main("public", add_parser, sys.argv[1:]))
