"""The controller FMU in the hosts the observer runs in: the closed loop (MotionControl.ssp,
controller ↔ plant) in the C host of tests/hosts (dlopen, no Python linked, a bare PATH),
the ecos C++ engine, fmpy under each other CPython and libcosim (libcosimpy), the last two
with the building Python's installation hidden (tests/foreign_hosts.py), every one
against the SSP runner's Jacobi run of the same system."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from arcosim.build.ssp import MOTION_CONTROL, motion_control_sets, write_ssp
from arcosim.host.ecos import ecos_binary, run_ecos
from arcosim.host.ssp import run_ssp
from tests.chain_harness import compile_c_host, run_chain
from tests.foreign_hosts import WANTED, bare_env, hidden

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux hosts only"),
    pytest.mark.system,
    pytest.mark.slow,
]
STOP, H = 1.5, 1e-3
SETS = motion_control_sets(3)


def _spec(fmus: dict[str, Path], folder: Path, values: dict) -> list[tuple[str, str]]:
    """Write the C host's spec.txt for the closed loop; return the recorded outputs."""
    from fmpy import read_model_description

    lines, variables = [], {}
    for component, fmu in fmus.items():
        target = folder / component
        with zipfile.ZipFile(fmu) as z:
            z.extractall(target)
        md = read_model_description(str(fmu))
        variables[component] = {v.name: v for v in md.modelVariables}
        lines.append(f"fmu {component} {target} {md.coSimulation.modelIdentifier} {md.guid}")
    kinds = {"Real": "real", "Integer": "int", "Boolean": "bool", "String": "string"}
    for component, given in values.items():
        for name, value in given.items():
            v = variables[component][name]
            lines.append(f"{kinds[v.type]} {component} {v.valueReference} {value}")
    for a, out, b, inp in MOTION_CONTROL.connections:
        va, vb = variables[a][out].valueReference, variables[b][inp].valueReference
        lines.append(f"link {a} {va} {b} {vb}")
    order = []
    for component in fmus:
        for v in variables[component].values():
            if v.causality == "output" and v.type == "Real":
                lines.append(f"out {component} {v.valueReference} r")
                order.append((component, v.name))
    lines.append(f"run {STOP} {H}")
    (folder / "spec.txt").write_text("\n".join(lines) + "\n")
    return order


def _assert_same(ours, theirs: dict[tuple[str, str], np.ndarray], rows: int) -> int:
    """Every output within 1e-9 of its largest magnitude; return how many were compared."""
    for (component, name), values in theirs.items():
        mine = ours[f"{component}.{name}"][:rows]
        scale = max(np.max(np.abs(mine)), 1e-300)
        assert np.max(np.abs(mine - values[:rows])) <= 1e-9 * scale, f"{component}.{name}"
    return len(theirs)


def test_the_closed_loop_in_a_c_host(build_fmus, tmp_path) -> None:
    folder = build_fmus(3)
    fmus = {c: folder / f"{stem}.fmu" for c, stem in MOTION_CONTROL.components}
    order = _spec(fmus, tmp_path, SETS["move"])
    binary = compile_c_host(tmp_path)
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}
    result = subprocess.run(
        [str(binary), "spec.txt", "out.txt"], capture_output=True, text=True, env=env, cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr[-3000:]
    lines = (tmp_path / "out.txt").read_text().splitlines()
    assert "status OK" in lines
    data = np.array([[float(x) for x in r.split(",")] for r in lines if not r[0].isalpha()])
    theirs = {key: data[:, j + 1] for j, key in enumerate(order)}
    ours = run_ssp(folder / "MotionControl.ssp", "move", STOP, H)
    assert _assert_same(ours, theirs, len(data)) == len(order) == 19  # 4 + 15 Real outputs
    last = ours["plant.theta[3]"]
    assert 0.5 < last[-1] < 1.05  # the move is under way or done


def test_the_closed_loop_ssp_in_ecos(build_fmus, tmp_path) -> None:
    """ecos prints six decimals, so the FMUs write their outputs themselves
    (``trace_file``) at full precision."""
    binary, why_not = ecos_binary()
    if binary is None:
        pytest.skip(why_not)
    folder = build_fmus(3)
    traced = {
        "trace": {
            c: {**SETS["move"][c], "trace_file": str(tmp_path / f"trace_{c}.csv")}
            for c in SETS["move"]
        }
    }
    ssp = write_ssp(tmp_path / "traced.ssp", folder, traced, stop=STOP, layout=MOTION_CONTROL)
    result = run_ecos(binary, ssp, tmp_path, stop=STOP, parameter_set="trace")
    assert result.returncode == 0, result.stderr[-2000:]
    ours = run_ssp(ssp, None, STOP, H, extra=SETS["move"])
    compared = 0
    for component in SETS["move"]:
        trace = tmp_path / f"trace_{component}.csv"
        names = trace.read_text().splitlines()[0].split(",")[1:]
        data = np.loadtxt(trace, delimiter=",", skiprows=1)
        rows = data.shape[0]  # ecos sums its time and may stop one step short
        assert rows >= 1000
        theirs = {(component, name): data[:, j + 1] for j, name in enumerate(names)}
        np.testing.assert_allclose(data[:, 0], ours.time[:rows], rtol=0, atol=1e-12)
        compared += _assert_same(ours, theirs, rows)
    assert compared >= 19
    print(json.dumps({"compared": compared}))


# -- fmpy under other CPythons and libcosim, the building Python hidden ------------------


def _loop_spec(folder: Path) -> dict:
    """tests/hosts/chain_run.py's SPEC of the closed loop's ``move`` set."""
    return {
        "components": {c: str(folder / f"{stem}.fmu") for c, stem in MOTION_CONTROL.components},
        "parameters": SETS["move"],
        "connections": [list(c) for c in MOTION_CONTROL.connections],
        "stop": STOP,
        "h": H,
        "shadow": None,
    }


def _assert_same_outputs(ours, produced: dict[str, dict[str, np.ndarray]], rows: int) -> int:
    """Every Real output of both FMUs over ``rows`` samples; return how many compared."""
    theirs = {
        (component, name): np.asarray(values, dtype=float)
        for component, signals in produced.items()
        for name, values in signals.items()
        if f"{component}.{name}" in ours.signals
    }
    for (component, name), values in theirs.items():
        assert len(values) >= rows, f"{component}.{name}: {len(values)} samples"
    return _assert_same(ours, theirs, rows)


@pytest.mark.parametrize("label", WANTED)
def test_the_closed_loop_in_fmpy_of_another_python(build_fmus, venvs, tmp_path, label) -> None:
    """The controller embeds the host's Python: a fresh venv of each other CPython, the
    building one hidden, runs the loop to the SSP runner's Jacobi results."""
    folder = build_fmus(3)
    python = venvs(label)
    out = run_chain(python, _loop_spec(folder), tmp_path, bare_env(python), hidden)
    assert out["environ_changed"] == [], out["environ_changed"]
    assert len(out["libpython_after"]) <= 1
    ours = run_ssp(folder / "MotionControl.ssp", "move", STOP, H)
    rows = round(STOP / H) + 1
    assert _assert_same_outputs(ours, out["outputs"], rows) == 19  # 4 + 15 Real outputs
    assert 0.5 < ours["plant.theta[3]"][-1] < 1.05


def test_the_closed_loop_in_libcosim_under_another_python(
    build_fmus, libcosim_python, tmp_path
) -> None:
    from fmpy import read_model_description

    folder = build_fmus(3)
    spec = _loop_spec(folder)
    variables = {
        c: {v.name: [v.valueReference, v.type] for v in read_model_description(p).modelVariables}
        for c, p in spec["components"].items()
    }
    traces = {c: str(tmp_path / f"trace_{c}.csv") for c in spec["components"]}
    (tmp_path / "spec.json").write_text(
        json.dumps({**spec, "variables": variables, "traces": traces})
    )
    runner = Path(__file__).parent / "hosts"
    env = {**bare_env(libcosim_python), "PYTHONPATH": str(runner)}
    command = [libcosim_python, str(runner / "libcosim_run.py"), "spec.json", "out.json"]
    result = hidden(command, env, tmp_path)
    assert result.returncode == 0, result.stderr[-3000:]
    out = json.loads((tmp_path / "out.json").read_text())
    assert out["simulated"] and out["environ_changed"] == [], out
    assert len(out["libpython_after"]) == 1
    produced, rows = {}, []
    for component, path in traces.items():
        names = Path(path).read_text().splitlines()[0].split(",")[1:]
        data = np.loadtxt(path, delimiter=",", skiprows=1)
        assert np.allclose(data[:, 0], np.arange(len(data)) * H, rtol=0, atol=1e-9)
        produced[component] = {n: data[:, j + 1] for j, n in enumerate(names)}
        rows.append(len(data))
    assert min(rows) >= round(STOP / H)
    ours = run_ssp(folder / "MotionControl.ssp", "move", STOP, H)
    assert _assert_same_outputs(ours, produced, min(rows)) == 19
