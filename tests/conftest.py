"""Shared fixtures: FMUs built once per test session from the current source.

The session gets a cache of its own (``ARCOSIM_CACHE``, inherited by every command a
test starts), so no test reads or writes the user's ``~/.cache/arcosim``. FMUs are
built in a subprocess (``python -m arcosim build``), as a user would, so the test
process never imports a half-built copy; each test then loads the FMU file. The
paper's bench (n = 3) is copied from ``make build``'s ``dist/`` instead when that
folder is current (complete, and its source digest that of these sources): the same
files, without a build in every session of ``make check``.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

#: ``make build``'s FMUs for n = 3.
DIST = Path(__file__).resolve().parents[1] / "dist"


@pytest.fixture(scope="session", autouse=True)
def session_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A per-session FMU cache, set as ``ARCOSIM_CACHE`` for this process and its children."""
    folder = tmp_path_factory.mktemp("arcosim-cache")
    before = os.environ.get("ARCOSIM_CACHE")
    os.environ["ARCOSIM_CACHE"] = str(folder)
    yield folder
    if before is None:
        os.environ.pop("ARCOSIM_CACHE", None)
    else:
        os.environ["ARCOSIM_CACHE"] = before


@pytest.fixture(scope="session")
def build_fmus(session_cache: Path) -> Callable[[int], Path]:
    """``build_fmus(n)`` → the session cache's folder of the project's FMUs for n masses."""
    from arcosim.build.cache import default_folder

    built: dict[int, Path] = {}

    def build(n: int = 3) -> Path:
        if n == 3 and 3 not in built and copied_from_dist(default_folder(3)):
            built[3] = default_folder(3)
        if n not in built:
            result = subprocess.run(
                [sys.executable, "-m", "arcosim", "build", "--masses", str(n)],
                capture_output=True,
                text=True,
            )
            assert result.returncode == 0, result.stderr
            built[n] = default_folder(n)
            assert (built[n] / "ReactionTorqueObserver.fmu").is_file(), result.stdout
        return built[n]

    return build


def copied_from_dist(folder: Path) -> bool:
    """Copy ``dist/`` into ``folder`` if it holds current FMUs for n = 3 (under its lock)."""
    from arcosim.build.cache import LOCK_FILE, is_current, lock_folder

    if not (DIST / LOCK_FILE).is_file():  # never built there: no lock file to make in it
        return False
    with lock_folder(DIST):
        if not is_current(DIST, 3):
            return False
        shutil.copytree(DIST, folder, ignore=shutil.ignore_patterns(LOCK_FILE), dirs_exist_ok=True)
    return True


@pytest.fixture(scope="session")
def fmus(build_fmus: Callable[[int], Path]) -> Path:
    """The folder of the FMUs for the paper's bench (n = 3).

    Modules that want the FMUs in another shape (by component, as a pair) define a
    ``fmus`` fixture of their own, which takes precedence there.
    """
    return build_fmus(3)


@pytest.fixture(scope="session")
def plant_fmu(build_fmus: Callable[[int], Path]) -> Path:
    """The plant FMU for the paper's bench (n = 3)."""
    return build_fmus(3) / "MotorChainPlant.fmu"


@pytest.fixture(scope="session")
def venvs(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], str]:
    """``venvs(label)`` → python of a venv with fmpy for that CPython (tests/foreign_hosts.py),
    made once per session, or kept in ARCOSIM_HOST_VENVS."""
    from tests.foreign_hosts import venv_maker

    keep = os.environ.get("ARCOSIM_HOST_VENVS")
    return venv_maker(Path(keep) if keep else tmp_path_factory.mktemp("venvs"))


@pytest.fixture(scope="session")
def libcosim_python(venvs: Callable[[str], str]) -> str:
    """A venv of a CPython other than the building one with libcosimpy (from PyPI)."""
    from tests.foreign_hosts import libcosim_venv

    return libcosim_venv(venvs)


def _needs_data(item: pytest.Item) -> str | None:
    """The environment variable a ``data`` test's folder is named by, when it is unset."""
    marker = item.get_closest_marker("data")
    if marker is None or os.environ.get(marker.args[0]):
        return None
    return marker.args[0]


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Deselect the tests that read fetched files whose folder is not named (marker
    ``data``): CI has no such files and skips nothing; the summary says what to set."""
    unnamed = {item: _needs_data(item) for item in items}
    left_out = [item for item, variable in unnamed.items() if variable]
    if left_out:
        config.hook.pytest_deselected(items=left_out)
        items[:] = [item for item in items if not unnamed[item]]
        config.stash[_DATA_LEFT_OUT] = sorted({v for v in unnamed.values() if v})


_DATA_LEFT_OUT = pytest.StashKey[list[str]]()


def pytest_terminal_summary(terminalreporter, config: pytest.Config) -> None:
    """Name the variables that would run the deselected ``data`` tests."""
    variables = config.stash.get(_DATA_LEFT_OUT, [])
    if variables:
        terminalreporter.write_line(
            "deselected: tests that read fetched files; name their folder with "
            + ", ".join(f"{v}=DIR" for v in variables)
            + " (where to get them: docs/control.md, docs/identification.md)"
        )
