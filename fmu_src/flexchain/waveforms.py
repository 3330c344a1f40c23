"""Waveforms of the current command (A) as functions of time: the rigid maneuver, the
multi-sine, the chirp and filtered noise, one sample at a time.

Standard library only: the ExcitationSource FMU bundles this module, and
``arcosim.experiments.current_commands`` evaluates the same functions over arrays, so an FMU
run and an offline run see the same signal.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from . import defaults
from .noise import gaussian, uniform


def raised_cosine_window(t: float, duration: float, ramp: float, derivative: int = 0) -> float:
    """Window rising over ``ramp`` s as a raised cosine, 1 in the middle, falling over
    the last ``ramp`` s of ``duration``, 0 outside.

    Parameters
    ----------
    t : float
        Time (s).
    duration : float
        The window's length (s).
    ramp : float
        Length of each ramp (s), at most ``duration / 2``.
    derivative : int
        0 for the window (dimensionless), 1 or 2 for its first or second time
        derivative (1/s, 1/s²).

    Returns
    -------
    float
        The window or its derivative at ``t``.
    """
    if t < 0.0 or t > duration:
        return 0.0
    k = math.pi / ramp
    for tau, sign in ((t, 1.0), (duration - t, -1.0)):
        if tau < ramp:
            if derivative == 0:
                return 0.5 - 0.5 * math.cos(k * tau)
            if derivative == 1:
                return sign * 0.5 * k * math.sin(k * tau)
            return 0.5 * k * k * math.cos(k * tau)
    return 1.0 if derivative == 0 else 0.0


def rigid_maneuver(
    t: float,
    amplitude: float = defaults.RIGID_AMPLITUDE,
    frequency: float = defaults.RIGID_FREQUENCY,
    periods: int = defaults.RIGID_PERIODS,
    ramp_periods: int = defaults.RIGID_RAMP_PERIODS,
) -> float:
    """Back-and-forth maneuver far below the first mode, without drift or ringing.

    The motion is ``p(t) = w(t) sin(ω t)`` with ``w`` a raised-cosine window of
    ``ramp_periods`` periods each side, and the current is proportional to its
    acceleration, ``i = −(amplitude / ω²) p̈``: p and ṗ vanish at both ends, so the
    current's first and second integrals vanish too and the chain swings about its
    start and comes back to rest there (a windowed cosine current would leave it
    several radians away). The smooth window keeps energy away from the resonances
    (docs/method.md); ω defaults to about an eighth of the bench's first mode.

    The amplitude must be well above the current that overcomes the motor's
    Coulomb friction (f_c / k_t ≈ 0.05 A on the bench): the motor sticks at every
    reversal while the spring torque crosses the ±f_c band, the reaction torque is
    hidden then, and the double integral of mode 1 turns that into drift. On the
    bench 0.5 A gave k̂ 90 % low, 1 A 2–8 %, 2 A 1.3–3.5 % and 3 A (the default)
    0.8–1.0 % (ideal to realistic sensors).

    Parameters
    ----------
    t : float
        Time (s).
    amplitude : float
        Peak current (A), reached in the middle part.
    frequency : float
        Maneuver frequency ω (rad/s).
    periods : int
        Total length in periods, ramps included (a count).
    ramp_periods : int
        Length of each ramp in periods (a count).

    Returns
    -------
    float
        The current command at ``t`` (A); 0 outside the maneuver.
    """
    period = 2.0 * math.pi / frequency
    duration, ramp = periods * period, ramp_periods * period
    w = raised_cosine_window(t, duration, ramp)
    w1 = raised_cosine_window(t, duration, ramp, 1)
    w2 = raised_cosine_window(t, duration, ramp, 2)
    s, c = math.sin(frequency * t), math.cos(frequency * t)
    return amplitude * (w * s - (2.0 / frequency) * w1 * c - w2 * s / frequency**2)


def multisine_phases(lines: int, seed: int) -> list[float]:
    """Random phases for ``lines`` sines, reproducible for ``seed``.

    Parameters
    ----------
    lines : int
        Number of sines (a count).
    seed : int
        Noise stream (:func:`~arcosim.fmu.flexchain.noise.uniform`).

    Returns
    -------
    list of float
        Phases in [0, 2π) (rad), shape ``(lines,)``.
    """
    return [2.0 * math.pi * uniform(seed, j) for j in range(lines)]


def multisine(
    t: float, amplitude: float, frequencies: Sequence[float], phases: Sequence[float]
) -> float:
    """Sum of sines, each of ``amplitude / len(frequencies)``, so the peak never exceeds
    ``amplitude``.

    Parameters
    ----------
    t : float
        Time (s).
    amplitude : float
        Bound of the sum (A).
    frequencies : Sequence[float]
        The lines (rad/s), shape ``(m,)``.
    phases : Sequence[float]
        Their phases (rad), shape ``(m,)`` (:func:`multisine_phases`).

    Returns
    -------
    float
        The current command at ``t`` (A).
    """
    total = math.fsum(math.sin(w * t + p) for w, p in zip(frequencies, phases))
    return amplitude * total / len(frequencies)


def log_spaced(low: float, high: float, lines: int) -> list[float]:
    """Frequencies evenly spaced on a log scale.

    Parameters
    ----------
    low, high : float
        The first and last frequency (rad/s), > 0.
    lines : int
        How many (a count), ≥ 1; one line is ``low``.

    Returns
    -------
    list of float
        The frequencies (rad/s), shape ``(lines,)``, ascending when ``high > low``.
    """
    if lines == 1:
        return [low]
    ratio = (high / low) ** (1.0 / (lines - 1))
    return [low * ratio**j for j in range(lines)]


def chirp(t: float, amplitude: float, w0: float, w1: float, duration: float) -> float:
    """Linear chirp, then 0.

    Parameters
    ----------
    t : float
        Time (s).
    amplitude : float
        Peak current (A).
    w0, w1 : float
        Instantaneous frequency at the start and at the end (rad/s).
    duration : float
        Length of the sweep (s), > 0.

    Returns
    -------
    float
        The current command at ``t`` (A); 0 after ``duration``.
    """
    if t > duration:
        return 0.0
    rate = (w1 - w0) / duration
    return amplitude * math.sin(w0 * t + 0.5 * rate * t * t)


class FilteredNoise:
    """Gaussian white noise through a 4th-order Butterworth low-pass, scaled so the
    output's rms is ``amplitude`` (A). Causal and reproducible: sample k uses noise
    sample k of ``seed``; the filter is discretized (bilinear, pre-warped) for the
    step actually taken.

    Parameters
    ----------
    amplitude : float
        Rms of the output (A).
    cutoff : float
        Corner frequency (rad/s), below the Nyquist frequency π/h.
    seed : int
        Noise stream (:func:`~arcosim.fmu.flexchain.noise.gaussian`).
    """

    def __init__(self, amplitude: float, cutoff: float, seed: int) -> None:
        self.amplitude = amplitude
        self.cutoff = cutoff
        self.seed = seed
        self.k = 0
        self.h = 0.0
        self.states = [[0.0, 0.0], [0.0, 0.0]]  # two biquads, transposed direct form II
        self.sections: list[list[float]] = []
        self.gain = 0.0

    def next(self, h: float) -> float:
        """The next sample.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0; a new step size redesigns the filter.

        Returns
        -------
        float
            The current command (A).
        """
        if abs(h - self.h) > 1e-9 * h:  # a new step size, not rounding of the same one
            self._design(h)
        x = self.gain * gaussian(self.seed, self.k)
        self.k += 1
        for (b0, b1, b2, a1, a2), z in zip(self.sections, self.states):
            y = b0 * x + z[0]
            z[0] = b1 * x - a1 * y + z[1]
            z[1] = b2 * x - a2 * y
            x = y
        return x

    def _design(self, h: float) -> None:
        self.h = h
        wc = 2.0 / h * math.tan(min(self.cutoff * h / 2.0, 1.5))  # pre-warped
        k = wc * h / 2.0
        self.sections = []
        for q in (0.5411961001461969, 1.3065629648763766):  # 4th-order Butterworth
            norm = 1.0 + k / q + k * k
            b0 = k * k / norm
            self.sections.append(
                [b0, 2.0 * b0, b0, 2.0 * (k * k - 1.0) / norm, (1.0 - k / q + k * k) / norm]
            )
        self.gain = self.amplitude / math.sqrt(self._unit_variance())

    def _unit_variance(self) -> float:
        """Output variance for unit white noise: Σ of the squared impulse response."""
        states = [[0.0, 0.0], [0.0, 0.0]]
        total, x = 0.0, 1.0
        for _ in range(max(2000, int(40.0 / (self.cutoff * self.h)))):
            v = x
            for (b0, b1, b2, a1, a2), z in zip(self.sections, states):
                y = b0 * v + z[0]
                z[0] = b1 * v - a1 * y + z[1]
                z[1] = b2 * v - a2 * y
                v = y
            total += v * v
            x = 0.0
        return total
