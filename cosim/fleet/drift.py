"""How each axis's parameters drifted from its baseline, and the alarms that raises.

Per axis, the baseline is the axis's first trusted identification (or, with a date
given, its first trusted one on or after that date); the latest is its last trusted
one. For each parameter both fits hold, with x_b, σ_b the baseline's value and
standard error and x_l, σ_l the latest's:

* the relative change c = (x_l − x_b) / x_b;
* the change in standard errors of the difference, s = (x_l − x_b) / √(σ_b² + σ_l²);
* an alarm when |c| > threshold **and** |s| > 3: a change that is large and that the
  two fits resolve. A parameter without a standard error (at its bound) never alarms.

A latest fit whose number of masses n differs from the baseline's is its own alarm,
``"structure"``, and its parameters are not compared (they are not the same springs).
An untrusted or failed fit is never a baseline nor the latest; each is listed (the
untrusted per axis with the verdict's reasons, the failed with their reason).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from arcosim.errors import UserError
from arcosim.fleet.store import STD, parameter_names, read_store, store_path

#: Default relative change that, resolved by the fits, raises an alarm (a ratio).
THRESHOLD = 0.05
#: Standard errors of the difference a change must exceed to raise an alarm.
SIGMAS = 3.0


@dataclass(frozen=True)
class AxisDrift:
    """One axis's drift.

    Parameters
    ----------
    axis : str
        The axis's name.
    baseline : dict or None
        The baseline fit's row (None: no trusted fit yet).
    latest : dict or None
        The latest trusted fit's row (None when it is the baseline or there is none).
    changes : list of dict
        Per parameter compared: ``parameter``, ``baseline``, ``latest`` (its units),
        ``change`` (a ratio), ``sigmas`` (standard errors of the difference; None
        without errors), ``alarm`` (bool).
    alarms : list of dict
        The changes that alarm, and a ``"structure"`` alarm when n differs.
    history : list of dict
        Every fit of the axis by date: ``date``, ``log``, ``status``, ``verdict``,
        ``n``, its parameters' values (``parameters``) and their standard errors
        (``std``, NaN where a fit gives none).
    untrusted : list of dict
        The untrusted fits: ``date``, ``log``, ``reasons``.

    Examples
    --------
    >>> drift = AxisDrift("a1", None, None, [], [], [], [])  # an axis with no trusted fit
    >>> drift.axis, drift.alarms
    ('a1', [])
    """

    axis: str
    baseline: dict | None
    latest: dict | None
    changes: list[dict] = field(default_factory=list)
    alarms: list[dict] = field(default_factory=list)
    history: list[dict] = field(default_factory=list)
    untrusted: list[dict] = field(default_factory=list)


@dataclass(frozen=True)
class DriftReport:
    """The fleet's drift: per axis, and the logs that failed.

    Parameters
    ----------
    axes : dict of str to AxisDrift
        By axis name.
    failed : list of dict
        ``log``, ``axis``, ``date``, ``reason`` of every failed log.
    threshold : float
        The relative change that alarms (a ratio).

    Examples
    --------
    >>> report = DriftReport({}, [], 0.05)
    >>> report.alarmed, report.to_json()
    (False, '{"axes": {}, "failed": []}')
    """

    axes: dict[str, AxisDrift]
    failed: list[dict]
    threshold: float = THRESHOLD

    @property
    def alarmed(self) -> bool:
        """Whether any axis has an alarm."""
        return any(drift.alarms for drift in self.axes.values())

    def to_dict(self) -> dict:
        """The report as plain data (what :meth:`to_json` writes)."""
        axes = {
            name: {
                "alarms": d.alarms,
                "baseline": _fit(d.baseline),
                "latest": _fit(d.latest),
                "changes": d.changes,
                "untrusted": d.untrusted,
                "history": d.history,
            }
            for name, d in self.axes.items()
        }
        return {"axes": axes, "failed": self.failed}

    def to_json(self) -> str:
        """The report as JSON: ``{"axes": {axis: {"alarms": […], "history": […], …}},
        "failed": [{"log": …, "reason": …}]}`` (NaN written as null)."""
        return json.dumps(_finite(self.to_dict()))

    def text(self) -> str:
        """The report for a reader: the alarms first, then each axis, then the failures."""
        lines = [
            f"alarms: {sum(len(d.alarms) for d in self.axes.values())} "
            f"(a change over {100 * self.threshold:g} % and over {SIGMAS:g} sigma)"
        ]
        for name, d in self.axes.items():
            for alarm in d.alarms:
                lines.append(f"ALARM {name}: {_alarm_text(alarm)}")
        for name, d in self.axes.items():
            lines.append("")
            lines.extend(_axis_text(name, d))
        if self.failed:
            lines.append("")
            lines.append(f"failed logs: {len(self.failed)}")
            lines.extend(f"  {f['log']}: {f['reason']}" for f in self.failed)
        return "\n".join(lines)


def fleet_drift(
    out: str | Path, *, threshold: float = THRESHOLD, baseline: str | None = None
) -> DriftReport:
    """The drift of every axis in the store in ``out`` (the rule: the module's docstring).

    Parameters
    ----------
    out : str or Path
        The output folder of :func:`arcosim.identify_fleet`.
    threshold : float
        Relative change that, also over 3 standard errors of the difference, raises an
        alarm (a ratio; 0.05 is 5 %).
    baseline : str, optional
        An ISO date: each axis's baseline is its first trusted fit on or after it
        (default: its first trusted fit).

    Returns
    -------
    DriftReport
        Per axis, the baseline, the latest, the changes and alarms, and the failures.

    Raises
    ------
    UserError
        No store in ``out``, a threshold that is not a positive number.

    Examples
    --------
    Two trusted fits of one axis, written by hand (k[1] in N·m/rad):

    >>> from pathlib import Path
    >>> from arcosim.fleet.store import write_store
    >>> fit = {"axis": "a1", "status": "ok", "verdict": "trusted", "n": 1, "k[1]_std": 1e-3}
    >>> rows = [{**fit, "date": "2026-01-05", "log": "a.csv", "k[1]": 0.3},
    ...         {**fit, "date": "2026-02-05", "log": "b.csv", "k[1]": 0.264}]
    >>> _ = write_store(Path("fleet-out"), rows)
    >>> report = arcosim.fleet_drift("fleet-out", threshold=0.05)
    >>> alarms = report.axes["a1"].alarms
    >>> [(a["parameter"], round(a["change"], 2), round(a["sigmas"])) for a in alarms]
    [('k[1]', -0.12, -25)]
    """
    out = Path(out)
    if not (isinstance(threshold, (int, float)) and math.isfinite(threshold) and threshold > 0):
        raise UserError(f"--threshold {threshold}: give a relative change > 0, e.g. 0.05")
    if not store_path(out).exists():
        raise UserError(f"{out}: no {store_path(out).name}; run `arcosim fleet identify` first")
    return drift_of(read_store(out), threshold=threshold, baseline=baseline)


def drift_of(
    rows: Sequence[Mapping[str, object]],
    *,
    threshold: float = THRESHOLD,
    baseline: str | None = None,
) -> DriftReport:
    """:func:`fleet_drift` on the store's rows (as :func:`arcosim.fleet.store.read_store`
    gives them): the rule alone, for rows from anywhere."""
    by_axis: dict[str, list[Mapping[str, object]]] = {}
    for row in sorted(rows, key=lambda r: (str(r["axis"]), str(r["date"]))):
        by_axis.setdefault(str(row["axis"]), []).append(row)
    failed = [
        {"log": r["log"], "axis": r["axis"], "date": r["date"], "reason": r["reason"]}
        for r in rows
        if r["status"] != "ok"
    ]
    axes = {name: axis_drift(name, fits, threshold, baseline) for name, fits in by_axis.items()}
    return DriftReport(axes, failed, threshold)


def axis_drift(
    name: str, rows: Sequence[Mapping[str, object]], threshold: float, since: str | None = None
) -> AxisDrift:
    """One axis's drift from its rows, sorted by date (the rule: the module's docstring)."""
    trusted = [r for r in rows if r["status"] == "ok" and r["verdict"] == "trusted"]
    eligible = [r for r in trusted if since is None or str(r["date"]) >= since]
    history = [_history(r) for r in rows]
    untrusted = [
        {"date": r["date"], "log": r["log"], "reasons": r.get("verdict_reasons", "")}
        for r in rows
        if r["status"] == "ok" and r["verdict"] != "trusted"
    ]
    if not eligible:
        return AxisDrift(name, None, None, history=history, untrusted=untrusted)
    base, last = dict(eligible[0]), dict(eligible[-1])
    if len(eligible) == 1:
        return AxisDrift(name, base, None, history=history, untrusted=untrusted)
    if base["n"] != last["n"]:
        alarm = {"parameter": "n", "kind": "structure", "baseline": base["n"], "latest": last["n"]}
        return AxisDrift(name, base, last, [], [alarm], history, untrusted)
    held = set(parameter_names(last))  # a column of the store is NaN where a fit has none
    changes = [_change(p, base, last, threshold) for p in parameter_names(base) if p in held]
    alarms = [{"kind": "drift", **c} for c in changes if c["alarm"]]
    return AxisDrift(name, base, last, changes, alarms, history, untrusted)


def _change(
    parameter: str, base: Mapping[str, object], last: Mapping[str, object], threshold: float
) -> dict:
    """One parameter's change from ``base`` to ``last``, and whether it alarms."""
    xb, xl = float(base[parameter]), float(last[parameter])
    sb, sl = float(base.get(parameter + STD, math.nan)), float(last.get(parameter + STD, math.nan))
    change = (xl - xb) / abs(xb) if xb else math.copysign(math.inf, xl - xb) if xl != xb else 0.0
    spread = math.hypot(sb, sl)
    sigmas = (xl - xb) / spread if math.isfinite(spread) and spread > 0 else None
    alarm = abs(change) > threshold and sigmas is not None and abs(sigmas) > SIGMAS
    return {
        "parameter": parameter,
        "baseline": xb,
        "latest": xl,
        "change": change,
        "sigmas": sigmas,
        "alarm": alarm,
        "baseline_date": base["date"],
        "latest_date": last["date"],
    }


def _history(row: Mapping[str, object]) -> dict:
    entry = {k: row.get(k) for k in ("date", "log", "status", "verdict", "n")}
    entry["parameters"] = {p: row[p] for p in parameter_names(row)}
    entry["std"] = {p: float(row.get(p + STD, math.nan)) for p in entry["parameters"]}
    return entry


def _fit(row: Mapping[str, object] | None) -> dict | None:
    if row is None:
        return None
    return {"date": row["date"], "log": row["log"], "n": row["n"]}


def _finite(value: object) -> object:
    """``value`` with every non-finite float as None (JSON has no NaN)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def _alarm_text(alarm: Mapping[str, object]) -> str:
    if alarm["kind"] == "structure":
        return f"n changed from {alarm['baseline']} to {alarm['latest']} masses (structure)"
    return (
        f"{alarm['parameter']} {alarm['change']:+.1%} ({alarm['sigmas']:+.1f} sigma), "
        f"{alarm['baseline']:.4g} on {alarm['baseline_date']} -> {alarm['latest']:.4g} "
        f"on {alarm['latest_date']}"
    )


def _axis_text(name: str, d: AxisDrift) -> list[str]:
    untrusted = [
        f"  untrusted {u['date']}: {u['reasons'] or 'no reason given'}" for u in d.untrusted
    ]
    if d.baseline is None:
        return [f"{name}: no trusted fit to take as baseline ({len(d.history)} logs)", *untrusted]
    head = f"{name}: baseline {d.baseline['date']} (n = {d.baseline['n']})"
    if d.latest is None:
        return [head + ", no later trusted fit", *untrusted]
    lines = [head + f", latest {d.latest['date']} (n = {d.latest['n']})"]
    for c in d.changes:
        sigmas = "no std" if c["sigmas"] is None else f"{c['sigmas']:+.1f} sigma"
        mark = "  ALARM" if c["alarm"] else ""
        lines.append(f"  {c['parameter']:<8} {c['change']:+8.2%}  {sigmas}{mark}")
    return lines + untrusted
