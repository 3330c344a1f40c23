"""The fleet store's cost per row: rows per second added to a store that already holds
1,000 and 10,000 rows, the way ``arcosim fleet identify`` adds them now (one line
appended and synced, :func:`arcosim.fleet.store.append_store`) against the way it did
before (the whole store rewritten through a temporary file after each log,
:func:`arcosim.fleet.store.write_store`).

The rows are those of a three-mass fit (J, k, B of each mass, D_m, f_c, each with its
standard error; a verdict's reasons), as :mod:`benchmarks.simulators.fleet_sample`'s fleets give
them. Both ways sync the file to disk (``fsync``), so the figures depend on the disk;
the run prints the folder it wrote to.

Run: ``python -m benchmarks.fleet_store [--sizes 1000 10000] [--folder DIR]`` (about
half a minute).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from arcosim.fleet import append_store, write_store

#: Rows already in the store when a row is added: a fleet's first months, and the
#: 10,000 logs of the docs' estimate.
SIZES = (1_000, 10_000)
#: Rows added (appends) or stores rewritten (rewrites) per figure; the median is kept,
#: so one slow sync of a shared disk does not set it.
REPEATS = {"append": 200, "rewrite": 5}


def fit_row(i: int) -> dict[str, object]:
    """The ``i``-th row: a trusted three-mass fit, its values those of the paper's chain."""
    row: dict[str, object] = {
        "axis": f"axis-{i % 100:03d}",
        "date": f"2026-01-01T{i:08d}",
        "log": f"/plant/fleet/axis-{i % 100:03d}/2026-01-01T{i:08d}.csv",
        "status": "ok",
        "reason": "",
        "n": 3,
        "verdict": "trusted",
        "verdict_reasons": "the residual (0.00041 N·m) is 1.1 × the noise floor; "
        "the torque balance reads J = 1.2e-3 kg·m² against 1.1e-3 ± 5e-5",
        "seconds": 5.83,
        "version": "0.2.0",
    }
    values = {"J": 4.5e-4, "k": 0.3, "B": 2e-5}
    for letter, value in values.items():
        for m in (1, 2, 3):
            row[f"{letter}[{m}]"] = value * (1 + 1e-3 * (i % 7))
            row[f"{letter}[{m}]_std"] = value * 1e-3
    row.update({"D_m": 2e-5, "D_m_std": 1e-6, "f_c": 2e-3, "f_c_std": 5e-5})
    return row


def per_row(folder: Path, size: int) -> dict[str, float]:
    """Seconds to add one row to a store of ``size`` rows, appended and rewritten."""
    rows = [fit_row(i) for i in range(size)]
    seconds = {}
    for way, repeats in REPEATS.items():
        out = folder / f"{way}-{size}"
        write_store(out, rows)
        times = []
        for r in range(repeats):
            row = fit_row(size + r)
            started = time.perf_counter()
            if way == "append":
                append_store(out, row)
            else:
                rows.append(row)  # the store before: every row, sorted, written whole
                write_store(out, sorted(rows, key=lambda x: (str(x["axis"]), str(x["date"]))))
            times.append(time.perf_counter() - started)
        seconds[way] = statistics.median(times)
        rows = rows[:size]
    return seconds


def table(figures: dict[int, dict[str, float]]) -> str:
    """The figures as a markdown table, one row per store size."""
    lines = [
        "| rows in the store | rewrite (before): rows/s | append (now): rows/s | ratio |",
        "|---|---|---|---|",
    ]
    for size, s in figures.items():
        lines.append(
            f"| {size:,} | {1 / s['rewrite']:.1f} | {1 / s['append']:.0f} | "
            f"{s['rewrite'] / s['append']:.0f} × |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    parser.add_argument("--folder", type=Path, help="write the stores here (default: a temp)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="arcosim-store-") as temporary:
        folder = args.folder or Path(temporary)
        print(f"stores written in {folder}", file=sys.stderr)
        figures = {size: per_row(folder, size) for size in args.sizes}
    print(table(figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
