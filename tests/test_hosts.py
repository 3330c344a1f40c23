"""The FMUs in a host that is not Python: the ecos C++ co-simulation engine
(``ecospy`` on PyPI), run as its own process with a bare environment — no
LD_PRELOAD, no PYTHONPATH, no activated venv, only /usr/bin:/bin on PATH."""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import pytest

from arcosim.host.ecos import ecos_binary, run_ecos

pytestmark = pytest.mark.system


def ecos_executable() -> Path:
    """The ecos binary, or skip naming what is missing (.ci/run installs libtbb12)."""
    binary, why_not = ecos_binary()
    if binary is None:
        pytest.skip(why_not)
    return binary


def run_ecos_csv(fmu: Path, workdir: Path, stop: float = 0.05) -> list[dict[str, str]]:
    """Simulate ``fmu`` alone in ecos with a bare environment; return its CSV rows."""
    result = run_ecos(ecos_executable(), fmu, workdir, stop, timeout=120)
    assert result.returncode == 0, f"ecos exit {result.returncode}: {result.stderr[-2000:]}"
    (out,) = workdir.glob("*.csv")
    with out.open() as f:
        return [{k.strip(): v.strip() for k, v in row.items()} for row in csv.DictReader(f)]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
@pytest.mark.parametrize("name", ["MotorChainPlant", "ReactionTorqueObserver"])
def test_fmu_runs_in_the_ecos_cpp_engine(build_fmus, tmp_path, name) -> None:
    fmu = build_fmus(3) / f"{name}.fmu"
    rows = run_ecos_csv(fmu, tmp_path)
    assert len(rows) >= 50
    key = next(k for k in rows[0] if k.endswith("::J[3][REAL]"))
    assert float(rows[-1][key]) == pytest.approx(6.192707e-4, abs=1e-6)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only")
def test_ssp_in_ecos_matches_the_fmpy_jacobi_run(build_fmus, tmp_path) -> None:
    """source → plant → observer in ecos (its own process, bare environment) and in
    our Jacobi master: every output of every FMU within 1e-9 (measured 7e-12).
    ecos prints six decimals, so the FMUs write their outputs themselves
    (``trace_file``) at full precision."""
    import numpy as np

    from arcosim.build.ssp import BENCH, write_ssp
    from arcosim.host.ssp import run_ssp

    ecos = ecos_executable()
    traced = {
        "trace": {c: {**BENCH[c], "trace_file": str(tmp_path / f"trace_{c}.csv")} for c in BENCH}
    }
    ssp = write_ssp(tmp_path / "traced.ssp", build_fmus(3), traced, stop=1.0)
    result = run_ecos(ecos, ssp, tmp_path, stop=1.0, parameter_set="trace")
    assert result.returncode == 0, result.stderr[-2000:]
    ours = run_ssp(ssp, None, 1.0, 1e-3, extra=BENCH)
    compared = 0
    for component in BENCH:
        trace = tmp_path / f"trace_{component}.csv"
        names = trace.read_text().splitlines()[0].split(",")[1:]
        theirs = np.loadtxt(trace, delimiter=",", skiprows=1)
        rows = theirs.shape[0]  # ecos sums its time and may stop one step short
        assert rows >= 1000
        np.testing.assert_allclose(theirs[:, 0], ours.time[:rows], rtol=0, atol=1e-12)
        for j, name in enumerate(names):
            mine = ours[f"{component}.{name}"][:rows]
            scale = max(np.max(np.abs(mine)), 1e-300)
            assert np.max(np.abs(mine - theirs[:, j + 1])) <= 1e-9 * scale, f"{component}.{name}"
            compared += 1
    # 1 source + 16 plant + 38 observer outputs: 20 (w_tip_hat, alpha_tip_hat among them) and
    # the tracker's 18 for n = 3 (k, B and their σ per spring; f_c, D_m and their σ; the alarm
    # and the validity)
    assert compared == 55


def test_a_missing_system_library_skips_ecos_naming_its_package(
    build_fmus, tmp_path, monkeypatch, capsys
) -> None:
    """Where libtbb12 is missing, ``import ecospy`` raises OSError and the ecos binary
    cannot start: validate still passes, with a note naming the Debian package.
    (An ecospy stand-in that behaves so; .ci/run also runs the tests with the real
    library hidden.)"""
    import importlib

    from arcosim.cli import main

    package = tmp_path / "site" / "ecospy"
    (package / "binaries").mkdir(parents=True)
    (package / "__init__.py").write_text(
        "raise OSError('libtbb.so.12: cannot open shared object file')\n"
    )
    binary = package / "binaries" / "ecos"
    binary.write_text(
        '#!/bin/sh\necho "$0: error while loading shared libraries: libtbb.so.12: cannot '
        'open shared object file: No such file or directory" >&2\nexit 127\n'
    )
    binary.chmod(0o755)
    monkeypatch.delitem(sys.modules, "ecospy", raising=False)
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    importlib.invalidate_caches()
    found, why = ecos_binary()
    assert found is None
    assert why == (
        "ecos needs the Debian package libtbb12 (apt-get install libtbb12): "
        "libtbb.so.12 is missing or unreadable"
    )
    assert main(["validate", str(build_fmus(1) / "MotorChainPlant.fmu")]) == 0
    out = capsys.readouterr().out
    assert ": OK" in out and f"note: ecos run skipped: {why}" in out
