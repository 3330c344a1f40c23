"""The ``arcosim`` command line as a user meets it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from cosim import __version__
from cosim.cli import main


def arcosim(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "cosim", *args], capture_output=True, text=True, cwd=cwd
    )


def test_version_is_the_package_version() -> None:
    result = arcosim("--version")
    assert result.returncode == 0
    assert result.stdout.strip() == f"arcosim {__version__}"
    assert __version__ != "0.0.0+unknown"


def test_build_refuses_an_unsupported_number_of_masses(capsys) -> None:
    assert main(["build", "--masses", "0"]) == 2
    err = capsys.readouterr().err
    assert "--masses 0" in err and "1 to 20" in err
    assert "Traceback" not in err


def test_no_command_prints_help(capsys) -> None:
    assert main([]) == 2
    assert "build" in capsys.readouterr().out


def test_build_writes_into_dist_by_default_and_demo_runs(tmp_path: Path) -> None:
    result = arcosim("demo", "--out", "report", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "dist" / "MotorChainPlant.fmu").is_file()
    assert (tmp_path / "report" / "plant_demo.png").stat().st_size > 10_000
    assert "peak spring-1 twist" in result.stdout
    result = arcosim("build", "--masses", "2", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "dist" / "n2" / "MotorChainPlant.fmu").is_file()
