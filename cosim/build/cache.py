"""Where built FMUs live, and whether a folder of them can be trusted.

A folder of FMUs is *current* when it holds every FMU and the SSP, each a zip that
opens with a modelDescription.xml that parses, and a ``.source-digest`` equal to the
digest of the sources they are built from (:func:`source_digest`). The digest is
written last, after every file is complete, so a build that died halfway leaves a
folder that is rebuilt, never trusted. Builds and the checks before them take the
folder's lock (:func:`lock_folder`), so two builds into one folder never interleave.

Without a folder named by the user, FMUs go to a per-user cache:
``$ARCOSIM_CACHE`` if set, else ``$XDG_CACHE_HOME/arcosim`` (``~/.cache/arcosim``),
one subfolder per number of masses and source digest.
"""

from __future__ import annotations

import contextlib
import fcntl
import functools
import hashlib
import io
import os
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from xml.etree import ElementTree

from arcosim.build.recipes import (
    CONTROL_SSP_NAME,
    LINK,
    RECIPES,
    SSP_NAME,
    check_elements,
    check_masses,
)
from arcosim.errors import BuildError
from arcosim.fmu.flexchain.defaults import LINK_ELEMENTS
from arcosim.version import __version__

#: Written beside the FMUs, last: the digest of the sources they were built from.
DIGEST_FILE = ".source-digest"
#: The lock file of a folder of FMUs.
LOCK_FILE = ".arcosim-build.lock"


def fmu_package_dir() -> Path:
    """Folder of :mod:`arcosim.fmu`, the code the Python FMUs bundle."""
    import arcosim.fmu

    return Path(arcosim.fmu.__file__).parent


def plant_package_dir() -> Path:
    """Folder of :mod:`arcosim.plant`: the reference plant and ``motorchain_c/``."""
    import arcosim.plant

    return Path(arcosim.plant.__file__).parent


def cache_root() -> Path:
    """The per-user cache folder of arcosim (see the module docstring)."""
    if os.environ.get("ARCOSIM_CACHE"):
        return Path(os.environ["ARCOSIM_CACHE"]).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base).expanduser() / "arcosim"


def default_folder(n: int = 3, elements: int = LINK_ELEMENTS) -> Path:
    """The cache folder of the FMUs for ``n`` masses (and a link of ``elements`` Hermite
    elements) built from the current sources.

    Examples
    --------
    >>> default_folder(3).parent.name
    'fmus'
    """
    digest = source_digest(check_masses(n), check_elements(elements))
    return cache_root() / "fmus" / f"n{n}-{digest[:16]}"


@functools.cache
def source_digest(n: int, elements: int = LINK_ELEMENTS) -> str:
    """SHA-256 (hex) of everything the FMUs for ``n`` masses are built from.

    The bundled code, the plant's Python and C sources, and the build code itself,
    with the project version, ``n`` and the link's number of elements. Computed once per
    process (a process runs one version of the sources).
    """
    digest = hashlib.sha256(f"{__version__} n={n} elements={elements}".encode())
    roots = (fmu_package_dir(), plant_package_dir(), Path(__file__).parent)
    files = sorted(
        (f for root in roots for f in root.rglob("*") if f.suffix in {".py", ".c", ".h"}),
        key=lambda f: (f.name, str(f)),
    )
    for f in files:
        digest.update(f.name.encode())
        digest.update(f.read_bytes())
    return digest.hexdigest()


@contextlib.contextmanager
def lock_folder(folder: Path) -> Iterator[None]:
    """Hold the exclusive build lock of ``folder`` (waits while another process holds it).

    The lock is an ``flock`` on :data:`LOCK_FILE` in the folder: the kernel drops it
    when its holder exits, however it exits (``kill -9`` too), so it is never stale.

    Raises
    ------
    BuildError
        When the folder cannot be created or the lock file cannot be opened.
    """
    try:
        folder.mkdir(parents=True, exist_ok=True)
        handle = open(folder / LOCK_FILE, "a+b")  # noqa: SIM115 (held across the yield)
    except OSError as error:
        what = "is a file, not a folder" if folder.is_file() else (error.strerror or str(error))
        raise BuildError(f"cannot build into {folder}: {what}") from None
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def fmu_problem(path: Path) -> str | None:
    """Why ``path`` is not a complete FMU (or SSP), or None if it is one.

    Checks that the zip opens, every member's CRC-32 matches, and the model
    description (``SystemStructure.ssd`` for an SSP) parses as XML.
    """
    inner = "SystemStructure.ssd" if path.suffix == ".ssp" else "modelDescription.xml"
    try:
        with zipfile.ZipFile(path) as z:
            bad = z.testzip()
            if bad is not None:
                return f"{path.name}: member {bad} is corrupt"
            ElementTree.fromstring(z.read(inner))
    except FileNotFoundError:
        return f"{path.name} is missing"
    except (
        zipfile.BadZipFile,
        KeyError,
        ElementTree.ParseError,
        OSError,
        EOFError,
        zlib.error,  # a corrupt deflate stream (testzip reads every member)
        ValueError,
    ) as error:
        return f"{path.name} is not a complete FMU ({error})"
    return None


def is_current(folder: Path, n: int, elements: int = LINK_ELEMENTS) -> bool:
    """True if ``folder`` holds complete FMUs for ``n`` masses (and the link of
    ``elements`` elements) built from these sources."""
    stamp = folder / DIGEST_FILE
    try:
        if stamp.read_text(encoding="utf-8").strip() != source_digest(n, elements):
            return False
    except OSError:
        return False
    wanted = [folder / r.file_name for r in (*RECIPES, LINK)] + [folder / SSP_NAME]
    wanted.append(folder / CONTROL_SSP_NAME)
    return all(fmu_problem(path) is None for path in wanted)


def built_names() -> list[str]:
    """The names of the files a build writes into its folder (FMUs and SSPs)."""
    return [r.file_name for r in (*RECIPES, LINK)] + [SSP_NAME, CONTROL_SSP_NAME]


def made_by_arcosim(path: Path) -> bool:
    """True if ``path`` is a file a build of this project wrote, so a rebuild may replace it.

    An FMU is ours when its modelDescription.xml names arcosim as its ``generationTool``
    and its model is the one of its file name (``MotorChainPlant_n3`` in
    ``MotorChainPlant.fmu``); an SSP when its system has the file's name and every FMU
    it packs is ours. Anything else (another tool's file, no zip, a missing file) is not.
    """
    try:
        with zipfile.ZipFile(path) as z:
            return _zip_is_ours(z, path.stem, path.suffix)
    except (OSError, zipfile.BadZipFile, KeyError, ElementTree.ParseError, ValueError):
        return False


def _zip_is_ours(z: zipfile.ZipFile, stem: str, suffix: str) -> bool:
    if suffix == ".fmu":
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
        return root.get("generationTool", "").startswith("arcosim ") and root.get(
            "modelName", ""
        ).startswith(f"{stem}_")
    root = ElementTree.fromstring(z.read("SystemStructure.ssd"))
    fmus = [m for m in z.namelist() if m.startswith("resources/") and m.endswith(".fmu")]
    if root.get("name") != stem or not fmus:
        return False
    for member in fmus:
        with zipfile.ZipFile(io.BytesIO(z.read(member))) as inner:
            if not _zip_is_ours(inner, Path(member).stem, ".fmu"):
                return False
    return True


def foreign_files(folder: Path) -> list[Path]:
    """The files in ``folder`` a build would replace but did not write itself."""
    paths = [folder / name for name in built_names()]
    return [p for p in paths if (p.exists() or p.is_symlink()) and not made_by_arcosim(p)]
