"""``arcosim fleet drift DIR --plot PLOTDIR``: the overview and one figure per alarmed
axis, from a small hand-made store; a folder that cannot take them is refused in one
line before anything is drawn."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import pytest

from arcosim.cli import main
from arcosim.fleet.drift import drift_of
from arcosim.fleet.figures import fleet_figures
from arcosim.fleet.store import write_store

K1 = 0.3  # N·m/rad
DATES = ("2026-01-05", "2026-02-05", "2026-03-05")
PNG = b"\x89PNG\r\n\x1a\n"


def fit(axis: str, date: str, k1: float, *, n: int = 1, verdict: str = "trusted") -> dict:
    """A store row of an ok fit: k[1] (N·m/rad) with a 1e-3 standard error, J[1] fixed."""
    row = {
        "axis": axis,
        "date": date,
        "log": f"/fleet/{axis}/{date}.csv",
        "status": "ok",
        "reason": "",
        "n": n,
        "verdict": verdict,
        "verdict_reasons": "" if verdict == "trusted" else "residual above the noise floor",
        "seconds": 1.0,
        "version": "0",
        "J[1]": 4e-4,
        "J[1]_std": 1e-7,
        "k[1]": k1,
        "k[1]_std": 1e-3,
    }
    if n == 2:
        row.update({"k[2]": 0.2, "k[2]_std": 1e-3})
    return row


def small_store(out: Path) -> list[dict]:
    """Four axes: k[1] 12 % down on ``belt``, n 1 → 2 on ``rebuilt``, nothing on
    ``steady`` (one untrusted fit, one failed log), no trusted fit on ``sticky``."""
    failed = {"axis": "steady", "date": "2026-01-20", "log": "/fleet/steady/2026-01-20.csv"}
    failed.update(status="failed", reason="row 3, column i_a: 'x' is not a number")
    rows = [fit("belt", d, K1 * f) for d, f in zip(DATES, (1.0, 0.94, 0.88))]
    rows += [fit("rebuilt", DATES[0], K1), fit("rebuilt", DATES[1], K1, n=2)]
    rows += [fit("steady", d, K1) for d in DATES[:2]] + [failed]
    rows += [fit("steady", DATES[2], 2 * K1, verdict="untrusted")]
    rows += [fit("sticky", d, K1, verdict="untrusted") for d in DATES]
    write_store(out, rows)
    return rows


def test_plot_writes_the_overview_and_one_figure_per_alarmed_axis(tmp_path: Path, capsys) -> None:
    small_store(tmp_path / "out")
    figures = tmp_path / "figures"
    assert main(["fleet", "drift", str(tmp_path / "out"), "--plot", str(figures)]) == 1
    expected = {"overview.png", "axis-belt.png", "axis-rebuilt.png"}
    assert {p.name for p in figures.iterdir()} == expected
    assert all((figures / name).read_bytes().startswith(PNG) for name in expected)
    out = capsys.readouterr().out
    assert all(f"wrote {figures / name}" in out for name in expected)
    assert "ALARM belt: k[1] -12.0%" in out


def test_the_figures_are_refused_over_earlier_ones_without_force(tmp_path: Path, capsys) -> None:
    small_store(tmp_path / "out")
    command = ["fleet", "drift", str(tmp_path / "out"), "--plot", str(tmp_path / "f")]
    assert main(command) == 1
    capsys.readouterr()
    assert main(command) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "overview.png: the file exists; add --force" in err
    (tmp_path / "f" / "axis-gone.png").write_bytes(PNG)  # an axis that alarmed before
    assert main([*command, "--force"]) == 1
    assert "axis-gone.png (their axes no longer alarm" in capsys.readouterr().err
    assert main(["fleet", "drift", str(tmp_path / "out"), "--force"]) == 2
    assert "--force goes with --plot" in capsys.readouterr().err


@pytest.mark.parametrize("where", ["a file", "/proc"])
def test_a_plot_folder_that_cannot_take_figures_is_one_line(
    tmp_path: Path, capsys, where: str
) -> None:
    small_store(tmp_path / "out")
    plot = tmp_path / "figures.png" if where == "a file" else Path("/proc/arcosim-figures")
    if where == "a file":
        plot.write_bytes(b"not a folder")
    assert main(["fleet", "drift", str(tmp_path / "out"), "--json", "--plot", str(plot)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith(f"arcosim: error: --plot {plot}: ")
    assert ("is a file, not a folder" if where == "a file" else "cannot") in captured.err


def test_the_history_carries_each_fits_standard_error(tmp_path: Path) -> None:
    rows = small_store(tmp_path / "out")
    history = drift_of(rows).axes["belt"].history
    assert [h["std"]["k[1]"] for h in history] == [1e-3] * 3
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no left-over figure, no matplotlib warning
        paths = fleet_figures(drift_of(rows, threshold=0.2), tmp_path / "f")
    assert [p.name for p in paths] == ["overview.png", "axis-rebuilt.png"]  # 12 % < 20 %


def test_the_alarmed_axis_figure_marks_the_untrusted_and_failed_logs(tmp_path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from arcosim.fleet.figures import _axis_figure

    rows = small_store(tmp_path / "out")
    steady = [r for r in rows if r["axis"] == "steady"]
    steady.append(fit("steady", "2026-04-05", 0.8 * K1))  # now it alarms
    figure = _axis_figure(plt, drift_of(steady), "steady")
    try:
        k1 = next(p for p in figure.axes if p.get_ylabel().startswith("k[1]"))
        assert k1.get_title().startswith("ALARM k[1]: -20.0%")
        labels = figure.axes[0].get_legend_handles_labels()[1]
        assert {"trusted fit", "untrusted fit", "failed log"} <= set(labels)
        failed_lines = [
            line
            for line in k1.get_lines()
            if line.get_linestyle() == ":"
            and len(line.get_xdata())  # the legend's entry has none
            and math.isclose(
                matplotlib.dates.date2num(line.get_xdata()[0]),
                matplotlib.dates.datestr2num("2026-01-20"),
            )
        ]
        assert failed_lines
    finally:
        plt.close(figure)
