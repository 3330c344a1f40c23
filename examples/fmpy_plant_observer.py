"""The plant FMU drives the observer FMU in plain fmpy: the reaction torque the observer
estimates from the motor's current and encoder alone, beside the plant's true one.

Run: ``python examples/fmpy_plant_observer.py`` (builds the FMUs for 3 masses into the
per-user cache on first use; any FMI 2.0 host connects them the same way).
"""

import numpy as np
from fmpy import extract, instantiate_fmu, read_model_description

import arcosim

folder, h = arcosim.ensure_built(3), 1e-3  # the FMUs' folder; the step (s)
fmus, refs = {}, {}
for name in ("MotorChainPlant", "ReactionTorqueObserver"):
    path, description = str(folder / f"{name}.fmu"), read_model_description(folder / f"{name}.fmu")
    fmus[name] = fmu = instantiate_fmu(extract(path), description, "CoSimulation")
    refs[name] = {v.name: v.valueReference for v in description.modelVariables}
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
plant, observer, p, o = *fmus.values(), refs["MotorChainPlant"], refs["ReactionTorqueObserver"]
error, torque = [], []
for k in range(2000):  # 2 s of a 1 A sine at 1 Hz on the current reference
    plant.setReal([p["i_ref"]], [np.sin(2 * np.pi * k * h)])
    plant.doStep(k * h, h)
    signals = plant.getReal([p["i_a"], p["omega_m"], p["theta_m"]])
    observer.setReal([o["i_a"], o["omega_m"], o["theta_m"]], signals)
    observer.doStep(k * h, h)
    estimate, truth = observer.getReal([o["tau_reac_hat"]])[0], plant.getReal([p["tau_reac"]])[0]
    if k * h >= 0.5:  # after the disturbance observer has settled
        error.append(estimate - truth)
        torque.append(truth)
rms = np.sqrt(np.mean(np.square(error))), np.sqrt(np.mean(np.square(torque)))
print(f"tau_reac_hat - tau_reac: {rms[0]:.2e} N.m rms against {rms[1]:.2e} N.m of tau_reac")
for fmu in fmus.values():
    fmu.terminate()
    fmu.freeInstance()
