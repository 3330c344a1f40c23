"""``fmu_src/flexchain/`` installed as ``arcosim.fmu.flexchain``: the algorithms of the
action-reaction method for flexible drives, in pure Python.

Standard library only: the package is bundled into the FMUs and runs in any host that has
a Python 3, and the offline tools (``arcosim.identification``, the experiments, the
benchmarks) run the same code. Modules, in the order data flows:

Settings

* :mod:`~arcosim.fmu.flexchain.defaults` — every default of the project (SI units).
* :mod:`~arcosim.fmu.flexchain.codes` — the codes of modes, estimators and signals (enums).

Foundations

* :mod:`~arcosim.fmu.flexchain.linalg` — small dense matrices as lists of lists, the
  matrix exponential and the zero-order hold.
* :mod:`~arcosim.fmu.flexchain.chain` — the motor–spring–mass chain: its values
  (``Chain``) and its linear model.
* :mod:`~arcosim.fmu.flexchain.driven_chain` — the load chain driven by the motor angle,
  exact over each step.
* :mod:`~arcosim.fmu.flexchain.filters` — G(s) = g/(s + g), exact for the step taken.

The signals

* :mod:`~arcosim.fmu.flexchain.waveforms` — the current commands: rigid maneuver,
  multi-sine, chirp, filtered noise.
* :mod:`~arcosim.fmu.flexchain.noise` — reproducible noise and the encoder model (the
  plant's sensors).

The observer

* :mod:`~arcosim.fmu.flexchain.dob` — disturbance and reaction torque observers (eq. 8–16).
* :mod:`~arcosim.fmu.flexchain.least_squares` — normal equations, one sample at a time.
* :mod:`~arcosim.fmu.flexchain.self_identification` — mode 0: the actuator's terms.
* :mod:`~arcosim.fmu.flexchain.rigid_identification` — mode 1: k and B from a rigid
  maneuver.
* :mod:`~arcosim.fmu.flexchain.recursion` — mode 2, estimator 0: the paper's recursion.
* :mod:`~arcosim.fmu.flexchain.model_observer` — mode 2, estimator 1: the model-based
  observer and the noise levels its Kalman design solves.
* :mod:`~arcosim.fmu.flexchain.load_observer` — the same with the torque on one load mass.
* :mod:`~arcosim.fmu.flexchain.link_observer` — the same on a flexible link's modes: the
  tip's deflection.
* :mod:`~arcosim.fmu.flexchain.chain_tracker` — mode 2, estimator 1, ``tracking``: the
  chain's springs, dampers and the motor friction tracked in service, their σ, the drift
  alarm.
* :mod:`~arcosim.fmu.flexchain.observer` — the settings, their rules
  (``ObserverSettings.problems``) and the observer that runs the configured mode.

The controller

* :mod:`~arcosim.fmu.flexchain.riccati` — the discrete Riccati equation (the Kalman gains'
  and the state feedback's one solver).
* :mod:`~arcosim.fmu.flexchain.control` — the motion controller (its package lists its
  modules).
"""

import importlib

#: Public name → the module that defines it, relative to this package (the package's
#: API; ``tests/test_public_api.py``). Loaded on first use, so an FMU imports only what
#: it runs. A name whose module is ``.name`` itself is that module (``defaults``).
_API: dict[str, str] = {
    "defaults": ".defaults",
    "STEP": ".defaults",
    "G_DIST": ".defaults",
    "ENCODER_CPR": ".defaults",
    "I_NOISE_STD": ".defaults",
    "Mode": ".codes",
    "Estimator": ".codes",
    "spring_matrix": ".chain",
    "gaussian": ".noise",
    "quantize": ".noise",
    "Observer": ".observer",
    "NoiseModel": ".model_observer",
    "step_model": ".model_observer",
    "NOISE_RANGE": ".model_observer",
    "NOISE_RATIO": ".model_observer",
    "RefinedEstimator": ".control.refined_estimator",
    "PARTS": ".control.controller",
    "LINK_ELEMENTS": ".defaults",
}
__all__ = list(_API)


def __getattr__(name: str) -> object:
    if name not in _API:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = importlib.import_module(_API[name], __name__)
    value = module if _API[name] == f".{name}" else getattr(module, name)
    globals()[name] = value
    return value
