"""Can a drive log support whole-chain identification? Checks before any fit (offline).

:func:`check_log` looks at a log (time, i_a, omega_m, theta_m) with what the user knows
(k_t, J_m, the encoder's counts, the DOB bandwidth) and reports, each with what would
fix it: the step's regularity, the motion (encoder range, how often the motor stands
still), the excitation's band (its lines, found in the current by
:func:`excitation_lines`, against the band 0.3/h and 3·g_dist leave,
:mod:`arcosim.identification.band`, and how well the encoder sees them), and the modes
the record shows (:func:`arcosim.identification.modal_start.detect_modes`: stable, with
residues above their standard errors; the weak ones named), and the log's plausibility
(:func:`log_plausibility`: its units and length, warnings that
:func:`~arcosim.identification.drive.identify_drive` gives too). One helper per check,
each adding its findings to the :class:`CheckReport`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain.defaults import G_DIST, VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.band import sample_band, search_band
from arcosim.identification.blas import single_threaded
from arcosim.identification.encoder_fit import STUCK_VELOCITY_COUNTS
from arcosim.identification.errors import IdentificationError
from arcosim.identification.excitation_design import LINE_T
from arcosim.identification.modal_start import DetectedModes, detect_modes
from arcosim.identification.motor_friction import friction_cleaned
from arcosim.identification.plausibility import plausibility_warnings
from arcosim.identification.records import encoder_record, motor_record, smooth_velocity
from arcosim.identification.whole_chain import MAX_AUTO_MASSES

#: Largest relative spread of the sample step the fits accept.
STEP_TOLERANCE = 1e-6
#: A log whose motor moves slower than STUCK_VELOCITY_COUNTS (counts/s) for longer than
#: this share of the time is flagged (Coulomb friction then holds it at reversals).
STUCK_LIMIT = 0.1
#: A mode whose residue t value is below this is flagged as weakly determined.
MODE_T = 30.0
#: A stable pole whose residue t value is below this (or negative: a spring chain's
#: modes all have positive residues) is as likely a pole of the noise as a mode.
WEAK_T = 2.0
#: Least encoder range (counts).
LEAST_RANGE_COUNTS = 50
#: An excitation line stands this many times above the current spectrum's median.
LINE_PROMINENCE = 30.0


@dataclass
class CheckReport:
    """What :func:`check_log` found.

    Attributes
    ----------
    ok : bool
        Nothing stands in the way of a fit.
    problems : list of str
        What stands in the way, each with what to do.
    warnings : list of str
        What may limit the fit (a mode seen but weakly excited).
    step : float
        Mean sample step (s).
    step_spread : float
        (max − min) / mean of the steps (dimensionless).
    range_counts : float
        Encoder range (counts).
    stuck_fraction : float
        Share of samples where the motor moves slower than
        :data:`~arcosim.identification.encoder_fit.STUCK_VELOCITY_COUNTS` counts per
        second (dimensionless, 0 … 1).
    lines : list of float
        Excitation lines found in the current (rad/s).
    line_t : list of float
        Per line, the encoder angle's amplitude there over its standard error (the
        counts' noise), dimensionless: how well the encoder sees the line.
    band : float
        Highest mode sought, min(3·g_dist, 0.3/h) (rad/s;
        :func:`~arcosim.identification.band.search_band`).
    modes : list of float
        The modes the record shows (rad/s).
    t_values : list of float
        Their residue t values (dimensionless).
    weak : list of tuple of float
        Stable poles seen whose residue t value is below the fit's threshold (rad/s, t
        value): too weakly excited modes (t ≥ :data:`WEAK_T`), or not modes.
    """

    ok: bool
    problems: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    step: float = 0.0
    step_spread: float = 0.0
    range_counts: float = 0.0
    stuck_fraction: float = 0.0
    lines: list[float] = field(default_factory=list)
    line_t: list[float] = field(default_factory=list)
    band: float = 0.0
    modes: list[float] = field(default_factory=list)
    t_values: list[float] = field(default_factory=list)
    weak: list[tuple[float, float]] = field(default_factory=list)

    def text(self) -> str:
        """A few lines for the user."""
        out = [
            f"step {self.step:.6g} s (spread {self.step_spread:.1e}); encoder range "
            f"{self.range_counts:.0f} counts; motor slower than {STUCK_VELOCITY_COUNTS:g} "
            f"counts/s {100 * self.stuck_fraction:.1f} % of the time",
            f"excitation lines: {len(self.lines)}"
            + (f", {min(self.lines):.3g} … {max(self.lines):.4g} rad/s" if self.lines else "")
            + (
                f" (encoder sees them with t = {min(self.line_t):.0f} … {max(self.line_t):.0f})"
                if self.line_t
                else ""
            )
            + f"; modes sought below {self.band:.0f} rad/s",
            "modes seen: "
            + (
                ", ".join(f"{w:.2f} (t = {t:.0f})" for w, t in zip(self.modes, self.t_values))
                or "none"
            )
            + self._weak_text(),
        ]
        out += [f"problem: {p}" for p in self.problems]
        out += [f"warning: {w}" for w in self.warnings]
        out.append("ok: the log can support identification" if self.ok else "not ok")
        return "\n".join(out)

    def _weak_text(self) -> str:
        """The modes seen but too weakly excited, and how many other stable poles were
        set aside as not modes of the chain."""
        weak = [(w, t) for w, t in self.weak if t >= WEAK_T]
        text = ""
        if weak:
            text = "; too weakly excited to fit: " + ", ".join(
                f"{w:.1f} (t = {t:.1f})" for w, t in weak
            )
        others = len(self.weak) - len(weak)
        if others:
            text += (
                f"; {others} other stable pole(s) set aside (t < {WEAK_T:g} or a negative "
                "residue: not modes of a spring chain)"
            )
        return text


@single_threaded
def check_log(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float = G_DIST,
) -> CheckReport:
    """Can a log support whole-chain identification? Checks before any fit.

    The step's regularity, the motion (encoder range, how often the motor stands
    still), the excitation's lines against the band the sample rate and the DOB leave,
    and the modes the record shows (stable, with residues above their standard
    errors; the weak ones named). Raises nothing for a poor log: every finding goes
    into the report, with what would fix it.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    i_a : ndarray
        Current (A), shape ``(N,)``.
    omega_m : ndarray
        Motor velocity (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A), from the datasheet (the observer FMU's ``k_to``).
    J_m : float
        Motor inertia (kg·m²), from the datasheet (the observer FMU's ``J_mo``).
    encoder_cpr : int
        Encoder counts per revolution (a count; the observer FMU's ``encoder_cpr``);
        0 for an angle not quantized.
    g_dist : float
        Bandwidth of the disturbance observer (rad/s).

    Returns
    -------
    CheckReport
        ``ok``, the problems and warnings (one sentence each, with what to do), and
        the figures behind them; ``text()`` for the user.

    Examples
    --------
    >>> run = arcosim.run_scenario(arcosim.SCENARIOS["identification"], 2,
    ...                            plant={"J[1]": 4e-4, "J[2]": 8e-4, "k[1]": 0.3, "k[2]": 0.2})
    >>> signals = [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> report = arcosim.check_log(run.time, *signals, k_t=0.0406, J_m=2.09e-5, encoder_cpr=2000)
    >>> report.ok, len(report.modes)
    (True, 2)
    """
    time = np.asarray(time, dtype=float)
    report = CheckReport(ok=True)
    steps = np.diff(time)
    if len(steps) < 16 or np.any(steps <= 0):
        report.ok = False
        report.problems.append("the log needs increasing times and at least 16 samples")
        return report
    h = _check_step(report, steps)
    report.warnings += log_plausibility(time, i_a, omega_m, theta_m, k_t, J_m)
    count = 2.0 * np.pi / encoder_cpr if encoder_cpr > 0 else 0.0
    theta = np.asarray(theta_m, dtype=float)
    _check_range(report, theta, count)
    _check_stuck(report, theta, h, count, g_dist)
    _check_lines(report, i_a, h, g_dist)
    _check_line_visibility(report, theta, h, count)
    _check_modes(report, time, i_a, omega_m, theta, k_t, J_m, encoder_cpr, g_dist)
    report.ok = not report.problems
    return report


def _check_step(report: CheckReport, steps: np.ndarray) -> float:
    """The step's regularity: the mean step (s) and its spread into ``report`` (``steps``
    in s, shape ``(N − 1,)``); a problem above :data:`STEP_TOLERANCE`. Returns the step."""
    report.step = h = float(np.mean(steps))
    report.step_spread = float((steps.max() - steps.min()) / h)
    if report.step_spread > STEP_TOLERANCE:
        report.problems.append(
            f"the sample step varies by {report.step_spread:.1e} of its mean: the fits need "
            "a constant step (resample the log, or log at a fixed rate)"
        )
    return h


def _check_range(report: CheckReport, theta: np.ndarray, count: float) -> None:
    """The encoder's range (counts; ``theta`` in rad, shape ``(N,)``, one count
    ``count`` rad, 0: not quantized): a problem under :data:`LEAST_RANGE_COUNTS`."""
    report.range_counts = float(np.ptp(theta) / count) if count else float("inf")
    if report.range_counts < LEAST_RANGE_COUNTS:
        report.problems.append(
            f"the encoder moved over {report.range_counts:.0f} counts only: raise the current"
        )


def _check_stuck(
    report: CheckReport, theta: np.ndarray, h: float, count: float, g_dist: float
) -> None:
    """How often the motor stands still (``theta`` in rad, shape ``(N,)``; step ``h`` in
    s; one count ``count`` rad, 0: not checked; ``g_dist`` rad/s for the smoothing): a
    problem above :data:`STUCK_LIMIT`."""
    if not count:
        return
    speed = smooth_velocity(theta, h, VELOCITY_SMOOTHING * g_dist)
    report.stuck_fraction = float(np.mean(np.abs(speed) < STUCK_VELOCITY_COUNTS * count))
    if report.stuck_fraction > STUCK_LIMIT:
        report.problems.append(
            f"the motor moves slower than {STUCK_VELOCITY_COUNTS:g} counts/s "
            f"{100 * report.stuck_fraction:.0f} % of the time (Coulomb friction holds "
            "it there; the fit's friction model is then approximate: J_i, k_i 1–2 % "
            "off at 18 %): raise the current, use fewer lines, or add a slow speed offset"
        )


def _check_lines(report: CheckReport, i_a: np.ndarray, h: float, g_dist: float) -> None:
    """The excitation's lines in the current (A, shape ``(N,)``; step ``h`` in s) against
    the band (``g_dist`` in rad/s): a problem when they stop well under it or go above
    what the sample rate leaves."""
    report.band = search_band(g_dist, h)
    report.lines = [float(w) for w in excitation_lines(np.asarray(i_a, dtype=float), h)]
    if report.lines and max(report.lines) < 0.5 * report.band:
        report.problems.append(
            f"the excitation stops at {max(report.lines):.0f} rad/s, well under the band "
            f"({report.band:.0f} rad/s): modes above it are not excited (extend the lines)"
        )
    if report.lines and max(report.lines) > sample_band(h):
        report.problems.append(
            f"lines above 0.3/h = {sample_band(h):.0f} rad/s: sample faster or lower the band"
        )


def _check_line_visibility(report: CheckReport, theta: np.ndarray, h: float, count: float) -> None:
    """How well the encoder sees each line (``theta`` in rad, shape ``(N,)``; step ``h`` in
    s; one count ``count`` rad, 0: not checked): a problem for lines under :data:`LINE_T`."""
    if not (report.lines and count):
        return
    report.line_t = line_visibility(theta, h, np.array(report.lines), count)
    blind = [w for w, t in zip(report.lines, report.line_t) if t < LINE_T]
    if blind:
        report.problems.append(
            f"the encoder barely sees {len(blind)} of the {len(report.lines)} lines "
            f"(t < {LINE_T:g}; from {min(blind):.0f} rad/s): modes there sink into the "
            "counts; more current per line (fewer lines, a higher amplitude), a finer "
            "encoder or a longer record"
        )


def _check_modes(
    report: CheckReport,
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta: np.ndarray,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float,
) -> None:
    """The modes the record shows (:func:`_modes`; arguments as :func:`check_log`'s):
    a problem when it shows none (or cannot be read), a warning per weakly determined
    mode (t under :data:`MODE_T`) and per mode too weakly excited to count."""
    try:
        i_a = np.asarray(i_a, float)
        detected = _modes(time, i_a, omega_m, theta, k_t, J_m, encoder_cpr, g_dist)
    except IdentificationError as error:
        report.problems.append(str(error))
        return
    report.modes = [float(w) for w in detected.frequency]
    report.t_values = [float(t) for t in detected.t_value]
    report.weak = list(detected.weak)
    if not detected.n:
        report.problems.append(
            "the record shows no excited mode: excite the chain across its modes "
            "(a multi-sine of many lines, `arcosim.design_excitation`)"
        )
    for w, t in zip(report.modes, report.t_values):
        if t < MODE_T:
            report.warnings.append(
                f"the mode at {w:.1f} rad/s is weakly determined (t = {t:.0f} < "
                f"{MODE_T:g}): the fit will confirm it by its information criterion"
            )
    for w, t in detected.weak:
        if t >= WEAK_T:
            report.warnings.append(
                f"a mode near {w:.1f} rad/s is too weakly excited (t = {t:.1f}): more "
                "current per line there, a longer record or a finer encoder"
            )


def _modes(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta: np.ndarray,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float,
) -> DetectedModes:
    """The record's modes as the whole-chain fit reads them (friction not known: first
    estimated from the modes, taken out of τ̂, and the modes read again); arguments as
    :func:`check_log`'s."""
    actuator = Actuator(J_m, k_t)
    record = motor_record(time, i_a, omega_m, theta, actuator, g_dist)
    detected = detect_modes(record, MAX_AUTO_MASSES)
    if detected.n and encoder_cpr > 0:
        encoder = encoder_record(
            time, i_a, theta, actuator, encoder_cpr, friction_given=False, g_dist=g_dist
        )
        detected = friction_cleaned(record, encoder, detected.modes(), MAX_AUTO_MASSES)[3]
    return detected


def log_plausibility(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    J_m: float,
) -> list[str]:
    """The log's plausibility warnings
    (:func:`~arcosim.identification.plausibility.plausibility_warnings`) with the lowest
    excitation line :func:`excitation_lines` finds: what ``check`` and ``identify``
    both warn of. Arguments as :func:`check_log`'s; returns one line per finding."""
    time = np.asarray(time, dtype=float)
    i_a = np.asarray(i_a, dtype=float)
    lines = excitation_lines(i_a, float(np.mean(np.diff(time))))
    lowest = float(min(lines)) if len(lines) else None
    args = (np.asarray(omega_m, dtype=float), np.asarray(theta_m, dtype=float))
    return plausibility_warnings(time, i_a, *args, k_t, J_m, lowest)


def line_visibility(theta: np.ndarray, h: float, lines: np.ndarray, count: float) -> list[float]:
    """Per line: the amplitude of the encoder angle at it (least squares on a sine and
    cosine per line, a trend removed) over its standard error with the counts' noise
    q/√12 per sample (dimensionless); ``theta`` in rad (shape ``(N,)``), step ``h`` in s,
    ``lines`` in rad/s (shape ``(L,)``), one count ``count`` in rad."""
    t = np.arange(len(theta)) * h
    x = theta - np.polyval(np.polyfit(t, theta, 3), t)
    phase = np.outer(t, lines)
    X = np.hstack([np.sin(phase), np.cos(phase)])
    coef = np.linalg.lstsq(X, x, rcond=None)[0]
    amplitude = np.hypot(coef[: len(lines)], coef[len(lines) :])
    error = (count / np.sqrt(12.0)) * np.sqrt(2.0 / len(theta))
    return [float(a / error) for a in amplitude]


def excitation_lines(current: np.ndarray, h: float) -> np.ndarray:
    """Frequencies (rad/s) of the lines of a multi-sine in ``current`` (any unit):
    spectral peaks :data:`LINE_PROMINENCE` times above the median, shape (L,)."""
    x = np.asarray(current, dtype=float)
    x = (x - x.mean()) * np.hanning(len(x))
    power = np.abs(np.fft.rfft(x)) ** 2
    frequency = 2.0 * np.pi * np.fft.rfftfreq(len(x), h)
    floor = max(float(np.median(power[1:])), 1e-300)
    peak = (power[1:-1] > power[:-2]) & (power[1:-1] >= power[2:])
    strong = power[1:-1] > LINE_PROMINENCE * floor
    j = np.flatnonzero(peak & strong) + 1
    # parabolic interpolation of the log power: the line between the bins
    left, mid, right = (np.log(power[j + d]) for d in (-1, 0, 1))
    shift = (
        0.5 * (left - right) / np.where(left - 2 * mid + right == 0, -1.0, left - 2 * mid + right)
    )
    return frequency[j] + np.clip(shift, -0.5, 0.5) * (frequency[1] - frequency[0])
