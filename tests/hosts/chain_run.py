"""Run source → plant → observer in this Python with fmpy only, and report as JSON.

Started by tests/test_portable_hosts.py with the interpreter of a fresh venv (any
CPython ≥ 3.9 with fmpy; nothing of the project is importable here). Jacobi master,
the schedule of ``arcosim.host.ssp.run_ssp``: every step each input takes its start's output
at t, then every FMU steps from t to t + h.

    python chain_run.py SPEC.json OUT.json

SPEC: {"components": {name: fmu path}, "parameters": {name: {var: value}},
"connections": [[a, out, b, in], ...], "stop": s, "h": s, "shadow": folder or null}.
With "shadow", that folder goes first on sys.path and every package in it is imported
before any FMU is loaded (a host with its own ``fmukit``, ``flexchain``, ``pythonfmu``).
OUT: every output of every component at every communication point, the environment
check, and the libpython files mapped into this process.
"""

from __future__ import annotations

import importlib
import json
import os
import shutil
import sys
import tempfile


def mapped_libpythons():
    """Paths of every libpython shared object mapped into this process."""
    found = set()
    with open("/proc/self/maps") as maps:
        for line in maps:
            path = line.split()[-1] if len(line.split()) >= 6 else ""
            if os.path.basename(path).startswith("libpython3."):
                found.add(path)
    return sorted(found)


def import_shadow(folder):
    """Put ``folder`` first on sys.path and import every package in it; their names."""
    sys.path.insert(0, folder)
    shadowed = []
    for name in sorted(os.listdir(folder)):
        if os.path.isfile(os.path.join(folder, name, "__init__.py")):
            importlib.import_module(name)
            shadowed.append(name)
    return shadowed


def set_parameter(slave, variable, value):
    """Set one start value through the setter of the variable's type."""
    if variable.type == "Real":
        slave.setReal([variable.valueReference], [float(value)])
    elif variable.type in ("Integer", "Enumeration"):
        slave.setInteger([variable.valueReference], [int(value)])
    elif variable.type == "Boolean":
        slave.setBoolean([variable.valueReference], [bool(value)])
    else:
        slave.setString([variable.valueReference], [str(value)])


def load(name, fmu, parameters):
    """Extract, instantiate and initialize one FMU: (slave, its folder, its variables)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu)
    folder = extract(fmu, unzipdir=tempfile.mkdtemp(prefix="chain_"))
    variables = {v.name: v for v in md.modelVariables}
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=folder,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    slave.instantiate(loggingOn=True)
    slave.setupExperiment(startTime=0.0)
    for var, value in parameters.items():
        set_parameter(slave, variables[var], value)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    return slave, folder, variables


def output_reader(variables):
    """(Real, Boolean and Integer value references, their names in that order)."""
    outs = [v for v in variables.values() if v.causality == "output"]
    reals = [v for v in outs if v.type == "Real"]
    bools = [v for v in outs if v.type == "Boolean"]
    ints = [v for v in outs if v.type == "Integer"]
    return (
        [v.valueReference for v in reals],
        [v.valueReference for v in bools],
        [v.valueReference for v in ints],
        [v.name for v in reals] + [v.name for v in bools] + [v.name for v in ints],
    )


def simulate(slaves, readers, links, stop, h):
    """Jacobi steps from 0 to ``stop``; every output at every communication point."""
    log = {name: {out: [] for out in readers[name][3]} for name in slaves}

    def record():
        for name, slave in slaves.items():
            reals, bools, ints, names = readers[name]
            values = list(slave.getReal(reals)) if reals else []
            values += [float(b) for b in slave.getBoolean(bools)] if bools else []
            values += [float(i) for i in slave.getInteger(ints)] if ints else []
            for out, value in zip(names, values):
                log[name][out].append(value)

    record()
    for k in range(round(stop / h)):
        t = k * h
        for a, vr_out, b, vr_in in links:
            slaves[b].setReal([vr_in], slaves[a].getReal([vr_out]))
        for slave in slaves.values():
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        record()
    return log


def changed_variables(*environs):
    """Names of the environment variables that differ between any of ``environs``."""
    keys = set().union(*environs)
    return sorted(k for k in keys if len({repr(e.get(k)) for e in environs}) > 1)


def main(spec_path, out_path):
    with open(spec_path) as f:
        spec = json.load(f)
    shadowed = import_shadow(spec["shadow"]) if spec.get("shadow") else []
    # fmpy is imported before the environment is first read, as it always was
    import fmpy.fmi2  # noqa: F401

    environ_before = dict(os.environ)
    maps_before = mapped_libpythons()
    slaves, readers, variables, folders = {}, {}, {}, []
    for name, fmu in spec["components"].items():
        parameters = spec["parameters"].get(name, {})
        slaves[name], folder, variables[name] = load(name, fmu, parameters)
        folders.append(folder)
        readers[name] = output_reader(variables[name])
    environ_loaded = dict(os.environ)
    maps_loaded = mapped_libpythons()
    links = [
        (a, variables[a][out].valueReference, b, variables[b][inp].valueReference)
        for a, out, b, inp in spec["connections"]
    ]
    log = simulate(slaves, readers, links, spec["stop"], spec["h"])
    for slave in slaves.values():
        slave.terminate()
        slave.freeInstance()
    for folder in folders:
        shutil.rmtree(folder, ignore_errors=True)
    report = {
        "python": sys.version,
        "executable": sys.executable,
        "environ_changed": changed_variables(environ_before, environ_loaded, dict(os.environ)),
        "libpython_before": maps_before,
        "libpython_after": maps_loaded,
        "shadowed": shadowed,
        "shadow_modules": {n: getattr(sys.modules[n], "__file__", None) for n in shadowed},
        "outputs": log,
    }
    with open(out_path, "w") as f:
        json.dump(report, f)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
