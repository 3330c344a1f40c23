"""``arcosim control``: the controller designed for a chain and its loops checked.

The figures come from :func:`arcosim.controller_margins` (its linearization is tested in
``tests/test_control_margins.py``); here: what the command reads, prints and exits with.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from benchmarks.control_margins import CHAINS, params
from tests.cli_runs import run


def refusal(capsys, *argv: object) -> str:
    """The one line ``arcosim: error: …`` of a refused input (exit status 2)."""
    code, out, err = run(capsys, *argv)
    lines = err.strip().splitlines()
    assert code == 2 and not out and len(lines) == 1, (code, out, err)
    assert lines[0].startswith("arcosim: error: ")
    return lines[0]


def chain_file(tmp_path: Path, name: str) -> Path:
    """A whole-chain report holding one of the margins table's chains."""
    values = {key: v for key, v in params(CHAINS[name]).items() if key[0] in "JkB"}
    values.pop("J_mo")
    path = tmp_path / "chain.json"
    path.write_text(json.dumps({"masses": CHAINS[name].n, **values}), encoding="utf-8")
    return path


@pytest.mark.slow
def test_a_robust_chain_exits_0_with_units_and_the_defaults_it_used(capsys) -> None:
    code, out, err = run(capsys, "control", "--masses", 1)
    assert code == 0, err
    assert "verdict: robust" in out
    assert "rad/s" in out and "1/s" in out and "ms" in out
    assert "move_time 1 s" in out and "bandwidth 8 rad/s" in out
    assert "assumption: not given, so the paper bench's value was used: J_mo" in out


def test_the_json_report_names_its_units(capsys) -> None:
    code, out, _ = run(capsys, "control", "--masses", 1, "--set", "move_time=0.5", "--json")
    report = json.loads(out, parse_constant=pytest.fail)  # no NaN or Infinity
    assert code == 0 and report["robust"] is True
    assert report["move_time_s"] == 0.5 and report["bandwidth_rad_s"] == 16.0
    assert len(report["sensorless_under_errors"]) == 22
    assert report["sensorless"]["decay_1_s"] > 0.0
    assert report["sensorless_under_errors"][0]["J_factors"] == [1.1]
    hold = report["hold_with_dither"]  # the model exact and the two corners, at rest
    assert [h["model"] for h in hold[:3]] == [
        "the model exact, at rest with the dither",
        "J +10 %, k −10 %, at rest with the dither",
        "J −10 %, k +10 %, at rest with the dither",
    ]
    assert all(h["decay_1_s"] >= report["min_decay_1_s"] for h in hold)


def test_without_a_dither_the_hold_is_the_moving_loop_and_not_checked_again(capsys) -> None:
    code, out, _ = run(capsys, "control", "--masses", 1, "--set", "hold_dither=0", "--json")
    assert code == 0 and json.loads(out)["hold_with_dither"] == []
    code, out, _ = run(capsys, "control", "--masses", 1, "--set", "hold_dither=0")
    assert "at rest with the hold's dither" not in out and "and at rest" not in out


def test_a_hold_that_grows_where_the_move_decays_is_named_with_its_way_out() -> None:
    """The verdict when only the loop at rest fails: it names that case and the
    parameter that holds without the dither (the logic, on a hold case set to grow)."""
    import dataclasses

    from arcosim.control.margins import LoopDecay, controller_margins

    chain = params(CHAINS["bench, two masses"])
    found = controller_margins(chain, h=1e-3, random_models=0)
    assert found.robust and len(found.hold) == 3
    growing = LoopDecay("J +10 %, k −10 %, at rest with the dither", -0.5, 78.0)
    found = dataclasses.replace(found, hold=(found.hold[0], growing))
    assert not found.robust and found.failing == [growing]
    verdict = found.verdict()
    assert verdict.startswith(
        "verdict: NOT robust at rest: with J +10 %, k −10 %, at rest with the dither, the loop"
    )
    assert "grows at 0.5 1/s at 78 rad/s" in verdict and "hold_dither=0" in verdict


@pytest.mark.slow
def test_the_five_mass_chain_is_refused_at_thirty_percent_naming_the_model(
    capsys, tmp_path: Path
) -> None:
    """Robust to ±20 % with the model refitted from the move (docs/control.md#margins); at
    ±30 % a random model's error grows at the chain's top modes: exit 1, the model and the
    frequency named, and the smaller error it passes."""
    path = chain_file(tmp_path, "five masses")
    code, out, err = run(capsys, "control", "--chain", path, "--error", 0.3)
    assert code == 1, err
    verdict = out.splitlines()[-2]
    assert verdict.startswith("verdict: NOT robust to ±30 %: with random ")
    rate = float(verdict.split("grows at ")[1].split(" 1/s")[0])
    frequency = float(verdict.split(" 1/s at ")[1].split(" rad/s")[0])
    assert rate > 0.1 and 63.0 < frequency < 146.0  # the top modes, 63.5–145.9 rad/s free
    assert "within ±10 %" in verdict
    assert "the bench's chain" not in out  # the chain came from the file


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (("--set", "move_time=0"), "move_time = 0.0 s and bandwidth = 0.0 rad/s"),
        (("--set", "jmo=1"), "did you mean J_mo"),
        (("--masses", 2, "--set", "control_mass=3"), "control_mass"),
        (("--masses", 2, "--set", "k[2]=-1"), "k[2]"),
        (("--masses", 2, "--set", "theta_ref=1"), "not a parameter"),
        (("--error", 0), "--error"),
        (("--masses", "two"), "--masses"),
        (("--error", 1), "give 0 < E < 1"),
        (("--set", "move_time=1e-6"), "use a step ≤ 3.93e-08 s or a longer move_time"),
        (("--masses", 1, "--step", 0.02), "fastest mode, 90 rad/s"),
        (("--set", "J[1]=1e300"), "the design overflows"),
    ],
)
def test_a_bad_input_is_one_line_naming_it(capsys, argv: tuple, named: str) -> None:
    assert named in refusal(capsys, "control", *argv)


def test_masses_that_disagree_with_the_chain_file_are_refused(capsys, tmp_path: Path) -> None:
    path = chain_file(tmp_path, "bench, two masses")
    line = refusal(capsys, "control", "--chain", path, "--masses", 3)
    assert "--masses 3" in line and "holds 2" in line


def test_a_step_too_coarse_for_a_parallel_master_is_not_stable(capsys) -> None:
    """At 10 ms the loop one step late grows (its full-state bound too): exit 1, the case
    named and the advice naming the step."""
    code, out, _ = run(capsys, "control", "--masses", 1, "--step", 0.01)
    assert code == 1
    verdict = out.splitlines()[-2]
    assert verdict.startswith("verdict: NOT stable: with the model exact, one step late, the")
    assert "a shorter step" in verdict


def test_a_run_that_never_comes_to_rest_is_not_linearized() -> None:
    """The three-mass bench at 10 ms, one step late: the current stays pinned at ±i_max,
    where a linearization would show only the plant's own poles (decaying, through D_m);
    the loop is reported as not at rest instead."""
    from arcosim.control.sensorless_loop import sensorless_decay, sensorless_loop

    chain = params(CHAINS["bench, three masses"])
    assert not sensorless_loop(chain, chain, h=0.01, delay=1).settled
    decay, frequency = sensorless_decay(chain, chain, h=0.01, delay=1)
    assert decay == -float("inf") and frequency != frequency


def test_a_chain_in_grams_is_named_a_unit_mistake(capsys) -> None:
    """J[i] given in g·m² (1000 × too large): the 1 rad move in 1 s would need about
    190 A on the chain's inertia (1.03 kg·m² × 7.5 rad/s² / 0.0406 N·m/A), 19 × i_max,
    and the loop never comes to rest. The verdict says what the move needs and names
    the units to check, where it only suggested a shorter step."""
    code, out, _ = run(
        capsys, "control", "--masses", 2, "--set", "J[1]=0.515", "--set", "J[2]=0.515"
    )
    assert code == 1
    verdict = out.splitlines()[-2]
    assert verdict.startswith("verdict: NOT stable: with the model exact, the loop does not")
    needs = float(verdict.split(" needs ")[1].split(" A")[0])
    assert 180.0 < needs < 200.0
    assert "check the units" in verdict and "kg·m²" in verdict and "move_time" in verdict


@pytest.mark.parametrize(
    ("content", "named"),
    [
        (
            {"masses": 0, "J[1]": 1e-4, "k[1]": 50.0, "B[1]": 1e-3},
            "masses = 0 (a rigid drive) but it holds J[1]",
        ),
        ({"masses": 25}, "masses = 25: the number of load masses must be 1 to 20"),
        ({"masses": 1, "J[1]": -1e-4, "k[1]": 50.0, "B[1]": 1e-3}, "J[1] = -0.0001 must be > 0"),
        ({"masses": 1, "J[1]": 1e-4, "k[1]": 50.0, "B[1]": -1e-3}, "B[1] = -0.001 must be >= 0"),
    ],
)
def test_a_chain_file_mistake_names_the_file_and_its_field(
    capsys, tmp_path: Path, content: dict, named: str
) -> None:
    """The message names what the user gave: the file and its field, never an option
    (``--masses 25``) the user did not type, nor a J[1] the file does hold."""
    path = tmp_path / "chain.json"
    path.write_text(json.dumps(content), encoding="utf-8")
    line = refusal(capsys, "control", "--chain", path)
    assert f"--chain {path}: {named}" in line
    assert "--masses 25" not in line and "no J[1]" not in line


def test_a_robust_verdict_prints_the_measured_rate_beside_the_threshold() -> None:
    """ "decays at 0.1 1/s or faster" is the pass mark, not a finding: the verdict names the
    slowest decay measured over the cases it checked, and the case."""
    import arcosim
    from arcosim.control.margins import MIN_DECAY

    chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3}
    chain.update({"J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5})
    found = arcosim.controller_margins(chain, h=1e-3, random_models=0)
    assert found.robust
    fs = found.full_state
    decays = [found.sensorless, found.sensorless_late, found.worst, *found.hold]
    slowest = min([d.decay for d in decays] + [fs["slowest_decay"], fs["decay_one_step_late"]])
    verdict = found.verdict()
    assert f"the slowest loop checked decays at {slowest:.3g} 1/s (" in verdict, verdict
    assert f"pass: {MIN_DECAY:g} 1/s or faster" in verdict
