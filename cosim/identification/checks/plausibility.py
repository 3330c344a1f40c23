"""Is a drive log plausible at all? Checks of its units and length at the door (offline).

A log with its time in ms, its current off by 1000 or a record shorter than its slowest
line still fits, confidently and wrongly; these checks name the column and the
``--scale`` or ``--set`` to try first. Each is a pure function returning one line (the
problem and its fix) or ``None``; :func:`plausibility_warnings` runs them all, and both
:func:`~arcosim.identification.checks.log_check.check_log` and
:func:`~arcosim.identification.drive_identification.identify_drive` call it, so ``check`` and
``identify`` warn alike.

- :func:`angle_wraps`: steps where the angle jumps by half a turn more than the steps
  beside it, which no drive does between two samples: a single-turn angle wrapping at
  2π, or a counter overflowing.
- :func:`columns_swapped`: the speed column's differences give the angle column (and
  not the other way round): ``omega_m`` and ``theta_m`` named the wrong way.
- :func:`step_against_motion`: the speed the angle's differences give over the step
  (its jumps left out) against the logged ω_m; off by more than
  :data:`SPEED_RATIO_LIMIT` (a time in ms gives 1000).
- :func:`torque_balance`: the low-frequency balance k_t·i = J·α + D·ω at the lowest
  excitation line (least squares of the current and angle there); J outside
  [:data:`INERTIA_LOW`, :data:`INERTIA_HIGH`]·J_m by more than :data:`BALANCE_SIGMAS`
  of its standard errors names the current scale, k_t and the time column. The line is
  fitted under a Hann window (a slow load's motion leaks into it as 1/k³ of the bins
  between them, not 1/k); its standard error is the noise near the line (the local
  level of the periodogram of what the fit leaves, between the lines), and the lines
  the window merges with it bound its error by a factor (:func:`merged_line_factor`).
- :func:`record_length`: fewer than :data:`LEAST_PERIODS` periods of the lowest line the
  current shows.
- :func:`angle_steps`: an encoder's angle moves by whole counts; when the logged angle
  moves by whole multiples of a step other than the count 2π/``encoder_cpr`` given
  (or assumed), the angle's unit (degrees, counts) or the encoder's count is wrong, and
  with it the noise floor the verdict judges the fit against.

Both read the lowest line the record resolves (:func:`resolved_lowest`): one holding at
least :data:`RESOLVED_PERIODS` periods, so that it is told from the record's mean and
trend.
- :func:`mode_record_length`: fewer than :data:`LEAST_MODE_PERIODS` periods of the
  lowest mode the record shows (judged once the modes are read,
  :func:`~arcosim.identification.checks.log_decision.decide_log`; it does not rest on finding
  the lines, which a short record of many close lines blurs).
"""

from __future__ import annotations

import numpy as np

from arcosim.identification.excitation.periodic import noise_level
from arcosim.identification.excitation.spectrum import ExcitationSpectrum

#: Largest factor (dimensionless) between the RMS speed the angle's differences give
#: over the logged step and the RMS logged ω_m. Both measure the same motion; the
#: encoder's quantization and a backward difference change the RMS by a few % only,
#: while a wrong time or speed unit gives 1000 (ms), 9.55 (rpm) or 2π (rev/s).
SPEED_RATIO_LIMIT = 1.5
#: Lower bound of the plausible total inertia, in units of J_m (dimensionless). The
#: load can only add to the motor's inertia; a fit above the modes sees J_m alone, and
#: noise scatters it, so half of J_m is the margin before a scale error is named.
INERTIA_LOW = 0.5
#: Upper bound of the plausible total inertia, in units of J_m (dimensionless): a load
#: 1000 times the motor's inertia is outside any servo's inertia-ratio range (10–30
#: usual, a few hundred at most).
INERTIA_HIGH = 1e3
#: The logged angle counts as an encoder's whole counts when this share of its nonzero
#: steps lie within :data:`WHOLE_COUNT` of a whole multiple of the smallest
#: (dimensionless): an encoder's angle does on every step, a continuous angle on about
#: 2·WHOLE_COUNT of them, a decimal print of varying magnitude seldom.
QUANTIZED_SHARE = 0.99
#: How far from a whole multiple of the step a quantized angle's step may lie, in steps
#: (dimensionless): a CSV's rounding of the angle is far below it.
WHOLE_COUNT = 0.05
#: The angle's step and the count given are the same when they agree to this ratio
#: (dimensionless): a count is exact, so only the log's rounding separates them; a
#: quadrature factor is 4, degrees 57.3.
COUNT_AGREEMENT = 1.01
#: The least correlation (dimensionless) of the speed an angle's differences give with a
#: logged speed for the two to be one motion: the encoder's counts and a backward
#: difference leave the RMS within a few % (:data:`SPEED_RATIO_LIMIT`), and an
#: acceleration against its speed (the columns the right way round) correlates
#: negatively or about 0 over any oscillating motion. Measured without it (the RMS
#: alone): the README's sample log with its time in ms, and a 30 rad/s sine with its
#: time in ms, read as swapped.
SWAP_CORRELATION = 0.9
#: The angle's jumps are one wrap's when their sizes, less the motion beside them, agree
#: to this share (dimensionless): a wrap's period is exact, and the motion's change over
#: a step is far below a turn; jumps of many sizes have no period. Measured without
#: the agreement: the swapped columns' "angle" (a speed in steps of count/h) read as a
#: wrap.
WRAP_AGREEMENT = 0.01
#: Least number of periods (a count) of the lowest excitation line a record should
#: hold: the line's frequency is then resolved to a third of itself, and the fits' start
#: transients (a few periods of the slowest motion) leave part of the record.
LEAST_PERIODS = 3.0
#: The torque balance's inertia counts as implausible only when it lies this many of its
#: standard errors outside the plausible range (the three-sigma rule: under Gaussian
#: errors a plausible log crosses one bound by chance 0.13 % of the time). The rate holds
#: only with a σ that holds: the noise's near the line, the lines beside it apart.
BALANCE_SIGMAS = 3.0
#: Half the Hann window's main lobe (bins of 2π/T): lines closer than this to the
#: balance's line leak into its estimate (:func:`merged_line_factor`); beyond it the
#: window's sidelobes, falling as 1/k³, keep them out.
MAIN_LOBE = 2.0
#: Least periods (a count) of a line the record must hold for the line to count as
#: resolved: the record's frequency grid is 2π/T, and the Hann window's main lobe spans
#: :data:`MAIN_LOBE` bins either side of a line, so a line under two bins (two periods)
#: from 0 shares its lobe with bin 0, the record's mean and the trend the detrend
#: removed: the record cannot tell it from them (the remnant of 40 lines' partial periods
#: reads as a "line" of 1.1 periods, 13 % of the lines' amplitude, on one seed in five).
RESOLVED_PERIODS = MAIN_LOBE
#: Least number of periods (a count) of the lowest mode a record should hold: its
#: spectrum's resolution 2π/T is then at most a tenth of the mode, and the fit's start
#: transients (a few periods of the slowest motion) leave most of the record. The 20 s
#: logs of the benchmarks hold 36–45 periods of their lowest mode; 3 s of the README's
#: excitation holds 5.3 of the three-mass chain's 11.2 rad/s.
LEAST_MODE_PERIODS = 10.0


def angle_jumps(theta_m: np.ndarray) -> np.ndarray:
    """Which of the angle's steps jump: each step exceeding the mean of its two
    neighbours' by more than half a turn (π rad).

    A drive's step changes between samples by its acceleration times h², and half a turn
    in one sample (π/h² rad/s², 3·10⁶ at 1 kHz) lies beyond any motor; a wrapped angle
    changes it by a whole turn, a counter's overflow by its range.

    Parameters
    ----------
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.

    Returns
    -------
    ndarray
        Boolean, shape ``(N − 1,)``: the steps that jump.

    Examples
    --------
    >>> theta = np.mod(np.arange(1000) * 0.01, 2 * np.pi)   # wraps at one turn
    >>> np.flatnonzero(angle_jumps(theta)).tolist()
    [628]
    >>> bool(np.any(angle_jumps(np.arange(1000) * 6.28)))   # fast, steady: no jump
    False
    """
    steps = np.abs(np.diff(np.asarray(theta_m, dtype=float)))
    if len(steps) < 3:
        return np.zeros(len(steps), dtype=bool)
    before, after = _neighbours(steps)
    jumps = steps - 0.5 * (before + after) > np.pi
    # a jump's neighbours hold it in their own "beside": only the step itself exceeds them
    return jumps & (steps >= before) & (steps >= after)


def _neighbours(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each element's neighbour before and after (the ends repeat themselves)."""
    padded = np.concatenate([[x[0]], x, [x[-1]]])
    return padded[:-2], padded[2:]


def angle_wraps(theta_m: np.ndarray) -> str | None:
    """A wrapped angle: steps that jump by a turn (or a counter's range) between samples
    (:func:`angle_jumps`).

    Parameters
    ----------
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.

    Returns
    -------
    str or None
        How often and by how much it jumps, and how to unwrap it; None without jumps.

    Examples
    --------
    >>> angle_wraps(np.mod(np.arange(3000) * 0.01, 2 * np.pi))[:40]
    'the angle jumps by 6.28 rad 4 times betw'
    >>> angle_wraps(np.arange(3000) * 0.01) is None
    True
    """
    theta = np.asarray(theta_m, dtype=float)
    jumps = angle_jumps(theta)
    if not np.any(jumps):
        return None
    steps = np.diff(theta)
    before, after = _neighbours(steps)
    beyond = steps - 0.5 * (before + after)  # the jump less the motion beside it
    sizes = np.abs(beyond[jumps])
    size = float(np.median(sizes))
    if np.any(np.abs(sizes / size - 1.0) > WRAP_AGREEMENT):
        return None  # jumps of many sizes: no period, not a wrap (the other checks speak)
    if abs(size / (2.0 * np.pi) - 1.0) <= WRAP_AGREEMENT:
        what, unwrap = "a single-turn angle wrapping at 2π", "numpy.unwrap(theta_m)"
    else:
        what = "an angle wrapping at a counter's range"
        unwrap = f"numpy.unwrap(theta_m, period={size:.6g})"
    return (
        f"the angle jumps by {size:.3g} rad {int(jumps.sum())} times between samples, "
        f"beyond any drive's motion in one step: {what}; unwrap it first ({unwrap}), "
        "and take omega_m from the unwrapped angle if it came from the wrapped one"
    )


def columns_swapped(time: np.ndarray, omega_m: np.ndarray, theta_m: np.ndarray) -> str | None:
    """``omega_m`` and ``theta_m`` named the wrong way round: the logged speed's
    differences over the step give the logged angle (the same motion within
    :data:`SPEED_RATIO_LIMIT` in RMS, correlated by at least :data:`SWAP_CORRELATION`),
    while the angle's differences do not give the speed.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    omega_m, theta_m : ndarray
        The logged speed and angle columns, shape ``(N,)``.

    Returns
    -------
    str or None
        The finding and the fix; None when the columns are the right way round or
        neither way fits.

    Examples
    --------
    >>> t = np.arange(4000) * 1e-3
    >>> theta, omega = np.sin(3 * t), 3 * np.cos(3 * t)
    >>> columns_swapped(t, omega, theta) is None
    True
    >>> columns_swapped(t, theta, omega)[:40]
    'the speed column omega_m changes as the '
    """
    if _motion_agrees(time, omega_m, theta_m) or not _motion_agrees(time, theta_m, omega_m):
        return None
    return (
        "the speed column omega_m changes as the angle column theta_m should, and the "
        "angle's changes do not give the speed: omega_m and theta_m are swapped; name "
        "the columns the other way round"
    )


def _motion_agrees(time: np.ndarray, speed: np.ndarray, angle: np.ndarray) -> bool:
    """Whether ``angle``'s differences over the step give ``speed`` (RMS within
    :data:`SPEED_RATIO_LIMIT`, correlation at least :data:`SWAP_CORRELATION`)."""
    from_angle, keep = _angle_speed(time, angle)
    logged = np.asarray(speed, dtype=float)[1:][keep]
    a, b = float(np.sqrt(np.mean(from_angle**2))), float(np.sqrt(np.mean(logged**2)))
    if not (a > 0 and b > 0 and 1 / SPEED_RATIO_LIMIT <= a / b <= SPEED_RATIO_LIMIT):
        return False
    return float(np.corrcoef(from_angle, logged)[0, 1]) >= SWAP_CORRELATION


def _angle_speed(time: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The speed (rad/s) ``angle``'s differences give over the mean step, its jumps
    (:func:`angle_jumps`: a wrap is no motion) left out, and which steps were kept
    (boolean, shape ``(N − 1,)``)."""
    h = float(np.mean(np.diff(time)))
    keep = ~angle_jumps(angle)
    return np.diff(np.asarray(angle, dtype=float))[keep] / h, keep


def step_against_motion(time: np.ndarray, omega_m: np.ndarray, theta_m: np.ndarray) -> str | None:
    """The sample step against the motion: does the angle's difference over one step
    give the logged speed?

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    omega_m : ndarray
        Motor velocity (rad/s), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.

    Returns
    -------
    str or None
        The problem and its fix, when the RMS speeds differ by more than
        :data:`SPEED_RATIO_LIMIT`; None otherwise.

    Examples
    --------
    >>> t = np.arange(2000) * 1e-3
    >>> step_against_motion(t, np.cos(t), np.sin(t)) is None
    True
    >>> step_against_motion(t * 1e3, np.cos(t), np.sin(t))[:23]
    'the sample step is 1 s:'
    """
    h = float(np.mean(np.diff(time)))
    speed = _angle_speed(time, theta_m)[0]  # a wrap is no motion (angle_wraps names it)
    from_angle = float(np.sqrt(np.mean(speed**2))) if len(speed) else 0.0
    logged = float(np.sqrt(np.mean(np.asarray(omega_m, float)[1:] ** 2)))
    if not (from_angle > 0 and logged > 0):
        return None
    ratio = from_angle / logged
    if 1 / SPEED_RATIO_LIMIT <= ratio <= SPEED_RATIO_LIMIT:
        return None
    hint = _unit_hint(ratio)
    return (
        f"the sample step is {h:.4g} s: the angle's differences over it give speeds "
        f"{ratio:.3g} × the logged omega_m{hint}"
    )


def _unit_hint(ratio: float) -> str:
    """The likely unit error for a ratio (angle-difference speed / logged speed)."""
    if 3e-4 < ratio < 3e-3:
        return ": is `time` in ms? use --scale time=0.001"
    if 300 < ratio < 3000:
        return ": is `time` in ks? use --scale time=1000"
    return (
        f": check the units of `time`, `omega_m` and `theta_m` (--scale omega_m={ratio:.4g} "
        "if the angle and time are right)"
    )


def torque_balance(
    time: np.ndarray,
    i_a: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    J_m: float,
    lowest: float | None,
) -> str | None:
    """The low-frequency torque balance: the total inertia k_t·i asks for.

    At the lowest excitation line ω, under the chain's first mode, the chain moves as
    one body: k_t·I = (−ω²·J + jω·D)·Θ for the line's complex amplitudes I of the
    current and Θ of the angle, so J = −Re(k_t·I/Θ)/ω² (the viscous and Coulomb
    friction sit in the imaginary part).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    i_a : ndarray
        Motor current (A), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    J_m : float
        Motor inertia (kg·m²).
    lowest : float or None
        The lowest excitation line (rad/s); None: not checked.

    Returns
    -------
    str or None
        The problem and the columns or values to check, when J lies outside
        [:data:`INERTIA_LOW`, :data:`INERTIA_HIGH`]·J_m; None otherwise.

    Examples
    --------
    >>> t = np.arange(4000) * 1e-3
    >>> theta = 0.1 * np.sin(2 * t)
    >>> current = -1e-3 * 0.4 * np.sin(2 * t) / 0.04   # J = 1e-3, k_t = 0.04
    >>> torque_balance(t, current, theta, 0.04, 1e-4, 2.0) is None
    True
    >>> torque_balance(t, current * 1e-3, theta, 0.04, 1e-4, 2.0)[:28]
    'the torque balance k_t·i = J'
    >>> torque_balance(t, -current, theta, 0.04, 1e-4, 2.0).split("): ")[1][:43]
    'the current and the encoder count opposite '
    """
    found = balance_inertia(time, i_a, theta_m, k_t, lowest, with_error=True)
    if found is None:
        return None
    J, sigma = found
    # implausible only beyond the balance's own uncertainty: the noise near the line
    # (BALANCE_SIGMAS standard errors), and the lines a window merges with it
    merged = merged_line_factor(float(time[-1] - time[0]), lowest)

    def plausible(inertia: float) -> bool:
        return (
            INERTIA_LOW * J_m / merged - BALANCE_SIGMAS * sigma
            <= inertia
            <= INERTIA_HIGH * J_m * merged + BALANCE_SIGMAS * sigma
        )

    if plausible(J):
        return None
    asks = (
        f"the torque balance k_t·i = J·α at {lowest:.3g} rad/s asks for a total inertia "
        f"J = {J:.3g} kg·m² = {J / J_m:.3g} × J_m (plausible: {INERTIA_LOW:g} … "
        f"{INERTIA_HIGH:g} × J_m)"
    )
    if plausible(-J):  # a plausible inertia, turned: the current pushes against the count
        return (
            f"{asks}: the current and the encoder count opposite ways; turn the current "
            "(--scale i_a=-1) or the angle (--scale theta_m=-1 --scale omega_m=-1)"
        )
    return (
        f"{asks}: check the current's scale (--scale i_a=…; A or mA?), "
        "k_t (--set k_to=…) and the time column's unit (--scale time=…)"
    )


def merged_line_factor(duration: float, lowest: float) -> float:
    """The factor (dimensionless, ≥ 1) the torque balance's inertia at the line
    ``lowest`` (rad/s) may err by, either way, from the excitation's lines the Hann
    window merges with it in a record of ``duration`` s.

    Lines within :data:`MAIN_LOBE` bins (2π/T each) of the balance's line share its
    window's main lobe, and its estimate takes part of each (half of one a bin away):
    a multi-sine's low end has its lines 1–2 bins apart. Below the chain's first mode
    they move the current and the angle alike, the angle weighted by 1/ω², so the
    inertia read lies between (ω/ω_n)² and (ω_n/ω)² times the chain's, ω_n the farthest
    such line: a bound, not a noise (the standard error does not cover it).

    Examples
    --------
    >>> round(merged_line_factor(20.0, 3.0), 2)   # lines up to 0.63 rad/s away
    1.46
    """
    reach = MAIN_LOBE * 2.0 * np.pi / max(duration, 1e-300)
    return float((1.0 + reach / lowest) ** 2)


def balance_inertia(
    time: np.ndarray,
    i_a: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    lowest: float | None,
    with_error: bool = False,
):
    """Total inertia (kg·m²) of the torque balance at the line ``lowest`` (see
    :func:`torque_balance`; arguments alike), or None when there is no line or motion;
    with ``with_error``, ``(J, σ_J)``: σ_J (kg·m²) from the two line fits' standard
    errors (:func:`_line_amplitude`'s, the noise's near the line), propagated to first order."""
    theta = np.asarray(theta_m, float)
    if not lowest or lowest <= 0 or len(theta) < 16:
        return None
    t = np.asarray(time, float) - time[0]
    torque, sigma_torque = _line_amplitude(t, k_t * np.asarray(i_a, float), lowest)
    angle, sigma_angle = _line_amplitude(t, theta, lowest)
    if not abs(angle) > 0:
        return None
    J = float(-(torque / angle).real / lowest**2)
    if not with_error:
        return J
    relative = np.hypot(sigma_torque / max(abs(torque), 1e-300), sigma_angle / abs(angle))
    return J, float(abs(torque / angle) / lowest**2 * relative)


def _line_amplitude(t: np.ndarray, x: np.ndarray, w: float) -> tuple[complex, float]:
    """Complex amplitude of ``x`` (shape ``(N,)``) at ``w`` (rad/s) over times ``t`` (s):
    least squares on a sine and cosine, a cubic trend removed, each sample weighted by a
    Hann window; with its standard error (the magnitude's, ``x``'s unit).

    The window: a slow load's motion (one period of 0.3 rad/s in a 20 s record, tens of
    rad) is more than a cubic trend can follow, and under uniform weights its remnant
    leaks into the line as 1/k of the bins k between them (the balance of a slow-load
    log read −33 × J_m where the chain has 58); the Hann window's sidelobes fall as
    1/k³. The error: the noise near ``w``, the local noise level of the Hann periodogram
    of what the fit leaves, read between the lines (its lower quartile,
    :func:`~arcosim.identification.excitation.periodic.noise_level`, the level every
    line of the excitation is detected against): a weighted line estimate
    2·Σ wₜxₜe^(−jωt)/Σ wₜ errs by √(2·level)/Σ wₜ in each of its cosine and sine. What
    the fit leaves also holds the excitation's other lines, the ones beside ``w`` a
    window merges with it included; they are not noise, and a long-run variance of
    the whole residual (Newey–West's) counted them: it erred large by five times or
    more on 40 lines 3–150 rad/s, and missed a time column in ms on half the seeds."""
    span = t[-1] if t[-1] > 0 else 1.0
    s = t / span
    X = np.column_stack([np.cos(w * t), np.sin(w * t), np.ones_like(s), s, s**2, s**3])
    window = np.hanning(len(t))
    root = np.sqrt(window)[:, None]  # weighted least squares on root-scaled rows
    c, *_ = np.linalg.lstsq(X * root, x * root[:, 0], rcond=None)
    power = np.abs(np.fft.rfft((x - X @ c) * window)) ** 2
    at = int(np.clip(np.rint(w * len(t) * (t[1] - t[0]) / (2.0 * np.pi)), 1, len(power) - 1))
    level = float(noise_level(power[1:])[at - 1])
    return complex(c[0], -c[1]), float(np.sqrt(2.0 * level) / window.sum())


def resolved_lowest(spectrum: ExcitationSpectrum | None, duration: float) -> float | None:
    """The lowest frequency (rad/s) the excitation carries that a record of ``duration``
    s resolves: of the lines played, the lowest holding at least
    :data:`RESOLVED_PERIODS` periods (a line closer to 0 is not told from the record's
    mean and trend); a broadband excitation's lowest frequency as it is. None without
    excitation or without a resolved line.

    Examples
    --------
    >>> lines = np.array([0.34, 3.2, 4.9])
    >>> resolved_lowest(ExcitationSpectrum("lines", lines, np.ones(3), (0.34, 4.9)), 20.0)
    3.2
    >>> resolved_lowest(ExcitationSpectrum("broadband", band=(3.0, 90.0)), 20.0)
    3.0
    """
    if spectrum is None or spectrum.lowest is None:
        return None
    if spectrum.kind == "broadband":
        return spectrum.lowest
    lines = np.sort(np.asarray(spectrum.lines, dtype=float))
    resolved = lines[lines * duration >= RESOLVED_PERIODS * 2.0 * np.pi]
    return float(resolved[0]) if len(resolved) else None


def record_length(time: np.ndarray, lowest: float | None) -> str | None:
    """The record's length against its lowest line.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    lowest : float or None
        The lowest excitation line the record shows (rad/s); None: none.

    Returns
    -------
    str or None
        The problem and its fix, when the record holds fewer than
        :data:`LEAST_PERIODS` periods of ``lowest``; None otherwise.

    Examples
    --------
    >>> record_length(np.arange(3001) * 1e-3, 3.0)[:32]
    'the record lasts 3 s, 1.4 period'
    """
    short = _periods_short(time, lowest, LEAST_PERIODS)
    if short is None:
        return None
    duration, periods = short
    return (
        f"the record lasts {duration:.3g} s, {periods:.2g} periods of its lowest excitation "
        f"line ({lowest:.3g} rad/s; fewer than {LEAST_PERIODS:g}): modes that low are "
        f"poorly resolved; record at least {LEAST_PERIODS * 2 * np.pi / lowest:.3g} s"
    )


def _periods_short(
    time: np.ndarray, omega: float | None, least: float
) -> tuple[float, float] | None:
    """(record length in s, periods of ``omega`` rad/s in it) when fewer than ``least``
    periods; None when ``omega`` is absent or the record is long enough."""
    if not omega or omega <= 0:
        return None
    duration = float(time[-1] - time[0])
    periods = duration * omega / (2 * np.pi)
    return None if periods >= least else (duration, periods)


def mode_record_length(time: np.ndarray, lowest_mode: float | None) -> str | None:
    """The record's length against its lowest mode.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    lowest_mode : float or None
        The lowest mode the record shows (rad/s); None: none.

    Returns
    -------
    str or None
        The problem and its fix, when the record holds fewer than
        :data:`LEAST_MODE_PERIODS` periods of ``lowest_mode``; None otherwise.

    Examples
    --------
    >>> mode_record_length(np.arange(3001) * 1e-3, 11.2)[:48]
    'the record lasts 3 s, 5.3 periods of its lowest '
    >>> mode_record_length(np.arange(20001) * 1e-3, 11.2) is None
    True
    """
    short = _periods_short(time, lowest_mode, LEAST_MODE_PERIODS)
    if short is None:
        return None
    duration, periods = short
    return (
        f"the record lasts {duration:.3g} s, {periods:.2g} periods of its lowest mode "
        f"({lowest_mode:.3g} rad/s; fewer than {LEAST_MODE_PERIODS:g}): that mode and its "
        "damping rest on few periods, their σ may not cover the error; record at least "
        f"{LEAST_MODE_PERIODS * 2 * np.pi / lowest_mode:.3g} s"
    )


def angle_step(theta_m: np.ndarray) -> float | None:
    """The step an encoder's angle moves by (the angle's unit), or None when the angle
    does not move by whole multiples of one step (:data:`QUANTIZED_SHARE` of its
    nonzero steps within :data:`WHOLE_COUNT` of one).

    Examples
    --------
    >>> count = 2 * np.pi / 2000
    >>> theta = np.floor(np.sin(np.arange(5000) * 1e-3) / count) * count
    >>> round(2 * np.pi / angle_step(theta), 6)
    2000.0
    >>> angle_step(np.sin(np.arange(5000) * 1e-3)) is None
    True
    """
    theta = np.asarray(theta_m, dtype=float)
    steps = np.abs(np.diff(theta))
    steps = steps[steps > 1e-9 * max(float(np.max(np.abs(theta), initial=0.0)), 1e-300)]
    if len(steps) < 16:
        return None
    multiples = steps / steps.min()
    whole = np.abs(multiples - np.rint(multiples)) <= WHOLE_COUNT
    if whole.mean() < QUANTIZED_SHARE:
        return None
    return float(steps[whole].sum() / np.rint(multiples[whole]).sum())


def angle_steps(theta_m: np.ndarray, encoder_cpr: int) -> str | None:
    """The logged angle's step against the encoder's count 2π/``encoder_cpr``.

    An incremental encoder's angle moves by whole counts. When the logged angle moves by
    whole multiples of one step (:func:`angle_step`) that is not the count given, the
    angle is in another unit (degrees, counts) or the encoder has another count (a
    quadrature factor of 4, a default taken for the drive's); the fits' noise floor, the
    count's Δ²/12, is then wrong too.

    Parameters
    ----------
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    encoder_cpr : int
        Encoder counts per revolution given or assumed (a count); 0: not checked.

    Returns
    -------
    str or None
        The step found, the count given and what to set; None when they agree, when the
        angle is not quantized, or without a count.

    Examples
    --------
    >>> count = 2 * np.pi / 2000
    >>> theta = np.floor(np.sin(np.arange(5000) * 1e-3) / count) * count
    >>> angle_steps(theta, 2000) is None
    True
    >>> angle_steps(np.degrees(theta), 2000)[-64:]
    'is `theta_m` in degrees? --scale theta_m=0.0174533 (and omega_m)'
    >>> angle_steps(theta, 500)[-36:]
    'the encoder has 2000 counts per turn'
    """
    if encoder_cpr <= 0:
        return None
    step = angle_step(theta_m)
    count = 2.0 * np.pi / encoder_cpr
    if step is None or 1.0 / COUNT_AGREEMENT <= step / count <= COUNT_AGREEMENT:
        return None
    said = (
        f"the angle moves by whole steps of {step:.4g}, not of the count 2π/{encoder_cpr} = "
        f"{count:.4g} rad given for the encoder"
    )
    if 1.0 / COUNT_AGREEMENT <= step <= COUNT_AGREEMENT:
        return f"{said}: is `theta_m` in counts? --scale theta_m={count:.6g} (and omega_m)"
    degree = np.pi / 180.0
    if 1.0 / COUNT_AGREEMENT <= step * degree / count <= COUNT_AGREEMENT:
        return f"{said}: is `theta_m` in degrees? --scale theta_m={degree:.6g} (and omega_m)"
    turns = 2.0 * np.pi / step
    return (
        f"{said}: --set encoder_cpr={turns:.0f} if `theta_m` is in rad and "
        f"the encoder has {turns:.0f} counts per turn"
    )


def plausibility_warnings(
    time: np.ndarray,
    i_a: np.ndarray,
    omega_m: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    J_m: float,
    lowest: float | None,
    encoder_cpr: int = 0,
) -> list[str]:
    """Every plausibility check's finding, in order: the angle's wraps, the speed and
    angle columns swapped, the step against the motion, the angle's steps against the
    encoder's count, the torque balance, the record's length. A wrapped angle's jumps
    are no motion, and swapped columns give none of it, so with either found only the
    record's length is judged besides.

    Parameters
    ----------
    time, i_a, omega_m, theta_m : ndarray
        The log: times (s), current (A), motor velocity (rad/s) and angle (rad), each of
        shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    J_m : float
        Motor inertia (kg·m²).
    lowest : float or None
        The lowest excitation line the current shows that the record resolves (rad/s,
        :func:`resolved_lowest`); None: none found.
    encoder_cpr : int
        Encoder counts per revolution (a count); 0: the angle's steps are not checked.

    Returns
    -------
    list of str
        One line per finding, each naming the column and the ``--scale`` or ``--set``
        to try; empty for a plausible log.

    Examples
    --------
    >>> t = np.arange(20000) * 1e-3
    >>> theta = 0.1 * np.sin(3 * t)
    >>> current = -1e-3 * 0.9 * np.sin(3 * t) / 0.04   # J = 1e-3, k_t = 0.04
    >>> plausibility_warnings(t, current, np.gradient(theta, t), theta, 0.04, 1e-4, 3.0)
    []
    """
    wraps = angle_wraps(theta_m)
    swapped = None if wraps else columns_swapped(time, omega_m, theta_m)
    if wraps or swapped:  # the checks that read the motion wait for the angle to be right
        found = [wraps or swapped, record_length(time, lowest)]
    else:
        found = [
            step_against_motion(time, omega_m, theta_m),
            angle_steps(theta_m, encoder_cpr),
            torque_balance(time, i_a, theta_m, k_t, J_m, lowest),
            record_length(time, lowest),
        ]
    return [text for text in found if text]
