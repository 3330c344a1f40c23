"""FMU state: get → step 100 → set → step 100 gives bit-identical outputs, and a
serialized state restored in a new instance does too (every filter and
accumulator included)."""

from __future__ import annotations

import math

import pytest

from arcosim.host.instance import FmuInstance


def inputs_at(k: int) -> dict[str, float]:
    """A deterministic, rich input sequence (for either FMU)."""
    t = k * 1e-3
    return {
        "i_ref": 0.4 * math.sin(9 * t) + 0.2 * math.sin(71 * t),
        "i_a": 0.3 * math.sin(5 * t) + 0.01 * math.sin(300 * t),
        "omega_m": 4 * math.cos(5 * t) + 0.5 * math.sin(40 * t),
        "theta_m": 0.8 * math.sin(5 * t),
    }


def run(fmu: FmuInstance, start: int, steps: int) -> list[list[float]]:
    names = [n for n in ("i_ref", "i_a", "omega_m", "theta_m") if n in fmu.variables]
    read = fmu.reader(fmu.output_names())
    rows = []
    for k in range(start, start + steps):
        fmu.set({n: inputs_at(k)[n] for n in names})
        assert fmu.do_step(k * 1e-3, 1e-3) == 0, fmu.messages
        rows.append(read())
    return rows


CASES = [
    ("MotorChainPlant", {}),
    ("MotorChainPlant", {"current_bandwidth": 500.0}),
    ("ReactionTorqueObserver", {"mode": 0}),
    ("ReactionTorqueObserver", {"mode": 1, "f_c": 2e-3}),
    ("ReactionTorqueObserver", {"mode": 2}),
    ("ReactionTorqueObserver", {"mode": 2, "estimator": 1, "load_mass": 3}),
    ("ReactionTorqueObserver", {"mode": 2, "estimator": 1, "link_modes": 2}),
    ("ReactionTorqueObserver", {"mode": 2, "tracking": 1}),
    ("ExcitationSource", {"signal": 3}),
    ("ExcitationSource", {"signal": 1}),
    ("ActionReactionController", {}),
]


@pytest.mark.parametrize(("name", "parameters"), CASES)
def test_get_step_set_step_is_bit_identical(build_fmus, name, parameters) -> None:
    with FmuInstance(build_fmus(3) / f"{name}.fmu", "a") as fmu:
        fmu.initialize(parameters)
        run(fmu, 0, 60)
        state = fmu.slave.getFMUstate()
        first = run(fmu, 60, 100)
        fmu.slave.setFMUstate(state)
        again = run(fmu, 60, 100)
        fmu.slave.setFMUstate(state)  # the same state twice: it did not change
        third = run(fmu, 60, 100)
        fmu.slave.freeFMUstate(state)
    assert first == again == third
    assert first[0] != first[-1]


@pytest.mark.parametrize(("name", "parameters"), CASES)
def test_serialized_state_continues_in_a_new_instance(build_fmus, name, parameters) -> None:
    path = build_fmus(3) / f"{name}.fmu"
    with FmuInstance(path, "source") as fmu:
        fmu.initialize(parameters)
        run(fmu, 0, 60)
        state = fmu.slave.getFMUstate()
        data = fmu.slave.serializeFMUstate(state)
        fmu.slave.freeFMUstate(state)
        expected = run(fmu, 60, 100)
    with FmuInstance(path, "copy") as fmu:
        fmu.initialize()  # defaults: the state brings the parameters and everything else
        restored = fmu.slave.deSerializeFMUstate(data)
        fmu.slave.setFMUstate(restored)
        fmu.slave.freeFMUstate(restored)
        assert run(fmu, 60, 100) == expected


def test_load_torque_states_round_trip(build_fmus) -> None:
    """The load torque observer's own states (d, the output low-pass) are in the state:
    restored into a new instance, tau_load_hat continues bit for bit, and it moves."""
    path = build_fmus(3) / "ReactionTorqueObserver.fmu"
    parameters = {"mode": 2, "estimator": 1, "load_mass": 3}
    with FmuInstance(path, "source") as fmu:
        fmu.initialize(parameters)
        run(fmu, 0, 60)
        state = fmu.slave.getFMUstate()
        data = fmu.slave.serializeFMUstate(state)
        fmu.slave.freeFMUstate(state)
        column = fmu.output_names().index("tau_load_hat")
        expected = [row[column] for row in run(fmu, 60, 100)]
    assert len(set(expected)) > 50 and all(x != 0.0 for x in expected)
    with FmuInstance(path, "copy") as fmu:
        fmu.initialize()  # load_mass = 0 here: the state brings the estimator back
        restored = fmu.slave.deSerializeFMUstate(data)
        fmu.slave.setFMUstate(restored)
        fmu.slave.freeFMUstate(restored)
        assert [row[column] for row in run(fmu, 60, 100)] == expected
