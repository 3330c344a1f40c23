"""The fleet's drift drawn: a figure per alarmed axis, and an overview of every axis.

:func:`fleet_figures` draws a :class:`~arcosim.fleet.drift.DriftReport`
(``arcosim fleet drift DIR --plot PLOTDIR``):

* ``axis-<axis>.png``, one per alarmed axis: a panel per parameter, its history by
  date in its own unit. The trusted fits as points joined by a line inside their ±σ
  band; the untrusted fits as open grey points with their σ; the baseline as a dashed
  line inside the threshold band, baseline × (1 ± threshold); a failed log as a red
  dotted line across every panel. An alarmed parameter's panel is titled with its
  change, in red.
* ``overview.png``: a panel per axis (the alarmed first), every parameter's change
  relative to the axis's baseline, (x − x_baseline) / |x_baseline|, against date, with
  its σ band (σ / |x_baseline|) and the threshold band ±threshold around 0. The
  alarmed parameters are drawn in colour and named, the others in grey; a change off
  the panel's scale (which the alarms set) is drawn at its edge as a triangle. An axis
  without a trusted baseline shows its logs' dates only. A fleet so large that the
  page would pass :data:`MAX_PIXELS` in height is drawn at fewer dots per inch.

Matplotlib draws them with the Agg backend (no display needed); each file is written
atomically, and an existing one only with ``force``.
"""

from __future__ import annotations

import datetime
import math
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

from arcosim.fleet.drift import DriftReport
from arcosim.fleet.store import column_unit
from arcosim.outputs import check_output, check_output_folder, save_figure

#: The overview's file in the figures' folder.
OVERVIEW = "overview.png"
#: An alarmed axis's file: this prefix, the axis's name, ``.png`` (never the overview's).
AXIS_PREFIX = "axis-"
#: Panels per row of the overview: four fit a page's width at a readable size.
COLUMNS = 4
#: The overview's scale, in thresholds either side of 0, when no alarm sets a larger
#: one: the threshold band and a change a few times over it stay visible.
SCALE_THRESHOLDS = 4.0
#: Room above an alarmed axis's panels for its title (inches): one line of its font.
TITLE_INCHES = 0.3
#: Dots per inch of every figure: a screen's, as the project's other figures.
DPI = 100
#: The most pixels a figure may have in height: Agg draws under 2**16; the overview of
#: a fleet that would be taller is drawn at fewer dots per inch instead.
MAX_PIXELS = 60_000


def figure_paths(report: DriftReport, folder: str | Path) -> list[Path]:
    """The files :func:`fleet_figures` writes: the overview, then one per
    alarmed axis, in the report's order."""
    folder = Path(folder)
    alarmed = [name for name, drift in report.axes.items() if drift.alarms]
    return [folder / OVERVIEW, *(folder / f"{AXIS_PREFIX}{name}.png" for name in alarmed)]


def fleet_figures(
    report: DriftReport, folder: str | Path, *, force: bool = False, option: str = "--plot"
) -> list[Path]:
    """Draw ``report`` into ``folder``: the overview and one figure per alarmed axis.

    Parameters
    ----------
    report : DriftReport
        The drift, as :func:`arcosim.fleet_drift` gives it.
    folder : str or Path
        The figures' folder, created if missing.
    force : bool
        Whether existing figures of the same names may be replaced.
    option : str
        The option that named ``folder``, for messages.

    Returns
    -------
    list of Path
        The files written: ``overview.png``, then ``axis-<axis>.png`` per alarmed axis.

    Raises
    ------
    UserError
        ``folder`` is a file or cannot take files, or a figure exists without ``force``;
        checked before any figure is drawn.

    Examples
    --------
    Two trusted fits of one axis, its k[1] (N·m/rad) 12 % lower on the second:

    >>> from arcosim.fleet.drift import drift_of
    >>> fit = {"axis": "a1", "status": "ok", "verdict": "trusted", "n": 1, "k[1]_std": 1e-3}
    >>> rows = [{**fit, "date": "2026-01-05", "log": "a.csv", "k[1]": 0.3},
    ...         {**fit, "date": "2026-02-05", "log": "b.csv", "k[1]": 0.264}]
    >>> [p.name for p in arcosim.fleet_figures(drift_of(rows), "drift-figures")]
    ['overview.png', 'axis-a1.png']
    """
    folder = check_output_folder(folder, option)
    paths = figure_paths(report, folder)
    for path in paths:
        check_output(path, force=force, option=option)
    _warn_stale(folder, paths)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figures = [(_overview(plt, report), paths[0])]
    alarmed = [name for name, drift in report.axes.items() if drift.alarms]
    figures += [(_axis_figure(plt, report, name), p) for name, p in zip(alarmed, paths[1:])]
    for figure, path in figures:
        try:
            dpi = min(DPI, MAX_PIXELS / figure.get_figheight())
            save_figure(figure, path, dpi=dpi, force=force, option=option)
        finally:
            plt.close(figure)
    return paths


# -- one alarmed axis ----------------------------------------------------------------------


def _axis_figure(plt, report: DriftReport, name: str) -> object:
    """A panel per parameter of the axis ``name``: its history in its own unit."""
    drift = report.axes[name]
    alarms = {a["parameter"]: a for a in drift.alarms if a["kind"] == "drift"}
    names = sorted(_parameters(drift.history), key=lambda p: p not in alarms)  # alarms first
    figure, panels = plt.subplots(
        len(names), 1, sharex=True, squeeze=False, figsize=(8, 1.2 + 1.8 * len(names))
    )
    for panel, parameter in zip(panels[:, 0], names):
        _parameter_panel(panel, drift, parameter, report.threshold, alarms.get(parameter))
    failed = _failed_dates(drift.history)
    for panel in panels[:, 0]:
        for date in failed:
            panel.axvline(date, color="C3", ls=":", lw=1.2)
    if failed:
        panels[0, 0].plot([], [], color="C3", ls=":", lw=1.2, label="failed log")
    panels[0, 0].legend(loc="best", fontsize=7, ncol=2)
    panels[-1, 0].set_xlabel("date of the log")
    figure.autofmt_xdate()
    structure = [a for a in drift.alarms if a["kind"] == "structure"]
    title = f"{name}: {len(drift.alarms)} alarm(s)"
    if structure:
        title += f"; n changed from {structure[0]['baseline']} to {structure[0]['latest']}"
    figure.suptitle(title, color="C3")
    figure.tight_layout(rect=(0, 0, 1, 1 - TITLE_INCHES / figure.get_figheight()))
    return figure


def _parameter_panel(panel, drift, parameter: str, threshold: float, alarm: Mapping | None) -> None:
    """One parameter's history: trusted fits in their σ band, untrusted ones apart, the
    baseline in its threshold band."""
    trusted = _points(drift.history, parameter, trusted=True)
    untrusted = _points(drift.history, parameter, trusted=False)
    if trusted[0]:
        dates, values, stds = trusted
        low = [v - (s if math.isfinite(s) else 0.0) for v, s in zip(values, stds)]
        high = [v + (s if math.isfinite(s) else 0.0) for v, s in zip(values, stds)]
        panel.fill_between(dates, low, high, color="C0", alpha=0.25, lw=0, label="±σ")
        errors = [s if math.isfinite(s) else 0.0 for s in stds]  # one fit: no band, a bar
        panel.errorbar(dates, values, yerr=errors, fmt="C0o-", ms=4, lw=1.0, label="trusted fit")
    if untrusted[0]:
        dates, values, stds = untrusted
        errors = [s if math.isfinite(s) else 0.0 for s in stds]
        panel.errorbar(
            dates,
            values,
            yerr=errors,
            fmt="o",
            mfc="none",
            color="0.55",
            ms=5,
            lw=0.8,
            label="untrusted fit",
        )
    baseline = drift.baseline.get(parameter) if drift.baseline else None
    if isinstance(baseline, float) and math.isfinite(baseline):
        band = threshold * abs(baseline)
        panel.axhspan(
            baseline - band,
            baseline + band,
            color="C2",
            alpha=0.15,
            label=f"baseline ±{threshold:.0%}",
        )
        panel.axhline(baseline, color="C2", ls="--", lw=1.0, label="baseline")
    panel.set_ylabel(_label(parameter), fontsize=8)
    panel.ticklabel_format(axis="y", useOffset=False)
    panel.grid(True, lw=0.3)
    if alarm is not None:
        sigmas = "" if alarm["sigmas"] is None else f", {alarm['sigmas']:+.1f} σ"
        panel.set_title(
            f"ALARM {parameter}: {alarm['change']:+.1%}{sigmas}", color="C3", fontsize=9
        )
        for spine in panel.spines.values():
            spine.set_color("C3")


# -- every axis ----------------------------------------------------------------------------


def _overview(plt, report: DriftReport) -> object:
    """A panel per axis: every parameter's relative change from the axis's baseline."""
    names = sorted(report.axes, key=lambda a: not report.axes[a].alarms) or ["(no axis)"]
    rows = math.ceil(len(names) / COLUMNS)
    columns = min(COLUMNS, len(names))
    figure, panels = plt.subplots(
        rows, columns, squeeze=False, figsize=(3.6 * columns, 0.8 + 2.6 * rows)
    )
    for panel, name in zip(panels.flat, names):
        if name in report.axes:
            _axis_panel(panel, report, name)
    for panel in list(panels.flat)[len(names) :]:
        panel.set_visible(False)
    alarmed = sum(1 for d in report.axes.values() if d.alarms)
    figure.suptitle(
        f"{len(report.axes)} axes, {alarmed} alarmed; change from each axis's baseline "
        f"(band: ±{report.threshold:.0%}); failed logs: {len(report.failed)}",
        fontsize=10,
    )
    figure.text(
        0.5,
        0.005,
        "filled points joined: trusted fits, shaded: their ±σ; open points: untrusted fits; "
        "red dotted line: a failed log; triangle: a change off the panel's scale; "
        "coloured: an alarmed parameter",
        ha="center",
        va="bottom",
        fontsize=7,
        color="0.3",
    )
    figure.tight_layout(rect=(0, 0.03, 1, 1))
    return figure


def _axis_panel(panel, report: DriftReport, name: str) -> None:
    """One axis of the overview (the module's docstring)."""
    drift, threshold = report.axes[name], report.threshold
    alarmed = {a["parameter"]: a for a in drift.alarms if a["kind"] == "drift"}
    for failed in _failed_dates(drift.history):
        panel.axvline(failed, color="C3", ls=":", lw=1.2)
    if drift.baseline is None:
        dates = [_date(h["date"]) for h in drift.history if h["status"] == "ok"]
        panel.plot(dates, [0.0] * len(dates), "o", mfc="none", color="0.55", ms=5)
        panel.text(
            0.5,
            0.5,
            "no trusted fit:\nnot monitored",
            ha="center",
            va="center",
            transform=panel.transAxes,
            fontsize=8,
            color="0.35",
        )
        panel.set_yticks([])
        _axis_title(panel, name, drift)
        return
    scale = max(
        [SCALE_THRESHOLDS * threshold] + [1.25 * abs(a["change"]) for a in alarmed.values()]
    )
    panel.axhspan(-threshold, threshold, color="C2", alpha=0.15)
    panel.axhline(0.0, color="C2", ls="--", lw=0.8)
    colours = iter(f"C{i}" for i in (3, 1, 4, 5, 6, 8, 9))
    for parameter in _parameters(drift.history):
        base = drift.baseline.get(parameter)
        if not (isinstance(base, float) and math.isfinite(base) and base):
            continue
        colour = next(colours, "C3") if parameter in alarmed else "0.6"
        _relative(panel, drift.history, parameter, base, scale, colour, parameter in alarmed)
    panel.set_ylim(-1.05 * scale, 1.05 * scale)
    panel.yaxis.set_major_formatter(_percent())
    if alarmed:
        panel.legend(loc="best", fontsize=6)
    _axis_title(panel, name, drift)


def _relative(
    panel, history, parameter: str, base: float, scale: float, colour: str, alarmed: bool
) -> None:
    """A parameter's change relative to ``base`` and its σ band; trusted points joined,
    untrusted open; off the scale, a triangle at the edge."""
    for trusted in (True, False):
        dates, values, stds = _points(history, parameter, trusted=trusted)
        if not dates:
            continue
        change = [(v - base) / abs(base) for v in values]
        sigma = [s / abs(base) if math.isfinite(s) else 0.0 for s in stds]
        shown = [min(max(c, -scale), scale) for c in change]
        if trusted:
            low = [max(c - s, -scale) for c, s in zip(change, sigma)]
            high = [min(c + s, scale) for c, s in zip(change, sigma)]
            alpha = 0.25 if alarmed else 0.06  # the other bands must not hide the alarms
            panel.fill_between(dates, low, high, color=colour, alpha=alpha, lw=0)
            panel.plot(
                dates,
                shown,
                "-",
                color=colour,
                lw=1.6 if alarmed else 0.7,
                label=parameter if alarmed else None,
            )
        panel.plot(
            [d for d, c in zip(dates, change) if abs(c) <= scale],
            [c for c in change if abs(c) <= scale],
            "o",
            ms=3.5,
            color=colour,
            mfc=colour if trusted else "none",
        )
        off = [(d, s) for d, c, s in zip(dates, change, shown) if abs(c) > scale]
        for d, s in off:
            panel.plot([d], [s], "^" if s > 0 else "v", ms=5, color=colour)


def _axis_title(panel, name: str, drift) -> None:
    words = ", ".join(
        a["parameter"] if a["kind"] == "drift" else "structure (n)" for a in drift.alarms
    )
    panel.set_title(
        f"{name}: ALARM {words}" if words else name, fontsize=8, color="C3" if words else "black"
    )
    panel.grid(True, lw=0.3)
    panel.tick_params(labelsize=6)
    for label in panel.get_xticklabels():
        label.set_rotation(30)


# -- the history as points -------------------------------------------------------------------


def _parameters(history: Sequence[Mapping]) -> list[str]:
    """Every parameter any fit holds, in the store's order (by name)."""
    return sorted({p for entry in history for p in entry.get("parameters", {})})


def _points(
    history: Sequence[Mapping], parameter: str, *, trusted: bool
) -> tuple[list[datetime.datetime], list[float], list[float]]:
    """Dates, values and standard errors of the ``parameter`` of the trusted (or the
    untrusted) fits."""
    dates, values, stds = [], [], []
    for entry in history:
        if entry["status"] != "ok" or (entry["verdict"] == "trusted") != trusted:
            continue
        value = entry["parameters"].get(parameter)
        if value is None or not math.isfinite(value):
            continue
        std = entry.get("std", {}).get(parameter)
        dates.append(_date(entry["date"]))
        values.append(float(value))
        stds.append(math.nan if std is None else float(std))
    return dates, values, stds


def _failed_dates(history: Sequence[Mapping]) -> list[datetime.datetime]:
    return [_date(h["date"]) for h in history if h["status"] != "ok"]


def _date(text: object) -> datetime.datetime:
    return datetime.datetime.fromisoformat(str(text))


def _label(parameter: str) -> str:
    unit = column_unit(parameter)
    return f"{parameter} ({unit})" if unit else parameter


def _percent():
    from matplotlib.ticker import FuncFormatter

    return FuncFormatter(lambda y, _: f"{100 * y:+.0f} %")


def _warn_stale(folder: Path, paths: Sequence[Path]) -> None:
    """Warn of an alarmed axis's figure an earlier run left that this run does not
    rewrite (its axis no longer alarms): kept, but named, so nobody reads it as today's."""
    mine = {p.name for p in paths}
    stale = sorted(p.name for p in folder.glob(f"{AXIS_PREFIX}*.png") if p.name not in mine)
    if stale:
        warnings.warn(
            f"{folder} holds figures of an earlier run that this run does not rewrite: "
            f"{', '.join(stale)} (their axes no longer alarm; delete them)",
            stacklevel=3,
        )
