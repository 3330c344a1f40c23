"""The ActionReactionController FMU: valid, refuses bad goals at initialization, runs the
library's algorithm, and closes the loop around the plant FMU in both master orders."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from fmpy.validation import validate_fmu

from arcosim.errors import UserError
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control.controller import MotionController, design_controller
from arcosim.host.control_loop import control_loop
from arcosim.host.instance import FmuInstance
from tests.control_runs import BENCH_3, observer_params

H = 1e-3
COUNT = 2 * math.pi / defaults.ENCODER_CPR
MEASURED = ("i_a", "omega_m", "theta_m")


@pytest.fixture(scope="module")
def fmus(build_fmus):
    return build_fmus(3)


def test_the_controller_fmu_is_valid(fmus) -> None:
    assert not validate_fmu(str(fmus / "ActionReactionController.fmu"))


@pytest.mark.parametrize(
    "goals",
    [{"move_time": 0.0, "bandwidth": 0.0}, {"move_time": 1.0, "bandwidth": 5.0}],
    ids=["neither", "both"],
)
def test_move_time_and_bandwidth_exactly_one_or_fmi2error(fmus, goals: dict) -> None:
    with (
        FmuInstance(fmus / "ActionReactionController.fmu", "controller") as fmu,
        pytest.raises(UserError, match=r"move_time = .* and bandwidth = .*: set exactly one"),
    ):
        fmu.initialize(goals)
    assert any(m.startswith("error") for m in fmu.messages)


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"hold_dither": -0.5}, r"parameter hold_dither = -0.5 must be >= 0"),
        (
            {"hold_dither": 0.9, "i_max": 0.5},
            r"hold_dither = 0.9 counts needs ±0.364 A at rest, more than half of i_max = 0.5 A",
        ),
    ],
    ids=["negative", "more than half of i_max"],
)
def test_a_dither_it_cannot_run_is_fmi2error_naming_it(fmus, settings: dict, message) -> None:
    with (
        FmuInstance(fmus / "ActionReactionController.fmu", "controller") as fmu,
        pytest.raises(UserError, match=message),
    ):
        fmu.initialize(settings)
    assert any(m.startswith("error") for m in fmu.messages)


def _run(fmus, ordering: str, stop: float, plant: dict | None = None):
    """A 1 rad move of the bench's last mass, controller and plant FMUs in fmpy."""
    steps = round(stop / H)
    with (
        FmuInstance(fmus / "ActionReactionController.fmu", "controller") as controller,
        FmuInstance(fmus / "MotorChainPlant.fmu", "plant") as plant_fmu,
    ):
        return control_loop(
            controller,
            plant_fmu,
            [1.0] * steps,
            H,
            [*MEASURED, "theta_m_true", "theta[3]"],
            plant_parameters=plant,
            ordering=ordering,
        )


@pytest.mark.slow
@pytest.mark.parametrize("ordering", ["sequential", "parallel"])
def test_the_fmu_runs_the_library_controller_and_settles(fmus, ordering: str) -> None:
    """The FMU's commands are the library's on the same samples (to rounding), and the
    loop moves the last mass 1 rad into ±1 % by 2.5 s with either master order."""
    run = _run(fmus, ordering, 4.0)
    design = design_controller(observer_params(**BENCH_3), h=H)
    library = MotionController(design)
    samples = zip(*(run[f"plant.{name}"] for name in MEASURED))
    expected = [library.step(H, 1.0, *map(float, sample)) for sample in samples]
    # the last sample ends the run: the controller never took it
    np.testing.assert_allclose(run["controller.i_ref"][:-1], expected[:-1], rtol=1e-9, atol=1e-12)
    last = run["plant.theta[3]"]
    outside = np.flatnonzero(np.abs(last - 1.0) > 0.01)
    assert run.time[outside[-1]] <= 2.5
    tail = run.time >= 3.0  # the motor at rest: 4 counts (sequential), 13 (parallel) in 6 s runs
    assert np.ptp(run["plant.theta_m"][tail]) <= 16 * COUNT + 1e-12
    assert np.abs(run["controller.i_ref"]).max() <= defaults.I_MAX


@pytest.mark.slow
def test_simulate_move_prints_how_the_move_went(fmus, capsys) -> None:
    from arcosim.cli import main

    assert (
        main(["simulate", "--scenario", "move", "--duration", "3", "--json", "--fmus", str(fmus)])
        == 0
    )
    summary = json.loads(capsys.readouterr().out)
    assert 1.0 < summary["settling_1pct"] <= 2.5
    assert abs(summary["final_error"]) < 0.01
    assert (
        main(
            [
                "simulate",
                "--scenario",
                "move",
                "--set",
                "controller.bandwidth=5",
                "--fmus",
                str(fmus),
            ]
        )
        == 2
    )
    assert "move_time = 1.0 s and bandwidth = 5.0 rad/s" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("parameter_set", ["move", "move-load"])
def test_the_closed_loop_ssp_moves_the_last_mass(fmus, parameter_set: str) -> None:
    """MotionControl.ssp in the SSP runner (Jacobi: the command one step late), with a
    constant load of −5 mN·m on the last mass in ``move-load``."""
    from arcosim.host.ssp import run_ssp

    run = run_ssp(fmus / "MotionControl.ssp", parameter_set, stop=4.0)
    last = run["plant.theta[3]"]
    outside = np.flatnonzero(np.abs(last - 1.0) > 0.01)
    assert run.time[outside[-1]] <= 2.5
    assert abs(last[-1] - 1.0) < 0.005
