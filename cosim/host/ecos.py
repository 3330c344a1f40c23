"""The ecos C++ co-simulation engine (from the ``ecospy`` wheel) as a separate process.

Used to prove that the FMUs and the SSP run in a host that is not Python: ecos is
started with a bare environment (only ``/usr/bin:/bin`` on PATH, no PYTHONPATH, no
venv), as a user's C++ tool would start.
"""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
from pathlib import Path

from arcosim.fmu.flexchain.defaults import STEP

#: Shared libraries ecos needs beyond a base system, and the Debian package of each.
SYSTEM_PACKAGES = {"libtbb.so.12": "libtbb12"}


def ecos_binary() -> tuple[Path | None, str | None]:
    """``(path, None)`` if ecos can run here, else ``(None, why not)``.

    The ``ecospy`` package is located without importing it (its import loads a
    library that needs ``libtbb12``, and fails with ``OSError`` where that is missing);
    then ``ecos --version`` is run with the bare environment of :func:`run_ecos`. A
    missing or unreadable shared library is named with its Debian package.
    """
    try:
        spec = importlib.util.find_spec("ecospy")
    except (ImportError, ValueError):
        spec = None
    if spec is None or not spec.submodule_search_locations:
        return None, "ecospy is not installed (pip install ecospy)"
    binary = Path(next(iter(spec.submodule_search_locations))) / "binaries" / "ecos"
    if not binary.is_file():
        return None, f"ecospy has no ecos binary for this platform ({binary})"
    try:
        if not os.access(binary, os.X_OK):
            binary.chmod(0o755)  # the wheel ships it without the execute bit
        probe = subprocess.run(
            [str(binary), "--version"],
            capture_output=True,
            text=True,
            timeout=60,
            env={"PATH": "/usr/bin:/bin"},
        )
    except (OSError, subprocess.SubprocessError) as error:
        return None, f"ecos cannot be started ({error})"
    if probe.returncode != 0:
        said = " ".join((probe.stderr or probe.stdout).split())
        missing = re.search(r"error while loading shared libraries: ([^:]+):", said)
        if missing:
            library = Path(missing.group(1)).name
            package = SYSTEM_PACKAGES.get(library)
            need = (
                f"the Debian package {package} (apt-get install {package})" if package else library
            )
            return None, f"ecos needs {need}: {library} is missing or unreadable"
        return None, f"ecos --version failed with exit {probe.returncode}: {said[:200]}"
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
    """``ecos simulate`` of an FMU or SSP in ``workdir`` with a bare environment.

    Parameters
    ----------
    binary : Path
        The ecos executable (:func:`ecos_binary`).
    path : Path
        The ``.fmu`` or ``.ssp`` to run.
    workdir : Path
        Where ecos runs and writes its CSV (also its ``HOME``).
    stop : float
        Stop time (s).
    step : float
        Communication step (s).
    parameter_set : str, optional
        The SSP's parameter set to apply.
    timeout : float
        Longest the run may take (s).

    Returns
    -------
    subprocess.CompletedProcess
        Its exit status and text output.
    """
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
