"""Shared fixtures: FMUs built once per test session from the current source.

FMUs are built in a subprocess (``python -m cosim build``), as a user would, so the
test process never imports a half-built copy; each test then loads the FMU file.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def build_fmus(tmp_path_factory: pytest.TempPathFactory) -> Callable[[int], Path]:
    """``build_fmus(n)`` → folder holding the project's FMUs for n masses."""
    root = tmp_path_factory.mktemp("fmus")
    built: dict[int, Path] = {}

    def build(n: int = 3) -> Path:
        if n not in built:
            out = root / f"n{n}"
            result = subprocess.run(
                [sys.executable, "-m", "cosim", "build", "--masses", str(n), "--out", str(out)],
                capture_output=True,
                text=True,
            )
            assert result.returncode == 0, result.stderr
            built[n] = out
        return built[n]

    return build


@pytest.fixture(scope="session")
def plant_fmu(build_fmus: Callable[[int], Path]) -> Path:
    """The plant FMU for the paper's bench (n = 3)."""
    return build_fmus(3) / "MotorChainPlant.fmu"
