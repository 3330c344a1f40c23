"""Recorded drive logs: reading, checking and scaling, and writing recordings as CSV.

A log is a CSV file with a header row and at least the columns ``time`` (s),
``i_a`` (A), ``omega_m`` (rad/s) and ``theta_m`` (rad), one row per sample as the
timing contract of docs/method.md defines it: the angle and velocity at ``time``
and the current that acted over the step ending at ``time``.

Every CSV file arcosim writes (``write_csv``) has a sidecar ``FILE.units.json``,
``{column: unit}`` (FMI unit names: ``"rad/s"``, ``"N.m"``; ``"1"`` for a count or a
code; ``"%"`` for a percent error), so the CSV itself stays a plain header and numbers
that any reader takes. Asked for tool-safe names (``tool_names=True``, the CLI's
``--tool-names``), the columns are written as ``theta_hat_1`` for ``theta_hat[1]`` and
``plant_i_noise_std`` for ``plant.i_noise_std``, names MATLAB, R or a spreadsheet keep as
they are (``tool_name``); the log columns are such names already, so ``read_log`` reads
either form, and files without a sidecar as before. ``read_log`` reads a log's sidecar
back and refuses scales it contradicts.
"""

from __future__ import annotations

import codecs
import csv
import io
import json
import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from arcosim.errors import UserError
from arcosim.outputs import atomic_output, write_text

LOG_COLUMNS = ("time", "i_a", "omega_m", "theta_m")
#: Units of the columns arcosim writes that no recording states (a recording carries
#: its FMUs' units), by name without its ``fmu.`` prefix and ``[i]`` index.
COLUMN_UNITS = {
    "time": "s",
    "i_a": "A",
    "omega_m": "rad/s",
    "theta_m": "rad",
    "i_ref": "A",
    "omega_ref": "rad/s",
    "tau_load_hat": "N.m",
    "tau_reac_hat": "N.m",
    "theta_hat": "rad",
    "omega_hat": "rad/s",
    "innovation": "N.m",
}


@dataclass(frozen=True)
class DriveLog:
    """A checked drive log: ``time`` strictly increasing, every value finite, SI units.

    One row per sample, as the timing contract defines it (``docs/method.md``): the
    angle and velocity at ``time`` and the current that acted over the step ending
    at ``time``.

    Parameters
    ----------
    path : Path
        The file it was read from.
    columns : dict of str to ndarray
        ``time`` (s), ``i_a`` (A), ``omega_m`` (rad/s), ``theta_m`` (rad), each of
        shape ``(N,)``.

    Examples
    --------
    >>> from pathlib import Path
    >>> t = np.arange(3) * 1e-3
    >>> log = arcosim.DriveLog(Path("x.csv"), {"time": t, "i_a": t, "omega_m": t, "theta_m": t})
    >>> len(log), float(log.time[-1])
    (3, 0.002)
    """

    path: Path
    columns: dict[str, np.ndarray]

    @property
    def time(self) -> np.ndarray:
        """Sample times (s), shape ``(N,)``."""
        return self.columns["time"]

    def __len__(self) -> int:
        return len(self.time)


def parse_scales(texts: Iterable[str]) -> dict[str, float]:
    """``["i_a=0.001", ...]`` → ``{"i_a": 0.001}`` (factor to SI); checks each.

    Parameters
    ----------
    texts : iterable of str
        ``--scale`` texts, ``"COLUMN=FACTOR"``, COLUMN one of the log's columns and
        FACTOR the dimensionless multiplier to SI units.

    Returns
    -------
    dict of str to float
        The factors by column (dimensionless), what :func:`read_log` takes.

    Raises
    ------
    UserError
        A text that is not ``COLUMN=FACTOR``, an unknown column, a factor that is not a
        finite non-zero number.

    Examples
    --------
    >>> arcosim.parse_scales(["i_a=0.001", "theta_m=0.00314"])
    {'i_a': 0.001, 'theta_m': 0.00314}
    """
    scales = {}
    for text in texts:
        column, sep, factor = text.partition("=")
        try:
            value = float(factor)
        except ValueError:
            value = math.nan
        if not sep or column not in LOG_COLUMNS or not math.isfinite(value) or value == 0.0:
            raise UserError(
                f"--scale {text!r}: write COLUMN=FACTOR with COLUMN one of "
                f"{', '.join(LOG_COLUMNS)} and a finite, non-zero FACTOR (e.g. i_a=0.001 for mA)"
            )
        scales[column] = value
    return scales


def read_log(path: str | Path, scales: Mapping[str, float] | None = None) -> DriveLog:
    """Read and check a drive log.

    The file is UTF-8 text, with or without a byte-order mark; any other encoding is
    refused, naming the first byte that is not UTF-8.

    Parameters
    ----------
    path : str or Path
        CSV file with a header row naming at least ``time``, ``i_a``, ``omega_m``,
        ``theta_m`` (other columns are ignored), one row per sample.
    scales : mapping of str to float, optional
        Factors that convert a column to SI units (dimensionless multipliers):
        ``{"i_a": 1e-3}`` for mA, ``{"theta_m": 2 * pi / 4096}`` for counts.

    Returns
    -------
    DriveLog
        The log's columns in SI units (s, A, rad/s, rad).

    Raises
    ------
    UserError
        Naming the row or column at fault: no such file, an empty file, a missing
        column, a column twice, columns separated by ``;`` or tabs, a cell that is not
        a finite number, time that does not increase, fewer than two rows, a file that
        is not UTF-8 text; or a scale the log's units sidecar contradicts
        (:func:`check_scales_against_units`).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = path.write_text("time,i_a,omega_m,theta_m\\n0,0,0,0\\n0.001,0.5,0.1,0.0001\\n")
    >>> log = arcosim.read_log(path, {"i_a": 1e-3})
    >>> len(log), float(log.columns["i_a"][1])
    (2, 0.0005)
    """
    path = Path(path)
    text = read_text_file(path, "log")
    reader = csv.reader(io.StringIO(text, newline=""))
    try:
        index = _column_index(path, next(reader, None))
        rows = [
            (line, _row_values(path, line, row, index))
            for line, row in enumerate(reader, start=2)
            if row and not all(not cell.strip() for cell in row)
        ]
    except csv.Error as error:
        raise UserError(f"{path}, row {reader.line_num}: not CSV text ({error})") from None
    if len(rows) < 2:
        raise UserError(f"{path}: needs at least two data rows (has {len(rows)})")
    check_scales_against_units(path, scales or {})  # the sidecar counts too
    data = np.array([v for _, v in rows])
    with np.errstate(over="ignore", invalid="ignore"):
        for c, factor in (scales or {}).items():
            data[:, LOG_COLUMNS.index(c)] *= factor
        steps = np.diff(data[:, 0])
    overflow = np.argwhere(~np.isfinite(data))
    if overflow.size:
        r, j = overflow[0]
        raise UserError(
            f"{path}, row {rows[r][0]}, column {LOG_COLUMNS[j]}: not finite once scaled "
            f"by --scale {LOG_COLUMNS[j]}={float((scales or {})[LOG_COLUMNS[j]])!r}"
        )
    bad = np.flatnonzero(~(steps > 0) | ~np.isfinite(steps))
    if bad.size:
        line = rows[bad[0] + 1][0]
        raise UserError(
            f"{path}, row {line}, column time: {float(data[bad[0] + 1, 0])!r} s does not increase "
            f"(previous row: {float(data[bad[0], 0])!r} s)"
        )
    return DriveLog(path, {c: data[:, j] for j, c in enumerate(LOG_COLUMNS)})


def _column_index(path: Path, header: list[str] | None) -> dict[str, int]:
    """Where each of :data:`LOG_COLUMNS` is in the header row; refuse an empty file or a
    missing column."""
    if header is None:
        raise UserError(
            f"{path}: the file is empty (expected a header row with {', '.join(LOG_COLUMNS)})"
        )
    header = [h.strip() for h in header]
    missing = [c for c in LOG_COLUMNS if c not in header]
    for sep in (";", "\t"):
        if missing and all(c in [h.strip() for h in sep.join(header).split(sep)] for c in missing):
            raise UserError(
                f"{path}: the columns are separated by {sep!r}: give a comma-separated CSV"
            )
    twice = [c for c in LOG_COLUMNS if header.count(c) > 1]
    if twice:
        raise UserError(
            f"{path}: column {', '.join(twice)} appears twice in the header; "
            "keep one (which to read is not for arcosim to guess)"
        )
    if missing:
        shown = ", ".join(repr(h) if not h.isprintable() else h for h in header[:20])
        raise UserError(f"{path}: missing column {', '.join(missing)} (the header has: {shown})")
    return {c: header.index(c) for c in LOG_COLUMNS}


def check_scales_against_units(path: Path, scales: Mapping[str, float]) -> None:
    """Refuse ``--scale`` factors the log's units sidecar (:func:`read_units`) contradicts:
    a factor other than ±1 for a column it says is in SI units already (−1 turns a
    column's sign, its unit stays), and no factor for a column it says is in another unit.

    Raises
    ------
    UserError
        Naming the factor, the sidecar and the unit it states; or a sidecar that is not
        a JSON object.
    """
    units = read_units(path)
    for column in LOG_COLUMNS:
        unit, si, factor = units.get(column, ""), COLUMN_UNITS[column], scales.get(column)
        if unit == si and factor is not None and abs(factor) != 1.0:
            raise UserError(
                f"--scale {column}={factor:g} contradicts {units_path(path)}, which says "
                f"{column} is in {unit!r} (SI) already: drop --scale {column}, or fix the "
                "units file if it is wrong"
            )
        if unit not in ("", si) and factor is None:
            raise UserError(
                f"{units_path(path)} says {column} is in {unit!r}: give --scale "
                f"{column}=FACTOR that converts it to {si!r}"
            )


def _row_values(path: Path, line: int, row: list[str], index: dict[str, int]) -> list[float]:
    """The values of :data:`LOG_COLUMNS` in one row (line ``line`` of the file); refuse a
    cell that is not a finite number (a missing cell is an empty one)."""
    values = []
    for c in LOG_COLUMNS:
        i = index[c]
        cell = row[i].strip() if i < len(row) else ""
        try:
            x = float(cell)
        except ValueError:
            raise UserError(
                f"{path}, row {line}, column {c}: {cell[:40]!r} is not a number"
            ) from None
        if not math.isfinite(x):
            raise UserError(f"{path}, row {line}, column {c}: {cell[:40]} is not a finite number")
        values.append(x)
    return values


def read_text_file(path: Path, what: str = "file") -> str:
    """The text of a UTF-8 file (a byte-order mark is dropped); refuse anything else.

    Parameters
    ----------
    path : Path
        The file to read.
    what : str
        What the file is, for messages (``"log"``, ``"spec"``).

    Returns
    -------
    str
        The file's text.

    Raises
    ------
    UserError
        When the file is missing, a folder, unreadable, or not UTF-8 (naming the
        encoding when a byte-order mark says which, else the first bad byte).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = path.write_bytes(b"\\xef\\xbb\\xbftime,i_a\\n")
    >>> arcosim.read_text_file(path, "log")
    'time,i_a\\n'
    """
    if path.is_dir():
        raise UserError(f"{path}: is a folder, not a {what}")
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise UserError(f"{path}: no such file") from None
    except OSError as error:
        raise UserError(f"{path}: cannot read the {what} ({error.strerror or error})") from None
    for bom, name in (
        (codecs.BOM_UTF32_LE, "UTF-32"),
        (codecs.BOM_UTF32_BE, "UTF-32"),
        (codecs.BOM_UTF16_LE, "UTF-16"),
        (codecs.BOM_UTF16_BE, "UTF-16"),
    ):
        if data.startswith(bom):
            raise UserError(f"{path}: the {what} is {name} text; save it as UTF-8")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        byte = data[error.start]
        raise UserError(
            f"{path}, line {line}: byte 0x{byte:02x} is not UTF-8 (the {what} must be UTF-8 "
            "text; Latin-1 or Windows-1252? save it as UTF-8)"
        ) from None
    if "\x00" in text:
        line = text.count("\n", 0, text.index("\x00")) + 1
        raise UserError(f"{path}, line {line}: a NUL byte: the {what} must be text, not binary")
    return text


def write_csv(
    path: str | Path,
    columns: Mapping[str, np.ndarray],
    *,
    units: Mapping[str, str] | None = None,
    tool_names: bool = False,
    force: bool = False,
    option: str = "--out",
) -> Path:
    """Write columns of equal length as a CSV file with a header, at full precision,
    and their units beside it (``FILE.units.json``, ``{column: unit}``).

    Parameters
    ----------
    path : str or Path
        The file to write (its folder is created if needed). Written atomically
        (:func:`arcosim.outputs.atomic_output`): never left half-written.
    columns : mapping of str to ndarray
        Column name → values, each of shape ``(N,)``.
    units : mapping of str to str, optional
        Column name → unit (a recording's ``units``); a column it lacks takes its unit
        from :data:`COLUMN_UNITS`.
    tool_names : bool
        Whether to write the names tool-safe (:func:`tool_name`: ``theta_hat_1``), in
        the CSV and in its sidecar.
    force : bool
        Whether an existing file may be replaced (else :class:`UserError`); the
        sidecar belongs to the file and is replaced with it.
    option : str
        The option that named ``path``, for messages.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "out.csv"
    >>> _ = arcosim.write_csv(path, {"time": np.array([0.0, 0.001]), "i_a": np.array([0.0, 0.5])})
    >>> path.read_text().splitlines()[0]
    'time,i_a'
    >>> from arcosim.logs import read_units
    >>> read_units(path)
    {'time': 's', 'i_a': 'A'}
    """
    path = Path(path)
    names = list(columns)
    found = column_units(names, units)
    written = [tool_name(n) for n in names] if tool_names else names
    if len(set(written)) != len(written):
        raise UserError(f"{option} {path}: --tool-names gives two columns one name; drop one")
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    with atomic_output(path, "w", force=force, option=option) as f:
        np.savetxt(f, data, delimiter=",", header=",".join(written), comments="", fmt="%.17g")
    sidecar = {w: found[n] for w, n in zip(written, names)}
    write_text(units_path(path), json.dumps(sidecar, indent=1) + "\n", force=True, option=option)
    return path


def tool_name(name: str) -> str:
    """A column or key name as other tools keep it: letters, digits and ``_`` only.

    Parameters
    ----------
    name : str
        A name as arcosim writes it: ``"theta_hat[1]"``, ``"plant.i_noise_std"``.

    Returns
    -------
    str
        Every run of other characters as one ``_``, none at the ends, and an ``x`` in
        front of a leading digit: ``"theta_hat_1"``, ``"plant_i_noise_std"``.

    Examples
    --------
    >>> tool_name("theta_hat[1]"), tool_name("plant.i_noise_std"), tool_name("J[2]")
    ('theta_hat_1', 'plant_i_noise_std', 'J_2')
    """
    safe = re.sub(r"[^0-9A-Za-z_]+", "_", name).strip("_") or "x"
    return f"x{safe}" if safe[0].isdigit() else safe


def tool_keys(value: object) -> object:
    """``value`` (JSON data) with every dict key made tool-safe (:func:`tool_name`), at any
    depth; refuse two keys that become one.

    Parameters
    ----------
    value : object
        JSON data: dicts, lists and scalars, nested.

    Returns
    -------
    object
        The same data, every dict key as :func:`tool_name` writes it.

    Raises
    ------
    UserError
        When two keys of one dict give one name.

    Examples
    --------
    >>> arcosim.tool_keys({"J[1]": 1e-4, "std": {"k[1]": 0.2}})
    {'J_1': 0.0001, 'std': {'k_1': 0.2}}
    """
    if isinstance(value, dict):
        renamed = {tool_name(str(k)): tool_keys(v) for k, v in value.items()}
        if len(renamed) != len(value):
            raise UserError(f"--tool-names: two keys of {list(value)[:8]} give one name")
        return renamed
    if isinstance(value, list):
        return [tool_keys(v) for v in value]
    return value


def units_path(path: str | Path) -> Path:
    """The units sidecar of a CSV file: ``FILE.csv`` → ``FILE.units.json``."""
    path = Path(path)
    return path.with_name(f"{path.stem if path.suffix == '.csv' else path.name}.units.json")


def column_units(names: Iterable[str], units: Mapping[str, str] | None = None) -> dict[str, str]:
    """The unit of each column: from ``units``, else :data:`COLUMN_UNITS` by the name
    without its ``fmu.`` prefix and ``[i]`` index; ``""`` when neither knows it."""
    units = units or {}
    found = {}
    for name in names:
        base = re.sub(r"\[\d+\]$", "", name.rpartition(".")[2] if "." in name else name)
        found[name] = units.get(name) or COLUMN_UNITS.get(base, "")
    return found


def read_units(path: str | Path) -> dict[str, str]:
    """The units of a CSV file's columns from its sidecar (:func:`units_path`); ``{}``
    for a file written without one."""
    sidecar = units_path(path)
    if not sidecar.is_file():
        return {}
    try:
        units = json.loads(read_text_file(sidecar, "units file"))
    except ValueError as error:
        raise UserError(f"{sidecar}: the units file is not JSON ({error})") from None
    if not isinstance(units, dict):
        raise UserError(f'{sidecar}: the units file must be one JSON object {{"column": "unit"}}')
    return {str(k): str(v) for k, v in units.items()}
