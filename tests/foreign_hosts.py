"""Hosts off the building machine, for the portable-host tests of every FMU.

The building Python's installation (``sys.base_prefix``) hidden under an empty tmpfs in a
private mount namespace (``unshare -m``, as root), so nothing of it can be found or
loaded; venvs of other CPythons with fmpy (and one with libcosimpy); the bare environment
a user's shell might hand a host. The session fixtures ``venvs`` and ``libcosim_python``
in tests/conftest.py are made from :func:`venv_maker` and :func:`libcosim_venv`.

Venvs are made once per session under a temporary folder (about 16 s each: venv +
``pip install --no-deps fmpy numpy lxml attrs``); set ARCOSIM_HOST_VENVS to a folder to
keep them between sessions.
"""

from __future__ import annotations

import functools
import glob
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

HIDDEN = Path(sys.base_prefix).resolve()
BARE_PATH = "/usr/bin:/bin"
FMPY_PACKAGES = ["fmpy", "numpy", "lxml", "attrs"]
#: The interpreters every fmpy host test asks for.
WANTED = ["3.9", "3.10", "3.12", "3.13", "debian"]


@functools.cache
def namespace_problem() -> str | None:
    """Why the building Python cannot be hidden here, or None."""
    if shutil.which("unshare") is None:
        return "unshare (util-linux) is not installed"
    probe = subprocess.run(
        ["unshare", "-m", "sh", "-c", f"mount -t tmpfs tmpfs {HIDDEN} && ls -A {HIDDEN}"],
        capture_output=True,
        text=True,
    )
    if probe.returncode != 0:
        return f"unshare -m with a tmpfs over {HIDDEN} is not permitted: {probe.stderr.strip()}"
    if probe.stdout.strip():
        return f"{HIDDEN} is still visible inside the namespace"
    return None


def hidden(command: list[str], env: dict[str, str], cwd: Path, timeout: float = 300):
    """Run ``command`` with the building Python's installation hidden."""
    why = namespace_problem()
    if why:
        pytest.skip(why)
    script = f'{shutil.which("mount")} -t tmpfs tmpfs "{HIDDEN}" && exec "$@"'
    return subprocess.run(
        [shutil.which("unshare"), "-m", "/bin/sh", "-c", script, "sh", *command],
        capture_output=True,
        text=True,
        env=env,
        cwd=cwd,
        timeout=timeout,
    )


def pythons() -> dict[str, str]:
    """label → interpreter: pyenv 3.9, 3.10, 3.12, 3.13 and Debian's python3."""
    found = {}
    root = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv")) / "versions"
    for minor in (9, 10, 12, 13):
        candidates = sorted(glob.glob(str(root / f"3.{minor}.*" / "bin" / f"python3.{minor}")))
        if candidates:
            found[f"3.{minor}"] = candidates[-1]
    if Path("/usr/bin/python3").is_file():
        found["debian"] = "/usr/bin/python3"
    return found


def venv_maker(root: Path) -> Callable[[str], str]:
    """``get(label)`` → python of a venv with fmpy for that interpreter, made once in ``root``."""
    made: dict[str, str] = {}

    def get(label: str) -> str:
        if label in made:
            return made[label]
        base = pythons().get(label)
        if base is None:
            pytest.skip(f"no CPython {label} on this machine")
        if Path(base).resolve().is_relative_to(HIDDEN):
            pytest.skip(f"CPython {label} is the one the FMUs were built with, hidden here")
        venv = root / f"fmpy-{label}"
        python = venv / "bin" / "python"
        if not (venv / ".ready").is_file():
            shutil.rmtree(venv, ignore_errors=True)
            result = subprocess.run([base, "-m", "venv", str(venv)], capture_output=True, text=True)
            if result.returncode != 0:
                pytest.skip(f"{base} -m venv failed: {result.stderr.strip()[-300:]}")
            result = subprocess.run(
                [str(python), "-m", "pip", "install", "-q", "--no-deps", *FMPY_PACKAGES],
                capture_output=True,
                text=True,
            )
            assert result.returncode == 0, result.stderr[-2000:]
            (venv / ".ready").touch()
        made[label] = str(python)
        return made[label]

    return get


def libcosim_venv(venvs: Callable[[str], str]) -> str:
    """A venv of a CPython other than the building one with libcosimpy (from PyPI)."""
    for label in ("3.12", "3.13", "3.10"):
        if label not in pythons() or f"3.{sys.version_info.minor}" == label:
            continue
        python = venvs(label)
        result = subprocess.run(
            [python, "-m", "pip", "install", "-q", "libcosimpy"], capture_output=True, text=True
        )
        if result.returncode == 0:
            return python
    pytest.skip("libcosimpy installs under none of CPython 3.12, 3.13, 3.10 here")


def bare_env(python: str | None = None) -> dict[str, str]:
    """What a user's shell might hand a host: HOME and a PATH without the venv."""
    path = BARE_PATH if python is None else f"{Path(python).parent}:{BARE_PATH}"
    return {"PATH": path, "HOME": str(Path.home()), "LANG": "C.UTF-8"}
