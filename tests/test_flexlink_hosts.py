"""The flexible-link FMU in every host the chain plant runs in (tests/test_portable_hosts.py):
the C host (tests/hosts/chain_host.c, dlopen, no Python linked), the ecos C++ engine, fmpy
under each other CPython and libcosim (libcosimpy), the last two with the building
Python's installation hidden (tests/foreign_hosts.py). Every Real output at every step
must equal the building environment's fmpy run to 1e-9 of its largest value."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from arcosim.fmu.flexchain import defaults
from benchmarks.link_frequencies import run
from tests.chain_harness import compile_c_host, run_chain
from tests.foreign_hosts import WANTED, bare_env, hidden
from tests.test_hosts import run_ecos_csv

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries only"),
    pytest.mark.system,
]

#: The link's defaults with a current loop; friction, encoder and noise as built.
PARAMETERS = {"current_bandwidth": 400.0, "i_ref": 0.1}
STOP, H = 2.0, 1e-3
RTOL = 1e-9
RUNNER = Path(__file__).parent / "hosts"


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


# -- fmpy under other CPythons and libcosim, the building Python hidden ------------------


def link_spec(link_fmu) -> dict:
    """tests/hosts/chain_run.py's SPEC for the link alone: 2 s of 0.1 A from rest."""
    return {
        "components": {"link": str(link_fmu)},
        "parameters": {"link": PARAMETERS},
        "connections": [],
        "stop": STOP,
        "h": H,
        "shadow": None,
    }


@pytest.fixture(scope="module")
def link_reference(link_fmu, tmp_path_factory) -> dict[str, np.ndarray]:
    """The building environment's fmpy run of :func:`link_spec` (nothing hidden)."""
    out = run_chain(
        sys.executable, link_spec(link_fmu), tmp_path_factory.mktemp("ref"), dict(os.environ)
    )
    reference = {k: np.array(v) for k, v in out["outputs"]["link"].items()}
    assert np.ptp(reference["omega_m_true"]) > 0.5  # the hub did turn
    return reference


def assert_link_matches(reference: dict[str, np.ndarray], outputs: dict, rows: int) -> None:
    """Every output in ``reference``, at each of its first ``rows`` samples, within RTOL."""
    assert set(outputs) >= set(reference), sorted(set(reference) - set(outputs))
    worst = {}
    for name, ref in reference.items():
        got = np.asarray(outputs[name], dtype=float)[:rows]
        assert len(got) == rows, f"{name}: {len(got)} samples, {rows} expected"
        scale = max(float(np.max(np.abs(ref[:rows]))), 1e-300)
        worst[name] = float(np.max(np.abs(got - ref[:rows]))) / scale
    assert max(worst.values()) <= RTOL, worst
    assert len(reference) >= 10  # the angles, speeds, tip, reaction torque, nodes


@pytest.mark.slow
@pytest.mark.parametrize("label", WANTED)
def test_link_in_fmpy_of_another_python(link_fmu, link_reference, venvs, tmp_path, label):
    python = venvs(label)
    out = run_chain(python, link_spec(link_fmu), tmp_path, bare_env(python), hidden)
    assert out["environ_changed"] == [], out["environ_changed"]
    assert_link_matches(link_reference, out["outputs"]["link"], round(STOP / H) + 1)


@pytest.mark.slow
def test_link_in_libcosim_under_another_python(link_fmu, link_reference, libcosim_python, tmp_path):
    from fmpy import read_model_description

    md = read_model_description(str(link_fmu))
    variables = {"link": {v.name: [v.valueReference, v.type] for v in md.modelVariables}}
    trace = tmp_path / "trace_link.csv"
    spec = {**link_spec(link_fmu), "variables": variables, "traces": {"link": str(trace)}}
    (tmp_path / "spec.json").write_text(json.dumps(spec))
    env = {**bare_env(libcosim_python), "PYTHONPATH": str(RUNNER)}
    command = [libcosim_python, str(RUNNER / "libcosim_run.py"), "spec.json", "out.json"]
    result = hidden(command, env, tmp_path)
    assert result.returncode == 0, result.stderr[-3000:]
    out = json.loads((tmp_path / "out.json").read_text())
    assert out["simulated"] and out["environ_changed"] == [], out
    names = trace.read_text().splitlines()[0].split(",")[1:]
    data = np.loadtxt(trace, delimiter=",", skiprows=1)
    assert np.allclose(data[:, 0], np.arange(len(data)) * H, rtol=0, atol=1e-9)
    rows = len(data)
    assert rows >= round(STOP / H)
    produced = {n: data[:, j + 1] for j, n in enumerate(names)}
    real_outputs = {
        v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"
    }
    assert set(produced) >= real_outputs, sorted(real_outputs - set(produced))
    assert_link_matches({n: link_reference[n] for n in real_outputs}, produced, rows)
