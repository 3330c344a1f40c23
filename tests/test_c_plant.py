"""The compiled plant FMU against its reference, the Python plant
(plant_models/motorchain): same outputs to 1e-9 of each signal's range over runs
that cross every friction regime, with the current loop, external torques, the
encoder, current noise and varying step sizes."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.build.cplant import plant_class
from arcosim.host.instance import FmuInstance

CASES = [
    (3, {}),  # the bench: Coulomb friction, 2000-count encoder, current noise
    (3, {"current_bandwidth": 400.0, "seed": 11, "f_c": 0.004}),
    (1, {"encoder_cpr": 0, "attached": False}),
    (5, {"k[2]": 0.05, "B[4]": 0.0, "f_c": 0.0}),
]


def reference_plant(n: int, parameters: dict):
    """The Python plant class for n masses, instantiated and initialized in-process."""
    plant = plant_class(n)(instance_name="reference")
    plant.setup_experiment(0.0)
    for name, value in parameters.items():
        plant.v[plant.vr[name]] = value
    plant.enter_initialization_mode()
    plant.exit_initialization_mode()
    assert not plant.problems, plant.problems
    return plant


@pytest.mark.slow
@pytest.mark.parametrize(("n", "parameters"), CASES)
def test_c_plant_matches_the_python_reference(build_fmus, n: int, parameters: dict) -> None:
    reference = reference_plant(n, parameters)
    outputs = [v.name for v in reference.variables if v.causality == "output"]
    rng = np.random.default_rng(n)
    steps = 2500
    h = np.where(np.arange(steps) % 7 == 3, 5e-4, 1e-3)  # varying step sizes
    t = np.concatenate([[0.0], np.cumsum(h)])
    i_ref = 0.3 * np.sin(9.0 * t[:-1]) + 0.05 * rng.standard_normal(steps)  # reversals, stops
    i_ref[1200:1500] = 0.0  # the motor comes to rest and sticks
    tau = 0.005 * rng.standard_normal((steps, n))
    expected, got = [], []
    with FmuInstance(build_fmus(n) / "MotorChainPlant.fmu", "compiled") as plant:
        plant.initialize(parameters)
        for k in range(steps):
            inputs = {"i_ref": i_ref[k], **{f"tau_ext[{j + 1}]": tau[k, j] for j in range(n)}}
            for name, value in inputs.items():
                reference.v[reference.vr[name]] = float(value)
            plant.set(inputs)
            assert reference.do_step(t[k], h[k]), reference.problems
            assert plant.do_step(t[k], h[k]) == 0, plant.messages
            expected.append([reference.v[reference.vr[name]] for name in outputs])
            got.append(plant.get(outputs))
    expected, got = np.array(expected), np.array(got)
    scale = np.maximum(np.abs(expected).max(axis=0), 1e-300)
    worst = np.abs(got - expected).max(axis=0) / scale
    assert worst.max() <= 1e-9, dict(zip(outputs, worst))
    assert np.ptp(expected[:, outputs.index("omega_m_true")]) > 0.1  # the run did move


def test_c_plant_state_survives_serialization_into_a_new_instance(plant_fmu) -> None:
    """The serialized state of the compiled plant continues bit for bit elsewhere."""
    with FmuInstance(plant_fmu, "a") as a, FmuInstance(plant_fmu, "b") as b:
        a.initialize({"current_bandwidth": 300.0})
        b.initialize({"current_bandwidth": 300.0})
        for k in range(40):
            a.set({"i_ref": 0.3})
            assert a.do_step(k * 1e-3, 1e-3) == 0
        blob = a.slave.serializeFMUstate(a.slave.getFMUstate())
        b.slave.setFMUstate(b.slave.deSerializeFMUstate(blob))
        for k in range(40, 80):
            for fmu in (a, b):
                fmu.set({"i_ref": -0.2})
                assert fmu.do_step(k * 1e-3, 1e-3) == 0
        names = ["theta_m", "omega_m", "i_a", "theta[3]"]
        assert a.get(names) == b.get(names)
        with pytest.raises(Exception):  # noqa: B017 - fmpy raises its FMICallException
            b.slave.deSerializeFMUstate(blob[:-1])
        assert any("fmi2DeSerializeFMUstate refused" in m for m in b.messages), b.messages
