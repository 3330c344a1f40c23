"""The excitation a user plays on a drive for whole-chain identification (offline design).

:func:`design_excitation` turns a band and a current limit into a multi-sine: as arrays, and (for a
current) as the ExcitationSource FMU's parameters, which play the same signal (the same
``arcosim.fmu.flexchain.waveforms`` functions). What the design rests on, measured on the
whole-chain rows (README):

* many lines across the band (40 log-spaced lines; 11 let the subspace step take lines
  for modes), lines on both sides of every mode, the top line below the band the
  sample rate leaves (0.3/h) and below 3·g_dist (:mod:`arcosim.identification.excitation.band`);
* enough torque that the motor rarely sticks: an rms torque k_t·A/√(2L) of at least
  :data:`TORQUE_PER_FRICTION` times f_c (the bench motor at 1 A on 40 lines stuck 18 %
  of the time and biased J_i by 1.5 %; at 3 A, 0.2 % and within 0.1 %);
* motion the encoder sees at the top of the band: a line there, moving the motor by a
  (rad) against the counts' noise q/√12 per sample, is seen with t = a·√(6N)/q over N
  samples; below :data:`LINE_T` (rigid-body motion, J_total known: a lower bound) the
  modes up there sink into the counts (a stiff belt drive: t ≈ 1.6; the
  log's check, :func:`arcosim.identification.checks.log_check.check_log`, holds the lines it
  finds in a log to the same threshold);
* in a closed speed loop, a speed reference whose lines grow with frequency (about equal
  torque per line, as an open-loop current): equal speed lines leave the top modes
  unexcited.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain import waveforms
from arcosim.fmu.flexchain.codes import Signal
from arcosim.fmu.flexchain.defaults import STEP
from arcosim.identification.errors import IdentificationError
from arcosim.identification.excitation.band import dob_band, sample_band

#: Lines of the multi-sine (log-spaced over the band).
LINES = 40
#: Record length (s).
DURATION = 20.0
#: Least rms drive torque, in units of the Coulomb friction f_c.
TORQUE_PER_FRICTION = 5.0
#: Least t value of a line's motor motion against the encoder's counts: the angle's
#: amplitude at the line over its standard error with the counts' noise q/√12 per
#: sample (dimensionless). The design holds its top line to it, the log's check every
#: line it finds.
LINE_T = 5.0


class ExcitationError(IdentificationError):
    """A band or limit no excitation can meet; the message says what to change."""


@dataclass
class Excitation:
    """A designed multi-sine.

    Attributes
    ----------
    kind : str
        ``"current"`` (A) or ``"speed"`` (rad/s, a speed loop's reference).
    time : ndarray
        Sample times (s), shape ``(N,)``.
    signal : ndarray
        The command at each sample (A or rad/s), shape ``(N,)``.
    frequencies : ndarray
        The lines (rad/s), shape ``(L,)``.
    amplitudes : ndarray
        Each line's amplitude (A or rad/s), shape ``(L,)``.
    phases : ndarray
        Each line's phase (rad), shape ``(L,)``.
    source_parameters : dict or None
        ExcitationSource parameters that play the same current (``None`` for a speed
        reference: the FMU's lines are all equal).
    warnings : list of str
        What the design could not meet, one line each.
    """

    kind: str
    time: np.ndarray
    signal: np.ndarray
    frequencies: np.ndarray
    amplitudes: np.ndarray
    phases: np.ndarray
    source_parameters: dict | None
    warnings: list[str] = field(default_factory=list)

    def columns(self) -> dict[str, np.ndarray]:
        """CSV columns: ``time`` (s) and ``i_ref`` (current, A) or ``omega_ref`` (speed,
        rad/s), each of shape ``(N,)``."""
        return {"time": self.time, "i_ref" if self.kind == "current" else "omega_ref": self.signal}


def design_excitation(
    band: tuple[float, float],
    current_limit: float,
    h: float = STEP,
    duration: float = DURATION,
    lines: int = LINES,
    kind: str = "current",
    seed: int = 1,
    k_t: float | None = None,
    f_c: float | None = None,
    J_total: float | None = None,
    encoder_cpr: int | None = None,
    g_dist: float | None = None,
    speed_gain: float | None = None,
) -> Excitation:
    """Design the multi-sine to play on a drive for whole-chain identification.

    Log-spaced lines over the band whose amplitudes add up to the current limit (a
    current command), or grow with frequency (a speed loop's reference); checked,
    when the drive's figures are given, against the friction (sticking), the encoder
    (motion at the top line) and the DOB's band — each shortfall a warning with what
    to change.

    Parameters
    ----------
    band : tuple of float
        Lowest and highest line (rad/s).
    current_limit : float
        The drive's peak current (A): a current multi-sine's lines add up to it, so the
        command never exceeds it.
    h : float
        Sample step (s).
    duration : float
        Record length (s).
    lines : int
        Number of log-spaced lines (a count).
    kind : {"current", "speed"}
        ``"current"`` (open loop) or ``"speed"`` (the reference of a PI speed loop with
        proportional gain ``speed_gain``: lines ∝ frequency, whose currents through the
        gain add up to ``current_limit``).
    seed : int
        Seed of the phases (the ExcitationSource FMU's ``seed``); an index.
    k_t : float, optional
        Torque constant (N·m/A), for the friction check.
    f_c : float, optional
        Coulomb friction (N·m), for the friction check.
    J_total : float, optional
        Motor and load inertia (kg·m²), for the encoder check.
    encoder_cpr : int, optional
        Encoder counts per revolution (a count; the observer FMU's ``encoder_cpr``),
        for the encoder check.
    g_dist : float, optional
        DOB bandwidth (rad/s), for the band check.
    speed_gain : float, optional
        The speed loop's proportional gain (A·s/rad), for ``kind="speed"``.

    Returns
    -------
    Excitation
        Time (s) and command (A or rad/s), shape ``(N,)``; the lines (rad/s), their
        amplitudes and phases, shape ``(L,)``; ExcitationSource parameters that play
        the same current; the warnings.

    Raises
    ------
    ExcitationError
        For a band that is empty or above what the sample rate leaves, a non-positive
        limit, or a speed design without ``speed_gain``.

    Examples
    --------
    >>> design = arcosim.design_excitation((3.0, 150.0), 3.0, k_t=0.0406, f_c=2e-3)
    >>> design.signal.shape, bool(np.abs(design.signal).max() <= 3.0)
    ((20001,), True)
    >>> design.source_parameters["lines"], design.warnings
    (40, [])
    """
    low, high = _checked_request(band, current_limit, h, lines, kind)
    frequencies = np.array(waveforms.log_spaced(low, high, lines))
    phases = np.array(waveforms.multisine_phases(lines, seed))
    time = np.arange(round(duration / h) + 1) * h
    warnings: list[str] = []
    if kind == "current":
        amplitudes = np.full(lines, current_limit / lines)
        parameters = _source_parameters(current_limit, low, high, lines, seed)
        per_line_current = amplitudes
    else:
        amplitudes = _speed_amplitudes(frequencies, high, current_limit, speed_gain)
        parameters = None
        per_line_current = speed_gain * amplitudes
        warnings.append(
            "a speed reference with lines growing with frequency is not an ExcitationSource "
            "signal: play the CSV"
        )
    # the sines of the ExcitationSource's own lines and phases, every sample at once (its
    # multisine, sample by sample, gives the same current to the last bit or so)
    signal = np.sin(np.outer(time, frequencies) + phases) @ amplitudes
    checks = (
        _friction_warning(per_line_current, k_t, f_c),
        _encoder_warning(per_line_current, high, len(time), k_t, J_total, encoder_cpr),
        _dob_warning(high, g_dist),
    )
    warnings += [text for text in checks if text]
    return Excitation(kind, time, signal, frequencies, amplitudes, phases, parameters, warnings)


def _checked_request(
    band: tuple[float, float], current_limit: float, h: float, lines: int, kind: str
) -> tuple[float, float]:
    """The band's ``(low, high)`` (rad/s) once the request is one a design can meet.

    Raises
    ------
    ExcitationError
        For a band that is empty or above what the sample rate leaves, a non-positive
        limit, no line, or an unknown kind.
    """
    low, high = (float(x) for x in band)
    if not 0.0 < low < high:
        raise ExcitationError(f"the band must be 0 < low < high rad/s, got {band}")
    if high > sample_band(h):
        raise ExcitationError(
            f"the top line {high:g} rad/s is above 0.3/h = {sample_band(h):.0f} rad/s: "
            "sample faster or lower the band"
        )
    if not current_limit > 0:
        raise ExcitationError(f"the current limit must be > 0 A, got {current_limit}")
    if lines < 1:
        raise ExcitationError(f"need at least one line, got {lines}")
    if kind not in ("current", "speed"):
        raise ExcitationError(f"kind must be 'current' or 'speed', got {kind!r}")
    return low, high


def _source_parameters(
    current_limit: float, low: float, high: float, lines: int, seed: int
) -> dict[str, float | int]:
    """The ExcitationSource FMU's parameters that play the designed current (A, rad/s)."""
    return {
        "signal": int(Signal.MULTISINE),
        "amplitude": float(current_limit),
        "frequency": low,
        "frequency_end": high,
        "lines": int(lines),
        "seed": int(seed),
    }


def _speed_amplitudes(
    frequencies: np.ndarray, high: float, current_limit: float, speed_gain: float | None
) -> np.ndarray:
    """A speed reference's line amplitudes (rad/s, shape ``(L,)``) for the lines
    ``frequencies`` (rad/s, shape ``(L,)``) up to ``high`` (rad/s): above the loop's
    bandwidth the loop turns the reference r into kp·r of current, so the lines grow
    with frequency, scaled so that those currents add up to the limit (A).

    Raises
    ------
    ExcitationError
        Without the loop's gain ``speed_gain`` (A·s/rad).
    """
    if not speed_gain or speed_gain <= 0:
        raise ExcitationError("a speed reference needs the loop's gain (speed_gain, A·s/rad)")
    shape = frequencies / high
    return (current_limit / speed_gain) * shape / shape.sum()


def _friction_warning(
    per_line_current: np.ndarray, k_t: float | None, f_c: float | None
) -> str | None:
    """Why the motor will stick often (rms drive torque under :data:`TORQUE_PER_FRICTION`
    · f_c), or None; the lines' currents in A (shape ``(L,)``), ``k_t`` in N·m/A, ``f_c``
    in N·m (either None: not checked)."""
    if not (k_t and f_c):
        return None
    rms_torque = k_t * float(np.sqrt(np.sum(per_line_current**2) / 2.0))
    if not rms_torque < TORQUE_PER_FRICTION * f_c:
        return None
    need = TORQUE_PER_FRICTION * f_c / rms_torque
    return (
        f"rms drive torque {rms_torque:.3g} N·m is under {TORQUE_PER_FRICTION:g}·f_c: "
        f"the motor will stick often; raise the current {need:.1f}× or use fewer lines"
    )


def _encoder_warning(
    per_line_current: np.ndarray,
    high: float,
    samples: int,
    k_t: float | None,
    J_total: float | None,
    encoder_cpr: int | None,
) -> str | None:
    """Why the encoder cannot see the top line ``high`` (rad/s) over ``samples`` samples
    (its t value under :data:`LINE_T`, the motion taken as rigid-body), or None; the
    lines' currents in A (shape ``(L,)``), ``k_t`` in N·m/A, ``J_total`` in kg·m²
    (any of the three None: not checked)."""
    if not (k_t and J_total and encoder_cpr):
        return None
    motion = k_t * float(per_line_current[-1]) / (J_total * high**2)
    seen = motion / (2.0 * math.pi / encoder_cpr)
    t_value = seen * math.sqrt(6.0 * samples)
    if not t_value < LINE_T:
        return None
    return (
        f"a line at {high:g} rad/s moves the motor by about {seen:.2g} counts "
        f"(t = {t_value:.1f} over the record): the encoder cannot see the modes up "
        "there; raise the current, use fewer lines, a longer record, a lower band "
        "or a finer encoder"
    )


def _dob_warning(high: float, g_dist: float | None) -> str | None:
    """Why lines above the DOB's band (:func:`~arcosim.identification.excitation.band.dob_band`)
    are wasted, or None; ``high`` and ``g_dist`` in rad/s (None: not checked)."""
    if not (g_dist and high > dob_band(g_dist)):
        return None
    return (
        f"lines above 3·g_dist = {dob_band(g_dist):g} rad/s: the modal start reads modes only "
        "below it (raise g_dist)"
    )
