"""The ExcitationSource FMU: the same signals as arcosim.experiments.current_commands, in
any host."""

from __future__ import annotations

import re

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from arcosim.errors import UserError
from arcosim.experiments import current_commands
from arcosim.fmu.flexchain.waveforms import log_spaced
from arcosim.host.instance import FmuInstance


@pytest.fixture(scope="module")
def source(build_fmus):
    return build_fmus(3) / "ExcitationSource.fmu"


# The FMU evaluates at t + h, offline code at k h: the times differ by an ulp, so the
# signals agree to rounding, not bit for bit.
SAME = {"rtol": 1e-12, "atol": 1e-15}


def run_source(path, parameters: dict, steps: int, h: float = 1e-3) -> np.ndarray:
    """The source's i_ref after initialization and after each step."""
    with FmuInstance(path, "source") as fmu:
        fmu.initialize(parameters)
        read = fmu.reader(["i_ref"])
        values = [read()[0]]
        for k in range(steps):
            assert fmu.do_step(k * h, h) == 0, fmu.messages
            values.append(read()[0])
        assert not fmu.messages
    return np.array(values)


def test_source_validates(source) -> None:
    assert validate_fmu(str(source)) == []


def test_rigid_maneuver_is_the_offline_one(source) -> None:
    t = np.arange(3001) * 1e-3
    np.testing.assert_allclose(
        run_source(source, {}, 3000), current_commands.rigid_maneuver(t), **SAME
    )


def test_multisine_is_the_offline_one(source) -> None:
    t = np.arange(2001) * 1e-3
    got = run_source(source, {"signal": 1, "amplitude": 0.3, "lines": 6, "seed": 4}, 2000)
    want = current_commands.multisine(t, 0.3, np.array(log_spaced(2.1, 120.0, 6)), seed=4)
    np.testing.assert_allclose(got, want, **SAME)


def test_chirp_is_the_offline_one_and_stops(source) -> None:
    t = np.arange(2001) * 1e-3
    got = run_source(
        source,
        {
            "signal": 2,
            "amplitude": 0.2,
            "frequency": 5.0,
            "frequency_end": 50.0,
            "duration": 1.5,
            "offset": 0.01,
        },
        2000,
    )
    np.testing.assert_allclose(got, 0.01 + current_commands.chirp(t, 0.2, 5.0, 50.0, 1.5), **SAME)
    assert np.all(got[t > 1.5] == 0.01)


def test_filtered_random_is_the_offline_one(source) -> None:
    got = run_source(
        source, {"signal": 3, "amplitude": 0.15, "frequency_end": 150.0, "seed": 3}, 2000
    )
    want = current_commands.filtered_random(np.arange(1, 2001) * 1e-3, 0.15, 150.0, seed=3)
    np.testing.assert_allclose(got[1:], want, **SAME)


@pytest.mark.parametrize(
    ("parameters", "phrase"),
    [
        ({"signal": 9}, "signal = 9 is not allowed"),
        ({"frequency": 0.0}, "frequency = 0.0 must be > 0"),
        ({"ramp_periods": 5}, "two ramps must fit"),
        ({"lines": 0}, "lines = 0 must be >= 1"),
    ],
)
def test_bad_source_parameters_are_refused(source, parameters, phrase) -> None:
    with FmuInstance(source, "source") as fmu:
        with pytest.raises(UserError, match=re.escape(phrase)):  # fmi2Error, not fatal
            fmu.initialize(parameters)
        assert fmu.do_step(0.0, 1e-3) == 2
        assert any(phrase in m for m in fmu.messages), fmu.messages
