"""Write the SSP 1.0 systems: source → plant → observer (``ActionReaction.ssp``) and the
closed loop controller → plant → controller (``MotionControl.ssp``).

:func:`write_ssp` packs a system's FMUs with ``SystemStructure.ssd`` (components,
connectors, connections, a DefaultExperiment, parameter sets bound inline per
component, as ecos reads them, and OMSimulator's annotation of the system: its type,
a fixed-step master, without which OMSimulator cannot open a valid SSP 1.0 file).
:mod:`arcosim.host.ssp` runs such a file.
"""

from __future__ import annotations

import os
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from xml.etree import ElementTree
from xml.etree.ElementTree import Element, SubElement

from arcosim.fmu.flexchain.defaults import D_M, ENCODER_CPR, F_C, I_NOISE_STD
from arcosim.fmu.fmukit.variables import type_of

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
#: OMSimulator's vendor namespace (its schema/oms.xsd); OMSimulator matches the prefix
#: ``oms`` literally, as it does ``ssd`` and ``ssc``
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
NS = {"ssd": SSD, "ssc": SSC, "ssv": SSV, "oms": OMS}
#: OMSimulator's relative tolerance of a fixed-step master (its own default); unused by
#: a fixed step, required by its schema
OMS_RELATIVE_TOLERANCE = "0.0001"

#: (component, FMU file stem)
COMPONENTS = (
    ("source", "ExcitationSource"),
    ("plant", "MotorChainPlant"),
    ("observer", "ReactionTorqueObserver"),
)
#: (start component, connector, end component, connector)
CONNECTIONS = (
    ("source", "i_ref", "plant", "i_ref"),
    ("plant", "i_a", "observer", "i_a"),
    ("plant", "omega_m", "observer", "omega_m"),
    ("plant", "theta_m", "observer", "theta_m"),
)
#: The bench parameter set: the flexible maneuver (multi-sine, 0.48 A) and the
#: observer estimating the load angles with the bench's actuator terms.
BENCH = {
    "source": {
        "signal": 1,
        "amplitude": 0.48,
        "frequency": 3.0,
        "frequency_end": 120.0,
        "lines": 10,
        "seed": 1,
    },
    "plant": {"encoder_cpr": ENCODER_CPR, "i_noise_std": I_NOISE_STD, "seed": 1},
    "observer": {"mode": 2, "D_m": D_M, "f_c": F_C},
}


@dataclass(frozen=True)
class SspLayout:
    """One system: its name, a line saying what it does, components and connections.

    Parameters
    ----------
    name : str
        The system's name (``ssd:System``'s and the file's).
    description : str
        One line.
    components : tuple of (str, str)
        ``(component, FMU file stem)``.
    connections : tuple of (str, str, str, str)
        ``(start component, connector, end component, connector)``.
    sets : dict
        The parameter sets written when the caller gives none: set → component →
        variable → start value (in the variable's unit).
    """

    name: str
    description: str
    components: tuple[tuple[str, str], ...]
    connections: tuple[tuple[str, str, str, str], ...]
    sets: Mapping[str, Mapping[str, Mapping[str, float | int | bool | str]]]


ACTION_REACTION = SspLayout(
    "ActionReaction",
    "current source -> motor-chain plant -> action-reaction observer",
    COMPONENTS,
    CONNECTIONS,
    {"bench": BENCH},
)
#: The closed loop: the plant's sensors feed the controller, its i_ref the plant; the
#: target is the controller's input theta_ref, bound by the parameter set (a step at t0).
MOTION_CONTROL = SspLayout(
    "MotionControl",
    "target -> sensorless motion controller -> motor-chain plant -> controller",
    (("controller", "ActionReactionController"), ("plant", "MotorChainPlant")),
    (
        ("controller", "i_ref", "plant", "i_ref"),
        ("plant", "i_a", "controller", "i_a"),
        ("plant", "omega_m", "controller", "omega_m"),
        ("plant", "theta_m", "controller", "theta_m"),
    ),
    {},
)
#: The load torque of the move-load set (N·m on the last mass, pulling back).
LOAD_TORQUE = -5e-3


def motion_control_sets(n: int) -> dict[str, dict[str, dict[str, float | int]]]:
    """The closed loop's parameter sets for ``n`` load masses: ``move`` (a 1 rad step of
    the last mass's target at t0, the bench's sensors) and ``move-load`` (the same
    against a constant :data:`LOAD_TORQUE` on the last mass)."""
    plant = {"encoder_cpr": ENCODER_CPR, "i_noise_std": I_NOISE_STD, "seed": 1}
    return {
        "move": {"controller": {"theta_ref": 1.0}, "plant": plant},
        "move-load": {
            "controller": {"theta_ref": 1.0},
            "plant": {**plant, f"tau_ext[{n}]": LOAD_TORQUE},
        },
    }


def write_ssp(
    path: Path,
    fmu_dir: Path,
    parameter_sets: Mapping[str, Mapping[str, Mapping[str, float | int | bool | str]]]
    | None = None,
    stop: float = 10.0,
    step: float = 1e-3,
    layout: SspLayout = ACTION_REACTION,
) -> Path:
    """Pack the FMUs of ``layout`` from ``fmu_dir`` into an SSP at ``path``; return it.

    ``stop`` (s) goes into the DefaultExperiment, ``step`` (s) into OMSimulator's
    fixed-step master (SSP 1.0 has no place for a step); ``parameter_sets`` replace the
    layout's own.
    """
    sets = layout.sets if parameter_sets is None else parameter_sets
    for prefix, uri in NS.items():
        ElementTree.register_namespace(prefix, uri)
    root = Element(f"{{{SSD}}}SystemStructureDescription", {"version": "1.0", "name": layout.name})
    system = SubElement(
        root, f"{{{SSD}}}System", {"name": layout.name, "description": layout.description}
    )
    elements = SubElement(system, f"{{{SSD}}}Elements")
    for name, stem in layout.components:
        component = SubElement(
            elements,
            f"{{{SSD}}}Component",
            {
                "name": name,
                "source": f"resources/{stem}.fmu",
                "type": "application/x-fmu-sharedlibrary",
            },
        )
        connectors = SubElement(component, f"{{{SSD}}}Connectors")
        for a, ca, b, cb in layout.connections:
            for element, connector, kind in ((a, ca, "output"), (b, cb, "input")):
                if element == name:
                    c = SubElement(
                        connectors, f"{{{SSD}}}Connector", {"name": connector, "kind": kind}
                    )
                    SubElement(c, f"{{{SSC}}}Real")
        bindings = SubElement(component, f"{{{SSD}}}ParameterBindings")
        for set_name, per_component in sets.items():
            values = per_component.get(name, {})
            binding = SubElement(bindings, f"{{{SSD}}}ParameterBinding")
            holder = SubElement(binding, f"{{{SSD}}}ParameterValues")
            pset = SubElement(
                holder, f"{{{SSV}}}ParameterSet", {"version": "1.0", "name": set_name}
            )
            parameters = SubElement(pset, f"{{{SSV}}}Parameters")
            for pname, value in values.items():
                p = SubElement(parameters, f"{{{SSV}}}Parameter", {"name": pname})
                SubElement(p, f"{{{SSV}}}{type_of(value)}", {"value": _text(value)})
    connections = SubElement(system, f"{{{SSD}}}Connections")
    for a, ca, b, cb in layout.connections:
        SubElement(
            connections,
            f"{{{SSD}}}Connection",
            {"startElement": a, "startConnector": ca, "endElement": b, "endConnector": cb},
        )
    _omsimulator_annotation(system, step)
    SubElement(
        root, f"{{{SSD}}}DefaultExperiment", {"startTime": "0.0", "stopTime": repr(float(stop))}
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f".{path.name}.{os.getpid()}.part")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr(
            "SystemStructure.ssd",
            ElementTree.tostring(root, xml_declaration=True, encoding="UTF-8"),
        )
        for _, stem in layout.components:
            z.write(fmu_dir / f"{stem}.fmu", f"resources/{stem}.fmu")
    partial.replace(path)
    return path


def _omsimulator_annotation(system: Element, step: float) -> None:
    """OMSimulator's system annotation: a weakly coupled system (its ``oms-ma``, fixed
    step ``step`` s), the last child of ``ssd:System`` as SSP 1.0 orders it."""
    annotations = SubElement(system, f"{{{SSD}}}Annotations")
    annotation = SubElement(annotations, f"{{{SSC}}}Annotation", {"type": "org.openmodelica"})
    information = SubElement(
        SubElement(annotation, f"{{{OMS}}}Annotations"), f"{{{OMS}}}SimulationInformation"
    )
    SubElement(
        information,
        f"{{{OMS}}}FixedStepMaster",
        {
            "description": "oms-ma",
            "stepSize": format(Decimal(repr(float(step))), "f"),  # xs:decimal: no exponent
            "relativeTolerance": OMS_RELATIVE_TOLERANCE,
        },
    )


def _text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)
