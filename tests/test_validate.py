"""``arcosim validate``: passes the project's FMUs, fails a broken one."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from arcosim.cli import main


@pytest.mark.system
@pytest.mark.slow
def test_validate_passes_the_built_fmus(build_fmus, capsys) -> None:
    fmus = [
        str(build_fmus(n) / f"{name}.fmu")
        for n in (1, 3)
        for name in ("MotorChainPlant", "ReactionTorqueObserver")
    ] + [str(build_fmus(3) / "FlexLinkPlant.fmu")]
    assert main(["validate", *fmus]) == 0
    out = capsys.readouterr().out
    assert out.count(": OK") == 5 and "problem" not in out


def test_validate_names_what_is_wrong(build_fmus, tmp_path: Path, capsys) -> None:
    source = build_fmus(3) / "MotorChainPlant.fmu"
    broken = tmp_path / "Broken.fmu"
    with zipfile.ZipFile(source) as z, zipfile.ZipFile(broken, "w") as out:
        for item in z.infolist():
            data = z.read(item)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                text = text.replace('unit="N.m/A" ', "", 1)  # k_t loses its unit
                text = text.replace('description="Motor (rotor) inertia"', "", 1)
                data = text.encode()
            out.writestr(item, data)
    assert main(["validate", str(broken)]) == 1
    out = capsys.readouterr().out
    assert "k_t: unit None is missing or undefined" in out
    assert "J_m: no description" in out


@pytest.mark.system
@pytest.mark.slow
def test_validate_without_fmus_checks_the_cached_ones(build_fmus, capsys) -> None:
    build_fmus(3)
    assert main(["validate"]) == 0
    out = capsys.readouterr().out
    assert (
        out.count(": OK") == 5 and str(build_fmus(3)) in out
    )  # the link and the controller included


@pytest.mark.parametrize(
    "name",
    [
        "MotorChainPlant",
        "ReactionTorqueObserver",
        "ExcitationSource",
        "ActionReactionController",
        "FlexLinkPlant",
    ],
)
def test_every_fmu_declares_its_default_tolerance(build_fmus, name) -> None:
    """A host that takes the DefaultExperiment gets a relative tolerance too, not only a
    start, stop and step."""
    from xml.etree import ElementTree

    from arcosim.fmu.fmukit.model_description import DEFAULT_TOLERANCE

    with zipfile.ZipFile(build_fmus(3) / f"{name}.fmu") as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    experiment = root.find("DefaultExperiment")
    assert float(experiment.get("tolerance")) == DEFAULT_TOLERANCE
    assert float(experiment.get("stepSize")) > 0
