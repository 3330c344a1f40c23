"""The FMUs off the building machine: source → plant → observer in foreign hosts.

The FMUs are built once with the project's Python. Each host then runs in a private
mount namespace (``unshare -m``, as root) in which the building Python's installation
(``sys.base_prefix``) is an empty tmpfs, so nothing of it can be found or loaded:
- fmpy in a fresh venv of each pyenv CPython 3.9, 3.10, 3.12, 3.13 and of Debian's
  /usr/bin/python3 (3.11, a static interpreter with a separate libpython);
- a C host (tests/hosts/chain_host.c: dlopen, no Python linked) with only
  /usr/bin:/bin on PATH;
- the ecos C++ engine (``ecospy``) with only /usr/bin:/bin on PATH;
- libcosimpy (PyPI) under a CPython other than the building one.
Every output of every FMU must agree with the building environment's fmpy run to
1e-9 relative (of the output's largest magnitude), the host's environment must be
unchanged by loading, and at most one libpython may be mapped: the host's own.
Also: a host that imported its own ``fmukit``, ``flexchain`` and ``pythonfmu`` first
gets the FMU's results unchanged; two builds of the observer run in one process,
each with its own code.

Venvs are made once per session under a temporary folder (about 16 s each: venv +
``pip install --no-deps fmpy numpy lxml attrs``); set ARCOSIM_HOST_VENVS to a folder to
keep them between sessions.
"""

from __future__ import annotations

import glob
import json
import os
import sys
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from arcosim.build.ssp import BENCH
from tests.chain_harness import (
    TRACKER,
    chain_fmus,
    chain_spec,
    compile_c_host,
    connections_of,
    parameters_of,
    run_chain,
)
from tests.foreign_hosts import HIDDEN, WANTED, bare_env, hidden

pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux hosts only"),
    pytest.mark.system,
]

HERE = Path(__file__).parent / "hosts"
STOP, H = 1.0, 1e-3
RTOL = 1e-9


# -- the FMUs and the reference -----------------------------------------------------


@pytest.fixture(scope="session")
def fmus(build_fmus) -> dict[str, Path]:
    """The bench's FMUs, and the observer again as the chain's tracker (tracking = 1)."""
    bench = chain_fmus(build_fmus(3))
    return {**bench, TRACKER: bench["observer"]}


@pytest.fixture(scope="module")
def declared_outputs(fmus) -> int:
    """How many outputs the three FMUs declare: every one must be compared."""
    from fmpy import read_model_description

    return sum(
        v.causality == "output"
        for path in fmus.values()
        for v in read_model_description(str(path)).modelVariables
    )


@pytest.fixture(scope="session")
def reference(fmus, tmp_path_factory) -> dict[str, dict[str, np.ndarray]]:
    """The building environment's fmpy run (this interpreter, nothing hidden)."""
    out = run_chain(
        sys.executable, chain_spec(fmus, STOP, H), tmp_path_factory.mktemp("ref"), dict(os.environ)
    )
    return {c: {k: np.array(v) for k, v in o.items()} for c, o in out["outputs"].items()}


def assert_matches(reference, outputs, rows: int | None = None) -> int:
    """Every output within RTOL of its largest magnitude; returns how many compared."""
    compared, worst = 0, 0.0
    for component, signals in reference.items():
        for name, ref in signals.items():
            got = np.asarray(outputs[component][name])
            n = rows or len(ref)
            assert len(got) >= n, f"{component}.{name}: {len(got)} samples, {n} expected"
            scale = max(float(np.max(np.abs(ref[:n]))), 1e-300)
            error = float(np.max(np.abs(got[:n] - ref[:n])))
            assert error <= RTOL * scale, (
                f"{component}.{name}: error {error:.3g} (scale {scale:.3g})"
            )
            compared += 1
            worst = max(worst, error / scale)
    print(f"worst relative error over {compared} outputs: {worst:.3g}")  # shown with -s
    return compared


# -- fmpy hosts ---------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("label", WANTED)
def test_chain_in_fmpy_of_another_python(
    fmus, reference, venvs, tmp_path, label, declared_outputs
) -> None:
    python = venvs(label)
    out = run_chain(python, chain_spec(fmus, STOP, H), tmp_path, bare_env(python), hidden)
    assert out["environ_changed"] == [], out["environ_changed"]
    # the host's own libpython (none for Debian's static python3), never a second one
    assert out["libpython_after"] == out["libpython_before"], out["libpython_after"]
    assert len(out["libpython_after"]) <= 1
    assert not any(str(HIDDEN) in p for p in out["libpython_after"])
    assert assert_matches(reference, out["outputs"]) == declared_outputs


def test_user_pythonhome_for_another_python_changes_nothing(
    c_host, fmus, reference, tmp_path, declared_outputs
):
    """PYTHONHOME and PYTHONPATH meant for another Python in a C host's environment: the
    FMU's interpreter ignores the environment and takes the home of its libpython."""
    other = sorted(glob.glob(str(Path.home() / ".pyenv/versions/3.13.*")))
    if not other:
        pytest.skip("no pyenv CPython 3.13 to point PYTHONHOME at")
    env = {**bare_env(), "PYTHONHOME": other[-1], "PYTHONPATH": f"{other[-1]}/lib/python3.13"}
    out = run_c_host(c_host, fmus, tmp_path, env)
    assert "environ same" in out["tail"]
    assert assert_matches(reference, out["outputs"]) == declared_outputs


# -- the C host and ecos ----------------------------------------------------------------


@pytest.fixture(scope="session")
def c_host(tmp_path_factory) -> Callable[[], Path]:
    """``c_host()`` → tests/hosts/chain_host.c compiled, once per session (on first use)."""
    compiled: list[Path] = []

    def get() -> Path:
        if compiled:
            return compiled[0]
        compiled.append(compile_c_host(tmp_path_factory.mktemp("c_host")))
        return compiled[0]

    return get


def host_spec(fmus: dict[str, Path], folder: Path) -> str:
    """The C host's SPEC: unzip each FMU, parameters, links and outputs by value reference."""
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
    for component in fmus:
        for name, value in parameters_of(component).items():
            v = variables[component][name]
            lines.append(f"{kinds[v.type]} {component} {v.valueReference} {value}")
    for a, out, b, inp in (c for c in connections_of(fmus) if c[0] in fmus and c[2] in fmus):
        lines.append(
            f"link {a} {variables[a][out].valueReference} {b} {variables[b][inp].valueReference}"
        )
    order = []
    for component in fmus:
        outs = [v for v in variables[component].values() if v.causality == "output"]
        letters = {"Real": "r", "Boolean": "b", "Integer": "i"}
        for v in sorted(outs, key=lambda v: list(letters).index(v.type)):
            lines.append(f"out {component} {v.valueReference} {letters[v.type]}")
            order.append((component, v.name))
    lines.append(f"run {STOP} {H}")
    (folder / "spec.txt").write_text("\n".join(lines) + "\n")
    return json.dumps(order)


def run_c_host(c_host, fmus, tmp_path: Path, env: dict[str, str]) -> dict:
    binary = c_host()
    order = json.loads(host_spec(fmus, tmp_path))
    result = hidden([str(binary), "spec.txt", "out.txt"], env, tmp_path)
    assert result.returncode == 0, result.stderr[-3000:]
    rows, tail = [], []
    for line in (tmp_path / "out.txt").read_text().splitlines():
        (tail if line[0].isalpha() else rows).append(line)
    data = np.array([[float(x) for x in r.split(",")] for r in rows])
    outputs: dict[str, dict[str, np.ndarray]] = {c: {} for c in fmus}
    for j, (component, name) in enumerate(order):
        outputs[component][name] = data[:, j + 1]
    return {"outputs": outputs, "tail": tail, "stderr": result.stderr}


def test_chain_in_a_c_host_with_a_bare_path(
    c_host, fmus, reference, tmp_path, declared_outputs
) -> None:
    out = run_c_host(c_host, fmus, tmp_path, bare_env())
    assert "environ same" in out["tail"], out["tail"]
    libpythons = [t for t in out["tail"] if t.startswith("libpython ")]
    assert len(libpythons) == 1 and str(HIDDEN) not in libpythons[0], libpythons
    assert "status OK" in out["tail"]
    assert assert_matches(reference, out["outputs"]) == declared_outputs


def test_no_python_found_fails_instantiation_cleanly(c_host, fmus, tmp_path) -> None:
    """Nothing on PATH, an ARCOSIM_LIBPYTHON that does not exist: fmi2Instantiate logs
    what it tried and returns NULL; the host goes on (exit 5, not a crash)."""
    binary = c_host()
    host_spec({"source": fmus["source"]}, tmp_path)
    env = {"PATH": "/nonexistent", "ARCOSIM_LIBPYTHON": "/nonexistent/libpython3.12.so.1.0"}
    result = hidden([str(binary), "spec.txt", "out.txt"], env, tmp_path)
    assert result.returncode == 5, result.stderr
    assert "ARCOSIM_LIBPYTHON=/nonexistent/libpython3.12.so.1.0: no such file" in result.stderr
    assert "set ARCOSIM_LIBPYTHON" in result.stderr


def test_arcosim_libpython_chooses_the_python(
    c_host, fmus, reference, tmp_path, declared_outputs
) -> None:
    chosen = [  # the first of these that is not the building CPython (hidden here)
        found[-1]
        for v in ("3.12", "3.13", "3.10")
        if (
            found := sorted(
                glob.glob(str(Path.home() / f".pyenv/versions/{v}.*/lib/libpython{v}.so.1.0"))
            )
        )
        and not Path(found[-1]).resolve().is_relative_to(HIDDEN)
    ][:1]
    if not chosen:
        pytest.skip(
            "no pyenv CPython 3.12, 3.13 or 3.10 with a shared libpython but the building one"
        )
    out = run_c_host(c_host, fmus, tmp_path, {**bare_env(), "ARCOSIM_LIBPYTHON": chosen[-1]})
    libpythons = [t.split(" ", 1)[1] for t in out["tail"] if t.startswith("libpython ")]
    assert libpythons == [str(Path(chosen[-1]).resolve())]
    assert assert_matches(reference, out["outputs"]) == declared_outputs


def test_a_libpython_the_host_loaded_privately_is_the_one_used(
    c_host, fmus, reference, tmp_path, declared_outputs
):
    """The host dlopen()ed a libpython with RTLD_LOCAL and did not start it; a Debian
    Python is on PATH. The FMU promotes and starts the host's library, maps no other."""
    chosen = sorted(glob.glob(str(Path.home() / ".pyenv/versions/3.13.*/lib/libpython3.13.so.1.0")))
    if not chosen:
        pytest.skip("no pyenv CPython 3.13 with a shared libpython")
    out = run_c_host(
        c_host, fmus, tmp_path, {**bare_env(), "CHAIN_HOST_LOCAL_LIBPYTHON": chosen[-1]}
    )
    libpythons = [t.split(" ", 1)[1] for t in out["tail"] if t.startswith("libpython ")]
    assert libpythons == [str(Path(chosen[-1]).resolve())]
    assert "environ same" in out["tail"]
    assert assert_matches(reference, out["outputs"]) == declared_outputs


@pytest.mark.slow
def test_chain_in_ecos_with_a_bare_path(fmus, reference, tmp_path, declared_outputs) -> None:
    from arcosim.build.ssp import write_ssp
    from arcosim.host.ecos import ecos_binary

    ecos, why = ecos_binary()
    if ecos is None:
        pytest.skip(why)
    folder = next(iter(fmus.values())).parent
    # the bench, and the bench with its observer tracking the chain (the tracker's run)
    sets = {
        "trace": {c: BENCH[c] for c in BENCH},
        "tracking": {c: parameters_of(TRACKER) if c == "observer" else BENCH[c] for c in BENCH},
    }
    traced = {
        name: {c: {**values[c], "trace_file": str(tmp_path / f"{name}_{c}.csv")} for c in values}
        for name, values in sets.items()
    }
    ssp = write_ssp(tmp_path / "traced.ssp", folder, traced, stop=STOP)
    produced = {}
    for name in sets:
        command = [
            str(ecos),
            "simulate",
            "--path",
            str(ssp),
            "--stopTime",
            repr(STOP),
            "--stepSize",
            repr(H),
            "--noParallel",
            "--parameterSet",
            name,
        ]
        result = hidden(command, bare_env(), tmp_path)
        assert result.returncode == 0, result.stderr[-3000:]
        for component in BENCH if name == "trace" else ["observer"]:
            trace = tmp_path / f"{name}_{component}.csv"
            names = trace.read_text().splitlines()[0].split(",")[1:]
            data = np.loadtxt(trace, delimiter=",", skiprows=1)
            as_component = component if name == "trace" else TRACKER
            produced[as_component] = {n: data[:, j + 1] for j, n in enumerate(names)}
    rows = min(len(v) for o in produced.values() for v in o.values())
    assert rows >= 1000  # ecos sums its time and may stop one step short
    ref = {c: {n: reference[c][n] for n in produced[c]} for c in produced}
    assert assert_matches(ref, produced, rows) == declared_outputs


# -- libcosimpy ---------------------------------------------------------------------


@pytest.mark.slow
def test_chain_in_libcosim_under_another_python(
    fmus, reference, libcosim_python, tmp_path, declared_outputs
):
    from fmpy import read_model_description

    variables = {
        c: {
            v.name: [v.valueReference, v.type]
            for v in read_model_description(str(p)).modelVariables
        }
        for c, p in fmus.items()
    }
    traces = {c: str(tmp_path / f"trace_{c}.csv") for c in fmus}
    spec_ = {**chain_spec(fmus, STOP, H), "variables": variables, "traces": traces}
    (tmp_path / "spec.json").write_text(json.dumps(spec_))
    env = {**bare_env(libcosim_python), "PYTHONPATH": str(HERE)}
    command = [libcosim_python, str(HERE / "libcosim_run.py"), "spec.json", "out.json"]
    result = hidden(command, env, tmp_path)
    assert result.returncode == 0, result.stderr[-3000:]
    out = json.loads((tmp_path / "out.json").read_text())
    assert out["simulated"]
    assert out["environ_changed"] == [], out["environ_changed"]
    assert out["libpython_after"] == out["libpython_before"] and len(out["libpython_after"]) == 1
    produced = {}
    for component, path in traces.items():
        names = Path(path).read_text().splitlines()[0].split(",")[1:]
        data = np.loadtxt(path, delimiter=",", skiprows=1)
        assert np.allclose(data[:, 0], np.arange(len(data)) * H, rtol=0, atol=1e-9)
        produced[component] = {n: data[:, j + 1] for j, n in enumerate(names)}
    rows = min(len(v) for o in produced.values() for v in o.values())
    assert rows >= round(STOP / H)
    ref = {c: {n: reference[c][n] for n in produced[c]} for c in produced}
    assert assert_matches(ref, produced, rows) == declared_outputs
