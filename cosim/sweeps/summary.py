"""The summary of a sweep: metric quantiles per varied parameter, and plots.

A varied seed (``plant.seed``) draws another noise, not another drive: it is no factor,
so it has no quantiles of its own and no plot, only a word in the summary. The plots'
axes carry the units of ``results.units.json``.
"""

from __future__ import annotations

import csv
import itertools
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from arcosim.logs import read_units
from arcosim.outputs import save_figure, write_text
from arcosim.sweeps.spec import SweepSpec, metric_columns


def complete(row: Mapping[str, str | None]) -> bool:
    """A row written in full (an interrupted write leaves a short last line)."""
    return row.get("error") is not None and (row.get("run") or "").strip().isdigit()


def is_seed(name: str) -> bool:
    """Whether a varied parameter is a noise seed (``plant.seed``): no factor."""
    return name.rpartition(".")[2] == "seed"


def axis_label(name: str, units: Mapping[str, str]) -> str:
    """``name (unit)``: a percent error ``(%)``, a θ score ``(rms ratio)``, a count or
    code (unit ``1``) bare."""
    unit = units.get(name, "")
    if name.startswith("theta_error"):
        return f"{name} (rms ratio)"
    return f"{name} ({unit})" if unit and unit != "1" else name


def read_results(results: Path) -> list[dict[str, str]]:
    """The rows of a results CSV, one per finished run (a cut-off last line is left out).

    Parameters
    ----------
    results : Path
        A sweep's ``results.csv`` (:data:`arcosim.sweeps.RESULTS`), as :func:`sweep`
        writes it.

    Returns
    -------
    list of dict of str to str
        One row per finished run: column → its text as written (an empty ``error``
        for a run that succeeded). A last line cut off by an interrupted write is
        left out.

    Examples
    --------
    >>> import tempfile
    >>> folder = tempfile.TemporaryDirectory()
    >>> results = Path(folder.name) / "results.csv"
    >>> _ = results.write_text('''run,observer.g_dist,runtime,error
    ... 0,100.0,0.35,
    ... 1,200.0,0.0''', encoding="utf-8")
    >>> read_results(results)
    [{'run': '0', 'observer.g_dist': '100.0', 'runtime': '0.35', 'error': ''}]
    >>> folder.cleanup()
    """
    with open(results, newline="", encoding="utf-8") as f:
        return [row for row in csv.DictReader(f) if complete(row)]


def write_summary(spec: SweepSpec, results: Path, out: Path) -> Path:
    """``summary.md`` (metric quantiles per varied parameter) and PNG plots."""
    from arcosim.experiments.report import markdown_table

    rows = read_results(results)
    ok = [r for r in rows if not r["error"]]
    metrics = metric_columns(spec)
    units = read_units(results)
    factors = [name for name in spec.vary if not is_seed(name)]
    seeds = [name for name in spec.vary if is_seed(name)]
    lines = [
        f"# Sweep {spec.name}: {len(rows)} runs, {len(rows) - len(ok)} failed",
        "",
        f"Scenario `{spec.scenario}`, n = {spec.masses}, seed {spec.seed}. "
        "Quantiles 5 % / 50 % / 95 % of each metric.",
        "",
    ]
    if seeds:
        lines += [
            f"{', '.join(seeds)} draws a new noise each run, not a factor: no rows or plots "
            "of its own.",
            "",
        ]
    table = []
    for metric in metrics:
        x = np.array([float(r[metric]) for r in ok if r.get(metric)])
        if x.size:
            table.append(
                ["all runs", metric, x.size, *(f"{q:.4g}" for q in np.percentile(x, [5, 50, 95]))]
            )
        for name in factors:
            for label, members in _groups(ok, name):
                y = np.array([float(r[metric]) for r in members if r.get(metric)])
                if y.size:
                    table.append(
                        [
                            f"{name} {label}",
                            metric,
                            y.size,
                            *(f"{q:.4g}" for q in np.percentile(y, [5, 50, 95])),
                        ]
                    )
    lines.append(markdown_table(["runs", "metric", "count", "p5", "p50", "p95"], table))
    failures = [r for r in rows if r["error"]]
    if failures:
        lines += ["", "Failed runs:", ""] + [
            f"- run {r['run']}: {r['error']}" for r in failures[:20]
        ]
    lines += [
        "",
        *(
            f"![{m}]({_plot(spec, ok, m, out, factors, units).name})"
            for m in metrics
            if any(r.get(m) for r in ok)
        ),
    ]
    summary = out / "summary.md"
    write_text(summary, "\n".join(lines) + "\n", force=True)
    return summary


def _groups(rows: list[dict[str, str]], name: str) -> list[tuple[str, list[dict[str, str]]]]:
    values = sorted({float(r[name]) for r in rows})
    if len(values) <= 8:
        return [(f"= {v:g}", [r for r in rows if float(r[name]) == v]) for v in values]
    edges = np.percentile([float(r[name]) for r in rows], [0, 25, 50, 75, 100])
    groups = []
    for lo, hi in itertools.pairwise(edges):
        members = [r for r in rows if lo <= float(r[name]) <= hi]
        groups.append((f"in [{lo:.3g}, {hi:.3g}]", members))
    return groups


def _plot(
    spec: SweepSpec,
    rows: list[dict[str, str]],
    metric: str,
    out: Path,
    names: list[str],
    units: Mapping[str, str],
) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 1 + len(names), figsize=(4 * (1 + len(names)), 3.4), squeeze=False)
    y = np.array([float(r[metric]) for r in rows if r.get(metric)])
    axes[0, 0].hist(y, bins=min(30, max(5, len(y) // 5)))
    axes[0, 0].set_xlabel(axis_label(metric, units))
    axes[0, 0].set_ylabel("runs")
    for ax, name in zip(axes[0, 1:], names):
        x = np.array([float(r[name]) for r in rows if r.get(metric)])
        ax.plot(x, y, ".", alpha=0.6)
        ax.set_xlabel(axis_label(name, units))
        ax.set_ylabel(axis_label(metric, units))
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{spec.name}: {metric} ({len(y)} runs)")
    fig.tight_layout()
    path = out / f"{metric.replace('[', '_').replace(']', '')}.png"
    save_figure(fig, path, dpi=100, force=True)
    plt.close(fig)
    return path
