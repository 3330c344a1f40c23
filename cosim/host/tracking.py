"""A drive log replayed through the observer FMU with ``tracking = 1``: the chain's
parameters tracked over time, their standard deviations, the drift alarm and validity.

:func:`replay_tracking` runs the log through a ReactionTorqueObserver instance
(:func:`~arcosim.host.replay.replay_log`) and returns a :class:`TrackedChain`;
:func:`draw_tracking` draws it (``arcosim identify --set tracking=1 --plot FILE``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from arcosim.host.instance import FmuInstance
from arcosim.host.replay import replay_log
from arcosim.logs import DriveLog


@dataclass(frozen=True)
class TrackedChain:
    """The tracked parameters of a replay.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    names : tuple of str
        ``("k[1]", …, "k[n]", "B[1]", …, "B[n]", "f_c", "D_m")``, shape ``(P,)``.
    units : tuple of str
        Their units (FMU notation), shape ``(P,)``.
    values, stds : ndarray
        The tracked values and their standard deviations, shape ``(N, P)``.
    commissioning : ndarray
        The values the observer was given (the FMU's ``k[i]``, ``B[i]``, ``f_c``,
        ``D_m``), shape ``(P,)``.
    alarm, valid : ndarray
        ``drift_alarm`` and ``tracking_valid`` per sample (0 or 1), shape ``(N,)``.

    Examples
    --------
    >>> t = np.array([0.0, 1.0])
    >>> run = TrackedChain(t, ("k[1]",), ("N.m/rad",),
    ...     np.array([[1.0], [0.9]]), np.array([[0.1], [0.01]]), np.array([1.0]),
    ...     np.array([0, 1]), np.array([0, 1]))
    >>> run.first_alarm()
    1.0
    """

    time: np.ndarray
    names: tuple[str, ...]
    units: tuple[str, ...]
    values: np.ndarray
    stds: np.ndarray
    commissioning: np.ndarray
    alarm: np.ndarray
    valid: np.ndarray

    def first_alarm(self) -> float | None:
        """The first time the alarm was raised (s), None if never."""
        raised = np.flatnonzero(self.alarm > 0)
        return float(self.time[raised[0]]) if raised.size else None

    def columns(self) -> tuple[dict[str, np.ndarray], dict[str, str]]:
        """The CSV's columns and units: time, each value, its standard deviation
        (``<name>_std``), ``drift_alarm``, ``tracking_valid``."""
        columns = {"time": self.time}
        units = {"time": "s"}
        for j, (name, unit) in enumerate(zip(self.names, self.units)):
            columns[name] = self.values[:, j]
            columns[f"{name}_std"] = self.stds[:, j]
            units[name] = units[f"{name}_std"] = unit
        columns["drift_alarm"], columns["tracking_valid"] = self.alarm, self.valid
        units["drift_alarm"] = units["tracking_valid"] = "1"
        return columns, units

    def to_json(self) -> dict[str, object]:
        """The replay's end as JSON data: ``tracked`` (per name its last ``value``,
        ``std`` and ``commissioning`` value, each in its unit), the last ``drift_alarm``
        and ``tracking_valid`` (0 or 1), and ``first_alarm_time`` (s, None if never)."""
        final = {
            name: {"value": float(v), "std": float(s), "commissioning": float(c)}
            for name, v, s, c in zip(self.names, self.values[-1], self.stds[-1], self.commissioning)
        }
        return {
            "tracked": final,
            "drift_alarm": int(self.alarm[-1]),
            "tracking_valid": int(self.valid[-1]),
            "first_alarm_time": self.first_alarm(),
        }

    def text(self) -> str:
        """The replay's end as text: each tracked value ± σ (the commissioning value),
        the alarm with the time it was first raised, the validity."""
        summary = self.to_json()
        lines = [f"{len(self.time)} samples; the tracked chain at the end (value ± σ, given):"]
        for name, row in summary["tracked"].items():
            lines.append(
                f"  {name:8s} {row['value']:.6g} ± {row['std']:.2g}  ({row['commissioning']:.6g})"
            )
        alarm = summary["first_alarm_time"]
        lines.append(
            f"  drift_alarm {summary['drift_alarm']}, first raised at "
            + (f"{alarm:g} s" if alarm is not None else "no time")
        )
        lines.append(f"  tracking_valid {summary['tracking_valid']}")
        return "\n".join(lines)


#: The tracker's Integer outputs: the drift alarm and the motion's validity.
FLAGS = ("drift_alarm", "tracking_valid")


def tracking_outputs(n: int) -> tuple[list[str], list[str], list[str]]:
    """The observer's parameter names, tracked outputs and their σ outputs, each in the
    order of :attr:`TrackedChain.names`, for ``n`` masses."""
    idx = range(1, n + 1)
    given = [*(f"k[{i}]" for i in idx), *(f"B[{i}]" for i in idx), "f_c", "D_m"]
    tracked = [*(f"k_track[{i}]" for i in idx), *(f"B_track[{i}]" for i in idx)]
    tracked += ["f_c_track", "D_m_track"]
    stds = [*(f"k_track_std[{i}]" for i in idx), *(f"B_track_std[{i}]" for i in idx)]
    stds += ["f_c_track_std", "D_m_track_std"]
    return given, tracked, stds


def untracked_outputs(names: Sequence[str], n: int) -> list[str]:
    """``names`` (an observer's outputs) without the tracker's, which stay 0 while
    tracking is off: what a replay without tracking records, for ``n`` masses.

    Parameters
    ----------
    names : sequence of str
        Output names of the observer FMU, e.g. ``"d_hat"``, ``"k_track[1]"``.
    n : int
        Number of load masses (a count) the observer was built for.

    Returns
    -------
    list of str
        ``names`` in their order, without the tracked values, their σ and the
        tracker's flags.

    Examples
    --------
    >>> untracked_outputs(["d_hat", "k_track[1]", "k_track_std[1]", "drift_alarm"], 1)
    ['d_hat']
    """
    _, tracked, stds = tracking_outputs(n)
    tracker = {*tracked, *stds, *FLAGS}
    return [name for name in names if name not in tracker]


def replay_tracking(
    observer: FmuInstance,
    log: DriveLog,
    parameters: Mapping[str, float | int | bool],
    n: int,
) -> TrackedChain:
    """Replay ``log`` through the observer with tracking on; its tracked chain over time.

    Parameters
    ----------
    observer : FmuInstance
        A ReactionTorqueObserver instance for ``n`` masses, not yet initialized.
    log : DriveLog
        The samples (SI units).
    parameters : mapping of str to value
        Observer parameters by name; ``tracking`` is 1 unless they say otherwise.
    n : int
        Number of load masses (a count).

    Returns
    -------
    TrackedChain
        The tracked values, σ, alarm and validity per sample, and the commissioning chain.

    Raises
    ------
    UserError
        When the observer refuses its parameters or a sample.

    Examples
    --------
    >>> from pathlib import Path
    >>> from arcosim import ensure_built
    >>> t = np.arange(201) * 1e-3
    >>> still = {"time": t, "i_a": 0 * t, "omega_m": 0 * t, "theta_m": 0 * t}  # 0.2 s at rest
    >>> with FmuInstance(ensure_built(3) / "ReactionTorqueObserver.fmu", "obs") as observer:
    ...     tracked = replay_tracking(observer, DriveLog(Path("still.csv"), still), {}, 3)
    >>> tracked.names[:3], tracked.values.shape, tracked.first_alarm()
    (('k[1]', 'k[2]', 'k[3]'), (201, 8), None)
    """
    given, tracked, stds = tracking_outputs(n)
    run = replay_log(observer, log, {"tracking": 1, **parameters}, [*tracked, *stds, *FLAGS])

    def block(names: list[str]) -> np.ndarray:
        return np.column_stack([run.signals[f"observer.{name}"] for name in names])

    return TrackedChain(
        time=run.time,
        names=tuple(given),
        units=tuple(observer.unit(name) for name in tracked),
        values=block(tracked),
        stds=block(stds),
        commissioning=np.array(observer.get(given), dtype=float),
        alarm=run.signals["observer.drift_alarm"],
        valid=run.signals["observer.tracking_valid"],
    )
