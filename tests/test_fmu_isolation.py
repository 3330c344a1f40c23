"""The code an FMU runs is the code it ships, whatever the host imported before.

- A host that first imports packages of its own named ``fmukit``, ``flexchain`` and
  ``pythonfmu`` (stand-ins that define nothing an FMU needs) gets the FMU's results
  unchanged: the bundle imports none of them.
- Two builds of the observer with different code (the second one's ``d_hat`` is the
  first one's + 1) run in one process, each with its own code.
Each run is its own process (tests/hosts/chain_run.py with this interpreter).
"""

from __future__ import annotations

import os
import sys
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest

from arcosim.build.cplant import fmi_headers
from arcosim.build.portable import compile_trampoline
from arcosim.portability import bundle_name, portability_problems
from tests.chain_harness import chain_fmus, chain_spec, run_chain

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries")

STOP, H = 0.3, 1e-3
VARIANT = """

# --- test variant: d_hat + 1 ------------------------------------------------------
_original_step = ReactionTorqueObserver.step


def _variant_step(self, t, h):
    _original_step(self, t, h)
    self.v[self.vr["d_hat"]] += 1.0


ReactionTorqueObserver.step = _variant_step
"""


def run(spec: dict, folder: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return run_chain(sys.executable, spec, folder, env, timeout=600)


@pytest.fixture(scope="session")
def fmus(build_fmus) -> dict[str, Path]:
    return chain_fmus(build_fmus(3))


@pytest.fixture(scope="session")
def reference(fmus, tmp_path_factory) -> dict:
    return run(chain_spec(fmus, STOP, H), tmp_path_factory.mktemp("reference"))["outputs"]


def equal(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return bool(np.max(np.abs(a - b)) <= 1e-9 * max(float(np.max(np.abs(b))), 1e-300))


def test_built_fmus_pass_the_portability_checks(fmus) -> None:
    for fmu in fmus.values():
        assert portability_problems(fmu) == [], fmu.name


@pytest.mark.system
@pytest.mark.slow
def test_a_host_with_its_own_fmukit_flexchain_pythonfmu_gets_the_fmus_results(
    fmus, reference, tmp_path
) -> None:
    shadow = tmp_path / "host_packages"
    for package, modules in {
        "fmukit": ["slave", "state", "variables", "checks", "model_description", "units"],
        "flexchain": ["dob", "observer", "waveforms", "bench", "linalg", "chain"],
        "pythonfmu": ["fmi2slave", "enums"],
    }.items():
        (shadow / package).mkdir(parents=True)
        (shadow / package / "__init__.py").write_text(
            f'"""The host\'s own {package}."""\nHOST = 1\n'
        )
        for module in modules:
            (shadow / package / f"{module}.py").write_text("HOST = 1\n")
    out = run(chain_spec(fmus, STOP, H, shadow), tmp_path / "run")
    assert out["shadowed"] == ["flexchain", "fmukit", "pythonfmu"]
    assert all(str(shadow) in path for path in out["shadow_modules"].values())
    for component, signals in reference.items():
        for name, values in signals.items():
            assert equal(out["outputs"][component][name], values), f"{component}.{name}"


def rebundle(fmu: Path, out: Path, digest: str, patch: str) -> str:
    """A second build of ``fmu``: its bundle renamed for ``digest``, ``patch`` appended to
    the observer's module, the trampoline recompiled for the new bundle."""
    with zipfile.ZipFile(fmu) as z:
        members = {i.filename: z.read(i) for i in z.infolist()}
    root = ElementTree.fromstring(members["modelDescription.xml"])
    identifier = root.find("CoSimulation").get("modelIdentifier")
    old = members["resources/slavemodule.txt"].decode().split(".")[0]
    new = bundle_name(identifier, digest)
    renamed = {}
    for name, data in members.items():
        name = name.replace(f"resources/{old}", f"resources/{new}")
        if name.startswith("resources/") and name.endswith(".py"):
            data = data.replace(old.encode(), new.encode())
        renamed[name] = data
    renamed["resources/slavemodule.txt"] = f"{new}.slave".encode()
    renamed[f"resources/{new}/arobserver/fmu.py"] += patch.encode()
    renamed[f"binaries/linux64/{identifier}.so"] = compile_trampoline(
        identifier=identifier, guid=root.get("guid"), bundle=new, n=3, headers=fmi_headers()
    )
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in renamed.items():
            z.writestr(name, data)
    return new


@pytest.mark.system
@pytest.mark.slow
def test_two_builds_of_the_observer_run_in_one_process(fmus, reference, tmp_path) -> None:
    variant = tmp_path / "ReactionTorqueObserver_variant.fmu"
    new = rebundle(fmus["observer"], variant, "f" * 40, VARIANT)
    assert portability_problems(variant) == []
    both = {**fmus, "observer2": variant}
    out = run(chain_spec(both, STOP, H), tmp_path / "run")["outputs"]
    for name, values in reference["observer"].items():
        assert equal(out["observer"][name], values), f"observer.{name}"
        expected = np.asarray(values) + (1.0 if name == "d_hat" else 0.0)
        if name == "d_hat":
            expected[0] = values[0]  # the sample at t0, before any step
        assert equal(out["observer2"][name], expected), f"observer2.{name} ({new})"
