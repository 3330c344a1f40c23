"""The fleet's store: one row per identified log, in ``OUT/fleet.csv``.

A CSV, one line per row, in the order the logs were identified. The columns:
:data:`FIXED`, then each parameter and its standard error (``k[1]``, ``k[1]_std``),
sorted by name; a units sidecar ``fleet.units.json`` names each column's unit, as every
CSV the project writes has.

How a row is added (:func:`append_store`), so that a crash loses no finished row and the
cost of a row does not grow with the store:

* a row whose columns the header has is appended as one line, in one ``write`` on a file
  opened for appending, then ``fsync``-ed: once :func:`append_store` returns, the row
  survives a crash of the process or the machine;
* a row with a column the header lacks (the first fit of another n) rewrites the whole
  file with the new header through a temporary file and ``os.replace``
  (:func:`write_store`): a reader sees the old file or the new one. This happens once
  per new set of columns, not per row;
* a crash during an append can leave a last line without its newline (a torn row).
  :func:`read_store` ignores it (a reader running beside the writer may meet a line
  being written the same way), and the next :func:`append_store` cuts it off before
  writing, so its log, not being in the store, is identified again by the next run.

One writer at a time: the caller holds the folder's lock
(:func:`arcosim.sweeps.runner.lock_folder`); readers need none.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
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
    """Every row of the store in ``out``.

    Parameters
    ----------
    out : Path
        The output folder that holds the store (:data:`STORE`).

    Returns
    -------
    list of dict
        One dict a row, by column: numbers as float in their column's unit (empty
        cells as NaN), ``n`` as int (None when the fit failed), text as str; no
        store yet gives no rows.

    Raises
    ------
    UserError
        A file that is not a fleet store (other columns, not UTF-8 text).

    Examples
    --------
    >>> from pathlib import Path
    >>> row = {"axis": "a1", "date": "2026-01-05", "status": "ok", "n": 1, "k[1]": 0.3}
    >>> _ = write_store(Path("read-out"), [row])
    >>> [(r["axis"], r["n"], r["k[1]"]) for r in read_store(Path("read-out"))]  # N·m/rad
    [('a1', 1, 0.3)]
    >>> read_store(Path("no-store-yet"))
    []
    """
    path = store_path(out)
    if not path.exists():
        return []
    try:
        text = path.read_bytes().decode("utf-8")
        reader = csv.DictReader(io.StringIO(text[: text.rfind("\n") + 1]))  # no torn row
        if reader.fieldnames is None or tuple(reader.fieldnames[: len(FIXED)]) != FIXED:
            raise UserError(f"{path}: not a fleet store (its columns differ); choose another")
        return [_typed(row) for row in reader]
    except (UnicodeDecodeError, csv.Error) as error:
        raise UserError(f"{path}: not a fleet store ({error}); choose another folder") from None
    except OSError as error:
        raise UserError(f"{path}: cannot read it ({error.strerror})") from None


def append_store(out: Path, row: Mapping[str, object]) -> Path:
    """Add one row to the store in ``out``, durably (the module's docstring says how).

    Parameters
    ----------
    out : Path
        The output folder; the caller holds its lock (one writer).
    row : mapping
        :data:`FIXED`'s columns (those missing are written empty), parameters and their
        ``_std``.

    Returns
    -------
    Path
        The store's file.

    Raises
    ------
    UserError
        The store cannot be written (a full disk, no permission), or is not a fleet store.

    Examples
    --------
    >>> from pathlib import Path
    >>> row = {"axis": "a1", "date": "2026-01-05", "status": "ok", "n": 1, "k[1]": 0.3}
    >>> _ = append_store(Path("store-out"), row)
    >>> _ = append_store(Path("store-out"), {**row, "date": "2026-02-05", "k[1]": 0.27})
    >>> [(r["date"], r["k[1]"]) for r in read_store(Path("store-out"))]
    [('2026-01-05', 0.3), ('2026-02-05', 0.27)]
    """
    path = store_path(out)
    columns = _header(path)
    if columns is None or any(key not in columns for key in row):
        return write_store(out, [*read_store(out), row])
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=columns, restval="", lineterminator="\n")
    writer.writerow({k: _cell(v) for k, v in row.items()})
    try:
        fd = os.open(path, os.O_RDWR | os.O_APPEND)
        try:
            _cut_torn_row(fd)
            data = text.getvalue().encode("utf-8")
            while data:  # one write in practice; a short write goes on where it stopped
                data = data[os.write(fd, data) :]
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as error:
        raise UserError(f"{path}: cannot add a row ({error.strerror})") from None
    return path


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

    Examples
    --------
    >>> from pathlib import Path
    >>> fit = {"axis": "a1", "status": "ok", "n": 1}
    >>> rows = [{**fit, "date": "2026-01-05", "k[1]": 0.3, "k[1]_std": 1e-3},
    ...         {**fit, "date": "2026-02-05", "k[1]": 0.27, "k[1]_std": 1e-3}]
    >>> write_store(Path("write-out"), rows).name
    'fleet.csv'
    >>> [r["k[1]"] for r in read_store(Path("write-out"))]  # N·m/rad
    [0.3, 0.27]
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
    units = json.dumps({c: column_unit(c) for c in columns}, indent=1) + "\n"
    write_text(units_path(path), units, force=True)
    _sync_folder(out)
    return path


def _sync_folder(folder: Path) -> None:
    """Sync the folder's entries, so the renames that published the files survive a
    power cut as the rows appended later do (POSIX; elsewhere the rename stands alone)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # a file system that cannot sync a folder: the rename stands alone
    finally:
        os.close(fd)


def _header(path: Path) -> list[str] | None:
    """The store's columns from its first line; None when there is no store yet."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            first = f.readline()
    except FileNotFoundError:
        return None
    except (OSError, UnicodeDecodeError) as error:
        raise UserError(f"{path}: not a readable fleet store ({error}); choose another") from None
    columns = next(csv.reader([first]), [])
    if tuple(columns[: len(FIXED)]) != FIXED or not first.endswith("\n"):
        raise UserError(f"{path}: not a fleet store (its columns differ); choose another")
    return columns


#: Bytes read at a time from the end of the store, looking for the last newline: a
#: page, which holds several rows (any size finds it; this one in one read, usually).
_TAIL = 4096


def _cut_torn_row(fd: int) -> None:
    """Cut a last line without its newline (a row torn by a crash) off the file ``fd``."""
    end = size = os.fstat(fd).st_size
    if not size or os.pread(fd, 1, size - 1) == b"\n":
        return
    while end > 0:
        start = max(0, end - _TAIL)
        at = os.pread(fd, end - start, start).rfind(b"\n")
        if at >= 0:
            os.ftruncate(fd, start + at + 1)
            return
        end = start
    raise OSError(0, "no complete line, not even the header")


def parameter_names(row: Mapping[str, object]) -> list[str]:
    """The parameters a row holds a value of (every column but :data:`FIXED` and the errors)."""
    return [
        k
        for k, v in row.items()
        if k not in FIXED and not k.endswith(STD) and isinstance(v, float) and math.isfinite(v)
    ]


def column_unit(column: str) -> str:
    """The unit of a column of the store (``""`` for text, ``"1"`` for n).

    Examples
    --------
    >>> column_unit("k[2]_std"), column_unit("seconds"), column_unit("verdict")
    ('N*m/rad', 's', '')
    """
    name = column.removesuffix(STD)
    if column == "seconds":
        return "s"
    if column == "n":
        return "1"
    if column in TEXT:
        return ""
    return UNITS.get(name.split("[")[0], "")


def _cell(value: object) -> object:
    """A value as the store writes it: empty for None and NaN, text on one line (a row
    is one line, which is what tells a torn row)."""
    if isinstance(value, float) and not math.isfinite(value):
        return ""
    if isinstance(value, str):
        return " ".join(value.splitlines())
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
