"""A fleet's folder read and checked: its axes, each axis's drive figures, its logs by date.

The layout::

    FLEET/
      <axis>/axis.toml          the axis's drive figures (below)
      <axis>/<ISO date>.csv     one log per identification, dated by its name

``axis.toml`` holds a ``[set]`` table with ``k_to`` (N·m/A), ``J_mo`` (kg·m²) and
``encoder_cpr`` (counts per revolution), optionally ``D_m`` (N·m·s/rad), ``f_c`` (N·m)
and ``g_dist`` (rad/s); an optional ``[scale]`` table of column → factor (as
``arcosim identify --scale``); optional top-level ``masses`` (a whole number or
``"auto"``) and ``load`` (``"none"``, ``"constant"`` or ``"slow"``). A log's name is
an ISO date (``2026-03-01.csv``) or date and time (``2026-03-01T08:30.csv``, or
``2026-03-01T08-30-00.csv`` where a file name cannot hold a colon). Folders and files
whose names start with ``.`` or ``_`` are skipped, as are files other than CSV.
"""

from __future__ import annotations

import datetime
import sys
from dataclasses import dataclass, field
from pathlib import Path

from arcosim.errors import UserError
from arcosim.sweeps.toml_values import (
    integer_value,
    one_line,
    real_value,
    shown_key,
    table_value,
    text_value,
)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

#: The drive figures' file of an axis.
AXIS_FILE = "axis.toml"
#: ``[set]``'s keys: the figures every axis gives, then those it may give.
REQUIRED, OPTIONAL = ("k_to", "J_mo", "encoder_cpr"), ("D_m", "f_c", "g_dist")
#: The columns ``[scale]`` may convert (a log's columns).
COLUMNS = ("time", "i_a", "omega_m", "theta_m")
#: The load torque models ``load`` takes.
LOADS = ("none", "constant", "slow")


@dataclass(frozen=True)
class Axis:
    """One axis of the fleet: its drive figures and how its logs are read.

    Parameters
    ----------
    name : str
        The axis's folder name.
    k_t : float
        Torque constant (N·m/A), ``[set] k_to``.
    J_m : float
        Motor inertia (kg·m²), ``[set] J_mo``.
    encoder_cpr : int
        Encoder counts per revolution (a count).
    masses : int or str
        Load masses to fit (a count), or ``"auto"``.
    load : str, optional
        The load torque model, or None for the selection rule's choice.
    given : dict of str to float
        ``D_m`` (N·m·s/rad), ``f_c`` (N·m), ``g_dist`` (rad/s) when given.
    scales : dict of str to float
        Column → factor to SI units (dimensionless).

    Examples
    --------
    >>> Axis("a1", 0.0406, 2.09e-5, 2000).identify_options()["encoder_cpr"]
    2000
    """

    name: str
    k_t: float
    J_m: float
    encoder_cpr: int
    masses: int | str = "auto"
    load: str | None = None
    given: dict[str, float] = field(default_factory=dict)
    scales: dict[str, float] = field(default_factory=dict)

    def identify_options(self) -> dict[str, object]:
        """The keyword arguments of :func:`arcosim.identify_drive` for this axis's logs."""
        options: dict[str, object] = {
            "k_t": self.k_t,
            "J_m": self.J_m,
            "encoder_cpr": self.encoder_cpr,
            "masses": self.masses,
            "load": self.load,
        }
        return {**options, **self.given}


@dataclass(frozen=True)
class FleetLog:
    """One log of the fleet: its axis, its date (ISO text) and its file."""

    axis: str
    date: str
    path: Path


def log_date(path: Path) -> str:
    """The ISO date (or date and time) a log's name gives, normalised.

    Parameters
    ----------
    path : Path
        The log, named ``<ISO date or datetime>.csv``.

    Returns
    -------
    str
        ``YYYY-MM-DD``, or ``YYYY-MM-DDTHH:MM:SS`` for a date and time, so that the
        dates of an axis sort as text.

    Raises
    ------
    UserError
        When the name is not an ISO date, naming the file.

    Examples
    --------
    >>> log_date(Path("a1/2026-03-01.csv")), log_date(Path("a1/2026-03-01T08-30.csv"))
    ('2026-03-01', '2026-03-01T08:30:00')
    """
    stem = path.stem
    try:
        return datetime.date.fromisoformat(stem).isoformat()
    except ValueError:
        pass
    day, _, clock = stem.partition("T")
    try:
        if not clock:
            raise ValueError(stem)
        moment = datetime.datetime.fromisoformat(f"{day}T{clock.replace('-', ':')}")
        return moment.replace(tzinfo=None).isoformat(timespec="seconds")
    except ValueError:
        raise UserError(
            f"{path}: the log's name is not an ISO date; rename it to the day it was "
            "recorded, e.g. 2026-03-01.csv or 2026-03-01T08-30.csv"
        ) from None


def read_fleet(folder: Path, skip: Path | None = None) -> tuple[dict[str, Axis], list[FleetLog]]:
    """Every axis of the fleet folder and every log, in order of axis and date.

    Parameters
    ----------
    folder : Path
        The fleet's folder (the module's docstring gives its layout).
    skip : Path, optional
        A folder that is no axis even inside ``folder`` (the output folder).

    Returns
    -------
    axes : dict of str to Axis
        By name.
    logs : list of FleetLog
        Sorted by axis, then date.

    Raises
    ------
    UserError
        A missing folder, an axis without ``axis.toml`` or with a wrong one, a log whose
        name is not an ISO date; each naming the file and the fix.
    """
    if not folder.is_dir():
        raise UserError(f"{folder}: no such folder; give the fleet's folder (one per axis)")
    axes: dict[str, Axis] = {}
    logs: list[FleetLog] = []
    skipped = skip.resolve() if skip is not None else None
    subs = (p for p in folder.iterdir() if p.is_dir() and p.name[0] not in "._")
    for sub in sorted(p for p in subs if p.resolve() != skipped):
        axes[sub.name] = read_axis(sub)
        for path in sorted(p for p in sub.glob("*.csv") if p.name[0] not in "._"):
            logs.append(FleetLog(sub.name, log_date(path), path))
    if not axes:
        raise UserError(
            f"{folder}: no axis folders; make one folder per axis holding axis.toml and its logs"
        )
    logs.sort(key=lambda log: (log.axis, log.date, log.path.name))
    return axes, logs


def read_axis(folder: Path) -> Axis:
    """An axis's ``axis.toml`` read and checked (format in the module's docstring).

    Raises
    ------
    UserError
        A missing or unreadable file, a missing or wrong figure, an unknown key.
    """
    path = folder / AXIS_FILE
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError(
            f"{path}: missing; write the axis's [set] k_to, J_mo, encoder_cpr there "
            "(docs: the fleet page)"
        ) from None
    except (OSError, UnicodeDecodeError) as error:
        raise UserError(f"{path}: cannot read it ({one_line(str(error))})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise UserError(f"{path}: not valid TOML ({one_line(str(error))})") from None
    where = f"{path}:"
    _known(where, data, ("set", "scale", "masses", "load"))
    figures = table_value(where, "set", data.get("set", {}))
    _known(f"{path}: [set]", figures, REQUIRED + OPTIONAL)
    for key in REQUIRED:
        if key not in figures:
            raise UserError(f"{path}: [set] has no {key}; add {key} = … (the drive's figure)")
    inner = f"{path}: [set]"
    given = {
        key: real_value(inner, key, figures[key], 0.0, 1e12, low_open=key == "g_dist")
        for key in OPTIONAL
        if key in figures
    }
    return Axis(
        name=folder.name,
        k_t=real_value(inner, "k_to", figures["k_to"], 0.0, 1e6, low_open=True),
        J_m=real_value(inner, "J_mo", figures["J_mo"], 0.0, 1e6, low_open=True),
        encoder_cpr=integer_value(inner, "encoder_cpr", figures["encoder_cpr"], 1, 2**40),
        masses=_masses(where, data.get("masses", "auto")),
        load=_load(where, data.get("load")),
        given=given,
        scales=_scales(path, data.get("scale", {})),
    )


def _known(where: str, table: dict, keys: tuple[str, ...]) -> None:
    """Refuse a key the table does not take."""
    for key in table:
        if key not in keys:
            raise UserError(f"{where} {shown_key(key)}: not a key here; use {', '.join(keys)}")


def _masses(where: str, value: object) -> int | str:
    if value == "auto":
        return "auto"
    if isinstance(value, str):
        raise UserError(f'{where} masses = "{value}": a whole number from 0 to 8, or "auto"')
    return integer_value(where, "masses", value, 0, 8)


def _load(where: str, value: object) -> str | None:
    if value is None:
        return None
    text = text_value(where, "load", value)
    if text not in LOADS:
        raise UserError(f'{where} load = "{text}": one of {", ".join(LOADS)}')
    return text


def _scales(path: Path, value: object) -> dict[str, float]:
    table = table_value(f"{path}:", "scale", value)
    _known(f"{path}: [scale]", table, COLUMNS)
    return {
        k: real_value(f"{path}: [scale]", k, v, 0.0, 1e12, low_open=True) for k, v in table.items()
    }
