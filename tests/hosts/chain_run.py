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


def main(spec_path, out_path):
    with open(spec_path) as f:
        spec = json.load(f)
    shadowed = []
    if spec.get("shadow"):
        sys.path.insert(0, spec["shadow"])
        for name in sorted(os.listdir(spec["shadow"])):
            if os.path.isfile(os.path.join(spec["shadow"], name, "__init__.py")):
                importlib.import_module(name)
                shadowed.append(name)
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    environ_before = dict(os.environ)
    maps_before = mapped_libpythons()
    slaves, readers, writers, outputs = {}, {}, {}, {}
    folders = []
    for name, fmu in spec["components"].items():
        md = read_model_description(fmu)
        folder = extract(fmu, unzipdir=tempfile.mkdtemp(prefix="chain_"))
        folders.append(folder)
        variables = {v.name: v for v in md.modelVariables}
        slave = FMU2Slave(
            guid=md.guid,
            unzipDirectory=folder,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        slave.instantiate(loggingOn=True)
        slave.setupExperiment(startTime=0.0)
        for var, value in spec["parameters"].get(name, {}).items():
            v = variables[var]
            if v.type == "Real":
                slave.setReal([v.valueReference], [float(value)])
            elif v.type in ("Integer", "Enumeration"):
                slave.setInteger([v.valueReference], [int(value)])
            elif v.type == "Boolean":
                slave.setBoolean([v.valueReference], [bool(value)])
            else:
                slave.setString([v.valueReference], [str(value)])
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        slaves[name] = slave
        outs = [v for v in md.modelVariables if v.causality == "output"]
        outputs[name] = [v.name for v in outs]
        readers[name] = (
            [v.valueReference for v in outs if v.type == "Real"],
            [v.valueReference for v in outs if v.type == "Boolean"],
            [v.name for v in outs if v.type == "Real"]
            + [v.name for v in outs if v.type == "Boolean"],
        )
        writers[name] = variables
    environ_loaded = dict(os.environ)
    maps_loaded = mapped_libpythons()
    log = {name: {out: [] for out in readers[name][2]} for name in slaves}

    def record():
        for name, slave in slaves.items():
            reals, bools, names = readers[name]
            values = list(slave.getReal(reals)) if reals else []
            values += [float(b) for b in slave.getBoolean(bools)] if bools else []
            for out, value in zip(names, values):
                log[name][out].append(value)

    links = []
    for a, out, b, inp in spec["connections"]:
        src = {v.name: v for v in read_model_description(spec["components"][a]).modelVariables}
        links.append((a, src[out].valueReference, b, writers[b][inp].valueReference))
    record()
    h, steps = spec["h"], round(spec["stop"] / spec["h"])
    for k in range(steps):
        t = k * h
        for a, vr_out, b, vr_in in links:
            slaves[b].setReal([vr_in], slaves[a].getReal([vr_out]))
        for slave in slaves.values():
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        record()
    for slave in slaves.values():
        slave.terminate()
        slave.freeInstance()
    for folder in folders:
        shutil.rmtree(folder, ignore_errors=True)
    changed = sorted(
        k
        for k in set(environ_before) | set(environ_loaded) | set(os.environ)
        if not (environ_before.get(k) == environ_loaded.get(k) == os.environ.get(k))
    )
    report = {
        "python": sys.version,
        "executable": sys.executable,
        "environ_changed": changed,
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
