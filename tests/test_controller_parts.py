"""The controller's parts switched off one by one (``MotionController(design, without=…)``):
each switch changes the commands of a move and its hold, an unknown part is refused, and
the benchmarks' ``--without`` names only the controller's parts."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.errors import UserError
from arcosim.fmu.flexchain.control.controller import PARTS, MotionController, design_controller
from benchmarks.control_accuracy import parse_without
from tests.control_runs import BENCH_2, closed_loop

#: The model the runs are designed on: every J 10 % high and k 10 % low, so that the refit
#: from the move has something to correct.
WRONG = dict(
    BENCH_2, J=tuple(1.1 * j for j in BENCH_2["J"]), k=tuple(0.9 * k for k in BENCH_2["k"])
)
#: The run (s): the 1 s move, then the hold's dither (from 1.5 s), its estimator gain and
#: the hold near an edge (after 0.3 s quiet).
STOP = 3.0


@pytest.fixture(scope="module")
def shipped():
    return closed_loop(BENCH_2, WRONG, stop=STOP)


@pytest.mark.slow
@pytest.mark.parametrize("part", PARTS)
def test_each_part_switched_off_changes_the_commands(shipped, part: str) -> None:
    without = closed_loop(BENCH_2, WRONG, stop=STOP, without=frozenset({part}))
    changed = np.flatnonzero(without.i_ref != shipped.i_ref)
    assert changed.size, f"{part} off left every command as it was"


def test_an_unknown_part_is_refused_naming_the_parts() -> None:
    design = design_controller(
        {
            "J_mo": 2.09e-5,
            "k_to": 0.0406,
            "D_m": 2e-5,
            "f_c": 2e-3,
            "J[1]": 5e-4,
            "k[1]": 0.16,
            "B[1]": 1e-5,
        },
        h=1e-3,
    )
    with pytest.raises(ValueError, match="unknown controller parts \\['dither'\\]"):
        MotionController(design, frozenset({"dither"}))
    assert MotionController(design).parts == PARTS


def test_the_benchmarks_without_takes_the_parts_and_refuses_others() -> None:
    assert parse_without("hold_gain, move_refit") == frozenset({"hold_gain", "move_refit"})
    assert parse_without("") == frozenset()
    with pytest.raises(UserError, match="--without names unknown parts dither: use hold_dither"):
        parse_without("dither")
    with pytest.raises(UserError, match="--without names unknown parts bank: use hold_dither"):
        parse_without("bank")  # the estimator bank, removed
