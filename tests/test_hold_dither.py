"""The hold's dither: its current and path, the motor's angle below a count, the design's
refusals and the controller's use of it (``arcosim.fmu.flexchain.control.hold_dither``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arcosim.fmu.flexchain.control.controller import MotionController
from arcosim.fmu.flexchain.control.design import design_controller
from arcosim.fmu.flexchain.control.hold_dither import HoldDither
from tests.control_runs import BENCH_2, observer_params

H = 1e-3
COUNT = 2 * math.pi / 2000  # one encoder count (rad)


def _design(**changes):
    """The bench's two-mass chain at 1 ms; ``changes`` overrides chain parameters."""
    goals = {k: changes.pop(k) for k in ("i_max", "hold_dither") if k in changes}
    return design_controller({**observer_params(**BENCH_2), **changes}, h=H, **goals)


def test_the_free_motor_follows_the_dithers_path() -> None:
    """A motor alone (J_m θ̈ = k_t i, exact over each step under a held current) driven by
    the dither's current moves along ``path``, centred on its start, ``hold_dither``
    counts peak to peak at the samples, over 125 Hz (8 steps)."""
    design = _design(f_c=0.0)
    dither = HoldDither(design)
    dither.start(0.0, 0.0)
    theta = omega = 0.0
    samples, paths = [], []
    for _ in range(3 * design.dither_steps):
        current, friction = dither.command(H)
        assert friction == 0.0  # nothing to cancel on a frictionless motor
        accel = design.k_t * current / design.J_m
        theta += (omega + 0.5 * accel * H) * H
        omega += accel * H
        samples.append(theta)
        paths.append(dither.path)
    assert design.dither_steps == 8
    assert np.allclose(samples, paths, rtol=0, atol=1e-15)
    assert np.ptp(samples) == pytest.approx(design.hold_dither * COUNT, rel=1e-9)
    assert np.mean(samples[-8:]) == pytest.approx(dither.mean, abs=1e-15)
    assert abs(omega) < 1e-12 and samples[-1] == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("shift", [0.0, 0.5], ids=["edges at whole counts", "half a count on"])
def test_the_dither_tells_where_the_motor_sits_inside_its_count(shift: float) -> None:
    """A motor at rest at 21 places across a count, dithered: the observer's angle,
    averaged over the last period, within 0.25 count of the place (the eight samples of
    a period lie 0–0.9 count apart, and the mean of their quantization errors stays
    within 0.21 count, worked out from the floor), where the reading's middle of the
    count is up to half a count off."""
    design = _design(f_c=0.0)
    worst = worst_plain = 0.0
    for place in (np.arange(21) / 20.0 + shift) * COUNT:
        dither = HoldDither(design)
        dither.start(place, 0.0)
        estimates = []
        for _ in range(200):
            current, _ = dither.command(H)
            true = place + dither.path - dither.mean
            reading = math.floor(true / COUNT + 1e-9) * COUNT
            angle = dither.measure(H, current, reading + COUNT / 2)
            estimates.append(angle)
        worst = max(worst, abs(np.mean(estimates[-8:]) - place))
        plain = math.floor(place / COUNT + 1e-9) * COUNT + COUNT / 2
        worst_plain = max(worst_plain, abs(plain - place))
    assert worst < 0.25 * COUNT
    assert worst_plain > 0.45 * COUNT


def test_the_design_refuses_a_dither_it_cannot_run() -> None:
    with pytest.raises(ValueError, match=r"hold_dither = -1 counts must be ≥ 0 \(0 = off\)"):
        _design(hold_dither=-1)
    with pytest.raises(ValueError, match="hold_dither = nan"):
        _design(hold_dither=math.nan)
    # ±0.364 A at 0.9 count: more than half of a 0.5 A limit
    with pytest.raises(ValueError, match=r"needs ±0.364 A .* half of i_max = 0.5 A"):
        _design(i_max=0.5, hold_dither=0.9)
    assert _design(i_max=0.5, hold_dither=0.0).dither_current == 0.0
    assert _design(encoder_cpr=0).dither_current == 0.0  # an exact angle needs none


def test_the_controller_dithers_at_rest_only() -> None:
    """At rest with no move the dither starts half a move time in (±A about the hold's
    current); a move stops it at once; with ``hold_dither`` 0 there is none."""
    for counts in (0.9, 0.0):
        design = _design(hold_dither=counts, f_c=0.0)
        controller = MotionController(design)
        here = controller.theta0  # the target where the estimates start: no move
        commands = [0.0]
        for _ in range(700):  # the motor stays in its count, the current as commanded
            commands.append(controller.step(H, here, commands[-1], 0.0, 0.0))
        commands = commands[1:]
        jumps = np.abs(np.diff(commands))  # A per step
        assert jumps[:498].max() < 1e-3
        if counts:
            square = jumps[520:] > design.dither_current
            assert np.flatnonzero(square).tolist() == list(range(0, 179, 4))
            assert jumps[520:][square] == pytest.approx(2 * design.dither_current, rel=0.05)
            assert controller.dither is not None
            controller.step(H, 1.0, commands[-1], 0.0, 0.0)  # a move starts
            assert controller.dither is None
        else:
            assert jumps.max() < 1e-3 and controller.dither is None
