"""The verdict on a whole-chain fit: trusted on a clean log, untrusted with a reason that
names what to check when the log holds something the chain cannot describe.

The logs come from the independent simulator (``benchmarks/simulators/field_sim.py``), not the
plant FMU: a two-mass chain with Coulomb friction that sticks, a 2000-count encoder,
5 mA of current noise and the ``identification`` scenario's 40 lines (3–150 rad/s, 3 A,
20 s).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import arcosim
from arcosim.cli import main
from arcosim.experiments.scenarios import IDENTIFICATION_LINES
from arcosim.identification.checks.verdict import (
    Verdict,
    excitation_above_band,
    judge,
    modes_outside,
    resolved_band,
    unresolved,
)
from arcosim.identification.excitation.spectrum import ExcitationSpectrum
from benchmarks.simulators import field_sim

K_T, J_M = 0.0406, 2.09e-5
LINES = ExcitationSpectrum("lines", IDENTIFICATION_LINES, np.ones(40), (3.0, 150.0))


def test_resolved_band_widens_by_one_grid_step():
    low, high = resolved_band(LINES)
    ratio = IDENTIFICATION_LINES[1] / IDENTIFICATION_LINES[0]
    assert low == pytest.approx(3.0 / ratio)
    assert high == pytest.approx(150.0 * ratio)
    broadband = ExcitationSpectrum("broadband", band=(5.0, 400.0), resolution=0.3)
    assert resolved_band(broadband) == pytest.approx((4.7, 400.3))
    assert resolved_band(ExcitationSpectrum("none")) is None
    assert resolved_band(None) is None


def test_a_mode_inside_the_excited_band_is_no_reason():
    assert modes_outside([11.7, 36.9, 160.0], LINES) is None  # 160 < 150 × 1.105


@pytest.mark.parametrize("mode", [170.0, 248.0, 2.0])
def test_a_mode_outside_the_excited_band_names_k_t_and_j_m(mode):
    reason = modes_outside([11.7, mode], LINES)
    assert f"{mode:.3g} rad/s" in reason
    assert "--set k_to=" in reason and "--set J_mo=" in reason


def test_an_excitation_above_the_observers_band_names_g_dist():
    assert excitation_above_band(LINES, 100.0) is None  # 150 < 3 × 100
    reason = excitation_above_band(LINES, 40.0)
    assert "--set g_dist=50 " in reason and "150 rad/s" in reason


def test_judge_collects_every_reason_once():
    floor = ["the residual is 6 × the noise floor"]
    weak = unresolved({"J[1]": 1e-9, "k[1]": 0.3}, {"J[1]": 1e-9, "k[1]": 0.01})
    doubts = ["check the current's scale", excitation_above_band(LINES, 40.0)]
    verdict = judge(doubts, floor + floor, weak, [248.0], LINES)
    assert not verdict.trusted and verdict.word == "untrusted"
    assert len(verdict.reasons) == 5  # plausibility, floor (once), J[1], mode, band
    assert judge([], [], None, [11.7], LINES) == Verdict(())


def test_an_inertia_or_stiffness_within_three_sigma_of_zero_is_unresolved():
    assert unresolved({"J[1]": 3e-4, "B[1]": 1e-6}, {"J[1]": 0.9e-4, "B[1]": 1e-5}) is None
    assert "J[1]" in unresolved({"J[1]": 3e-4}, {"J[1]": 1.1e-4})
    assert "J_load" in unresolved({"J_load": 1.8e-18}, {"J_load": 0.0})  # σ 0: not moved
    assert "k[2]" in unresolved({"k[2]": 0.4}, {})  # no σ: at a bound


def test_an_unresolved_rigid_load_names_the_motor_inertia_not_fewer_masses():
    """n = 0 (the HSM150's record with its catalog J given as J_mo: J_load 8.6e-16 ± 0)
    has no mass to drop: the reason names J_mo and not --masses."""
    rigid = unresolved({"J_load": 8.55e-16}, {"J_load": 0.0})
    assert "--set J_mo" in rigid and "--masses" not in rigid
    assert "--masses" in unresolved({"J[1]": 3e-4}, {"J[1]": 1.1e-4})


@functools.cache
def _log(seed: int = 0) -> field_sim.Log:
    drive = field_sim.Drive(
        J_m=J_M,
        k_t=K_T,
        J=(4e-4, 8e-4),
        k=(0.3, 0.2),
        B=(2e-5, 1.5e-5),
        D_m=2e-5,
        f_c=2e-3,
        current_noise=5e-3,
        counts=2000,
    )
    excitation = field_sim.multisine(IDENTIFICATION_LINES, 3.0, seed=seed + 1)
    return field_sim.simulate(drive, 1e-3, 20.0, current=excitation, seed=seed)


def _identify(k_t: float = K_T, J_m: float = J_M) -> arcosim.DriveIdentification:
    log = _log()
    return arcosim.identify_drive(
        log.time, log.i_a, log.omega_m, log.theta_m, k_t=k_t, J_m=J_m, encoder_cpr=2000
    )


@pytest.mark.slow
def test_a_clean_log_is_trusted():
    result = _identify()
    assert result.masses == 2
    assert result.verdict.trusted, result.verdict.reasons
    assert result.report()["verdict"] == "trusted" and result.report()["reasons"] == []


@pytest.mark.slow
@pytest.mark.parametrize(("k_t", "J_m"), [(1.1 * K_T, J_M), (0.9 * K_T, J_M), (K_T, 1.1 * J_M)])
def test_a_wrong_k_t_or_j_m_is_untrusted_and_named(k_t, J_m):
    """k_t 10 % high fits a stiff extra mass above the excitation (a mode at ~248 rad/s
    under lines to 150 rad/s); 10 % low, or J_m 10 % high, leaves ~5 × the noise floor."""
    result = _identify(k_t, J_m)
    assert not result.verdict.trusted
    assert all("k_t" in reason for reason in result.verdict.reasons)


@pytest.mark.slow
def test_identify_exits_3_when_untrusted_and_still_writes(tmp_path, capsys):
    log = _log()
    path = tmp_path / "log.csv"
    rows = np.column_stack([log.time, log.i_a, log.omega_m, log.theta_m])
    np.savetxt(path, rows, delimiter=",", header="time,i_a,omega_m,theta_m", comments="")
    out = tmp_path / "chain.json"
    argv = ["identify", str(path), "--method", "whole-chain", "--out", str(out)]
    assert main([*argv, "--set", f"k_to={1.1 * K_T}"]) == 3
    printed = capsys.readouterr().out
    assert printed.startswith("verdict: untrusted")
    assert "reason: the chain has a mode at" in printed
    assert '"verdict": "untrusted"' in out.read_text()


def _write(path, log, current=None, time_scale=1.0):
    rows = np.column_stack(
        [log.time * time_scale, log.i_a if current is None else current, log.omega_m / time_scale,
         log.theta_m]
    )  # fmt: skip
    np.savetxt(path, rows, delimiter=",", header="time,i_a,omega_m,theta_m", comments="")
    return str(path)


@pytest.mark.slow
def test_a_constant_current_is_refused_naming_it(tmp_path, capsys):
    """A constant current was read as an excitation and fitted to a rigid drive with
    J_load 1.8e-18 ± 0, exit 0."""
    log = _log()
    path = _write(tmp_path / "constant.csv", log, np.full(len(log.time), 0.5))
    assert main(["check", path]) == 1
    assert "the current i_a is constant" in capsys.readouterr().out
    # a refusal of the data, exit 1 as check's; a usage error is 2
    assert main(["identify", path, "--method", "whole-chain"]) == 1
    assert "the current i_a is constant" in capsys.readouterr().err
    assert main(["identify", path, "--method", "whole-chain", "--masses", "x"]) == 2


@pytest.mark.slow
def test_a_current_of_noise_only_is_not_trusted(tmp_path, capsys):
    """A current that holds only its sensor's noise (the motor moved by something else)
    fits, but the torque balance names the current and k_t."""
    log = _log()
    noise = 0.5 + 5e-3 * np.random.default_rng(1).standard_normal(len(log.time))
    path = _write(tmp_path / "noise.csv", log, noise)
    assert main(["identify", path, "--method", "whole-chain"]) == 3
    assert "--scale i_a=" in capsys.readouterr().out


@pytest.mark.slow
def test_a_time_column_in_ms_is_untrusted_naming_the_time_scale(tmp_path, capsys):
    path = _write(tmp_path / "ms.csv", _log(), time_scale=1e3)
    assert main(["check", path]) == 3
    assert "doubtful" in capsys.readouterr().out
    assert main(["identify", path, "--method", "whole-chain"]) == 3
    printed = capsys.readouterr().out
    assert printed.startswith("verdict: untrusted") and "--scale time=" in printed
