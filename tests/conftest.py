"""Shared fixtures: FMUs built once per test session from the current source.

The session gets a cache of its own (``ARCOSIM_CACHE``, inherited by every command a
test starts), so no test reads or writes the user's ``~/.cache/arcosim``. FMUs are
built in a subprocess (``python -m arcosim build``), as a user would, so the test
process never imports a half-built copy; each test then loads the FMU file.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest


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
