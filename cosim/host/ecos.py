"""The ecos C++ co-simulation engine (from the ``ecospy`` wheel) as a separate process.

Used to prove that the FMUs and the SSP run in a host that is not Python: ecos is
started with a bare environment (only ``/usr/bin:/bin`` on PATH, no PYTHONPATH, no
venv), as a user's C++ tool would start.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from arcosim.fmu.flexchain.defaults import STEP


def ecos_binary() -> tuple[Path | None, str | None]:
    """``(path, None)`` if ecos can run here, else ``(None, why not)``."""
    try:
        import ecospy
    except ImportError:
        return None, "ecospy is not installed (pip install ecospy)"
    binary = Path(ecospy.__file__).parent / "binaries" / "ecos"
    if not binary.is_file():
        return None, f"ecospy has no ecos binary for this platform ({binary})"
    libraries = subprocess.run(["ldd", str(binary)], capture_output=True, text=True).stdout
    if "libtbb.so.12 => not found" in libraries:
        return None, "ecos needs the Debian package libtbb12 (apt-get install libtbb12)"
    binary.chmod(0o755)
    return binary, None


def run_ecos(
    binary: Path,
    path: Path,
    workdir: Path,
    stop: float,
    step: float = STEP,
    parameter_set: str | None = None,
    timeout: float = 300.0,
) -> subprocess.CompletedProcess:
    """``ecos simulate`` of an FMU or SSP in ``workdir`` with a bare environment."""
    command = [
        str(binary),
        "simulate",
        "--path",
        str(Path(path).resolve()),
        "--stopTime",
        repr(float(stop)),
        "--stepSize",
        repr(float(step)),
        "--noParallel",
    ]
    if parameter_set:
        command += ["--parameterSet", parameter_set]
    return subprocess.run(
        command,
        capture_output=True,
        text=True,
        cwd=workdir,
        timeout=timeout,
        env={"PATH": "/usr/bin:/bin", "HOME": str(workdir)},
    )
