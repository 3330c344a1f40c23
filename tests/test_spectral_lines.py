"""The spectral front end finds no line the excitation did not play: a linear detrend
of a multi-sine leaves a ramp that the Hann periodogram reads as a weak line one to two
bins above 0 (0.48 rad/s on a 20 s record of 40 lines from 3 rad/s), which then fed
the torque balance and the record-length check false warnings. The line
must pass the prominence test again on its fitted amplitude, over the noise and that
remnant; a real line as low is kept."""

from __future__ import annotations

import numpy as np
import pytest

from arcosim.identification.excitation.spectrum import excitation_spectrum
from benchmarks.simulators import field_sim

LINES = np.geomspace(3.0, 150.0, 40)  # the README's multi-sine: 40 lines 3–150 rad/s
T = np.arange(20001) * 1e-3  # 20 s at 1 kHz


def current(seed: int) -> np.ndarray:
    """The benchmarks' multi-sine current (3 A peak) for ``seed``, with 5 mA noise."""
    noise = 0.005 * np.random.default_rng(seed).standard_normal(len(T))
    return field_sim.multisine(LINES, 3.0, seed=seed)(T) + noise


@pytest.mark.parametrize("seed", [2, 4])
def test_the_detrend_s_remnant_is_no_line(seed) -> None:
    """Seeds whose remnant read as a line at 0.53 and 0.48 rad/s: the lowest line found is
    the multi-sine's own (its lowest pair merges, read between 2.9 and 3.2 rad/s)."""
    found = excitation_spectrum(current(seed), 1e-3)
    assert found.kind == "lines"
    assert 2.9 <= found.lowest <= 3.2, found.lines[:3]


def test_a_real_line_as_low_is_kept() -> None:
    """A line played at 0.6 rad/s (two periods in the record) as strong as the others."""
    x = current(4) + 0.075 * np.sin(0.6 * T)
    found = excitation_spectrum(x, 1e-3)
    assert found.lowest == pytest.approx(0.6, abs=0.05)
