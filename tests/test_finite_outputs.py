"""No output is ever NaN or infinite with status OK.

Every FMU refuses the numbers that would make its model not finite where they enter:
Real parameters beyond ±1e15 at initialization (named), a chain whose fastest mode or
decay is beyond 1e6 rad/s (named, with the bound), an input beyond ±1e15; a step
below 1 ns takes no new sample. A step that gives a non-finite output anyway is refused too.
"""

from __future__ import annotations

import math
import re

import pytest

from arcosim.errors import UserError
from arcosim.fmu.fmukit import FmuSlave, inp, out
from arcosim.fmu.fmukit.checks import FASTEST_RATE, LARGEST, SMALLEST_STEP
from arcosim.host.instance import FmuInstance


def outputs_finite(fmu: FmuInstance) -> bool:
    names = fmu.output_names()
    return all(math.isfinite(x) for x in fmu.reader(names)())


@pytest.mark.parametrize(
    ("name", "parameters", "phrase"),
    [
        ("ReactionTorqueObserver", {"J[1]": 1e300}, "parameter J[1] = 1e+300 is beyond ±1e+15"),
        ("ReactionTorqueObserver", {"J_mo": -1e200}, "parameter J_mo = -1e+200 is beyond"),
        (
            "ReactionTorqueObserver",
            {"mode": 2, "k[1]": 1e15},
            "parameters k[1] = 1e+15, k[2] = 0.1627 on J[1] = 0.000515299 make a mode of up to "
            "1.97e+09 rad/s",
        ),
        ("MotorChainPlant", {"k[1]": 1e15}, "on J_m = 2.09e-05 make a mode of up to 9.78e+09"),
        ("MotorChainPlant", {"B[2]": 1e3}, "make a decay of up to 3.88e+06 1/s"),
        ("MotorChainPlant", {"J_m": 1e300}, "parameter J_m = 1e+300 is beyond ±1e+15"),
        ("ExcitationSource", {"amplitude": 1e20}, "parameter amplitude = 1e+20 is beyond"),
    ],
)
def test_parameters_that_make_the_model_not_finite_are_refused_by_name(
    fmus, name, parameters, phrase
) -> None:
    with FmuInstance(fmus / f"{name}.fmu", "x") as fmu:
        with pytest.raises(UserError, match=re.escape(phrase)):
            fmu.initialize(parameters)
        assert fmu.do_step(0.0, 1e-3) == 2  # every step refused, never a NaN with OK


def test_the_bound_on_the_chain_follows_its_stated_rate(fmus) -> None:
    """Gershgorin's bound 2 (k_1 + k_2) / J_1 ≤ FASTEST_RATE² is where the refusal starts:
    just inside it the plant runs, just outside it refuses (J_1 = 1 kg·m², k_2 = 0)."""
    inside = FASTEST_RATE**2 / 2.0 * 0.99
    outside = FASTEST_RATE**2 / 2.0 * 1.01
    for k1, accepted in ((inside, True), (outside, False)):
        with FmuInstance(fmus / "MotorChainPlant.fmu", "x") as plant:
            chain = {"J_m": 1e3, "J[1]": 1.0, "k[1]": k1, "k[2]": 0.0, "k[3]": 0.0}
            if accepted:
                plant.initialize(chain)
                for k in range(20):
                    plant.set({"i_ref": 1.0})
                    assert plant.do_step(k * 1e-3, 1e-3) == 0
                assert outputs_finite(plant)
            else:
                with pytest.raises(UserError, match="make a mode of up to"):
                    plant.initialize(chain)


@pytest.mark.parametrize("name", ["ReactionTorqueObserver", "MotorChainPlant"])
def test_a_step_below_a_nanosecond_is_taken_and_inputs_beyond_the_range_are_refused(fmus, name):
    """A step below SMALLEST_STEP takes no new sample (see tests/test_small_steps.py)
    and leaves every output finite; an input beyond ±LARGEST is refused."""
    first_input = {"ReactionTorqueObserver": "i_a", "MotorChainPlant": "i_ref"}[name]
    with FmuInstance(fmus / f"{name}.fmu", "x") as fmu:
        fmu.initialize()
        assert 1e-308 < SMALLEST_STEP
        assert fmu.do_step(0.0, 1e-308) == 0
        assert not fmu.messages
        assert outputs_finite(fmu)
        fmu.set({first_input: 1e305})
        assert fmu.do_step(0.0, 1e-3) == 2
        assert f"input {first_input} = 1e+305 is beyond ±{LARGEST:g}" in fmu.messages[-1]
        fmu.set({first_input: 0.1})
        assert fmu.do_step(0.0, 1e-3) == 0  # the state was left as it was
        assert outputs_finite(fmu)


class Overflowing(FmuSlave):
    """A slave whose output overflows once its input passes 1e10 (x**40)."""

    @classmethod
    def declare(cls):
        return [inp("x", 0.0, "1", "input"), out("y", "1", "input to the 40th power")]

    def step(self, t: float, h: float) -> None:
        x = self.v[self.vr["x"]]
        self.v[self.vr["y"]] = math.inf if abs(x) > 1e10 else x**40


def test_a_step_with_a_non_finite_output_is_refused_and_so_is_every_later_one() -> None:
    slave = Overflowing(instance_name="overflow")
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    slave.v[slave.vr["x"]] = 2.0
    assert slave.do_step(0.0, 1e-3) is True
    slave.v[slave.vr["x"]] = 1e12  # finite, within the range: the output overflows
    assert slave.do_step(1e-3, 1e-3) is False
    assert "gave non-finite outputs (y)" in slave.problems[0]
    slave.v[slave.vr["x"]] = 2.0
    assert slave.do_step(1e-3, 1e-3) is False  # latched until a state is restored
