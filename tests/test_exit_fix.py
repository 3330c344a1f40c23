"""pythonfmu 0.7's exit-time use-after-free, and the build's fix (cosim/build/exit_fix.py).

CI once failed on it: a process that had instantiated an FMU aborted at exit with
"corrupted double-linked list" (about one process in 30-50). Valgrind shows the invalid
read in every such process, so the valgrind test below catches it deterministically.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from arcosim.build.exit_fix import UNLOAD_SYMBOL, fini_functions, has_exit_bug, remove_exit_bug


def pythonfmu_binary() -> bytes:
    """The Linux binary pythonfmu copies into every FMU it builds, as shipped."""
    import pythonfmu

    path = Path(pythonfmu.__file__).parent / "resources/binaries/linux64/libpythonfmu-export.so"
    if not path.is_file():
        pytest.skip(f"pythonfmu ships no Linux binary at {path}")
    return path.read_bytes()


def fmu_binaries(fmu: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(fmu) as z:
        return {
            n: z.read(n)
            for n in z.namelist()
            if n.startswith("binaries/linux64/") and n.endswith(".so") and "arcosim" not in n
        }


def test_pythonfmu_as_shipped_has_the_exit_bug() -> None:
    """If this fails, pythonfmu changed: re-check whether the fix is still needed."""
    assert has_exit_bug(pythonfmu_binary())


def test_fix_drops_only_the_unload_destructor() -> None:
    shipped = pythonfmu_binary()
    fixed = remove_exit_bug(shipped)
    assert not has_exit_bug(fixed)
    assert fini_functions(fixed) == fini_functions(shipped)[:-1]
    assert len(fixed) == len(shipped)
    differing = [k for k, (a, b) in enumerate(zip(shipped, fixed)) if a != b]
    assert len(differing) == 1, "one byte of DT_FINI_ARRAYSZ changes (16 -> 8)"


def test_fix_is_idempotent_and_leaves_other_files_alone() -> None:
    fixed = remove_exit_bug(pythonfmu_binary())
    assert remove_exit_bug(fixed) == fixed
    assert remove_exit_bug(b"not an ELF file") == b"not an ELF file"


@pytest.mark.parametrize("name", ["ReactionTorqueObserver", "ExcitationSource"])
def test_built_fmus_carry_the_fix(build_fmus, name) -> None:
    binaries = fmu_binaries(build_fmus(3) / f"{name}.fmu")
    if not binaries:
        pytest.skip("no Linux binary in this FMU")
    for binary in binaries.values():
        assert not has_exit_bug(binary)
        assert fini_functions(binary), "the C++ runtime's own destructor stays"


@pytest.mark.system
@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
def test_no_invalid_memory_access_at_exit_under_valgrind(build_fmus, tmp_path: Path) -> None:
    """Instantiate the observer (pythonfmu) and the plant (C) a few times, step them,
    exit, and let valgrind watch the steps and the exit.

    Valgrind also reports over-reads of the dynamic loader's own strncmp while it
    resolves RUNPATHs; those are its false positives and name no FMU code, so only
    errors that pass through the FMU binary or the exit handlers count."""
    if shutil.which("valgrind") is None:
        pytest.skip("needs the Debian package valgrind (.ci/run installs it)")
    script = (
        "import sys\n"
        "from arcosim.host.instance import FmuInstance\n"
        "for k in range(3):\n"
        "    with FmuInstance(sys.argv[1], f'exit-{k}') as observer,"
        " FmuInstance(sys.argv[2], f'plant-{k}') as plant:\n"
        "        observer.initialize()\n"
        "        plant.initialize({'current_bandwidth': 300.0})\n"
        "        for j in range(20):\n"
        "            plant.set({'i_ref': 0.3 - 0.03 * j})\n"
        "            assert observer.do_step(j * 1e-3, 1e-3) == 0\n"
        "            assert plant.do_step(j * 1e-3, 1e-3) == 0\n"
        "print('done')\n"
    )
    folder = build_fmus(3)
    fmus = [str(folder / "ReactionTorqueObserver.fmu"), str(folder / "MotorChainPlant.fmu")]
    log = tmp_path / "valgrind.log"
    result = subprocess.run(
        ["valgrind", "-q", f"--log-file={log}", sys.executable, "-c", script, *fmus],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip() == "done"
    errors = re.split(r"\n==\d+== *\n", log.read_text())  # one block per error
    at_exit = [
        e
        for e in errors
        if "Invalid" in e
        and any(
            k in e
            for k in (
                "ReactionTorqueObserver_n3",
                "MotorChainPlant_n3",
                "_dl_fini",
                "exit.c",
                UNLOAD_SYMBOL,
            )
        )
    ]
    assert not at_exit, "\n".join(at_exit)[:4000]
