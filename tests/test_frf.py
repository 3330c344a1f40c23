"""The measured frequency response (arcosim.identification.checks.frf) and the spectral front end
(arcosim.identification.excitation.spectrum), on logs of benchmarks.simulators.field_sim (written
apart from the
plant) and on synthetic signals: each estimator against the chain's exact response."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.identification.checks.frf import measured_response, model_response
from arcosim.identification.excitation.spectrum import excitation_spectrum, harmonic_fundamental
from benchmarks import excitations
from benchmarks.simulators import field_sim

J_M, K_T = 2.09e-5, 0.0406
CHAIN = dict(J=(3e-4,), k=(0.45,), B=(2e-5,))
LINES = np.geomspace(3.0, 150.0, 40)


def _drive(**kw) -> field_sim.Drive:
    return field_sim.Drive(J_m=J_M, k_t=K_T, D_m=2e-5, counts=2**16, **CHAIN, **kw)


def _model(omega: np.ndarray) -> np.ndarray:
    return model_response(omega, J_M, CHAIN["J"], CHAIN["k"], CHAIN["B"], 2e-5)


def test_the_model_response_of_a_rigid_body_and_one_spring() -> None:
    w = np.array([2.0, 40.0])
    np.testing.assert_allclose(model_response(w, 1e-3, [], [], []), 1 / (1j * w * 1e-3))
    # motor + one load, no damping: zero at the clamped mode √(k/J), pole at the free one
    clamped = np.sqrt(0.45 / 3e-4)
    assert abs(model_response(np.array([clamped]), J_M, [3e-4], [0.45], [0.0])[0]) < 1e-9


def test_off_grid_lines_count_once_and_a_square_wave_is_periodic() -> None:
    """40 lines half a bin off the grid: counted as lines (the window merges the pairs
    under two bins apart, at the low end), never as their leakage; a square wave's
    odd harmonics: one fundamental."""
    t = np.arange(20001) * 1e-3
    rng = np.random.default_rng(2)
    lines = excitations.offgrid_lines(LINES, 20.0)
    current = field_sim.multisine(lines, 3.0, seed=2)(t) + 0.005 * rng.standard_normal(len(t))
    found = excitation_spectrum(current, 1e-3)
    assert found.kind == "lines" and 30 <= len(found.lines) <= 40, found.text()
    high = found.lines[found.lines > 10.0]  # lines over 3 bins apart: each within 0.1 bin
    nearest = np.min(np.abs(high[:, None] - lines[None, :]), axis=1)
    assert np.all(nearest < 0.1 * 2 * np.pi / 20.0), nearest
    square = np.sign(np.sin(np.pi * t + 0.3)) + 0.01 * rng.standard_normal(len(t))
    periodic = excitation_spectrum(square, 1e-3)
    assert periodic.kind == "periodic" and periodic.fundamental == pytest.approx(np.pi, rel=1e-3)
    assert harmonic_fundamental(LINES, 0.3) == 0.0
    prbs = excitations.prbs(1.0, 1e-3, 4, seed=3)(t)
    broadband = excitation_spectrum(prbs, 1e-3)
    assert broadband.kind == "broadband" and broadband.band[1] > 600.0, broadband.text()


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["lines", "prbs"])
def test_open_loop_estimates_match_the_chain(kind: str) -> None:
    """H1 at the lines and Welch H1 on a one-mass chain (10 s, no Coulomb friction, 5 mA
    noise, 65536 counts): within 3 % of the exact response where the coherence is high."""
    if kind == "lines":
        current = field_sim.multisine(LINES, 3.0, seed=1)
    else:
        current = excitations.prbs(1.0, 1e-3, 4, seed=1)
    log = field_sim.simulate(_drive(current_noise=0.005), 1e-3, 10.0, current=current, seed=1)
    frf = measured_response(log.time, log.i_a, log.theta_m, K_T, top=150.0)
    good = frf.coherence > 0.95
    assert np.sum(good) >= 10 and not frf.warnings, (frf.estimator, frf.warnings)
    ratio = frf.response[good] / _model(frf.omega[good])
    assert np.median(np.abs(ratio - 1)) < 0.03, ratio
    assert frf.estimator.startswith("H1 at the lines" if kind == "lines" else "Welch H1")


@pytest.mark.slow
def test_a_closed_loop_warns_and_the_reference_removes_the_bias() -> None:
    """A PI speed loop (kp 0.1 A·s/rad, ki 0.75 A/rad) on a multi-sine reference (10 s,
    2000 counts: the loop feeds the counts' noise back as current): from the current and
    speed alone, a warning that the loop biases the response; through the logged
    reference, the indirect estimate, no warning, within 5 % at the lines."""
    reference = field_sim.multisine(LINES, 40.0, seed=1, slope=1.0)
    loop = field_sim.SpeedLoop(0.1, 0.75, reference, limit=10.0)
    drive = field_sim.Drive(J_m=J_M, k_t=K_T, D_m=2e-5, counts=2000, current_noise=0.005, **CHAIN)
    log = field_sim.simulate(drive, 1e-3, 10.0, speed_loop=loop, seed=1)
    alone = measured_response(log.time, log.i_a, log.theta_m, K_T, top=150.0)
    assert any("closed loop" in w for w in alone.warnings), alone.warnings
    indirect = measured_response(
        log.time, log.i_a, log.theta_m, K_T, reference=reference(log.time), top=150.0
    )
    assert indirect.estimator.startswith("indirect") and not indirect.warnings
    ratio = indirect.response / _model(indirect.omega)
    assert np.median(np.abs(ratio - 1)) < 0.05, ratio


@pytest.mark.slow
def test_identify_plot_writes_the_figure_and_its_csv(tmp_path, capsys) -> None:
    """``arcosim identify … --plot FILE.png`` on the README's sample: the figure, FILE.csv
    with ω, the measured and the model's magnitude and phase, the coherence, and its
    units; the measured response within 5 % of the model's where the coherence is high."""
    import csv
    import json
    from pathlib import Path

    from arcosim.cli import main

    sample = Path(__file__).parents[1] / "examples" / "data" / "belt_drive.csv"
    count = "0.0031415926535897933"
    scales = ["--scale", "i_a=0.001", "--scale", f"theta_m={count}", "--scale", f"omega_m={count}"]
    motor = ["--set", "k_to=0.0406", "--set", "J_mo=2.09e-5", "--set", "encoder_cpr=2000"]
    plot = tmp_path / "frf.png"
    args = ["identify", str(sample), *scales, *motor, "--method", "whole-chain"]
    assert main([*args, "--masses", "auto", "--plot", str(plot)]) == 0
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = list(csv.DictReader(plot.with_suffix(".csv").open()))
    units = json.loads(plot.with_suffix(".units.json").read_text())
    assert units["omega"] == "rad/s" and units["coherence"] == "1"
    assert list(rows[0]) == list(units) and len(rows) >= 20
    good = [r for r in rows if float(r["coherence"]) > 0.95]
    ratio = [float(r["measured_magnitude"]) / float(r["model_magnitude"]) for r in good]
    assert len(good) >= 10 and np.median(np.abs(np.array(ratio) - 1)) < 0.05, ratio
    assert main([*args, "--plot", str(plot)]) == 2  # never over an existing file
    assert "exists" in capsys.readouterr().err
