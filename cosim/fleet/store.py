"""The fleet's store: one row per identified log, in ``OUT/fleet.csv``.

A CSV, rewritten whole through a temporary file and ``os.replace`` after every row, so
that a reader (or a run that is interrupted) only ever sees a complete file; the parameter
columns are the union of every row's, so a fit with another n adds its columns. The
columns: :data:`FIXED`, then each parameter and its standard error (``k[1]``,
``k[1]_std``), sorted by name. A units sidecar ``fleet.units.json`` names each column's
unit, as every CSV the project writes has.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path

from arcosim.errors import UserError
from arcosim.logs import units_path
from arcosim.outputs import write_text

#: The store's file in the output folder.
STORE = "fleet.csv"
#: The columns every row has, in order; the parameters and their errors follow.
FIXED = (
    "axis",
    "date",
    "log",
    "status",
    "reason",
    "n",
    "verdict",
    "verdict_reasons",
    "seconds",
    "version",
)
#: A standard error's column is its parameter's name and this.
STD = "_std"
#: The unit of a parameter by its name, a chain's ``J[i]``, ``k[i]``, ``B[i]`` by its letter.
UNITS = {
    "J": "kg*m^2",
    "k": "N*m/rad",
    "B": "N*m*s/rad",
    "J_load": "kg*m^2",
    "D_m": "N*m*s/rad",
    "f_c": "N*m",
    "tau_load": "N*m",
}
#: The columns whose text stays text when read back.
TEXT = {"axis", "date", "log", "status", "reason", "verdict", "verdict_reasons", "version"}


def store_path(out: Path) -> Path:
    """The store's file in the output folder ``out``."""
    return out / STORE


def read_store(out: Path) -> list[dict[str, object]]:
    """Every row of the store in ``out``; numbers as float (empty cells as NaN), ``n``
    as int (None when the fit failed); no store yet gives no rows.

    Raises
    ------
    UserError
        A file that is not a fleet store (other columns, not UTF-8 text).
    """
    path = store_path(out)
    if not path.exists():
        return []
    try:
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            if reader.fieldnames is None or tuple(reader.fieldnames[: len(FIXED)]) != FIXED:
                raise UserError(f"{path}: not a fleet store (its columns differ); choose another")
            return [_typed(row) for row in reader]
    except (UnicodeDecodeError, csv.Error) as error:
        raise UserError(f"{path}: not a fleet store ({error}); choose another folder") from None


def write_store(out: Path, rows: Iterable[Mapping[str, object]]) -> Path:
    """Write every row to the store in ``out`` at once (atomically), and its units sidecar.

    Parameters
    ----------
    out : Path
        The output folder.
    rows : iterable of mapping
        The rows: :data:`FIXED`'s columns, parameters and their ``_std``.

    Returns
    -------
    Path
        The store's file.
    """
    rows = list(rows)
    columns = list(FIXED) + sorted({k for row in rows for k in row if k not in FIXED})
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _cell(v) for k, v in row.items()})
    path = store_path(out)
    write_text(path, text.getvalue(), force=True)
    units = json.dumps({c: _unit(c) for c in columns}, indent=1) + "\n"
    write_text(units_path(path), units, force=True)
    return path


def parameter_names(row: Mapping[str, object]) -> list[str]:
    """The parameters a row holds a value of (every column but :data:`FIXED` and the errors)."""
    return [
        k
        for k, v in row.items()
        if k not in FIXED and not k.endswith(STD) and isinstance(v, float) and math.isfinite(v)
    ]


def _unit(column: str) -> str:
    name = column.removesuffix(STD)
    if column == "seconds":
        return "s"
    if column == "n":
        return "1"
    if column in TEXT:
        return ""
    return UNITS.get(name.split("[")[0], "")


def _cell(value: object) -> object:
    if isinstance(value, float) and not math.isfinite(value):
        return ""
    return "" if value is None else value


def _typed(row: Mapping[str, str]) -> dict[str, object]:
    typed: dict[str, object] = {}
    for key, text in row.items():
        if key in TEXT:
            typed[key] = text or ""
        elif key == "n":
            typed[key] = int(text) if text else None
        else:
            try:
                typed[key] = float(text) if text else math.nan
            except ValueError:
                typed[key] = math.nan
    return typed
