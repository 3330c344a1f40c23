"""What ``check`` reads an excitation as (arcosim.identification.excitation.spectrum):
the lines a multi-sine plays, counted once each, on or off the record's grid; a periodic
multi-sine's lines, period and band, without the lines the drive adds beneath them;
broadband noise as no lines. Each signal is a drive log's current: the lines, white
noise and the current's quantisation."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.identification.checks.verdict import excitation_above_band
from arcosim.identification.excitation.periodic import detection_threshold, harmonic_lines
from arcosim.identification.excitation.spectrum import excitation_spectrum
from benchmarks import excitations

H = 1e-3
T = np.arange(20001) * H  # 20 s at 1 kHz
GRID = 2 * np.pi / (len(T) * H)  # the record's frequency grid 2π/T (rad/s)
LINES = np.geomspace(3.0, 150.0, 40)  # the README's multi-sine: 40 lines 3–150 rad/s
NOISE, COUNT = 0.005, 1e-3  # the current's noise and quantisation step (A)


def drive_current(lines: np.ndarray, seed: int) -> np.ndarray:
    """40 random-phase lines of 0.075 A (3 A peak), 5 mA noise, quantised to 1 mA."""
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * np.pi, len(lines))
    x = 0.075 * np.sin(np.outer(T, lines) + phases).sum(axis=1)
    x += NOISE * rng.standard_normal(len(T))
    return np.round(x / COUNT) * COUNT


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_forty_lines_on_the_grid_read_as_forty(seed) -> None:
    """On the grid (lines one bin apart at the low end): every line in its bin, none more."""
    lines = np.rint(LINES / GRID) * GRID
    found = excitation_spectrum(drive_current(lines, seed), H)
    assert found.kind == "lines", found.text()
    np.testing.assert_allclose(found.lines, lines, atol=1e-9)
    assert found.band == pytest.approx((lines[0], lines[-1]))


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("offset", ["geometric", "half a bin"])
def test_forty_lines_off_the_grid_invent_none(seed, offset) -> None:
    """Off the grid: the lines under two bins apart (under about 6 rad/s in 20 s, one to
    two bins apart) merge in the Hann window and are told apart again by the
    least-squares search, so all 40; every line within a fifth of a bin, none over a bin
    from a played one."""
    lines = LINES if offset == "geometric" else excitations.offgrid_lines(LINES, 20.0)
    found = excitation_spectrum(drive_current(lines, seed), H)
    assert found.kind == "lines" and len(found.lines) == 40, found.text()
    assert len(found.unresolved) == 0, found.text()
    to_played = np.min(np.abs(lines[:, None] - found.lines[None, :]), axis=1)
    assert np.all(to_played < 0.2 * GRID), lines[to_played >= 0.2 * GRID]
    nearest = np.min(np.abs(found.lines[:, None] - lines[None, :]), axis=1)
    assert np.all(nearest < GRID), found.lines[nearest >= GRID]
    assert found.band[1] == pytest.approx(lines[-1], abs=0.1 * GRID)


def schroeder(harmonics: np.ndarray, count: int) -> np.ndarray:
    """Schroeder phases −π·k(k−1)/K for K lines (a low crest factor)."""
    k = np.arange(1, count + 1)
    return -np.pi * k * (k - 1) / count


def test_a_schroeder_multisine_reads_lines_period_and_band() -> None:
    """Odd harmonics 5 … 99 of a 1 s period, 10 periods at 1 kHz: 48 lines, period 1 s,
    10 whole periods, 31.4 … 622 rad/s."""
    harmonics = np.arange(5, 100, 2)
    n = np.arange(10000)
    phases = schroeder(harmonics, len(harmonics))
    x = 0.1 * np.cos(2 * np.pi * np.outer(n / 1000.0, harmonics) + phases).sum(axis=1)
    x += NOISE * np.random.default_rng(4).standard_normal(len(n))
    found = excitation_spectrum(np.round(x / COUNT) * COUNT, H)
    assert found.kind == "periodic" and found.periods == 10, found.text()
    np.testing.assert_allclose(found.lines, 2 * np.pi * harmonics, rtol=1e-12)
    assert found.fundamental == pytest.approx(2 * np.pi)
    assert found.band == pytest.approx((2 * np.pi * 5, 2 * np.pi * 99))
    assert "period 1 s, 10 whole periods" in found.text()


def bench_current(seed: int) -> np.ndarray:
    """A current built like the motor bench's (FdiTools' multisine: every harmonic
    11 … 250 of a 1 s period at 2.5 kHz, 20 periods, random phases, 0.9 A per line),
    with what a drive adds: lines of its own on every other harmonic to the Nyquist
    frequency, 0.002 … 0.14 A (the record's: friction's and the current loop's), and
    noise coloured tenfold over the band."""
    rng = np.random.default_rng(seed)
    period, periods = 2500, 20
    n = np.arange(period * periods)
    played = np.arange(11, 251)
    others = np.setdiff1d(np.arange(1, period // 2), played)
    amplitudes = np.r_[rng.uniform(0.77, 0.93, len(played)), rng.uniform(0.002, 0.14, len(others))]
    harmonics = np.r_[played, others]
    phases = rng.uniform(0, 2 * np.pi, len(harmonics))
    x = np.zeros(len(n))
    for k, a, p in zip(harmonics, amplitudes, phases):
        x += a * np.cos(2 * np.pi * k * n / period + p)
    white = rng.standard_normal(len(n))
    coloured = np.fft.irfft(np.fft.rfft(white) * np.linspace(0.3, 3.0, len(n) // 2 + 1), len(n))
    return x + 0.02 * coloured


@pytest.mark.parametrize("seed", [1, 2])
def test_a_bench_like_periodic_multisine_reads_its_240_lines(seed) -> None:
    """240 lines 69.1 … 1571 rad/s, period 1 s, 20 periods; the 1009 harmonics the
    drive adds stand above the noise (they are lines) but are not played; the band check
    then names g_dist under the default 100 rad/s and is quiet at 1000 rad/s."""
    x = bench_current(seed)
    k, _, _ = harmonic_lines(x - x.mean(), 20)
    assert len(k) > 1000  # what the drive adds is above the noise: only its level tells
    found = excitation_spectrum(x, 4e-4)
    assert found.kind == "periodic" and found.periods == 20, found.text()
    np.testing.assert_allclose(found.lines, 2 * np.pi * np.arange(11, 251), rtol=1e-12)
    assert found.lowest == pytest.approx(2 * np.pi * 11)
    assert found.fundamental == pytest.approx(2 * np.pi)
    assert "g_dist=524" in excitation_above_band(found, 100.0)
    assert excitation_above_band(found, 1000.0) is None


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_broadband_noise_is_no_lines(seed) -> None:
    """White noise and a PRBS: broadband, no lines."""
    noise = np.random.default_rng(seed).standard_normal(len(T))
    assert excitation_spectrum(noise, H).kind == "broadband"
    prbs = excitations.prbs(1.0, H, 4, seed=seed)(T)
    assert excitation_spectrum(prbs, H).kind == "broadband"


def test_the_threshold_lets_half_a_false_line_through() -> None:
    """Noise alone over 200 records of 10 periods: on average about half a false line
    (the threshold's aim; the level's own scatter adds a little), never a dozen."""
    counts = [
        len(harmonic_lines(np.random.default_rng(s).standard_normal(4000), 10)[0])
        for s in range(200)
    ]
    assert 0.2 < np.mean(counts) < 1.0 and max(counts) < 5, np.mean(counts)
    assert detection_threshold(200) == pytest.approx(np.log(400.0))
