"""Can a drive log support whole-chain identification? Checks before any fit (offline).

:func:`check` looks at a log (time, i_a, omega_m, theta_m) with what the user knows
(k_t, J_m, the encoder's counts, the DOB bandwidth) and reports, each with what would
fix it: the step's regularity, the motion (encoder range, how often the motor stands
still), the excitation's band (its lines against the band 0.3/h and 3·g_dist leave),
and the modes the record shows (:func:`arcosim.identification.modal_start.detect_modes`: stable,
with
residues above their standard errors; the weak ones named).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain.defaults import G_DIST, VELOCITY_SMOOTHING
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.identification.blas import single_threaded
from arcosim.identification.encoder_fit import (
    STUCK_VELOCITY_COUNTS,
    encoder_record,
)
from arcosim.identification.errors import IdentificationError
from arcosim.identification.modal_start import (
    Detected,
    detect_modes,
    excitation_lines,
    search_band,
)
from arcosim.identification.output_error import motor_record, smooth_velocity
from arcosim.identification.whole_chain import MAX_AUTO_MASSES, friction_cleaned

#: Largest relative spread of the sample step the fits accept.
STEP_TOLERANCE = 1e-6
#: A log whose motor moves slower than STUCK_VELOCITY_COUNTS (counts/s) for longer than
#: this share of the time is flagged (Coulomb friction then holds it at reversals).
STUCK_LIMIT = 0.1
#: An excitation line the encoder sees has an angle amplitude this many standard
#: errors above the counts' noise (q/√12 per sample).
LINE_T = 5.0
#: A mode whose residue t value is below this is flagged as weakly determined.
MODE_T = 30.0
#: A stable pole whose residue t value is below this (or negative: a spring chain's
#: modes all have positive residues) is as likely a pole of the noise as a mode.
WEAK_T = 2.0
#: Least encoder range (counts).
LEAST_RANGE_COUNTS = 50


@dataclass
class CheckReport:
    """What :func:`check` found.

    Attributes:
        ok: nothing stands in the way of a fit.
        problems: what stands in the way, each with what to do.
        warnings: what may limit the fit (a mode seen but weakly excited).
        step: mean sample step (s); step_spread: (max − min) / mean of the steps.
        range_counts: encoder range (counts).
        stuck_fraction: share of samples where the motor moves slower than
            STUCK_VELOCITY_COUNTS counts per second.
        lines: excitation lines found in the current (rad/s).
        line_t: per line, the encoder angle's amplitude there over its standard error
            (the counts' noise): how well the encoder sees the line.
        band: highest mode sought, min(3·g_dist, 0.3/h) (rad/s).
        modes: the modes the record shows (rad/s); t_values: their residue t values.
        weak: stable poles seen whose residue t value is below the fit's threshold
            (rad/s, t value): too weakly excited modes (t ≥ WEAK_T), or not modes.
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
    report.step = h = float(np.mean(steps))
    report.step_spread = float((steps.max() - steps.min()) / h)
    if report.step_spread > STEP_TOLERANCE:
        report.problems.append(
            f"the sample step varies by {report.step_spread:.1e} of its mean: the fits need "
            "a constant step (resample the log, or log at a fixed rate)"
        )
    count = 2.0 * np.pi / encoder_cpr if encoder_cpr > 0 else 0.0
    theta = np.asarray(theta_m, dtype=float)
    report.range_counts = float(np.ptp(theta) / count) if count else float("inf")
    if report.range_counts < LEAST_RANGE_COUNTS:
        report.problems.append(
            f"the encoder moved over {report.range_counts:.0f} counts only: raise the current"
        )
    if count:
        speed = smooth_velocity(theta, h, VELOCITY_SMOOTHING * g_dist)
        report.stuck_fraction = float(np.mean(np.abs(speed) < STUCK_VELOCITY_COUNTS * count))
        if report.stuck_fraction > STUCK_LIMIT:
            report.problems.append(
                f"the motor moves slower than {STUCK_VELOCITY_COUNTS:g} counts/s "
                f"{100 * report.stuck_fraction:.0f} % of the time (Coulomb friction holds "
                "it there; the fit's friction model is then approximate: J_i, k_i 1–2 % "
                "off at 18 %): raise the current, use fewer lines, or add a slow speed offset"
            )
    report.band = search_band(g_dist, h)
    report.lines = [float(w) for w in excitation_lines(np.asarray(i_a, dtype=float), h)]
    if report.lines and max(report.lines) < 0.5 * report.band:
        report.problems.append(
            f"the excitation stops at {max(report.lines):.0f} rad/s, well under the band "
            f"({report.band:.0f} rad/s): modes above it are not excited (extend the lines)"
        )
    if report.lines and max(report.lines) > 0.3 / h:
        report.problems.append(
            f"lines above 0.3/h = {0.3 / h:.0f} rad/s: sample faster or lower the band"
        )
    if report.lines and count:
        report.line_t = line_visibility(theta, h, np.array(report.lines), count)
        blind = [w for w, t in zip(report.lines, report.line_t) if t < LINE_T]
        if blind:
            report.problems.append(
                f"the encoder barely sees {len(blind)} of the {len(report.lines)} lines "
                f"(t < {LINE_T:g}; from {min(blind):.0f} rad/s): modes there sink into the "
                "counts; more current per line (fewer lines, a higher amplitude), a finer "
                "encoder or a longer record"
            )
    try:
        i_a = np.asarray(i_a, float)
        detected = _modes(time, i_a, omega_m, theta, k_t, J_m, encoder_cpr, g_dist)
    except IdentificationError as error:
        detected = None
        report.problems.append(str(error))
    if detected is not None:
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
    report.ok = not report.problems
    return report


def _modes(time, i_a, omega_m, theta, k_t, J_m, encoder_cpr, g_dist) -> Detected:
    """The record's modes as the whole-chain fit reads them (friction not known: first
    estimated from the modes, taken out of τ̂, and the modes read again)."""
    actuator = Actuator(J_m, k_t)
    record = motor_record(time, i_a, omega_m, theta, actuator, g_dist)
    detected = detect_modes(record, MAX_AUTO_MASSES)
    if detected.n and encoder_cpr > 0:
        encoder = encoder_record(
            time, i_a, theta, actuator, encoder_cpr, friction_given=False, g_dist=g_dist
        )
        detected = friction_cleaned(record, encoder, detected.modes(), MAX_AUTO_MASSES)[3]
    return detected


def line_visibility(theta: np.ndarray, h: float, lines: np.ndarray, count: float) -> list[float]:
    """Per line (rad/s): the amplitude of the encoder angle at it (least squares on a
    sine and cosine per line, a trend removed) over its standard error with the counts'
    noise q/√12 per sample."""
    t = np.arange(len(theta)) * h
    x = theta - np.polyval(np.polyfit(t, theta, 3), t)
    phase = np.outer(t, lines)
    X = np.hstack([np.sin(phase), np.cos(phase)])
    coef = np.linalg.lstsq(X, x, rcond=None)[0]
    amplitude = np.hypot(coef[: len(lines)], coef[len(lines) :])
    error = (count / np.sqrt(12.0)) * np.sqrt(2.0 / len(theta))
    return [float(a / error) for a in amplitude]
