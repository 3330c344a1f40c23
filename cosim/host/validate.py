"""The checks a strict FMI host would run on an FMU (``arcosim validate``).

:func:`validate` runs fmpy's validation, the portability checks of
:mod:`arcosim.portability`, then what fmpy does not check: a unit from
``<UnitDefinitions>`` on every Real, a description on every variable, the project as
``generationTool``, a DefaultExperiment, state save/restore declared; then it runs the
FMU: a clean start and 20 steps with a silent log, a refused NaN input, step size 0, a
wrong communication point and a ``doStep`` before initialization (each fmi2Discard
with a log line, none fatal), a state round trip, and, where ecos (``ecospy``) and its
``libtbb12`` are installed, a run in that C++ engine with a bare environment.
"""

from __future__ import annotations

import math
import tempfile
import zipfile
import zlib
from pathlib import Path
from xml.etree import ElementTree

from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from arcosim.errors import UserError
from arcosim.host.ecos import ecos_binary, run_ecos
from arcosim.host.instance import FmuInstance
from arcosim.portability import portability_problems


def check_model_description(fmu: Path) -> list[str]:
    """Problems with the model description beyond fmpy's own validation."""
    with zipfile.ZipFile(fmu) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    problems = []
    if not (root.get("generationTool") or "").startswith("arcosim"):
        problems.append(f"generationTool is {root.get('generationTool')!r}, not arcosim")
    if root.find("DefaultExperiment") is None:
        problems.append("no DefaultExperiment")
    cs = root.find("CoSimulation")
    for flag in ("canGetAndSetFMUstate", "canSerializeFMUstate"):
        if cs is None or cs.get(flag) != "true":
            problems.append(f"CoSimulation does not declare {flag}=true")
    units = {u.get("name") for u in root.iter("Unit")}
    for sv in root.iter("ScalarVariable"):
        name = sv.get("name")
        if not sv.get("description"):
            problems.append(f"{name}: no description")
        real = sv.find("Real")
        if real is not None and real.get("unit") not in units:
            problems.append(f"{name}: unit {real.get('unit')!r} is missing or undefined")
    return problems


def check_runtime(fmu: Path) -> list[str]:
    """Run the FMU in fmpy: happy path, refused misuse, state round trip."""
    problems: list[str] = []
    with FmuInstance(fmu, "validate") as instance:
        real_inputs = [
            v.name
            for v in instance.description.modelVariables
            if v.causality == "input" and v.type == "Real"
        ]
        outputs = instance.output_names()
        read = instance.reader(outputs)
        if _status(lambda: instance.slave.doStep(0.0, 1e-3)) != 2:
            problems.append("doStep before initialization was not refused with fmi2Discard")
        clean_start = len(instance.messages)
        instance.initialize()
        for k in range(20):
            if instance.do_step(k * 1e-3, 1e-3) != 0:
                problems.append(f"step {k} of a clean run failed: {instance.messages[-1:]}")
                break
        values = read()
        if not all(math.isfinite(x) for x in values):
            problems.append("an output is not finite after a clean run")
        if instance.messages[clean_start:]:
            said = instance.messages[clean_start:][:3]
            problems.append(f"the log is not silent on a clean run: {said}")
        t = 20e-3
        misuse = (
            [
                (
                    "a NaN input",
                    lambda: instance.set({real_inputs[0]: math.nan}),
                    t,
                    1e-3,
                    f"input {real_inputs[0]} = nan",
                ),
                (
                    "step size 0",
                    lambda: instance.set({real_inputs[0]: 0.0}),
                    t,
                    0.0,
                    "step size 0.0",
                ),
                ("a wrong communication point", lambda: None, t + 5.0, 1e-3, "communication point"),
            ]
            if real_inputs
            else []
        )
        for what, prepare, when, h, phrase in misuse:
            prepare()
            before = len(instance.messages)
            status = instance.do_step(when, h)
            said = " ".join(instance.messages[before:])
            if status != 2 or phrase not in said:
                problems.append(f"{what} gave status {status} and log {said!r}")
        state = instance.slave.getFMUstate()
        first = [_step_read(instance, t + k * 1e-3, read) for k in range(10)]
        instance.slave.setFMUstate(state)
        again = [_step_read(instance, t + k * 1e-3, read) for k in range(10)]
        instance.slave.freeFMUstate(state)
        if first != again:
            problems.append("get state / step / set state / step did not repeat the outputs")
    return problems


def check_ecos(fmu: Path) -> tuple[list[str], str | None]:
    """Run the FMU alone in ecos with a bare environment: (problems, why skipped)."""
    binary, why_not = ecos_binary()
    if binary is None:
        return [], why_not
    with tempfile.TemporaryDirectory(prefix="arcosim_ecos_") as tmp:
        result = run_ecos(binary, fmu, Path(tmp), stop=0.02, timeout=120)
        if result.returncode != 0 or not list(Path(tmp).glob("*.csv")):
            return [f"ecos (C++ host) failed with exit {result.returncode}"], None
    return [], None


def not_an_fmu(path: Path) -> str | None:
    """Why ``path`` cannot be validated at all (not a file, not a complete FMU zip,
    an SSP), or None.

    Parameters
    ----------
    path : Path
        The file given to ``arcosim validate``.

    Returns
    -------
    str or None
        The reason, as a phrase that follows the file's name in a message; None when
        ``path`` is a readable zip with a ``modelDescription.xml`` (what
        :func:`validate` then checks).

    Examples
    --------
    >>> folder = tempfile.TemporaryDirectory()
    >>> fmu = Path(folder.name) / "Plant.fmu"
    >>> not_an_fmu(fmu)
    'no such file'
    >>> fmu.touch()
    >>> not_an_fmu(fmu)
    'an empty file, not an FMU'
    >>> with zipfile.ZipFile(fmu, "w") as z:
    ...     z.writestr("modelDescription.xml", "<fmiModelDescription/>")
    >>> print(not_an_fmu(fmu))
    None
    >>> folder.cleanup()
    """
    if not path.exists():
        return "no such file"
    if path.is_dir():
        return "is a folder, not an FMU (give the .fmu zip itself)"
    if not path.is_file():
        return "not a file"
    if not zipfile.is_zipfile(path):  # the zip's magic decides, not the name
        size = path.stat().st_size
        return "an empty file, not an FMU" if size == 0 else "not an FMU (not a zip file)"
    try:
        with zipfile.ZipFile(path) as z:
            if "SystemStructure.ssd" in z.namelist():
                return "an SSP system, not an FMU (run it with `arcosim ssp`; validate its FMUs)"
            if "modelDescription.xml" not in z.namelist():
                return "a zip file without modelDescription.xml, not an FMU"
            bad = z.testzip()
            if bad is not None:
                return f"a corrupt FMU (member {bad} fails its CRC-32)"
    except (OSError, zipfile.BadZipFile, EOFError, zlib.error) as error:
        return f"a truncated or corrupt FMU ({error})"
    return None


def validate(fmu: Path) -> tuple[list[str], list[str]]:
    """Check one FMU the way a strict FMI host would.

    fmpy's validation; portability (no absolute path or libpython among its Linux
    binaries' NEEDED, RPATH, RUNPATH entries; its Python code under one build-unique
    package that imports nothing but the standard library by absolute name); then
    what fmpy does not check (units from
    ``<UnitDefinitions>``, descriptions, generationTool, DefaultExperiment, state
    support), then a run: a clean start and 20 steps with a silent log, refused bad
    steps (NaN input, step size 0, a wrong communication point, a step before
    initialization), a state round trip, and a run in the ecos C++ engine where
    ``ecospy`` and its system library are installed.

    Parameters
    ----------
    fmu : Path
        The ``.fmu`` file.

    Returns
    -------
    problems : list of str
        Every problem found, one sentence each (empty: none).
    notes : list of str
        Checks that could not run here, and why.

    Examples
    --------
    >>> folder = arcosim.ensure_built(3)
    >>> problems, notes = arcosim.validate(folder / "MotorChainPlant.fmu")
    >>> problems
    []
    """
    try:
        problems = [f"fmpy: {p}" for p in validate_fmu(str(fmu))]
    except Exception as error:  # fmpy's reader raises whatever the file makes it meet
        return [f"fmpy cannot read the model description ({type(error).__name__}: {error})"], []
    problems += [f"portability: {p}" for p in portability_problems(fmu)]
    problems += check_model_description(fmu)
    try:
        problems += check_runtime(fmu)
    except (UserError, FMICallException) as error:
        problems.append(f"the FMU does not run in fmpy: {error}")
        return problems, ["the ecos run was skipped: the FMU does not run in fmpy"]
    ecos_problems, skipped = check_ecos(fmu)
    problems += ecos_problems
    return problems, [f"ecos run skipped: {skipped}"] if skipped else []


def _status(call) -> int:
    try:
        call()
    except FMICallException as error:
        return error.status
    return 0


def _step_read(instance: FmuInstance, t: float, read) -> list[float]:
    instance.do_step(t, 1e-3)
    return read()
