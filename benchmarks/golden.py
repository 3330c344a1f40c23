"""Outputs that a refactor must not change: record them, then compare two records.

A behaviour-preserving change must leave every file `arcosim reproduce` writes,
the CLI's outputs on the sample log and the field rows byte-identical, and the figures
pixel-identical. This script records them into a folder and compares two such folders.

Run, in a checkout before and after the change::

    python -m benchmarks.golden record DIR_BEFORE [--fmus dist]
    ...change...
    python -m benchmarks.golden record DIR_AFTER [--fmus dist]
    python -m benchmarks.golden compare DIR_BEFORE DIR_AFTER

What is recorded: `arcosim reproduce` (realistic and ``--ideal``: every CSV, report.md, the
PNG figures and the printed text), `check`, `identify` (whole-chain, observer, load-torque)
on ``examples/data/belt_drive.csv`` as the README runs them (text, ``--json`` and the
files they write), and two seeds of three field rows (``benchmarks.field_accuracy``,
timings removed). Text files are compared byte for byte; PNGs by their decoded pixels
(the PNG encoder's metadata may differ). Timing lines (``… s``, wall/CPU times) are the
only thing removed before comparing. Takes about 3 minutes.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "examples" / "data" / "belt_drive.csv"
SCALE = [
    "--scale",
    "i_a=0.001",
    "--scale",
    "theta_m=0.0031415926535897933",
    "--scale",
    "omega_m=0.0031415926535897933",
]
MOTOR = ["--set", "k_to=0.0406", "--set", "J_mo=2.09e-5", "--set", "encoder_cpr=2000"]
#: Field rows recorded (two seeds each): friction given and fitted, closed loop with a load.
FIELD_ROWS = (
    "belt-like two-mass, 4 kHz, friction",
    "five-mass, friction fitted",
    "three-mass, PI loop, constant load",
)
#: Printed text that varies from run to run: durations and progress bars.
VOLATILE = re.compile(r"(\d+(\.\d+)?\s?(s|ms)\b|it/s|s/it|\d+%\|)")
#: Lines that say the FMU cache was filled: they depend on the cache's state (a moved
#: source file changes the FMUs' digest), not on what the software computes.
CACHE_FILLED = re.compile(r"^arcosim: building the FMUs for .*\n", re.M)


def _cli(args: Sequence[str], out: Path, name: str) -> None:
    """Run ``arcosim ARGS`` and keep its stdout, stderr and exit status as ``NAME.txt``."""
    done = subprocess.run(
        [sys.executable, "-m", "arcosim", *args], capture_output=True, text=True, cwd=out
    )
    (out / f"{name}.txt").write_text(
        f"exit {done.returncode}\n--- stdout\n{done.stdout}--- stderr\n{done.stderr}"
    )


def record(out: Path, fmus: Path | None) -> None:
    """Record every output into ``out`` (created; must not exist)."""
    out.mkdir(parents=True)
    fm = ["--fmus", str(fmus)] if fmus else []
    for name, extra in (("reproduce", []), ("reproduce-ideal", ["--ideal"])):
        _cli(["reproduce", "--out", name, "--no-progress", *extra, *fm], out, name)
    log = SAMPLE.name  # copied in, so that no checkout's path shows in the text
    (out / log).write_bytes(SAMPLE.read_bytes())
    _cli(["check", log, *SCALE, *MOTOR], out, "check")
    _cli(["check", log, *SCALE, *MOTOR, "--json"], out, "check-json")
    STATES = ["--out", "states.csv"]
    TORQUE = ["--chain", "chain.json", "--set", "load_mass=2", "--out", "torque.csv"]
    wc = ["identify", log, *SCALE, *MOTOR, "--method", "whole-chain", "--masses", "auto"]
    _cli([*wc, "--out", "chain.json"], out, "whole-chain")
    _cli([*wc, "--json"], out, "whole-chain-json")
    _cli(
        ["identify", log, *SCALE, *MOTOR, "--masses", "2", "--set", "estimator=1", *STATES, *fm],
        out,
        "observer",
    )
    _cli(
        ["identify", log, *SCALE, *MOTOR, "--method", "load-torque", *TORQUE],
        out,
        "load-torque",
    )
    _cli(["identify", log, *SCALE, *MOTOR, "--method", "output-error", "--json"], out, "oe")
    from benchmarks import field_accuracy

    rows = field_accuracy.ROWS
    field = {}
    for name in FIELD_ROWS:
        for seed in (0, 1):
            result = field_accuracy.run_row(rows[name], seed)
            field[f"{name}/{seed}"] = {
                k: v for k, v in result.items() if k not in ("seconds", "cpu_seconds")
            }
    (out / "field.json").write_text(json.dumps(field, indent=1, sort_keys=True, default=str))


def _pixels(path: Path) -> str:
    """Digest of a PNG's decoded pixels."""
    import matplotlib.image

    return hashlib.sha256(matplotlib.image.imread(path).tobytes()).hexdigest()


def _text(path: Path) -> str:
    """A text file with its volatile parts masked."""
    return VOLATILE.sub("<t>", CACHE_FILLED.sub("", path.read_text(errors="replace")))


def compare(a: Path, b: Path) -> list[str]:
    """The files that differ between two records (empty when none)."""
    names = sorted(
        {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
        | {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    )
    differ = []
    for rel in names:
        pa, pb = a / rel, b / rel
        if not (pa.exists() and pb.exists()):
            differ.append(f"{rel}: only in {'the first' if pa.exists() else 'the second'}")
        elif rel.suffix == ".png":
            if _pixels(pa) != _pixels(pb):
                differ.append(f"{rel}: pixels differ")
        elif rel.suffix in (".txt", ".md") and _text(pa) != _text(pb):
            differ.append(f"{rel}: text differs")
        elif rel.suffix not in (".png", ".txt", ".md") and pa.read_bytes() != pb.read_bytes():
            differ.append(f"{rel}: bytes differ")
    return differ


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: ``record DIR [--fmus DIR]`` or ``compare DIR_A DIR_B``."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.golden", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="record the outputs into a new folder")
    rec.add_argument("out", type=Path)
    rec.add_argument("--fmus", type=Path, default=None, help="folder of built FMUs")
    cmp_ = sub.add_parser("compare", help="compare two records")
    cmp_.add_argument("a", type=Path)
    cmp_.add_argument("b", type=Path)
    args = parser.parse_args(argv)
    if args.command == "record":
        record(args.out.resolve(), args.fmus.resolve() if args.fmus else None)
        print(f"recorded {sum(1 for p in args.out.rglob('*') if p.is_file())} files")
        return 0
    differ = compare(args.a, args.b)
    for line in differ:
        print(line)
    n = sum(1 for p in args.a.rglob("*") if p.is_file())
    print(f"{n} files compared, {len(differ)} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
