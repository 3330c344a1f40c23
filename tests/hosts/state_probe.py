"""Feed bad serialized states to an FMU, then step, terminate and free it; report as JSON.

    python state_probe.py FMU OTHER_FMU OUT.json '["a positive parameter"]'

Run in a subprocess (a crash shows as the process dying, not as a failed assertion in
the test process). For FMU: serializes a good state, then offers fmi2DeSerializeFMUstate
truncated bytes, random bytes, ``{}``, a flipped byte, a state of OTHER_FMU, and the
good state; after each refusal the instance must step. Also reports
fmi2GetBooleanStatus(fmi2Terminated) after a refused step and after refused parameters.
"""

from __future__ import annotations

import json
import random
import shutil
import sys
import tempfile

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    defaultCallbacks,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Terminated,
)

messages: list[str] = []


def _log(env, instance, status, category, message) -> None:
    messages.append(f"[{status}] " + message.decode(errors="replace"))


callbacks = fmi2CallbackFunctions()
callbacks.logger = fmi2CallbackLoggerTYPE(_log)
callbacks.allocateMemory = defaultCallbacks.allocateMemory
callbacks.freeMemory = defaultCallbacks.freeMemory


def open_slave(fmu: str, name: str, parameters: dict | None = None):
    md = read_model_description(fmu)
    folder = extract(fmu, unzipdir=tempfile.mkdtemp(prefix="probe_"))
    variables = {v.name: v for v in md.modelVariables}
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=folder,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    slave.instantiate(loggingOn=True, callbacks=callbacks)
    slave.setupExperiment(startTime=0.0)
    for var, value in (parameters or {}).items():
        slave.setReal([variables[var].valueReference], [value])
    slave.enterInitializationMode()
    status = status_of(slave.exitInitializationMode)
    return slave, folder, status


def status_of(call) -> int:
    try:
        call()
    except FMICallException as error:
        return int(error.status)
    return 0


def terminated(slave) -> tuple[int, bool | None]:
    try:
        return 0, slave.getBooleanStatus(fmi2Terminated)
    except FMICallException as error:
        return int(error.status), None


def main(fmu: str, other: str, out: str) -> None:
    report: dict[str, object] = {}
    slave, folder, _ = open_slave(fmu, "probe")
    report["terminated_at_start"] = terminated(slave)
    for k in range(3):
        slave.doStep(k * 1e-3, 1e-3)
    good = bytes(slave.serializeFMUstate(slave.getFMUstate()))
    other_slave, other_folder, _ = open_slave(other, "other")
    foreign = bytes(other_slave.serializeFMUstate(other_slave.getFMUstate()))
    other_slave.terminate()
    other_slave.freeInstance()
    flipped = bytearray(good)
    flipped[len(good) // 2] ^= 0x01
    rng = random.Random(1)
    cases = {
        "truncated": good[: len(good) // 2],
        "random": bytes(rng.randrange(256) for _ in range(len(good))),
        "empty_json": b"{}",
        "flipped_byte": bytes(flipped),
        "other_fmu": foreign,
        "empty": b"",
    }
    t = 3e-3
    results = {}
    for name, data in cases.items():
        before = len(messages)
        status = status_of(lambda d=data: slave.deSerializeFMUstate(d))
        step = status_of(lambda t=t: slave.doStep(t, 1e-3))
        t += 1e-3
        results[name] = {"status": status, "step": step, "log": messages[before:]}
    restored = slave.deSerializeFMUstate(good)
    slave.setFMUstate(restored)
    results["good"] = {"step": status_of(lambda: slave.doStep(3e-3, 1e-3))}
    report["states"] = results
    report["bad_step"] = status_of(lambda: slave.doStep(0.5, 1e-3))  # wrong time
    report["terminated_after_refused_step"] = terminated(slave)
    slave.terminate()
    slave.freeInstance()
    report["freed"] = True
    # refused parameters: exitInitializationMode's status, then Terminated, then a step
    bad, bad_folder, status = open_slave(fmu, "bad", {next(iter(json.loads(sys.argv[4]))): -1.0})
    report["bad_parameters"] = {
        "exit_status": status,
        "terminated": terminated(bad),
        "step": status_of(lambda: bad.doStep(0.0, 1e-3)),
        "terminated_after_step": terminated(bad),
    }
    bad.terminate()
    bad.freeInstance()
    shutil.rmtree(bad_folder, ignore_errors=True)
    for f in (folder, other_folder):
        shutil.rmtree(f, ignore_errors=True)
    with open(out, "w") as f:
        json.dump(report, f)


if __name__ == "__main__":
    main(*sys.argv[1:4])
