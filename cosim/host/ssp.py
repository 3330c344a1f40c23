"""Read and run an SSP 1.0 system, such as ``ActionReaction.ssp`` (source → plant →
observer, written beside the FMUs by :mod:`arcosim.build.ssp`).

:func:`run_ssp` runs it with a fixed-step Jacobi master on fmpy, honouring its
connections, a named parameter set and its DefaultExperiment — which
``fmpy.ssp.simulate_ssp`` does not (it ignores parameter bindings,
LinearTransformation and DefaultExperiment, and needs every input connected).
``arcosim ssp FILE`` is the command line.
"""

from __future__ import annotations

import math
import tempfile
import zipfile
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from arcosim.errors import UserError
from arcosim.fmu.flexchain.defaults import STEP
from arcosim.host.instance import FmuInstance
from arcosim.host.master import MAX_STEPS, Recording
from arcosim.host.stepping import check_status


@dataclass
class SspSystem:
    """What :func:`read_ssp` found: FMU paths, connections, parameter sets, experiment.

    Parameters
    ----------
    components : dict of str to Path
        Component name → its FMU, unpacked from the SSP.
    connections : list of tuple of str
        ``(start component, start connector, end component, end connector)``.
    parameter_sets : dict
        Set name → component → variable → start value (in the variable's unit).
    start, stop : float
        The DefaultExperiment's start and stop time (s).
    folder : TemporaryDirectory, optional
        Where the SSP is unpacked; the caller cleans it up.
    """

    components: dict[str, Path]
    connections: list[tuple[str, str, str, str]]
    parameter_sets: dict[str, dict[str, dict[str, float | int | bool | str]]]
    start: float = 0.0
    stop: float = 10.0
    folder: tempfile.TemporaryDirectory | None = field(default=None, repr=False)


def read_ssp(path: Path) -> SspSystem:
    """Unpack an SSP and read its structure.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.

    Returns
    -------
    SspSystem
        Its structure; ``folder`` holds the unpacked files (clean it up when done).

    Raises
    ------
    UserError
        A missing file, a folder, or one that is not a readable SSP (the reason named:
        no zip, no ``SystemStructure.ssd``).
    """
    if Path(path).is_dir():
        raise UserError(f"{path}: is a folder, not an SSP file (give the .ssp zip itself)")
    if not Path(path).is_file():
        raise UserError(f"{path}: no such file")
    if not zipfile.is_zipfile(path):
        raise UserError(f"{path}: not an SSP (not a zip file)")
    folder = tempfile.TemporaryDirectory(prefix="arcosim_ssp_")
    try:
        with zipfile.ZipFile(path) as z:
            if "SystemStructure.ssd" not in z.namelist():
                raise UserError(f"{path} is not an SSP: no SystemStructure.ssd")
            z.extractall(folder.name)
        root = ElementTree.parse(Path(folder.name) / "SystemStructure.ssd").getroot()
    except UserError:
        folder.cleanup()
        raise
    except (zipfile.BadZipFile, ElementTree.ParseError, OSError, EOFError, zlib.error) as error:
        folder.cleanup()
        raise UserError(f"{path}: not a readable SSP ({error})") from None
    try:
        return _structure(path, root, folder)
    except (ValueError, TypeError, IndexError) as error:
        folder.cleanup()
        raise UserError(f"{path}: not a readable SSP ({error})") from None


def _structure(path: Path, root: ElementTree.Element, folder: tempfile.TemporaryDirectory):
    """The :class:`SspSystem` of a parsed ``SystemStructure.ssd``."""
    components, sets = {}, {}
    for c in root.iterfind("{*}System/{*}Elements/{*}Component"):
        if not c.get("name") or not c.get("source"):
            raise ValueError("a Component without name or source")
        components[c.get("name")] = Path(folder.name) / c.get("source")
        for pset in c.iterfind(
            "{*}ParameterBindings/{*}ParameterBinding/{*}ParameterValues/{*}ParameterSet"
        ):
            values = sets.setdefault(pset.get("name"), {}).setdefault(c.get("name"), {})
            for p in pset.iterfind("{*}Parameters/{*}Parameter"):
                typed = p[0]
                values[p.get("name")] = _parse(typed.tag.split("}")[1], typed.get("value"))
    connections = [
        (x.get("startElement"), x.get("startConnector"), x.get("endElement"), x.get("endConnector"))
        for x in root.iterfind("{*}System/{*}Connections/{*}Connection")
    ]
    for a, _, b, _ in connections:
        for end in (a, b):
            if end not in components:
                raise ValueError(f"a Connection names the unknown component {end!r}")
    experiment = root.find("{*}DefaultExperiment")
    system = SspSystem(components, connections, sets, folder=folder)
    if experiment is not None:
        system.start = float(experiment.get("startTime", 0.0))
        system.stop = float(experiment.get("stopTime", 10.0))
    if not (math.isfinite(system.start) and math.isfinite(system.stop)):
        raise ValueError(f"DefaultExperiment {system.start} … {system.stop} s is not finite")
    return system


def run_ssp(
    path: Path,
    parameter_set: str | None = "bench",
    stop: float | None = None,
    h: float = STEP,
    extra: Mapping[str, Mapping[str, float | int | bool | str]] | None = None,
) -> Recording:
    """Run an SSP system with a fixed-step Jacobi master.

    Every step, each connection's input takes its start's output at t, then every
    FMU steps from t to t + h. Unlike ``fmpy.ssp.simulate_ssp``, the file's parameter
    sets and DefaultExperiment are honoured.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file (e.g. ``ActionReaction.ssp`` beside the built FMUs).
    parameter_set : str or None
        Name of the parameter set to apply (``None``: none).
    stop : float, optional
        Stop time (s); default: the file's DefaultExperiment.
    h : float
        Communication step (s).
    extra : mapping, optional
        More start values, ``{component: {variable: value}}`` (in each variable's
        unit), applied after the parameter set.

    Returns
    -------
    Recording
        Every output of every component, named ``"component.variable"``.

    Raises
    ------
    UserError
        A missing or unreadable file, an unknown parameter set, a refused step.

    Examples
    --------
    >>> folder = arcosim.ensure_built(3)
    >>> run = arcosim.run_ssp(folder / "ActionReaction.ssp", "bench", stop=0.05)
    >>> run.time.shape, "observer.tau_reac_hat" in run.signals
    ((51,), True)
    """
    system = read_ssp(path)
    instances: dict[str, FmuInstance] = {}
    try:
        chosen = _parameter_values(path, system, parameter_set)
        stop = system.stop if stop is None else stop
        steps = _steps(system.start, stop, h)
        _instantiate(path, system, instances)
        for name, fmu in instances.items():
            fmu.initialize({**chosen.get(name, {}), **(extra or {}).get(name, {})}, system.start)
        outputs, logs = _run_steps(system, instances, steps, h)
        units = {
            name: [instances[name].unit(out) for out in outs] for name, outs in outputs.items()
        }
    finally:
        for fmu in instances.values():
            fmu.close()
        system.folder.cleanup()
    recording = Recording(time=system.start + np.arange(steps + 1) * h)
    for name, outs in outputs.items():
        for j, out in enumerate(outs):
            recording.signals[f"{name}.{out}"] = logs[name][:, j]
            recording.units[f"{name}.{out}"] = units[name][j]
    return recording


def _parameter_values(
    path: Path, system: SspSystem, parameter_set: str | None
) -> dict[str, dict[str, float | int | bool | str]]:
    """The start values of the parameter set ``parameter_set`` (None: none), by
    component; refuse a set the file does not have."""
    if parameter_set is not None and parameter_set not in system.parameter_sets:
        known = ", ".join(system.parameter_sets) or "none"
        raise UserError(f"{path}: no parameter set {parameter_set!r} (it has: {known})")
    return system.parameter_sets.get(parameter_set, {}) if parameter_set else {}


def _steps(start: float, stop: float, h: float) -> int:
    """The number of steps of ``h`` s from ``start`` to ``stop`` (s); refuse a stop
    that is not finite and after the start, and none or more than :data:`MAX_STEPS`."""
    if not (math.isfinite(stop) and stop > start):
        raise UserError(f"stop time {stop:g} s: it must be finite and after the start, {start:g} s")
    steps = round((stop - start) / h) if h > 0 and math.isfinite(h) else 0
    if not 1 <= steps <= MAX_STEPS:
        raise UserError(
            f"step {h:g} s from {start:g} to {stop:g} s gives {steps:.3g} steps; "
            f"a run takes 1 to {MAX_STEPS:,} steps"
        )
    return steps


def _instantiate(path: Path, system: SspSystem, instances: dict[str, FmuInstance]) -> None:
    """Instantiate every component into ``instances`` (filled as it goes, so the caller
    closes those made before a failure)."""
    for name, fmu in system.components.items():
        if not fmu.is_file():
            raise UserError(f"{path}: component {name}: no file {fmu.name} in the SSP")
        try:
            instances[name] = FmuInstance(fmu, name)
        except UserError as error:
            said = str(error).split(": ", 1)[-1]
            raise UserError(f"{path}: component {name} ({fmu.name}): {said}") from None


def _run_steps(
    system: SspSystem, instances: dict[str, FmuInstance], steps: int, h: float
) -> tuple[dict[str, list[str]], dict[str, np.ndarray]]:
    """Step the initialized components ``steps`` times by ``h`` s, Jacobi-wise.

    Returns every component's output names and their values after initialization and
    after every step (shape ``(steps + 1, outputs)``), by component.
    """
    links = [
        (instances[a].reader([ca]), instances[b].real_writer([cb]))
        for a, ca, b, cb in system.connections
    ]
    outputs = {name: fmu.output_names() for name, fmu in instances.items()}
    readers = {name: fmu.reader(outputs[name]) for name, fmu in instances.items()}
    logs = {name: np.empty((steps + 1, len(outputs[name]))) for name in instances}
    for name, read in readers.items():
        logs[name][0] = read()
    for k in range(steps):
        t = system.start + k * h
        for read, write in links:
            write(read())
        for name, fmu in instances.items():
            check_status(fmu.do_step(t, h), fmu, "stepping", t, name)
        for name, read in readers.items():
            logs[name][k + 1] = read()
    return outputs, logs


def _parse(kind: str, text: str) -> float | int | bool | str:
    if kind == "Boolean":
        return text in ("true", "1")
    if kind == "Integer":
        return int(text)
    if kind == "String":
        return text
    return float(text)
