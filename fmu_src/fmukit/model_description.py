"""Write a compliant FMI 2.0 co-simulation modelDescription.xml.

pythonfmu's own ``to_xml`` writes no units, no ``<InitialUnknowns>`` and no output
dependencies (see docs/development.md); every FMU of the project writes its model
description through :func:`model_description` instead.
"""

from __future__ import annotations

import datetime
import hashlib
import uuid
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from xml.etree.ElementTree import Element, SubElement

from .units import UNITS
from .variables import Variable

LOG_CATEGORIES = {
    "logStatusWarning": "Log messages with fmi2Warning status.",
    "logStatusDiscard": "Log messages with fmi2Discard status.",
    "logStatusError": "Log messages with fmi2Error status.",
    "logStatusFatal": "Log messages with fmi2Fatal status.",
    "logAll": "Log all messages.",
}

#: The relative tolerance every FMU's DefaultExperiment declares. None of the project's
#: FMUs runs an error-controlled solver: the plants step with the matrix exponential of
#: their linear part (exact to rounding between friction events), the observer, source
#: and controller are discrete, so each ignores the tolerance ``fmi2SetupExperiment``
#: passes. It is declared so that a host taking the DefaultExperiment gets a value for
#: its own solvers beside ours, one tighter than the plants' sensors resolve (a count of
#: 2000 in a revolution is 5e-4 of it) and loose enough for any variable-step solver.
DEFAULT_TOLERANCE = 1e-6

COSIMULATION_DEFAULTS = {
    "needsExecutionTool": "true",
    "canHandleVariableCommunicationStepSize": "true",
    "canInterpolateInputs": "false",
    "canBeInstantiatedOnlyOncePerProcess": "false",
    "canGetAndSetFMUstate": "false",
    "canSerializeFMUstate": "false",
    "canNotUseMemoryManagementFunctions": "true",
}


@dataclass(frozen=True)
class ModelInfo:
    """What the ``<fmiModelDescription>`` element says about the model.

    Parameters
    ----------
    identifier : str
        Model identifier (also the binary's name), e.g. ``MotorChainPlant_n3``.
    description : str
        One paragraph for the user.
    version : str
        Project version that generated the FMU.
    experiment : tuple of float
        DefaultExperiment ``(start, stop, step)`` (s), shape ``(3,)``.
    """

    identifier: str
    description: str
    version: str
    experiment: tuple[float, float, float] = (0.0, 10.0, 1e-3)


def model_description(
    info: ModelInfo,
    variables: Sequence[Variable],
    cosimulation: Mapping[str, str] | None = None,
) -> Element:
    """Build the whole ``<fmiModelDescription>`` element.

    Value references are the positions in ``variables`` (0-based); the XML index
    used by ``<ModelStructure>`` is that position plus one. Outputs are computed in
    ``doStep`` only, so they declare ``dependencies=""`` (no direct feedthrough) and
    are listed as ``<InitialUnknowns>`` (their ``initial`` is ``calculated``).

    Parameters
    ----------
    info : ModelInfo
        Model-level attributes.
    variables : Sequence[Variable]
        Every variable, in value-reference order.
    cosimulation : Mapping[str, str], optional
        Overrides of the ``<CoSimulation>`` capability flags.

    Returns
    -------
    Element
        The root element, ready for ``ElementTree.tostring``.
    """
    root = Element(
        "fmiModelDescription",
        {
            "fmiVersion": "2.0",
            "modelName": info.identifier,
            "guid": _guid(info, variables),
            "description": info.description,
            "author": "arcosim developers",
            "version": info.version,
            "license": "MIT",
            "generationTool": f"arcosim {info.version}",
            "generationDateAndTime": _now(),
            "variableNamingConvention": "structured",
            "numberOfEventIndicators": "0",
        },
    )
    options = dict(COSIMULATION_DEFAULTS)
    options.update(cosimulation or {})
    SubElement(root, "CoSimulation", {"modelIdentifier": info.identifier, **options})
    _unit_definitions(root, {v.unit for v in variables if v.type == "Real"})
    categories = SubElement(root, "LogCategories")
    for name, text in LOG_CATEGORIES.items():
        SubElement(categories, "Category", {"name": name, "description": text})
    start, stop, step = info.experiment
    SubElement(
        root,
        "DefaultExperiment",
        {
            "startTime": _num(start),
            "stopTime": _num(stop),
            "tolerance": _num(DEFAULT_TOLERANCE),
            "stepSize": _num(step),
        },
    )
    model_variables = SubElement(root, "ModelVariables")
    for vr, var in enumerate(variables):
        model_variables.append(_scalar_variable(vr, var))
    _model_structure(root, variables)
    return root


def _scalar_variable(vr: int, var: Variable) -> Element:
    attrib = {
        "name": var.name,
        "valueReference": str(vr),
        "description": var.description,
        "causality": var.causality,
        "variability": var.variability,
    }
    if var.causality == "parameter":
        attrib["initial"] = "exact"
    elif var.causality == "output":
        attrib["initial"] = "calculated"
    element = Element("ScalarVariable", attrib)
    type_attrib: dict[str, str] = {}
    if var.type == "Real":
        type_attrib["unit"] = var.unit
    if var.causality != "output":
        type_attrib["start"] = _value(var.initial_value)
    SubElement(element, var.type, type_attrib)
    return element


def _model_structure(root: Element, variables: Sequence[Variable]) -> None:
    structure = SubElement(root, "ModelStructure")
    indices = [str(vr + 1) for vr, v in enumerate(variables) if v.causality == "output"]
    if not indices:
        return
    outputs = SubElement(structure, "Outputs")
    for index in indices:
        SubElement(outputs, "Unknown", {"index": index, "dependencies": ""})
    initial = SubElement(structure, "InitialUnknowns")
    for index in indices:
        SubElement(initial, "Unknown", {"index": index, "dependencies": ""})


def _unit_definitions(root: Element, names: Iterable[str]) -> None:
    names = sorted(n for n in names if n)
    if not names:
        return
    definitions = SubElement(root, "UnitDefinitions")
    for name in names:
        exponents, display_units = UNITS[name]
        unit = SubElement(definitions, "Unit", {"name": name})
        SubElement(unit, "BaseUnit", {k: str(e) for k, e in exponents.items()})
        for display, factor in display_units:
            SubElement(unit, "DisplayUnit", {"name": display, "factor": _num(factor)})


def _guid(info: ModelInfo, variables: Sequence[Variable]) -> str:
    """A GUID that changes whenever the interface does, and only then."""
    digest = hashlib.sha256()
    digest.update(f"{info.identifier}/{info.version}".encode())
    for var in variables:
        digest.update(f"|{var.name}:{var.type}:{var.causality}:{var.unit}".encode())
    return "{" + str(uuid.UUID(bytes=digest.digest()[:16], version=5)) + "}"


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def _num(x: float) -> str:
    """Shortest decimal that reads back as the same double."""
    return repr(float(x))


def _value(x: float | int | bool | str) -> str:
    if isinstance(x, str):
        return x
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    return _num(x)
