"""Whole-chain rows on the excitations a field log carries (part of the accuracy benchmark).

Three rows on the three-mass drive of :mod:`benchmarks.field_accuracy` (clamped modes
11.2, 26.6, 53.0 rad/s; J_m 2.09e-5 kg·m², k_t 0.0406 N·m/A, D_m 2e-5 N·m·s/rad, f_c
2e-3 N·m, 2000 counts, 5 mA current noise, 1 kHz, 20 s), the friction fitted (only
k_t, J_m and the counts given), ``masses="auto"``; each excitation from
:mod:`benchmarks.excitations`:

- **off-grid multi-sine**: 40 log-spaced lines 3–150 rad/s, each moved half a bin
  (π/T) off the record's grid, 3 A peak, open loop;
- **square wave, position loop**: a ±0.5 rad square-wave position reference of 4 s
  period through a P position loop (20 /s) around a PI speed loop (kp 0.3 A·s/rad, ki
  2.25 A/rad, on the encoder's backward difference), current limit 10 A;
- **PRBS**: a ±1 A maximum-length sequence (14 bits) held 4 samples (its band to about
  1100 rad/s), open loop.

Per seed (the seed changes the noise, the phases, the sequence): the verdict (the
reasons of an untrusted seed in the JSON), n, J_i, k_i (errors in
%), B_i, D_m, f_c within 2σ (a friction term left out or at its bound: its reported bound
above the truth), and whether ``check`` agrees with ``identify``: ``check``
ok exactly when ``identify`` fits, and every ``check`` warning among ``identify``'s.

Run: ``python -m benchmarks.excitation_accuracy [--seeds 20] [--first-seed 1] [--rows NAME
...] [--out FILE.json]`` (prints the markdown table; ``--merge A.json B.json …`` tabulates
runs made in parts); ``arcosim bench accuracy`` runs it too.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from arcosim import check_log
from arcosim.experiments import markdown_table
from benchmarks import excitations, field_accuracy
from benchmarks.simulators import field_sim

#: Position loop around the PI speed loop: gain (1/s), PI (A·s/rad, A/rad), limit (A).
POSITION_GAIN, SPEED_PI, CURRENT_LIMIT = 20.0, (0.3, 2.25), 10.0
#: Square-wave position reference: amplitude (rad), period (s).
SQUARE = (0.5, 4.0)
#: PRBS: amplitude (A), samples per clock, bits.
PRBS = (1.0, 4, 14)


@dataclass(frozen=True)
class ExcitationRow(field_accuracy.Row):
    """A :class:`~benchmarks.field_accuracy.Row` whose log carries ``excitation``:
    ``"offgrid"``, ``"square"`` or ``"prbs"`` (the module doc states each)."""

    excitation: str = "offgrid"

    def log(self, seed: int, duration: float = field_accuracy.DURATION) -> field_sim.Log:
        """Simulate the row's record (``duration`` s) for ``seed``."""
        if self.excitation == "square":
            reference = excitations.square_position(*SQUARE, seed=seed)
            loop = field_sim.SpeedLoop(
                *SPEED_PI, reference, limit=CURRENT_LIMIT, position_gain=POSITION_GAIN
            )
            return field_sim.simulate(self.drive, self.h, duration, speed_loop=loop, seed=seed)
        if self.excitation == "prbs":
            amplitude, clock, bits = PRBS
            current = excitations.prbs(amplitude, self.h, clock, seed=seed, bits=bits)
        else:
            lines = excitations.offgrid_lines(self.lines, duration)
            current = field_sim.multisine(lines, self.amplitude, seed=seed)
        return field_sim.simulate(self.drive, self.h, duration, current=current, seed=seed)


_DRIVE = field_accuracy._drive(*field_accuracy._THREE)
ROWS: dict[str, ExcitationRow] = {
    r.name: r
    for r in (
        ExcitationRow("off-grid multi-sine", _DRIVE, friction_given=False, excitation="offgrid"),
        ExcitationRow(
            "square wave, position loop", _DRIVE, friction_given=False, excitation="square"
        ),
        ExcitationRow("PRBS", _DRIVE, friction_given=False, excitation="prbs"),
    )
}


def run_seed(row: ExcitationRow, seed: int) -> dict:
    """One record: identify's scores (:func:`benchmarks.field_accuracy.score_log`) and
    check's agreement with it."""
    log = row.log(seed)
    d = row.drive
    out = field_accuracy.score_log(row, log, seed)
    report = check_log(log.time, log.i_a, log.omega_m, log.theta_m, d.k_t, d.J_m, d.counts)
    fitted = "error" not in out
    out["check_ok"] = report.ok
    out["check_warnings"] = list(report.warnings)
    out["above_band"] = report.above_band
    among = all(w in out.get("warnings", []) or w in out.get("error", "") for w in report.warnings)
    out["agree"] = bool(report.ok == fitted and among)
    return out


def summary(results: list[dict], row: ExcitationRow) -> dict:
    """The field summary, with the friction within 2σ and the agreement counted."""
    out = field_accuracy.summary(results, row)
    right = [r for r in results if r.get("n") == row.drive.n]
    # a term left out or at its bound counts when the truth lies inside its bound
    out["friction_inside_2_sigma"] = field_accuracy.friction_covered(right)
    out["agree"] = (sum(bool(r["agree"]) for r in results), len(results))
    out["warned"] = sum(bool(r.get("warnings")) for r in results)
    return out


def markdown(summaries: dict[str, dict]) -> str:
    """The table."""
    header = [
        "row",
        "trusted",
        "n right",
        "max abs J_i err %",
        "max abs k_i err %",
        "B_i within 2σ",
        "D_m, f_c within 2σ or bound",
        "check agrees",
        "seeds warned",
        "s wall (median)",
    ]
    cells = []
    for name, s in summaries.items():
        b, f, a = s["B_inside_2_sigma"], s["friction_inside_2_sigma"], s["agree"]
        cells.append(
            [
                name,
                f"{s['trusted']} of {s['seeds']}",
                f"{s['n_right']} of {s['seeds']}",
                f"{s['max_abs_J_error_percent']:.2f}",
                f"{s['max_abs_k_error_percent']:.2f}",
                f"{b[0]} of {b[1]}",
                f"{f[0]} of {f[1]}",
                f"{a[0]} of {a[1]}",
                f"{s['warned']}",
                f"{s['seconds_median']:.1f}",
            ]
        )
    return markdown_table(header, cells) + "\n"


def score_rows(
    names: Sequence[str],
    seeds: Sequence[int],
    progress: Callable[[str], None] = print,
    out: Path | None = None,
) -> tuple[dict[str, dict], dict[str, list[dict]]]:
    """Every row of ``names`` over ``seeds``: the summaries, and every run's numbers
    (written to ``out`` as JSON after each seed, when given)."""
    summaries: dict[str, dict] = {}
    results: dict[str, list[dict]] = {}
    for name in names:
        results[name] = []
        for seed in seeds:
            r = run_seed(ROWS[name], seed)
            results[name].append(r)
            progress(f"{name}, seed {seed}: n = {r.get('n')}, agree {r['agree']}")
            summaries[name] = summary(results[name], ROWS[name])
            if out:
                out.write_text(json.dumps({"summary": summaries, "runs": results}, indent=1))
    return summaries, results


def merged(paths: Sequence[Path]) -> dict[str, dict]:
    """The summaries of several runs' JSON files (``--out`` of runs over other seeds or
    rows), their runs pooled per row (:func:`benchmarks.field_accuracy.pooled_runs`)."""
    runs = field_accuracy.pooled_runs(paths)
    return {name: summary(rows, ROWS[name]) for name, rows in runs.items()}


def table(
    seeds: Sequence[int], quick: bool, progress: Callable[[str], None]
) -> tuple[str, dict[str, object]]:
    """The rows as a markdown section and their summaries (``quick``: the first row)."""
    names = list(ROWS)[:1] if quick else list(ROWS)
    summaries, _ = score_rows(names, seeds, progress)
    text = (
        "\nWhole-chain identification by excitation (three-mass drive of "
        "`benchmarks/simulators/field_sim.py`, friction fitted, `auto`, "
        f"{len(seeds)} seeds; `benchmarks/excitation_accuracy.py` states each "
        "excitation; `check` agreeing with `identify` on every seed):\n\n" + markdown(summaries)
    )
    return text, {"whole_chain_excitations": summaries}


def main(argv: Sequence[str] | None = None, progress: Callable[[str], None] = print) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--rows", nargs="*", default=list(ROWS))
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--out", type=Path)
    parser.add_argument("--merge", type=Path, nargs="*", help="only tabulate these --out files")
    args = parser.parse_args(argv)
    if args.merge:
        print(markdown(merged(args.merge)))
        return 0
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    summaries, _ = score_rows(args.rows, seeds, progress, args.out)
    print(markdown(summaries))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
