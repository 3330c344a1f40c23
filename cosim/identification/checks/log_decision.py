"""One set of decisions on a drive log: what ``check`` judges and ``identify`` acts on.

:func:`decide_log` is the single home of every judgement a log gets before the
whole-chain fit: a **problem** is a reason the fit refuses (``check`` exits 1 on it,
:func:`~arcosim.identification.drive_identification.identify_drive` raises it before fitting), a
**warning** is something both print (``identify`` among its own). So ``check`` exits 0
exactly when ``identify`` goes on to fit, and every warning ``check`` gives,
``identify`` gives too. What it judges, only what the fit needs:

- the sample step: increasing, at least 16 samples, constant (a problem otherwise: the
  fits need a constant step);
- the log's plausibility (:mod:`arcosim.identification.checks.plausibility`: its units, the
  torque balance, the record's length against the lowest frequency excited that the
  record resolves and, once
  the modes are read, against the lowest mode seen), warnings;
- the motion: an encoder range under :data:`LEAST_RANGE_COUNTS` counts, a motor
  standing still more than :data:`STUCK_LIMIT` of the time (Coulomb friction then holds
  it), warnings;
- the excitation (:func:`~arcosim.identification.excitation.spectrum.excitation_spectrum`: lines,
  harmonics of one period, or broadband): a broadband excitation still strong at the
  Nyquist frequency π/h warns (a mode above it folds into the band; only a faster
  sample rate helps); the lines' count and band are reported, not judged — the modes
  are;
- above the band: an excitation reaching above 3·g_dist is tested for a mode there
  (:func:`~arcosim.identification.checks.above_band.above_band_test`), a doubt when one
  lies there or the record cannot tell
  (:func:`~arcosim.identification.checks.verdict.excitation_above_band`);
- the modes the fit reads (:func:`~arcosim.identification.fit.whole_chain.first_reading`,
  the fit's own first step) against the fit's own rule
  (:func:`~arcosim.identification.fit.whole_chain.refusal`), a problem when it refuses;
  a mode seen but too weakly excited to count warns.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain.defaults import G_DIST, VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.checks.above_band import AboveBand, above_band_test
from arcosim.identification.checks.plausibility import (
    mode_record_length,
    plausibility_warnings,
    resolved_lowest,
)
from arcosim.identification.checks.verdict import excitation_above_band
from arcosim.identification.errors import IdentificationError
from arcosim.identification.excitation.band import dob_band, search_band
from arcosim.identification.excitation.spectrum import ExcitationSpectrum, excitation_spectrum
from arcosim.identification.fit.encoder_fit import STUCK_VELOCITY_COUNTS
from arcosim.identification.fit.whole_chain import first_reading, refusal
from arcosim.identification.modes.detection import DetectedModes
from arcosim.identification.records.record import (
    EncoderRecord,
    MotorRecord,
    encoder_record,
    motor_record,
    smooth_velocity,
)

#: Largest relative spread of the sample step the fits accept.
STEP_TOLERANCE = 1e-6
#: A log whose motor moves slower than STUCK_VELOCITY_COUNTS (counts/s) for longer than
#: this share of the time warns (Coulomb friction then holds it at reversals).
STUCK_LIMIT = 0.1
#: Least encoder range (counts) before a warning.
LEAST_RANGE_COUNTS = 50
#: A mode seen stable whose residue t value is at least this (but under the count's
#: threshold) is named as too weakly excited; below it, as likely a pole of the noise.
WEAK_T = 2.0
#: A broadband excitation whose Welch spectrum still stands within 10 dB of its peak
#: above this share of the Nyquist frequency π/h reaches it (dimensionless).
NYQUIST_SHARE = 0.9


@dataclass
class LogDecision:
    """What :func:`decide_log` found.

    Attributes
    ----------
    problems : list of str
        Reasons the fit refuses, each with what to do; empty: it goes ahead.
    warnings : list of str
        What both ``check`` and ``identify`` warn of, one sentence each.
    plausibility : list of str
        The plausibility findings among the warnings (a refusal names them first).
    above_band : str or None
        The excitation reaching above the disturbance observer's band when something
        may lie there (:func:`~arcosim.identification.checks.verdict.excitation_above_band`).
    above_test : AboveBand or None
        The test of the response above that band
        (:func:`~arcosim.identification.checks.above_band.above_band_test`); None when
        the excitation stays below it or the record cannot tell.
    step : float
        Mean sample step (s).
    step_spread : float
        (max − min) / mean of the steps (dimensionless).
    range_counts : float
        Encoder range (counts).
    stuck_fraction : float
        Share of samples where the motor moves slower than
        :data:`~arcosim.identification.fit.encoder_fit.STUCK_VELOCITY_COUNTS` counts per
        second (dimensionless, 0 … 1).
    spectrum : ExcitationSpectrum or None
        What the current's spectrum shows.
    band : float
        Highest mode sought, min(3·g_dist, 0.3/h) (rad/s).
    detected : DetectedModes or None
        The modes the fit reads first; None when they could not be read.
    record : MotorRecord or None
        The reaction-torque record built for the reading (the friction given, if any).
    encoder : EncoderRecord or None
        The current → encoder record built for it (None without encoder counts).
    reading : tuple of (MotorRecord, EncoderRecord or None, DetectedModes) or None
        What :func:`~arcosim.identification.fit.whole_chain.first_reading` returned for them
        (the records then fitted and the modes), for the fit to start from; None when
        the modes could not be read.
    """

    problems: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    plausibility: list[str] = field(default_factory=list)
    above_band: str | None = None
    above_test: AboveBand | None = None
    step: float = 0.0
    step_spread: float = 0.0
    range_counts: float = 0.0
    stuck_fraction: float = 0.0
    spectrum: ExcitationSpectrum | None = None
    band: float = 0.0
    detected: DetectedModes | None = None
    record: MotorRecord | None = None
    encoder: EncoderRecord | None = None
    reading: tuple[MotorRecord, EncoderRecord | None, DetectedModes] | None = None

    @property
    def ok(self) -> bool:
        """No problem: the fit goes ahead."""
        return not self.problems

    @property
    def doubts(self) -> list[str]:
        """The findings among the warnings that leave any fit of the log untrusted: the
        plausibility findings and an excitation above the band
        (:mod:`~arcosim.identification.checks.verdict`)."""
        return self.plausibility + ([self.above_band] if self.above_band else [])


def decide_log(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    *,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float = G_DIST,
    masses: int | str = "auto",
    D_m: float | None = None,
    f_c: float | None = None,
    load: str = "none",
) -> LogDecision:
    """Every decision on a log before the whole-chain fit (the module doc lists them).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    i_a : ndarray
        Motor current (A), shape ``(N,)``.
    omega_m : ndarray
        Motor velocity (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    J_m : float
        Motor inertia (kg·m²).
    encoder_cpr : int
        Encoder counts per revolution (a count); 0 for an angle not quantized.
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).
    masses : int or "auto"
        Number of load masses asked for (a count), or ``"auto"``.
    D_m, f_c : float, optional
        Motor viscous (N·m·s/rad) and Coulomb (N·m) friction when known (both, or the
        friction is fitted).
    load : {"none", "constant", "slow"}
        The load torque model the fit will use.

    Returns
    -------
    LogDecision
        The problems (the fit's refusals), the warnings, and the figures behind them.

    Examples
    --------
    >>> run = arcosim.run_scenario(arcosim.SCENARIOS["identification"], 2,
    ...                            plant={"J[1]": 4e-4, "J[2]": 8e-4, "k[1]": 0.3, "k[2]": 0.2})
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> decision = decide_log(run.time, *signals, k_t=0.0406, J_m=2.09e-5, encoder_cpr=2000)
    >>> decision.ok, decision.detected.n, decision.spectrum.kind
    (True, 2, 'lines')
    """
    time, i_a, omega_m, theta_m = (
        np.asarray(x, dtype=float) for x in (time, i_a, omega_m, theta_m)
    )
    decision = LogDecision()
    steps = np.diff(time)
    if len(steps) < 16 or np.any(steps <= 0):
        decision.problems.append("the log needs increasing times and at least 16 samples")
        return decision
    h = _step(decision, steps, float(np.max(np.abs(time))))
    decision.band = search_band(g_dist, h)
    decision.spectrum = excitation_spectrum(i_a, h)
    _excitation(decision, i_a)
    lowest = resolved_lowest(decision.spectrum, float(time[-1] - time[0]))
    decision.plausibility = plausibility_warnings(
        time, i_a, omega_m, theta_m, k_t, J_m, lowest, encoder_cpr
    )
    _above_band(decision, i_a, theta_m, g_dist)
    decision.warnings += decision.doubts
    count = 2.0 * np.pi / encoder_cpr if encoder_cpr > 0 else 0.0
    _motion(decision, theta_m, h, count, g_dist)
    _nyquist(decision, h)
    if not decision.problems:
        friction = (D_m, f_c) if D_m is not None and f_c is not None else None
        _modes(
            decision,
            (time, i_a, omega_m, theta_m),
            k_t,
            J_m,
            encoder_cpr,
            g_dist,
            masses,
            friction,
            load,
        )
        _length_against_modes(decision, time)
    return decision


def _above_band(decision: LogDecision, i_a: np.ndarray, theta_m: np.ndarray, g_dist: float) -> None:
    """When the excitation reaches above 3·g_dist, whether a mode lies there
    (:func:`~arcosim.identification.checks.above_band.above_band_test`), and the doubt
    it leaves (``i_a`` A, ``theta_m`` rad, shape ``(N,)``; ``g_dist`` rad/s)."""
    spectrum, top = decision.spectrum, dob_band(g_dist)
    if spectrum is not None and spectrum.highest is not None and spectrum.highest > top:
        decision.above_test = above_band_test(
            i_a, theta_m, decision.step, top, spectrum.highest, spectrum.periods
        )
    decision.above_band = excitation_above_band(spectrum, g_dist, decision.above_test)


def _length_against_modes(decision: LogDecision, time: np.ndarray) -> None:
    """The record's length against the lowest mode the fit reads (of the modes that
    count; when none does, of those seen too weakly excited to, t ≥ :data:`WEAK_T`), a
    plausibility warning: it does not rest on finding the lines."""
    detected = decision.detected
    if detected is None:
        return
    seen = [float(w) for w in detected.frequency]
    seen = seen or [w for w, t in detected.weak if t >= WEAK_T]
    if not seen:
        return
    found = mode_record_length(time, min(seen))
    if found:
        decision.plausibility.append(found)
        decision.warnings.insert(len(decision.plausibility) - 1, found)


def _step(decision: LogDecision, steps: np.ndarray, latest: float) -> float:
    """The mean step (s) and its spread; a problem above :data:`STEP_TOLERANCE`, naming
    the times' own rounding when it explains the spread (``latest``: the largest |time|,
    s; a clock's absolute time holds a 1 ms step to a few 1e-7 s only)."""
    decision.step = h = float(np.mean(steps))
    decision.step_spread = float((steps.max() - steps.min()) / h)
    if decision.step_spread <= STEP_TOLERANCE:
        return h
    rounding = float(np.spacing(latest))  # the resolution of the times as written (s)
    if decision.step_spread * h <= 4.0 * rounding:  # a difference of two rounded times
        decision.problems.append(
            f"the sample step varies by {decision.step_spread:.1e} of its mean, as the times "
            f"themselves are rounded ({latest:.3g} s from zero hold {rounding:.1e} s): if the "
            f"drive samples at a fixed rate, write the time from the log's start as k·h "
            f"(h = {h:.6g} s), or resample the log"
        )
    else:
        decision.problems.append(
            f"the sample step varies by {decision.step_spread:.1e} of its mean: the fits "
            "need a constant step (resample the log, or log at a fixed rate)"
        )
    return h


def _excitation(decision: LogDecision, i_a: np.ndarray) -> None:
    """A problem when the current is constant (``i_a`` in A, shape ``(N,)``): the log
    holds no excitation at all. A current that varies by its noise only is not told
    here (a closed loop's current is as fast); its fit's verdict says the log is not
    plausible."""
    if np.ptp(i_a) > 1e-12 * max(float(np.abs(i_a).max()), 1e-300):
        return
    decision.problems.append(
        f"the current i_a is constant ({float(i_a[0]):.6g} A on every row): the log holds "
        "no excitation to identify from; log the motor current while an excitation plays "
        "(arcosim excite writes one), and check that the right column is named i_a"
    )


def _motion(
    decision: LogDecision, theta: np.ndarray, h: float, count: float, g_dist: float
) -> None:
    """The encoder's range and how often the motor stands still (``theta`` rad, step
    ``h`` s, one count ``count`` rad, 0: not quantized; ``g_dist`` rad/s): warnings."""
    decision.range_counts = float(np.ptp(theta) / count) if count else float("inf")
    if decision.range_counts < LEAST_RANGE_COUNTS:
        decision.warnings.append(
            f"the encoder moved over {decision.range_counts:.0f} counts only: the modes "
            "sink into the counts (a higher current next time)"
        )
    if not count:
        return
    speed = smooth_velocity(theta, h, VELOCITY_SMOOTHING * g_dist)
    decision.stuck_fraction = float(np.mean(np.abs(speed) < STUCK_VELOCITY_COUNTS * count))
    if decision.stuck_fraction > STUCK_LIMIT:
        decision.warnings.append(
            f"the motor moves slower than {STUCK_VELOCITY_COUNTS:g} counts/s "
            f"{100 * decision.stuck_fraction:.0f} % of the time (Coulomb friction holds "
            "it there; the fit's friction model is then approximate: J_i, k_i 1–2 % off "
            "at 18 %)"
        )


def _nyquist(decision: LogDecision, h: float) -> None:
    """A broadband excitation still strong near π/h: a warning (only a faster sample
    rate helps, on the next record)."""
    spectrum = decision.spectrum
    if spectrum.kind != "broadband" or spectrum.band[1] < NYQUIST_SHARE * np.pi / h:
        return
    decision.warnings.append(
        f"the excitation's spectrum reaches the Nyquist frequency π/h = {np.pi / h:.0f} "
        "rad/s: a mode above it folds into the band and would be fitted where it is not; "
        "record faster if the fit shows a mode you do not expect"
    )


def _modes(
    decision: LogDecision,
    log: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float,
    masses: int | str,
    friction: tuple[float, float] | None,
    load: str,
) -> None:
    """The modes the fit reads first, judged by the fit's own rule: a problem when it
    refuses (or cannot read them), a warning per mode seen but too weakly excited."""
    time, i_a, omega_m, theta = log
    actuator = Actuator(J_m, k_t, 0.0, 0.0, *friction) if friction else Actuator(J_m, k_t)
    try:
        decision.record = motor_record(time, i_a, omega_m, theta, actuator, g_dist)
        if encoder_cpr > 0:
            decision.encoder = encoder_record(
                time, i_a, theta, actuator, encoder_cpr, friction is not None, load, g_dist
            )
        elif friction is None or load != "none":
            raise IdentificationError(
                "without encoder counts (encoder_cpr = 0) the fit needs the motor friction "
                "(D_m and f_c) and no load torque model"
            )
        reading = first_reading(decision.record, masses, decision.encoder)
    except IdentificationError as error:
        decision.problems.append(str(error))
        return
    decision.reading = reading
    record, _, detected = reading
    decision.detected = detected
    why = refusal(detected, masses, record, decision.encoder is not None)
    if why:
        decision.problems.append(why)
    for w, t in detected.weak:
        if t >= WEAK_T:
            decision.warnings.append(
                f"a mode near {w:.1f} rad/s is too weakly excited to count (t = {t:.1f}): "
                "more current per line there, a longer record or a finer encoder"
            )
