"""The flexible-link FMU in the hosts the chain plant runs in, out of Python: the C host
(tests/hosts/chain_host.c, dlopen, no Python linked) and the ecos C++ engine."""

from __future__ import annotations

import subprocess
import sys
import zipfile

import numpy as np
import pytest

from arcosim.fmu.flexchain import defaults
from benchmarks.link_frequencies import run
from tests.chain_harness import compile_c_host
from tests.test_hosts import run_ecos_csv

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only"),
    pytest.mark.system,
]

#: The link's defaults with a current loop; friction, encoder and noise as built.
PARAMETERS = {"current_bandwidth": 400.0, "i_ref": 0.1}


@pytest.fixture(scope="module")
def link_fmu(build_fmus):
    return build_fmus(3) / "FlexLinkPlant.fmu"


def test_link_in_the_c_host_matches_fmpy(link_fmu, tmp_path) -> None:
    """2 s from rest (the hub breaks away from its Coulomb friction) in the C host: every
    Real output at every step equal to the fmpy run's to 1e-9 of its largest value."""
    from fmpy import read_model_description

    target = tmp_path / "link"
    with zipfile.ZipFile(link_fmu) as z:
        z.extractall(target)
    md = read_model_description(str(target))
    variables = {v.name: v for v in md.modelVariables}
    lines = [f"fmu link {target} {md.coSimulation.modelIdentifier} {md.guid}"]
    lines += [f"real link {variables[n].valueReference} {v}" for n, v in PARAMETERS.items()]
    outputs = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    lines += [f"out link {variables[n].valueReference} r" for n in outputs]
    lines.append("run 2 0.001")
    (tmp_path / "spec.txt").write_text("\n".join(lines) + "\n")
    result = subprocess.run(
        [str(compile_c_host(tmp_path)), "spec.txt", "out.txt"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    rows = [
        line.split(",")
        for line in (tmp_path / "out.txt").read_text().splitlines()
        if line[0].isdigit()
    ]
    theirs = np.array(rows, dtype=float)[1:, 1:]  # the steps' samples (row 0: t = 0)
    parameters = {k: v for k, v in PARAMETERS.items() if k != "i_ref"}
    ours = run(link_fmu, parameters, np.full(len(theirs), PARAMETERS["i_ref"]), 1e-3, outputs)
    assert theirs.shape == ours.shape
    scale = np.maximum(np.abs(ours).max(axis=0), 1e-300)
    worst = np.abs(theirs - ours).max(axis=0) / scale
    assert worst.max() <= 1e-9, dict(zip(outputs, worst, strict=True))
    assert np.ptp(ours[:, outputs.index("omega_m_true")]) > 0.5  # the hub did turn


def test_link_runs_in_the_ecos_cpp_engine(link_fmu, tmp_path) -> None:
    rows = run_ecos_csv(link_fmu, tmp_path)
    assert len(rows) >= 50
    key = next(k for k in rows[0] if k.endswith("::EI[REAL]"))
    assert float(rows[-1][key]) == pytest.approx(defaults.LINK_EI)
    tip = next(k for k in rows[0] if k.endswith("::w_tip[REAL]"))
    assert all(np.isfinite(float(row[tip])) for row in rows)
