"""The SSP 1.0 system source → plant → observer: ``dist/ActionReaction.ssp``.

:func:`write_ssp` packs the three FMUs with ``SystemStructure.ssd`` (components,
connectors, connections, a DefaultExperiment, and parameter sets bound inline per
component, as ecos reads them). :func:`run_ssp` runs such a file with a fixed-step
Jacobi master on fmpy, honouring its connections, a named parameter set and its
DefaultExperiment — which ``fmpy.ssp.simulate_ssp`` does not (it ignores parameter
bindings, LinearTransformation and DefaultExperiment, and needs every input
connected). ``arcosim ssp FILE`` is the command line.
"""

from __future__ import annotations

import argparse
import tempfile
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree
from xml.etree.ElementTree import Element, SubElement

import numpy as np

from cosim.errors import UserError
from cosim.instance import FmuInstance
from cosim.logs import write_csv
from cosim.master import Recording
from fmukit.variables import type_of

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
NS = {"ssd": SSD, "ssc": SSC, "ssv": SSV}

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
#: The bench parameter set: the flexible maneuver (multi-sine, 0.3 A peak) and the
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
    "plant": {"encoder_cpr": 2000, "i_noise_std": 0.005, "seed": 1},
    "observer": {"mode": 2, "D_m": 2e-5, "f_c": 2e-3},
}


@dataclass
class SspSystem:
    """What :func:`read_ssp` found: FMU paths, connections, parameter sets, experiment."""

    components: dict[str, Path]
    connections: list[tuple[str, str, str, str]]
    parameter_sets: dict[str, dict[str, dict[str, float | int | bool | str]]]
    start: float = 0.0
    stop: float = 10.0
    folder: tempfile.TemporaryDirectory | None = field(default=None, repr=False)


def write_ssp(
    path: Path,
    fmu_dir: Path,
    parameter_sets: Mapping[str, Mapping[str, Mapping[str, float | int | bool | str]]]
    | None = None,
    stop: float = 10.0,
) -> Path:
    """Pack the three FMUs of ``fmu_dir`` into an SSP at ``path``; return it."""
    sets = {"bench": BENCH} if parameter_sets is None else parameter_sets
    ElementTree.register_namespace("ssd", SSD)
    ElementTree.register_namespace("ssc", SSC)
    ElementTree.register_namespace("ssv", SSV)
    root = Element(
        f"{{{SSD}}}SystemStructureDescription", {"version": "1.0", "name": "ActionReaction"}
    )
    system = SubElement(
        root,
        f"{{{SSD}}}System",
        {
            "name": "ActionReaction",
            "description": "current source -> motor-chain plant -> action-reaction observer",
        },
    )
    elements = SubElement(system, f"{{{SSD}}}Elements")
    for name, stem in COMPONENTS:
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
        for a, ca, b, cb in CONNECTIONS:
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
    for a, ca, b, cb in CONNECTIONS:
        SubElement(
            connections,
            f"{{{SSD}}}Connection",
            {"startElement": a, "startConnector": ca, "endElement": b, "endConnector": cb},
        )
    SubElement(
        root, f"{{{SSD}}}DefaultExperiment", {"startTime": "0.0", "stopTime": repr(float(stop))}
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr(
            "SystemStructure.ssd",
            ElementTree.tostring(root, xml_declaration=True, encoding="UTF-8"),
        )
        for _, stem in COMPONENTS:
            z.write(fmu_dir / f"{stem}.fmu", f"resources/{stem}.fmu")
    return path


def read_ssp(path: Path) -> SspSystem:
    """Unpack an SSP and read its structure (raises :class:`UserError` on bad files)."""
    if not Path(path).is_file():
        raise UserError(f"{path}: no such file")
    folder = tempfile.TemporaryDirectory(prefix="arcosim_ssp_")
    try:
        with zipfile.ZipFile(path) as z:
            z.extractall(folder.name)
        root = ElementTree.parse(Path(folder.name) / "SystemStructure.ssd").getroot()
    except (zipfile.BadZipFile, FileNotFoundError, ElementTree.ParseError) as error:
        folder.cleanup()
        raise UserError(f"{path}: not a readable SSP ({error})") from None
    components, sets = {}, {}
    for c in root.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
        components[c.get("name")] = Path(folder.name) / c.get("source")
        for pset in c.iterfind(
            "ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/ssv:ParameterSet", NS
        ):
            values = sets.setdefault(pset.get("name"), {}).setdefault(c.get("name"), {})
            for p in pset.iterfind("ssv:Parameters/ssv:Parameter", NS):
                typed = p[0]
                values[p.get("name")] = _parse(typed.tag.split("}")[1], typed.get("value"))
    connections = [
        (x.get("startElement"), x.get("startConnector"), x.get("endElement"), x.get("endConnector"))
        for x in root.iterfind("ssd:System/ssd:Connections/ssd:Connection", NS)
    ]
    experiment = root.find("ssd:DefaultExperiment", NS)
    system = SspSystem(components, connections, sets, folder=folder)
    if experiment is not None:
        system.start = float(experiment.get("startTime", 0.0))
        system.stop = float(experiment.get("stopTime", 10.0))
    return system


def run_ssp(
    path: Path,
    parameter_set: str | None = "bench",
    stop: float | None = None,
    h: float = 1e-3,
    extra: Mapping[str, Mapping[str, float | int | bool | str]] | None = None,
) -> Recording:
    """Run an SSP with a Jacobi master: every step, each connection's input takes the
    start's output at t, then every FMU steps from t to t + h.

    Returns a recording of every output of every component (``"component.name"``).
    """
    system = read_ssp(path)
    if parameter_set is not None and parameter_set not in system.parameter_sets:
        known = ", ".join(system.parameter_sets) or "none"
        raise UserError(f"{path}: no parameter set {parameter_set!r} (it has: {known})")
    chosen = system.parameter_sets.get(parameter_set, {}) if parameter_set else {}
    stop = system.stop if stop is None else stop
    steps = round((stop - system.start) / h)
    instances = {name: FmuInstance(fmu, name) for name, fmu in system.components.items()}
    try:
        for name, fmu in instances.items():
            fmu.initialize({**chosen.get(name, {}), **(extra or {}).get(name, {})}, system.start)
        links = [
            (instances[a].reader([ca]), instances[b].real_writer([cb]))
            for a, ca, b, cb in system.connections
        ]
        readers = {
            name: (
                fmu.reader(
                    outs := [
                        v.name for v in fmu.description.modelVariables if v.causality == "output"
                    ]
                ),
                outs,
            )
            for name, fmu in instances.items()
        }
        logs = {name: np.empty((steps + 1, len(outs))) for name, (_, outs) in readers.items()}
        for name, (read, _) in readers.items():
            logs[name][0] = read()
        for k in range(steps):
            t = system.start + k * h
            for read, write in links:
                write(read())
            for name, fmu in instances.items():
                if fmu.do_step(t, h) > 1:
                    raise UserError(f"{name} refused the step at t = {t!r} s: {fmu.messages[-1:]}")
            for name, (read, _) in readers.items():
                logs[name][k + 1] = read()
    finally:
        for fmu in instances.values():
            fmu.close()
        system.folder.cleanup()
    recording = Recording(time=system.start + np.arange(steps + 1) * h)
    for name, (_, outs) in readers.items():
        for j, out in enumerate(outs):
            recording.signals[f"{name}.{out}"] = logs[name][:, j]
    return recording


def _text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)


def _parse(kind: str, text: str) -> float | int | bool | str:
    if kind == "Boolean":
        return text in ("true", "1")
    if kind == "Integer":
        return int(text)
    if kind == "String":
        return text
    return float(text)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim ssp``."""
    p = subparsers.add_parser(
        "ssp", help="run an SSP system (e.g. dist/ActionReaction.ssp)", description=__doc__
    )
    p.add_argument("path", type=Path, help="the .ssp file")
    p.add_argument(
        "--parameter-set", default="bench", help="parameter set to apply (default bench)"
    )
    p.add_argument(
        "--stop", type=float, help="stop time in s (default: the SSP's DefaultExperiment)"
    )
    p.add_argument(
        "--step", type=float, default=1e-3, help="communication step in s (default 0.001)"
    )
    p.add_argument("--out", type=Path, help="CSV of every output of every component")
    p.set_defaults(execute=_execute)


def _execute(args: argparse.Namespace) -> int:
    if not args.step > 0:
        raise UserError(f"--step {args.step}: the step must be > 0 s")
    recording = run_ssp(args.path, args.parameter_set, args.stop, args.step)
    if args.out:
        write_csv(args.out, {"time": recording.time, **recording.signals})
    print(f"{args.path}: {len(recording.time) - 1} steps of {args.step} s (Jacobi)")
    for key in ("observer.tau_reac_hat", "observer.theta_hat[1]", "plant.theta[1]"):
        if key in recording.signals:
            print(f"  final {key:24s} {recording[key][-1]:.6g}")
    if args.out:
        print(f"wrote {args.out}")
    return 0
