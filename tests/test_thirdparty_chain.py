"""A chain assembled from a plant we did not write (Dymola's ``edrive_mass.fmu``) against the
project's exact plant FMU.

The FMU is not in the repository: name the folder that holds it with
``ARCOSIM_THIRDPARTY_FMUS`` (where to get it:
:data:`benchmarks.simulators.thirdparty_plant.SOURCE`);
without it the test is deselected (marker ``data``) and the run's summary says so; a
folder without the file skips, naming where to get it.

The tolerance comes from the coupling: every stage of the classic Runge–Kutta step goes
through the FMUs (model exchange, no co-simulation delay), so the assembled chain differs
from ``MotorChainPlant``'s matrix exponential by RK4's phase error alone, at most
ω T (ω s)⁴ / 120 rad at the fastest mode ω after T seconds with steps of s; an angle
swinging over A radians is then off by at most A times that. Halving s must divide the
difference by about 2⁴ (fourth order), which an explicitly coupled spring (first order,
its torque a step late) would not.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from benchmarks import thirdparty_chain
from benchmarks.simulators.thirdparty_plant import ENV, FMU_FILE, where


@pytest.fixture(scope="module")
def folder() -> Path:
    named = os.environ.get(ENV)
    path = Path(named) if named else None
    if path is None or not (path / FMU_FILE).is_file():
        pytest.skip(where(path))
    return path


@pytest.mark.slow
@pytest.mark.system
@pytest.mark.data(ENV)
def test_assembled_chain_rings_as_the_project_plant(folder):
    check = thirdparty_chain.coupling(folder, substeps=1, duration=1.0)
    # the linear map through the FMUs has the model's modes and damping
    assert np.allclose(check["fmu_modes"], check["modes"], rtol=1e-6)
    assert np.allclose(check["fmu_zeta"], check["zeta"], rtol=1e-4)
    # a current step and free ringing: within RK4's phase-error bound at the fastest mode
    omega, s, T = max(check["modes"]), thirdparty_chain.STEP, check["duration"]
    bound = omega * T * (omega * s) ** 4 / 120.0
    assert max(check["step_error_relative"]) < bound
    finer = thirdparty_chain.coupling(folder, substeps=2, duration=1.0)
    ratio = check["step_error"][0] / finer["step_error"][0]
    assert ratio > 8.0, f"halving the step divided the motor's error by {ratio:.1f} only"


def test_benchmark_skips_naming_the_source_when_the_fmu_is_absent(tmp_path, capsys):
    from benchmarks import main

    assert main("thirdparty", thirdparty_chain.add_parser, ["--fmus", str(tmp_path)]) == 0
    said = capsys.readouterr().out
    assert "skip" in said and FMU_FILE in said and "OMSimulator" in said


@pytest.mark.slow
@pytest.mark.system
@pytest.mark.data(ENV)
def test_identification_only_fits_without_moving(folder):
    """``score_seed(..., control=False)``: the third-party chain identified (n right,
    J_i, k_i within the 0.5 % target), no move run."""
    found = thirdparty_chain.score_seed(folder, 1, corners=False, control=False)
    assert "models" not in found
    ident = found["identification"]
    assert ident["masses"] == thirdparty_chain.CHAIN.n
    for name, p in ident["parameters"].items():
        if name[0] in "Jk":
            assert abs(p["error_percent"]) < 0.5, (name, p)


def test_a_seed_scores_its_moves_as_the_control_benchmark_does(monkeypatch) -> None:
    """``score_seed``'s moves go through :func:`benchmarks.control_accuracy.score` (the
    third-party FMU not needed: the identification and the plant are stood in for, the
    motor and the last mass resting on target, so every criterion holds)."""
    from contextlib import nullcontext
    from types import SimpleNamespace

    from arcosim.experiments.closed_loop import LoopRun

    n = thirdparty_chain.CHAIN.n
    time = np.arange(6001) * 1e-3
    rest = LoopRun(time=time, theta=np.ones((n + 1, time.size)), theta_m=np.ones(time.size),
                   omega_m=np.zeros(time.size), i_a=np.zeros(time.size),
                   i_ref=np.zeros(time.size - 1))  # fmt: skip
    fake = SimpleNamespace(masses=n)
    monkeypatch.setattr(thirdparty_chain, "identify", lambda folder, seed: fake)
    monkeypatch.setattr(thirdparty_chain, "identification_errors", lambda result: {})
    monkeypatch.setattr(thirdparty_chain, "design_parameters", lambda result, ideal: {})
    monkeypatch.setattr(thirdparty_chain, "scaled", lambda params, fJ, fk: params)
    monkeypatch.setattr(thirdparty_chain, "cascade_gains", lambda params: None)
    monkeypatch.setattr(thirdparty_chain, "CascadeController", lambda *a: None)
    monkeypatch.setattr(thirdparty_chain, "sensorless", lambda params, without=frozenset(): None)
    monkeypatch.setattr(thirdparty_chain, "open_plant", lambda folder, seed: nullcontext())
    monkeypatch.setattr(thirdparty_chain, "run_loop", lambda *a: rest)
    found = thirdparty_chain.score_seed(Path("."), 1, corners=False)
    criteria = found["models"]["identified"]["criteria"]
    assert criteria == dict.fromkeys(("settles", "residual", "near_bound", "no_limit_cycle"), True)
