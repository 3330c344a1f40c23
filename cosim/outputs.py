"""Files a command writes: checked before the work starts, written atomically.

Every output of every command goes through here, so the rules hold everywhere:

* an output is written to a temporary file in its own folder and renamed over the
  name at the end, so a reader (or a crash, a full disk, ``kill -9``) sees the old
  file or the whole new one, never a part;
* an existing file is replaced only when the user says so (``--force``); otherwise
  the command is refused before it runs, naming the file, and the final rename is
  a hard link that fails if someone created the file meanwhile;
* an output is never one of the command's inputs (same inode, or same resolved
  path), whatever ``--force`` says;
* an output that is a folder, a device (``/dev/full``), a FIFO or in a folder that
  cannot take a file (``/proc``) is refused before the work starts.

Every refusal is a :class:`~arcosim.errors.UserError` naming the option and the file.
"""

from __future__ import annotations

import contextlib
import errno
import io
import os
import stat
import tempfile
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO

from arcosim.errors import UserError


def check_output(
    path: str | Path,
    *,
    inputs: Iterable[str | Path] = (),
    force: bool = False,
    option: str = "--out",
) -> Path:
    """Refuse ``path`` as an output unless a file can be written there; return it.

    Parameters
    ----------
    path : str or Path
        The file the command will write.
    inputs : iterable of str or Path
        Files the command reads; ``path`` may not be any of them.
    force : bool
        Whether an existing file may be replaced.
    option : str
        The option that named ``path``, for messages (``"--out"``).

    Returns
    -------
    Path
        ``path``, with ``~`` expanded.

    Raises
    ------
    UserError
        When ``path`` is an input, a folder, not a regular file, exists without
        ``force``, or its folder cannot take a new file.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> folder = Path(tempfile.mkdtemp())
    >>> arcosim.check_output(folder / "out.csv").name
    'out.csv'
    >>> arcosim.check_output(folder)
    Traceback (most recent call last):
    ...
    arcosim.errors.UserError: --out ...: is a folder; name a file in it
    """
    path = Path(path).expanduser()
    for source in inputs:
        if same_file(path, Path(source)):
            raise UserError(
                f"{option} {path}: that is an input of this command ({source}); "
                "write the output to another file"
            )
    try:
        info = path.stat()
    except FileNotFoundError:
        info = None
    except OSError as error:
        raise UserError(f"{option} {path}: cannot use this path ({_reason(error)})") from None
    if info is not None:
        if stat.S_ISDIR(info.st_mode):
            raise UserError(f"{option} {path}: is a folder; name a file in it")
        if not stat.S_ISREG(info.st_mode):
            raise UserError(f"{option} {path}: not a regular file (a device or pipe); name a file")
        if not force:
            raise UserError(f"{option} {path}: the file exists; add --force to replace it")
    _probe_folder(path, option)
    return path


def check_output_folder(folder: str | Path, option: str = "--out") -> Path:
    """Refuse ``folder`` as an output folder unless files can be created in it; create it.

    Parameters
    ----------
    folder : str or Path
        The folder the command will write its files into (created with its parents).
    option : str
        The option that named ``folder``, for messages (``"--out"``).

    Returns
    -------
    Path
        ``folder``, with ``~`` expanded, now existing.

    Raises
    ------
    UserError
        When ``folder`` is a file, cannot be created, or cannot take a new file.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> folder = arcosim.check_output_folder(Path(tempfile.mkdtemp()) / "reports")
    >>> folder.name, folder.is_dir()
    ('reports', True)
    """
    folder = Path(folder).expanduser()
    if folder.exists() and not folder.is_dir():
        raise UserError(f"{option} {folder}: is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise UserError(f"{option} {folder}: cannot create the folder ({_reason(error)})") from None
    _probe_folder(folder / "probe", option)
    return folder


def same_file(a: Path, b: Path) -> bool:
    """True if ``a`` and ``b`` name one file (same device and inode, or same real path).

    Parameters
    ----------
    a, b : Path
        Two paths; either may not exist (then their real paths are compared).

    Returns
    -------
    bool
        Whether writing to one would change the other.

    Examples
    --------
    >>> from pathlib import Path
    >>> arcosim.same_file(Path("a/../b.csv"), Path("b.csv"))
    True
    >>> arcosim.same_file(Path("a"), Path("b"))
    False
    """
    try:
        return os.path.samefile(a, b)
    except OSError:
        pass
    try:
        return os.path.realpath(a) == os.path.realpath(b)
    except (OSError, ValueError):
        return False


@contextlib.contextmanager
def atomic_output(
    path: str | Path, mode: str = "w", *, force: bool = False, option: str = "--out"
) -> Iterator[IO]:
    """Open a temporary file beside ``path``; on success move it to ``path``.

    The temporary file is in the same folder (a rename within one file system is
    atomic) and removed if the block raises. Without ``force`` the file is linked
    to ``path``, which fails if ``path`` exists by then.

    Parameters
    ----------
    path : str or Path
        The output file (through a symbolic link: the file it points to).
    mode : {"w", "wb"}
        Text (UTF-8, ``newline=""``) or binary.
    force : bool
        Whether an existing ``path`` may be replaced.
    option : str
        The option that named ``path``, for messages.

    Yields
    ------
    file object
        Open for writing; its ``name`` is the temporary file.

    Raises
    ------
    UserError
        When the file cannot be written (full disk, no permission) or exists
        without ``force``; the existing file is left as it was.
    """
    target = Path(os.path.realpath(Path(path).expanduser()))
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(
            prefix=f".{target.name}.", suffix=".part", dir=target.parent
        )
    except OSError as error:
        raise UserError(f"{option} {path}: cannot write here ({_reason(error)})") from None
    temporary = Path(temporary)
    try:
        try:
            with os.fdopen(
                fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})
            ) as f:
                yield f
                f.flush()
                os.fsync(f.fileno())
            os.chmod(temporary, _mode_for(target))
            _publish(temporary, target, force)
        except FileExistsError:
            raise UserError(
                f"{option} {path}: the file exists; add --force to replace it"
            ) from None
        except OSError as error:
            raise UserError(f"{option} {path}: cannot write it ({_reason(error)})") from None
    finally:
        temporary.unlink(missing_ok=True)


def write_bytes(
    path: str | Path, data: bytes, *, force: bool = False, option: str = "--out"
) -> Path:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_output`); return ``path``.

    Parameters
    ----------
    path : str or Path
        The output file.
    data : bytes
        What to write.
    force : bool
        Whether an existing ``path`` may be replaced.
    option : str
        The option that named ``path``, for messages (``"--out"``).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    UserError
        When the file cannot be written or exists without ``force`` (left as it was).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = arcosim.write_bytes(Path(tempfile.mkdtemp()) / "x.bin", b"\\x00\\x01")
    >>> path.read_bytes()
    b'\\x00\\x01'
    """
    with atomic_output(path, "wb", force=force, option=option) as f:
        f.write(data)
    return Path(path)


def write_text(path: str | Path, text: str, *, force: bool = False, option: str = "--out") -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; return ``path``.

    Parameters
    ----------
    path : str or Path
        The output file.
    text : str
        What to write, encoded as UTF-8.
    force : bool
        Whether an existing ``path`` may be replaced.
    option : str
        The option that named ``path``, for messages (``"--out"``).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    UserError
        When the file cannot be written or exists without ``force`` (left as it was).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = arcosim.write_text(Path(tempfile.mkdtemp()) / "note.md", "J = 1e-4 kg·m²\\n")
    >>> path.read_text(encoding="utf-8")
    'J = 1e-4 kg·m²\\n'
    """
    return write_bytes(path, text.encode("utf-8"), force=force, option=option)


def save_figure(
    figure: object, path: str | Path, *, dpi: int, force: bool = False, option: str = "--out"
) -> Path:
    """Save a matplotlib figure to ``path`` atomically (format from the suffix).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure to save.
    path : str or Path
        The output file; its suffix names the format (PNG without one).
    dpi : int
        Resolution (dots per inch).
    force : bool
        Whether an existing ``path`` may be replaced.
    option : str
        The option that named ``path``, for messages (``"--out"``).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    UserError
        When the file cannot be written or exists without ``force`` (left as it was).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from matplotlib.figure import Figure
    >>> path = arcosim.save_figure(Figure(), Path(tempfile.mkdtemp()) / "f.png", dpi=50)
    >>> path.read_bytes()[1:4]
    b'PNG'
    """
    buffer = io.BytesIO()
    figure.savefig(buffer, format=Path(path).suffix.lstrip(".") or "png", dpi=dpi)
    return write_bytes(path, buffer.getvalue(), force=force, option=option)


def refuse_existing(folder: Path, names: Iterable[str], option: str = "--out") -> None:
    """Refuse to run when files a command would write into ``folder`` exist already.

    Parameters
    ----------
    folder : Path
        The command's output folder.
    names : iterable of str
        The files the command would write there.
    option : str
        The option that named ``folder``, for messages (``"--out"``).

    Raises
    ------
    UserError
        Naming the first of those files that exists, and how many more do.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> folder = Path(tempfile.mkdtemp())
    >>> arcosim.refuse_existing(folder, ["report.md"])  # nothing there: no error
    >>> _ = (folder / "report.md").write_text("")
    >>> arcosim.refuse_existing(folder, ["report.md"])
    Traceback (most recent call last):
    ...
    arcosim.errors.UserError: --out ...: report.md exist(s) already; add --force ...
    """
    existing = [name for name in names if (folder / name).exists()]
    if existing:
        more = f" and {len(existing) - 1} more" if len(existing) > 1 else ""
        raise UserError(
            f"{option} {folder}: {existing[0]}{more} exist(s) already; add --force to "
            "replace them, or choose another folder"
        )


def warn_left_over(folder: Path, names: Iterable[str], written: Iterable[Path]) -> list[str]:
    """Warn of the files among ``names`` in ``folder`` that a run did not write (an
    earlier run's, such as ``reproduce --all-csv``'s runs): kept as they are, but named,
    so nobody takes them for this run's.

    Parameters
    ----------
    folder : Path
        The run's output folder.
    names : iterable of str
        The files the command may write there.
    written : iterable of Path
        The files this run wrote.

    Returns
    -------
    list of str
        The names warned of, in the order of ``names``.

    Examples
    --------
    >>> warn_left_over(Path("nowhere"), ["report.md"], [])
    []
    """
    mine = {path.name for path in written}
    stale = [name for name in names if name not in mine and (folder / name).exists()]
    if stale:
        warnings.warn(
            f"{folder} holds files of an earlier run, not rewritten by this run: "
            f"{', '.join(stale)} (delete them, or run again with the options that wrote them)",
            stacklevel=3,
        )
    return stale


def _publish(temporary: Path, target: Path, force: bool) -> None:
    if force:
        os.replace(temporary, target)
        return
    try:
        os.link(temporary, target)  # fails if target exists: no check-then-write race
    except FileExistsError:
        raise
    except OSError as error:
        if error.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.EXDEV, errno.EMLINK):
            raise
        if target.exists():  # a file system without hard links
            raise FileExistsError(target) from None
        os.replace(temporary, target)


def _mode_for(target: Path) -> int:
    """The permissions of the file replaced, or those of a new file (0666 less the umask)."""
    try:
        return stat.S_IMODE(target.stat().st_mode)
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def _probe_folder(path: Path, option: str) -> None:
    """Create and remove a temporary file beside ``path`` (its folder is created)."""
    folder = path.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".probe", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as error:
        raise UserError(f"{option} {path}: cannot write in {folder} ({_reason(error)})") from None


def _reason(error: OSError) -> str:
    return error.strerror or str(error)
