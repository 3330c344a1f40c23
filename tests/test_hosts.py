"""The FMUs in a host that is not Python: the ecos C++ co-simulation engine
(``ecospy`` on PyPI), run as its own process with a bare environment — no
LD_PRELOAD, no PYTHONPATH, no activated venv, only /usr/bin:/bin on PATH."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from cosim.native_loader import LOADER


def ecos_executable() -> Path:
    """The ecos binary shipped in the ecospy wheel, or skip with the reason."""
    try:
        import ecospy
    except ImportError:
        pytest.skip("ecospy is not installed (pip install ecospy)")
    binary = Path(ecospy.__file__).parent / "binaries" / "ecos"
    if not binary.is_file():
        pytest.skip(f"ecospy has no Linux ecos binary ({binary})")
    missing = subprocess.run(["ldd", str(binary)], capture_output=True, text=True).stdout
    if "libtbb.so.12 => not found" in missing:
        pytest.skip(
            "ecos needs the Debian package libtbb12 (apt-get install libtbb12); .ci/run installs it"
        )
    binary.chmod(0o755)
    return binary


def run_ecos(fmu: Path, workdir: Path, stop: float = 0.05) -> list[dict[str, str]]:
    """Simulate ``fmu`` alone in ecos with a bare environment; return its CSV rows."""
    result = subprocess.run(
        [
            str(ecos_executable()),
            "simulate",
            "--path",
            str(fmu),
            "--stopTime",
            str(stop),
            "--stepSize",
            "0.001",
            "--noParallel",
        ],
        capture_output=True,
        text=True,
        cwd=workdir,
        env={"PATH": "/usr/bin:/bin", "HOME": "/tmp"},
        timeout=120,
    )
    assert result.returncode == 0, f"ecos exit {result.returncode}: {result.stderr[-2000:]}"
    (out,) = workdir.glob("*.csv")
    with out.open() as f:
        return [{k.strip(): v.strip() for k, v in row.items()} for row in csv.DictReader(f)]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
@pytest.mark.parametrize("name", ["MotorChainPlant", "ReactionTorqueObserver"])
def test_fmu_runs_in_the_ecos_cpp_engine(build_fmus, tmp_path, name) -> None:
    fmu = build_fmus(3) / f"{name}.fmu"
    rows = run_ecos(fmu, tmp_path)
    assert len(rows) >= 50
    key = next(k for k in rows[0] if k.endswith("::J[3][REAL]"))
    assert float(rows[-1][key]) == pytest.approx(6.192707e-4, abs=1e-6)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
def test_fmu_binary_carries_the_python_loader(build_fmus, tmp_path) -> None:
    import zipfile

    with zipfile.ZipFile(build_fmus(3) / "MotorChainPlant.fmu") as z:
        names = z.namelist()
        z.extract("binaries/linux64/MotorChainPlant_n3.so", tmp_path)
    assert f"binaries/linux64/{LOADER}" in names
    if shutil.which("readelf"):
        dynamic = subprocess.run(
            ["readelf", "-d", str(tmp_path / "binaries/linux64/MotorChainPlant_n3.so")],
            capture_output=True,
            text=True,
        ).stdout
        assert LOADER in dynamic and "$ORIGIN" in dynamic
