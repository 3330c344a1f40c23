"""Excitations a drive log may carry, as reusable log generators for the benchmark rows
and tests (on :mod:`benchmarks.simulators.field_sim`, the simulator written apart from the plant).

- :func:`offgrid_lines`: a multi-sine's lines moved to half a bin off the record's
  frequency grid (the worst leakage);
- :func:`prbs`: a maximum-length pseudo-random binary current, held for ``clock``
  samples;
- :func:`square_position`: a square-wave position reference, for a P position loop
  around a PI speed loop (:class:`benchmarks.simulators.field_sim.SpeedLoop` with
  ``position_gain``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import signal


def offgrid_lines(lines: np.ndarray, duration: float) -> np.ndarray:
    """``lines`` (rad/s) each moved to the nearest half-bin point between the record's
    grid lines 2π/``duration`` (s): every line then leaks its worst."""
    grid = 2.0 * np.pi / duration
    return (np.floor(np.asarray(lines, dtype=float) / grid) + 0.5) * grid


def prbs(amplitude: float, h: float, clock: int, seed: int = 1, bits: int = 14) -> Callable:
    """A PRBS current (A) of ±``amplitude``: a maximum-length sequence of ``bits`` bits
    (period 2^bits − 1 clocks) from a state set by ``seed``, each value held for
    ``clock`` samples of ``h`` s; as a function of time (s)."""
    rng = np.random.default_rng(seed)
    state = rng.integers(0, 2, bits)
    state[0] = 1  # never all zeros
    sequence = signal.max_len_seq(bits, state=state)[0] * 2.0 - 1.0

    def current(t: np.ndarray) -> np.ndarray:
        index = (np.rint(np.asarray(t, dtype=float) / h).astype(int) // clock) % len(sequence)
        return amplitude * sequence[index]

    return current


def square_position(amplitude: float, period: float, seed: int = 1) -> Callable:
    """A square-wave position reference (rad): ±``amplitude`` with ``period`` s, its
    phase set by ``seed``; as a function of time (s)."""
    shift = np.random.default_rng(seed).uniform(0.0, period)

    def reference(t: np.ndarray) -> np.ndarray:
        phase = ((np.asarray(t, dtype=float) + shift) % period) / period
        return np.where(phase < 0.5, amplitude, -amplitude)

    return reference
