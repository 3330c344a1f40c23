"""The hold near an encoder edge (``hold_edge``), on hand-worked sequences.

A 2000-count encoder (q = 2π/2000 rad), the motor's mean kept within 0.3 count of an
edge, the other edge taken 0.1 count past the middle; the low-pass open (10⁹ rad/s)
unless a test is about it.
"""

from __future__ import annotations

import doctest
import math

import pytest

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.control import hold_edge
from arcosim.fmu.flexchain.control.hold_edge import HoldEdge

Q = 2 * math.pi / 2000  # one count (rad)


def keeper(bandwidth: float = 1e9) -> HoldEdge:
    return HoldEdge(Q, near=0.3, switch=0.1, bandwidth=bandwidth)


def test_the_module_examples_run() -> None:
    assert doctest.testmod(hold_edge).failed == 0


@pytest.mark.parametrize("past", [0.0, 0.2, 0.29, 0.71, 0.8, 1.0])
def test_near_an_edge_the_target_stays(past: float) -> None:
    """Within 0.3 count of either edge of count 318: no shift."""
    assert keeper().step(1e-3, (318 + past) * Q, 0.0) == 0.0


@pytest.mark.parametrize(("past", "shift"), [(0.4, -0.1), (0.45, -0.15), (0.55, 0.15), (0.6, 0.1)])
def test_the_first_edge_is_the_nearer_and_the_shift_the_least(past: float, shift: float) -> None:
    """The first step takes the nearer edge (318 below 0.5 count past it, 319 above) and
    moves the target by the least that brings the motor within 0.3 count of it."""
    edge = keeper()
    assert edge.step(1e-3, (318 + past) * Q, 0.0) / Q == pytest.approx(shift, abs=1e-9)
    rest = (edge.needed + edge.shift - edge.edge) / Q  # where the motor's mean rests
    assert rest == pytest.approx(0.3 if past < 0.5 else -0.3, abs=1e-9)


def test_the_edge_is_kept_until_past_the_middle_by_switch() -> None:
    """From 0.45 count past edge 318 up to 0.59 the shift grows (−0.15 → −0.29 count) on
    the same edge; at 0.65 edge 319 is taken; coming back, 319 is kept down to 0.41."""
    edge = keeper()
    passes = (0.45, 0.55, 0.59, 0.65, 0.55, 0.41)
    shifts = [edge.step(1e-3, (318 + p) * Q, 0.0) / Q for p in passes]
    assert shifts == pytest.approx([-0.15, -0.25, -0.29, 0.05, 0.15, 0.29], abs=1e-9)
    assert edge.step(1e-3, 318.35 * Q, 0.0) / Q == pytest.approx(-0.05, abs=1e-9)  # 318 again


def test_any_edge_of_the_grid_gives_the_same_shift() -> None:
    """The edge given is one of the grid's: counts 5 or −40 away name the same edges."""
    shifts = [keeper().step(1e-3, 318.42 * Q, k * Q) for k in (0, 5, -40, 318)]
    assert shifts == pytest.approx([shifts[0]] * 4, abs=1e-15) and shifts[0] < 0.0


def test_the_needed_angle_is_low_passed() -> None:
    """At 2 rad/s and 1 ms steps, a step of the needed angle from 318.2 to 318.5 counts
    reaches the shift through the low-pass: (1 − e^{−0.002}) of the way on the next step."""
    edge = keeper(bandwidth=2.0)
    assert edge.step(1e-3, 318.2 * Q, 0.0) == 0.0
    edge.step(1e-3, 318.5 * Q, 0.0)
    assert edge.needed / Q == pytest.approx(318.2 + 0.3 * (1 - math.exp(-2e-3)), rel=1e-12)
    for _ in range(5000):  # 5 s: ten time constants
        edge.step(1e-3, 318.5 * Q, 0.0)
    assert edge.shift / Q == pytest.approx(-0.2, abs=1e-4)  # e^−10 of 0.3 count left


def test_reset_forgets_the_edge() -> None:
    edge = keeper()
    edge.step(1e-3, 318.45 * Q, 0.0)
    edge.reset()
    assert (edge.shift, edge.edge) == (0.0, None)
    assert edge.step(1e-3, 318.55 * Q, 0.0) / Q == pytest.approx(0.15, abs=1e-9)  # 319 now


def test_the_controller_takes_its_settings_from_defaults(monkeypatch) -> None:
    """``hold_edge(cpr)`` reads the defaults when called (a test or a user may change
    them); no encoder, no edge."""
    monkeypatch.setattr(defaults, "HOLD_EDGE_NEAR", 0.4)
    made = hold_edge.hold_edge(4096)
    assert made.near == 0.4 and made.count == pytest.approx(2 * math.pi / 4096)
    assert hold_edge.hold_edge(0) is None


def test_near_half_a_count_or_more_turns_it_off() -> None:
    """``near`` 0.5: never a shift, past the middle of the count too (the edge kept up to
    0.6 count would otherwise shift by up to 0.1)."""
    edge = HoldEdge(Q, near=0.5, switch=0.1, bandwidth=1e9)
    shifts = [edge.step(1e-3, p * Q, 0.0) for p in (318.45, 318.55, 318.58, 318.5)]
    assert shifts == [0.0] * 4 and edge.edge is None
