"""The SSP carries OMSimulator's system annotation and stays valid SSP 1.0.

OMSimulator cannot open an SSP 1.0 system without its vendor annotation naming the
system's type ("[NewSystem] internal error", then an abort; OMSimulator issue #1318). The
annotation goes where SSP 1.0 allows any vendor's (``ssd:Annotations`` of the system),
so the file validates against the SSP 1.0 schema fmpy ships, and every other reader
(arcosim ssp, fmpy.ssp, ecos in tests/test_hosts.py) still reads it.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from arcosim.build.ssp import CONNECTIONS, NS, OMS
from arcosim.host.instance import FmuInstance
from arcosim.host.ssp import run_ssp


def _ssd(ssp: Path) -> bytes:
    with zipfile.ZipFile(ssp) as z:
        return z.read("SystemStructure.ssd")


def test_the_system_carries_omsimulators_fixed_step_master(fmus) -> None:
    from xml.etree import ElementTree

    text = _ssd(fmus / "ActionReaction.ssp")
    root = ElementTree.fromstring(text)
    (master,) = root.findall(
        "ssd:System/ssd:Annotations/ssc:Annotation[@type='org.openmodelica']"
        "/oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster",
        NS,
    )
    assert master.attrib == {
        "description": "oms-ma",
        "stepSize": "0.001",
        "relativeTolerance": "0.0001",
    }
    # OMSimulator (pugixml) matches element names with their prefixes, literally
    decoded = text.decode()
    assert f'xmlns:oms="{OMS}"' in decoded
    for tag in ("<ssd:Annotations>", '<ssc:Annotation type="org.openmodelica">'):
        assert tag in decoded
    for tag in ("oms:Annotations", "oms:SimulationInformation", "oms:FixedStepMaster"):
        assert f"<{tag}" in decoded


def test_the_ssd_is_valid_against_the_ssp_1_0_schema_fmpy_ships(fmus) -> None:
    import fmpy
    from lxml import etree  # a dependency of fmpy

    xsd = Path(fmpy.__file__).parent / "ssp" / "schema" / "SystemStructureDescription.xsd"
    if not xsd.is_file():
        pytest.skip(f"fmpy ships no SSP 1.0 schema at {xsd}")
    schema = etree.XMLSchema(file=str(xsd))
    root = etree.fromstring(_ssd(fmus / "ActionReaction.ssp"))
    assert schema.validate(root), str(schema.error_log)


def test_arcosim_ssp_runs_the_annotated_file(fmus) -> None:
    recording = run_ssp(fmus / "ActionReaction.ssp", "bench", stop=0.05)
    assert len(recording.time) == 51
    assert recording["observer.theta_hat[1]"][-1] != 0.0


def test_fmpy_ssp_reads_it_and_what_it_does_not_do(fmus) -> None:
    """What docs/fmus/other-tools.md says of fmpy.ssp (fmpy 0.3.32): it reads and runs
    the file, records only the connectors the SSD declares (none of the observer's
    outputs), and ignores the parameter bindings (the source plays its default rigid
    maneuver, not the bench set's multi-sine)."""
    from fmpy.ssp.simulation import simulate_ssp

    ssp = fmus / "ActionReaction.ssp"
    result = simulate_ssp(str(ssp), stop_time=0.1, step_size=1e-3)
    names = set(result.dtype.names) - {"time"}
    connectors = {f"{b}.{i}" for _, _, b, i in CONNECTIONS} | {
        f"{a}.{o}" for a, o, _, _ in CONNECTIONS
    }
    assert names == connectors
    assert not any(
        n.startswith("observer.") and n[9:] not in ("i_a", "omega_m", "theta_m") for n in names
    )
    with FmuInstance(fmus / "ExcitationSource.fmu", "defaults") as source:
        source.initialize()  # its defaults, no parameter set
        played = []
        for k in range(len(result)):
            source.do_step(k * 1e-3, 1e-3)
            played.append(source.get(["i_ref"])[0])
    np.testing.assert_allclose(result["source.i_ref"], played, rtol=1e-12, atol=1e-15)
    bench = run_ssp(ssp, "bench", stop=0.1)["source.i_ref"][1 : len(played) + 1]
    assert not np.allclose(bench, played)
