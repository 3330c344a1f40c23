"""Can a drive log support whole-chain identification? Checks before any fit (offline).

:func:`check_log` looks at a log (time, i_a, omega_m, theta_m) with what the user knows
(k_t, J_m, the encoder's counts, the DOB bandwidth, the friction if known) and reports
what :func:`~arcosim.identification.checks.log_decision.decide_log` decides — the one set of
decisions ``identify`` acts on too, so ``check`` is ok exactly when ``identify`` fits
and warns of nothing ``identify`` does not — with the figures behind it: the step, the
motion, the excitation (:func:`~arcosim.identification.excitation.spectrum.excitation_spectrum`:
a multi-sine's lines, a periodic reference's harmonics, or a broadband band; how well
the encoder sees each line, :func:`line_visibility`), and the modes the fit reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain.defaults import G_DIST
from arcosim.identification.checks.log_decision import WEAK_T, LogDecision, decide_log
from arcosim.identification.checks.plausibility import plausibility_warnings, resolved_lowest
from arcosim.identification.excitation.design import LINE_T
from arcosim.identification.excitation.spectrum import excitation_spectrum
from arcosim.identification.fit.encoder_fit import STUCK_VELOCITY_COUNTS
from arcosim.identification.threads import single_threaded


@dataclass
class CheckReport:
    """What :func:`check_log` found.

    Attributes
    ----------
    ok : bool
        Nothing stands in the way of a fit.
    problems : list of str
        What stands in the way, each with what to do.
    doubts : list of str
        The warnings that leave any fit of the log untrusted (the log's implausible
        units or length, an excitation above the band): ``check`` then says
        "doubtful" and exits with status 3, as ``identify`` would.
    warnings : list of str
        What may limit the fit, each one ``identify`` gives too.
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
    excitation : str
        What the current's spectrum shows, one line
        (:meth:`~arcosim.identification.excitation.spectrum.ExcitationSpectrum.text`).
    lines : list of float
        The lines played (rad/s): a multi-sine's lines or a periodic reference's
        harmonics; empty for a broadband excitation.
    unresolved_lines : list of float
        Where more lines lie than were told apart (rad/s): lines the Hann window merged
        (:attr:`~arcosim.identification.excitation.spectrum.ExcitationSpectrum.unresolved`);
        ``lines`` then holds a least count. Empty when every line was told apart.
    line_t : list of float
        Per line below the band, the encoder angle's amplitude there over its standard
        error (the counts' noise), dimensionless: how well the encoder sees the line.
    band : float
        Highest mode sought, min(3·g_dist, 0.3/h) (rad/s;
        :func:`~arcosim.identification.excitation.band.search_band`).
    modes : list of float
        The modes the record shows (rad/s).
    t_values : list of float
        Their residue t values (dimensionless).
    weak : list of tuple of float
        Stable poles seen whose residue t value is below the fit's threshold (rad/s, t
        value): too weakly excited modes (t ≥ :data:`WEAK_T`), or not modes.
    above_band : str
        When the excitation reaches above 3·g_dist and the record can tell, whether a
        mode lies there and the test's statistic
        (:func:`~arcosim.identification.checks.above_band.above_band_test`); empty
        otherwise.
    """

    ok: bool
    problems: list[str] = field(default_factory=list)
    doubts: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    step: float = 0.0
    step_spread: float = 0.0
    range_counts: float = 0.0
    stuck_fraction: float = 0.0
    excitation: str = ""
    lines: list[float] = field(default_factory=list)
    unresolved_lines: list[float] = field(default_factory=list)
    line_t: list[float] = field(default_factory=list)
    band: float = 0.0
    modes: list[float] = field(default_factory=list)
    t_values: list[float] = field(default_factory=list)
    weak: list[tuple[float, float]] = field(default_factory=list)
    above_band: str = ""

    def text(self) -> str:
        """A few lines for the user."""
        out = [
            f"step {self.step:.6g} s (spread {self.step_spread:.1e}); encoder range "
            f"{self.range_counts:.0f} counts; motor slower than {STUCK_VELOCITY_COUNTS:g} "
            f"counts/s {100 * self.stuck_fraction:.1f} % of the time",
            f"excitation: {self.excitation or 'not read'}"
            + (
                f" (the encoder sees those below the band with t = {min(self.line_t):.0f} … "
                f"{max(self.line_t):.0f}{self._blind_text()})"
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
        if self.above_band:
            out.append(f"above the band: {self.above_band}")
        out += [f"problem: {p}" for p in self.problems]
        out += [f"warning: {w}" for w in self.warnings]
        if not self.ok:
            out.append("not ok")
        elif self.doubts:
            out.append(
                "doubtful: a fit of this log would be untrusted until the warnings above "
                "are answered"
            )
        else:
            out.append("ok: the log can support identification")
        return "\n".join(out)

    def _blind_text(self) -> str:
        """How many lines the encoder barely sees (t under :data:`LINE_T`)."""
        blind = sum(t < LINE_T for t in self.line_t)
        return f"; {blind} under t = {LINE_T:g}" if blind else ""

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
    masses: int | str = "auto",
    D_m: float | None = None,
    f_c: float | None = None,
    load: str = "none",
) -> CheckReport:
    """Can a log support whole-chain identification? Checks before any fit.

    The decisions are :func:`~arcosim.identification.checks.log_decision.decide_log`'s, the
    ones :func:`~arcosim.identification.drive_identification.identify_drive` acts on: ``ok`` exactly
    when the fit goes ahead, and the warnings are among the fit's. Raises nothing for a
    poor log: every finding goes into the report, with what would fix it.

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
    masses : int or "auto"
        Number of load masses the fit will be asked for (a count), or ``"auto"``.
    D_m, f_c : float, optional
        Motor viscous (N·m·s/rad) and Coulomb (N·m) friction, when the fit is given them.
    load : {"none", "constant", "slow"}
        The load torque model the fit will use.

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
    decision = decide_log(
        time,
        i_a,
        omega_m,
        theta_m,
        k_t=k_t,
        J_m=J_m,
        encoder_cpr=encoder_cpr,
        g_dist=g_dist,
        masses=masses,
        D_m=D_m,
        f_c=f_c,
        load=load,
    )
    return report_of(decision, np.asarray(theta_m, dtype=float), encoder_cpr)


def report_of(decision: LogDecision, theta: np.ndarray, encoder_cpr: int) -> CheckReport:
    """The check's report of a decision (``theta`` the motor angle in rad, shape
    ``(N,)``, for how well the encoder sees each line; ``encoder_cpr`` a count)."""
    report = CheckReport(
        ok=decision.ok,
        problems=list(decision.problems),
        doubts=list(decision.doubts),
        warnings=list(decision.warnings),
        step=decision.step,
        step_spread=decision.step_spread,
        range_counts=decision.range_counts,
        stuck_fraction=decision.stuck_fraction,
        band=decision.band,
    )
    spectrum = decision.spectrum
    if spectrum is not None:
        report.excitation = spectrum.text()
        report.lines = [float(w) for w in spectrum.lines]
        report.unresolved_lines = [float(w) for w in spectrum.unresolved]
        shown = np.array([w for w in report.lines if w <= decision.band])
        if len(shown) and encoder_cpr > 0:
            report.line_t = line_visibility(theta, decision.step, shown, 2 * np.pi / encoder_cpr)
    test = decision.above_test
    if test is not None:
        report.above_band = f"{'a mode' if test.mode else 'no mode'} ({test.text()})"
    if decision.detected is not None:
        report.modes = [float(w) for w in decision.detected.frequency]
        report.t_values = [float(t) for t in decision.detected.t_value]
        report.weak = list(decision.detected.weak)
    return report


def log_plausibility(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    J_m: float,
    encoder_cpr: int = 0,
) -> list[str]:
    """The log's plausibility warnings
    (:func:`~arcosim.identification.checks.plausibility.plausibility_warnings`) with the lowest
    frequency the current excites that the record resolves
    (:func:`~arcosim.identification.checks.plausibility.resolved_lowest`)
    (:func:`~arcosim.identification.excitation.spectrum.excitation_spectrum`): what ``check`` and
    ``identify`` both warn of (:func:`~arcosim.identification.checks.log_decision.decide_log`
    runs the same). Arguments as :func:`check_log`'s; returns one line per finding."""
    time = np.asarray(time, dtype=float)
    i_a = np.asarray(i_a, dtype=float)
    spectrum = excitation_spectrum(i_a, float(np.mean(np.diff(time))))
    lowest = resolved_lowest(spectrum, float(time[-1] - time[0]))
    args = (np.asarray(omega_m, dtype=float), np.asarray(theta_m, dtype=float))
    return plausibility_warnings(time, i_a, *args, k_t, J_m, lowest, encoder_cpr)


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
