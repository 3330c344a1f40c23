"""The load torque chosen on the final fit: with ``--load`` not given the
selection rule takes none, constant or slow, the chain is refitted with the load it
takes and the report says so; a load the user gives is never overridden. The
independent simulator (:mod:`benchmarks.simulators.field_sim`) writes the log."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.fit.structure_choice import LOAD_MARGIN, choose, load_candidate
from benchmarks.field_accuracy import ROWS
from tests.field_runs import identify_log


def _fit(names: list[str], rms: float) -> ParameterFit:
    """A fit of ``names`` whose normalized innovations have rms ``rms`` (1 = the floor)."""
    values = np.ones(len(names))
    fit = ParameterFit(names, values, values, values, "", 0.0, 0.0, 10, 1)
    fit.extra.update(innovation_variance=rms**2, innovation_count=10000)
    return fit


def test_a_constant_load_is_taken_over_a_slow_one_that_explains_no_more() -> None:
    """A slow load counts one parameter more than a constant one (its random walk,
    the same ``tau_load``), so the rule takes the constant when both fit as well."""
    chain = [f"{p}[{i}]" for p in "JkB" for i in (1, 2, 3)]
    none = load_candidate("none", _fit(chain, 2.0))
    constant = load_candidate("constant", _fit([*chain, "tau_load"], 1.0))
    assert (none.parameters, constant.parameters) == (9, 10)
    slow = load_candidate("slow", _fit([*chain, "tau_load"], 0.98))
    assert slow.parameters == 11
    assert choose([none, constant, slow], LOAD_MARGIN).name == "constant"
    slower = load_candidate("slow", _fit([*chain, "tau_load"], 0.3))
    assert choose([none, constant, slower], LOAD_MARGIN).name == "slow"
    weak = load_candidate("constant", _fit([*chain, "tau_load"], 1.7))
    assert choose([none, weak], LOAD_MARGIN).name == "none"


@pytest.fixture(scope="module")
def slow_load_log():
    """10 s of the benchmark's slow-load row (0.01 N·m at 0.3 rad/s on the last mass)."""
    row = ROWS["three-mass, slow load, no --load"]
    return row.drive, row.log(1, 10.0)


@pytest.mark.slow
def test_an_unmodelled_slow_load_is_chosen_fitted_and_said(slow_load_log) -> None:
    d, log = slow_load_log
    result = identify_log(d, log)  # --load not given
    selection = result.report()["selection"]["load"]
    assert selection["chosen"] == "slow", selection
    assert set(selection["candidates"]) == {"none", "constant", "slow"}
    assert "tau_load" in result.parameters
    assert "chosen by the selection rule" in result.assumptions["load"]
    assert any("chosen by the selection rule" in w for w in result.warnings), result.warnings
    assert result.masses == 3
    chain = result.chain.parameters()
    truth = dict(zip([f"{p}[{i}]" for p in "Jk" for i in (1, 2, 3)], d.J + d.k))
    errors = {name: chain[name] / t - 1.0 for name, t in truth.items()}
    assert max(abs(e) for e in errors.values()) < 5e-3, errors
    B = np.array([chain[f"B[{i}]"] for i in (1, 2, 3)])
    sigma = np.array([result.std[f"B[{i}]"] for i in (1, 2, 3)])
    assert np.all(np.abs(B - np.array(d.B)) <= 3 * sigma), (B, d.B, sigma)


@pytest.mark.slow
def test_a_load_the_user_gives_as_none_is_kept_and_only_warned(slow_load_log) -> None:
    d, log = slow_load_log
    result = identify_log(d, log, load="none")
    assert "tau_load" not in result.parameters
    assert result.report()["selection"]["load"]["given"] == "none"
    assert any("--load slow" in w for w in result.warnings), result.warnings
