"""Teardown in any order: no call into a Python FMU crashes the host once the
host's Python has finalized, or while it finalizes; calls from other threads work
while it lives.

OMSimulator's Python API frees its instances from a C++ destructor at process exit,
after its embedded Python has finalized; before the fix, fmi2Terminate went through
the trampoline into pythonfmu, which took the GIL of a dead interpreter (SIGSEGV).
tests/hosts/teardown_host.c does what such a host does: start a libpython, load an FMU
with dlopen, instantiate, step, Py_FinalizeEx, then step, terminate and free.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

HERE = Path(__file__).parent / "hosts"
PYTHON_FMUS = ["ReactionTorqueObserver", "ExcitationSource"]

#: C hosts compiled and run in subprocesses (the system tier).
pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries"),
    pytest.mark.system,
]


def _libpythons() -> dict[str, tuple[Path, Path]]:
    """Shared libpythons to embed, by version: {"3.X": (library, home)}; this
    interpreter's first, then pyenv's CPython 3.9 ... 3.13 where installed."""
    found: dict[str, tuple[Path, Path]] = {}
    library = Path(sysconfig.get_config_var("LIBDIR") or "") / (
        sysconfig.get_config_var("INSTSONAME") or ""
    )
    if sysconfig.get_config_var("Py_ENABLE_SHARED") and library.is_file():
        found[f"{sys.version_info[0]}.{sys.version_info[1]}"] = (library, Path(sys.base_prefix))
    elif Path(f"/usr/lib/x86_64-linux-gnu/{library.name}").is_file():  # Debian's static python
        found[f"{sys.version_info[0]}.{sys.version_info[1]}"] = (
            Path(f"/usr/lib/x86_64-linux-gnu/{library.name}"),
            Path("/usr"),
        )
    versions = Path.home() / ".pyenv" / "versions"
    for minor in range(9, 14):
        for home in sorted(versions.glob(f"3.{minor}.*")) if versions.is_dir() else []:
            lib = home / "lib" / f"libpython3.{minor}.so.1.0"
            if lib.is_file() and f"3.{minor}" not in found:
                found[f"3.{minor}"] = (lib, home)
    return found


LIBPYTHONS = _libpythons()
CURRENT = f"{sys.version_info[0]}.{sys.version_info[1]}"


@pytest.fixture(scope="module")
def teardown_host(tmp_path_factory) -> Path:
    from arcosim.build.cplant import compiler, fmi_headers

    binary = tmp_path_factory.mktemp("teardown_host") / "teardown_host"
    command = [
        compiler(),
        "-std=c99",
        "-pedantic",
        "-O1",
        "-Wall",
        "-Wextra",
        f"-I{fmi_headers()}",
        str(HERE / "teardown_host.c"),
        "-o",
        str(binary),
        "-ldl",
        "-lpthread",
    ]
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode == 0 and not result.stderr.strip(), result.stderr
    return binary


@pytest.fixture(scope="module")
def unzipped(fmus, tmp_path_factory) -> dict[str, tuple[Path, str, str]]:
    """Each Python FMU unzipped: {name: (folder, model identifier, GUID)}."""
    from fmpy import read_model_description

    out = {}
    for name in PYTHON_FMUS:
        folder = tmp_path_factory.mktemp(name)
        with zipfile.ZipFile(fmus / f"{name}.fmu") as z:
            z.extractall(folder)
        md = read_model_description(str(folder))
        out[name] = (folder, md.coSimulation.modelIdentifier, md.guid)
    return out


def _run(host: Path, version: str, fmu: tuple[Path, str, str], mode: str, prefix=()):
    library, home = LIBPYTHONS[version]
    folder, identifier, guid = fmu
    env = {"PATH": "/usr/bin:/bin", "PYTHONHOME": str(home)}
    return subprocess.run(
        [*prefix, str(host), str(library), str(folder), identifier, guid, mode],
        capture_output=True,
        text=True,
        env=env,
        timeout=900,
    )


@pytest.mark.parametrize("name", PYTHON_FMUS)
@pytest.mark.parametrize("version", sorted(LIBPYTHONS) or ["none"])
def test_calls_after_the_host_finalized_python_return_without_crashing(
    teardown_host, unzipped, version, name
) -> None:
    """Step, read, terminate, free a state, free the instance and instantiate again after
    Py_FinalizeEx: each answers (fmi2Error, fmi2OK for terminate, NULL for the new
    instance) and says why through the host's (C) logger; the process exits 0."""
    if version == "none":
        pytest.skip("no shared libpython 3.9 ... 3.13 found (pyenv or this interpreter's)")
    result = _run(teardown_host, version, unzipped[name], "finalize-first")
    assert result.returncode == 0, (result.returncode, result.stdout[-3000:], result.stderr)
    assert "FAILED" not in result.stdout and result.stdout.rstrip().endswith("done")
    said = [line for line in result.stdout.splitlines() if line.startswith("log ")]
    assert len(said) >= 5 and all("has finalized or is finalizing" in s for s in said), said


@pytest.mark.parametrize("name", PYTHON_FMUS)
@pytest.mark.slow
def test_no_invalid_access_after_the_host_finalized_python_under_valgrind(
    teardown_host, unzipped, name, tmp_path
) -> None:
    if shutil.which("valgrind") is None:
        pytest.skip("needs the Debian package valgrind (.ci/run installs it)")
    if CURRENT not in LIBPYTHONS:
        pytest.skip(f"no shared libpython {CURRENT} to embed")
    log = tmp_path / "valgrind.log"
    result = _run(
        teardown_host,
        CURRENT,
        unzipped[name],
        "finalize-first",
        prefix=("valgrind", "-q", f"--log-file={log}"),
    )
    assert result.returncode == 0, (result.returncode, result.stdout[-3000:], result.stderr)
    assert result.stdout.rstrip().endswith("done")
    errors = re.findall(r"Invalid (?:read|write)[^\n]*", log.read_text())
    assert not errors, log.read_text()[:4000]


@pytest.mark.parametrize("name", PYTHON_FMUS)
def test_steps_from_a_second_thread_while_python_lives(teardown_host, unzipped, name) -> None:
    """The host releases the GIL; 50 steps on a worker thread, 50 on the main one."""
    if CURRENT not in LIBPYTHONS:
        pytest.skip(f"no shared libpython {CURRENT} to embed")
    result = _run(teardown_host, CURRENT, unzipped[name], "thread")
    assert result.returncode == 0, (result.returncode, result.stdout[-3000:], result.stderr)
    assert "FAILED" not in result.stdout and result.stdout.rstrip().endswith("done")
    assert "50 steps on a second thread" in result.stdout


FINALIZING = """
import ctypes, os, sys
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave

path = sys.argv[1]
folder = extract(path)
md = read_model_description(folder)
slave = FMU2Slave(guid=md.guid, unzipDirectory=folder,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="late")
slave.instantiate()
slave.setupExperiment(startTime=0.0)
slave.enterInitializationMode()
slave.exitInitializationMode()
slave.doStep(0.0, 1e-3)


class Late:
    # runs when the finalizing interpreter clears this module: raw ctypes, no fmpy
    def __init__(self, dll, component):
        self.terminate, self.free = dll.fmi2Terminate, dll.fmi2FreeInstance
        self.component = component
        self.terminate.restype = ctypes.c_int
        self.terminate.argtypes = self.free.argtypes = [ctypes.c_void_p]
        self.write = os.write

    def __del__(self):
        status = self.terminate(self.component)
        self.free(self.component)
        self.write(1, b"terminate %d\\n" % status)


late = Late(slave.dll, slave.component)
print("stepped", flush=True)
"""


@pytest.mark.parametrize("name", PYTHON_FMUS)
def test_calls_while_python_finalizes_return_without_touching_it(fmus, name, tmp_path) -> None:
    """An object freed by the finalizing interpreter terminates and frees its instance:
    the trampoline sees Python finalizing and answers fmi2OK without calling it."""
    script = tmp_path / "late.py"
    script.write_text(FINALIZING)
    result = subprocess.run(
        [sys.executable, str(script), str(fmus / f"{name}.fmu")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, (result.returncode, result.stdout, result.stderr[-3000:])
    assert result.stdout.split() == ["stepped", "terminate", "0"], result.stdout
