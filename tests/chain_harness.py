"""Source → plant → observer run by tests/hosts/chain_run.py in a process of its own:
the FMUs by component, the run's SPEC, and the run (tests/test_fmu_isolation.py,
tests/test_portable_hosts.py)."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Callable
from pathlib import Path

from arcosim.build.ssp import BENCH, CONNECTIONS

RUNNER = Path(__file__).parent / "hosts" / "chain_run.py"
C_HOST = Path(__file__).parent / "hosts" / "chain_host.c"
COMPONENTS = {
    "source": "ExcitationSource",
    "plant": "MotorChainPlant",
    "observer": "ReactionTorqueObserver",
}


#: A second observer that tracks the chain (``tracking = 1``), fed as the observer is: the
#: hosts run the tracker beside the bench's observer when ``fmus`` names it.
TRACKER = "tracker"
TRACKER_PARAMETERS = {**BENCH["observer"], "tracking": 1}


def parameters_of(component: str) -> dict:
    """A component's parameters: the bench's, the tracker's for :data:`TRACKER`."""
    return TRACKER_PARAMETERS if component == TRACKER else BENCH[component.rstrip("2")]


def connections_of(fmus: dict[str, Path]) -> list[list[str]]:
    """The bench's connections, and the observer's inputs to ``observer2`` and
    :data:`TRACKER` when ``fmus`` has them."""
    extra = [
        [a, o, other, i]
        for other in ("observer2", TRACKER)
        if other in fmus
        for a, o, b, i in CONNECTIONS
        if b == "observer"
    ]
    return [list(c) for c in CONNECTIONS] + extra


def chain_fmus(folder: Path) -> dict[str, Path]:
    """The bench's FMUs in ``folder``, by component."""
    return {c: folder / f"{name}.fmu" for c, name in COMPONENTS.items()}


def chain_spec(fmus: dict[str, Path], stop: float, h: float, shadow: Path | None = None) -> dict:
    """chain_run.py's SPEC: the bench's parameters and connections, for ``stop`` s in steps
    of ``h`` s; a component ``observer2`` gets the observer's parameters and inputs, and
    :data:`TRACKER` the observer's inputs and its own parameters."""
    return {
        "components": {c: str(p) for c, p in fmus.items()},
        "parameters": {c: parameters_of(c) for c in fmus},
        "connections": connections_of(fmus),
        "stop": stop,
        "h": h,
        "shadow": str(shadow) if shadow else None,
    }


def run_chain(
    python: str,
    spec: dict,
    workdir: Path,
    env: dict[str, str],
    launch: Callable[[list[str], dict[str, str], Path], subprocess.CompletedProcess] | None = None,
    timeout: float | None = None,
) -> dict:
    """chain_run.py under ``python`` in ``workdir`` (made if needed) with ``env``; its OUT.

    ``launch(command, env, cwd)`` starts it instead of ``subprocess.run`` (with
    ``timeout``), e.g. in a namespace.
    """
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "spec.json").write_text(json.dumps(spec))
    command = [python, str(RUNNER), "spec.json", "out.json"]
    if launch is None:
        result = subprocess.run(
            command, capture_output=True, text=True, env=env, cwd=workdir, timeout=timeout
        )
    else:
        result = launch(command, env, workdir)
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads((workdir / "out.json").read_text())


def compile_c_host(folder: Path) -> Path:
    """tests/hosts/chain_host.c compiled into ``folder`` (strict C99, no Python linked);
    the compiler's stderr in the assertion when it fails."""
    from arcosim.build.cplant import compiler, fmi_headers

    binary = folder / "chain_host"
    command = [compiler(), "-std=c99", "-O1", "-Wall", "-Wextra", f"-I{fmi_headers()}"]
    command += [str(C_HOST), "-o", str(binary), "-ldl"]
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return binary
