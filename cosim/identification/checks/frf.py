"""The measured frequency response of a drive, and the identified model's over it (offline).

What a commissioning engineer reads to trust a model: the response from the drive
torque k_t·i_a to the motor speed, measured from the log, with its coherence, beside
the identified chain's (:func:`model_response`), and the fit's residual against the
floor the encoder and the current noise explain (:func:`residual_spectrum`).
:func:`measured_response` picks its estimator from the excitation
(:func:`~arcosim.identification.excitation.spectrum.excitation_spectrum`) and says which:

- lines (a multi-sine, a periodic reference's harmonics), open loop: **H1 at the
  lines**, the ratio of the angle's and the torque's Hann-windowed Fourier sums at each
  line (off the grid), the speed's as jω times the angle's (no backward difference's
  half-step lag), the current's half step (it acted over the step ending at its row)
  taken out;
- broadband, open loop: **Welch H1**, S_τθ/S_ττ · jω (a closed loop is not told
  apart here: give its reference);
- a logged reference or added excitation r (closed loop): the **indirect estimate
  through r**, S_rθ/S_rτ · jω (at r's lines, or by Welch), which the loop does not
  bias: the noise the loop feeds back is uncorrelated with r;
- only the current and the speed logged while their noise is correlated between the
  excitation's lines (a closed loop: the speed's noise comes back through the
  controller as current): a warning that the loop biases the measured response, and
  how to remove the bias.

The coherence (of τ or r with θ) is read over four segments of the record at the lines,
by Welch for a broadband excitation.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from arcosim.identification.excitation.band import sample_band
from arcosim.identification.excitation.spectrum import excitation_spectrum

#: Welch segments per record (a count) for the coherence and the broadband estimates.
SEGMENTS = 8
#: Segments (a count) the coherence at the lines is read over.
LINE_SEGMENTS = 4
#: Log-spaced bands (a count) the residual's spectrum is averaged over.
BANDS = 300
#: Segments (a count) of the coherence between the lines: long ones, to leave bins
#: between lines 10 % apart.
LOOP_SEGMENTS = 4
#: Between the lines, a median coherence of the current with the angle above this
#: (dimensionless) reads as a closed loop: measured 0.48 in a PI speed loop on 2000 counts,
#: 0.19 and 0.24 open loop on 2000 and 65536 counts (one-mass chain, 10 s).
LOOP_COHERENCE = 0.35


@dataclass(frozen=True)
class MeasuredResponse:
    """A measured frequency response, drive torque → motor speed.

    Attributes
    ----------
    omega : ndarray
        Frequencies (rad/s), ascending, shape ``(F,)``.
    response : ndarray
        The response (rad/s per N·m, complex), shape ``(F,)``.
    coherence : ndarray
        Coherence at each frequency (dimensionless, 0 … 1), shape ``(F,)``.
    estimator : str
        Which estimate, one line (for the figure's title).
    warnings : list of str
        What biases it, one sentence each.

    Examples
    --------
    >>> frf = MeasuredResponse(np.array([10.0]), np.array([-0.1j]), np.array([1.0]), "H1")
    >>> float(abs(frf.response[0]) * frf.omega[0])  # 1/J of a rigid body (1/(kg·m²))
    1.0
    """

    omega: np.ndarray
    response: np.ndarray
    coherence: np.ndarray
    estimator: str
    warnings: list[str] = field(default_factory=list)


def measured_response(
    time: np.ndarray,
    i_a: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    reference: np.ndarray | None = None,
    top: float | None = None,
) -> MeasuredResponse:
    """The drive's measured response from torque to motor speed, estimator chosen from
    the excitation (the module doc lists them).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, a constant step.
    i_a : ndarray
        Motor current (A), shape ``(N,)``.
    theta_m : ndarray
        Motor angle (rad), shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    reference : ndarray, optional
        A logged reference or added excitation (any unit), shape ``(N,)``: the
        indirect estimate through it.
    top : float, optional
        Highest frequency shown (rad/s); default 0.3/h.

    Returns
    -------
    MeasuredResponse
        Frequencies (rad/s), the response (rad/s per N·m), the coherence, the
        estimator's name and the warnings.

    Examples
    --------
    A rigid body of 1e-3 kg·m² (response 1/(jωJ)) under two lines, with sensor noise:

    >>> t = np.arange(20001) * 1e-3
    >>> noise = np.random.default_rng(1).normal(0.0, 1e-3, (2, len(t)))
    >>> torque = np.sin(5.0 * t) + np.sin(20.0 * t) + noise[0]
    >>> theta = -(np.sin(5.0 * t) / 25 + np.sin(20.0 * t) / 400) / 1e-3 + noise[1]
    >>> frf = measured_response(t, torque, theta, 1.0)
    >>> frf.estimator, np.round(np.abs(frf.response) * frf.omega * 1e-3, 3)
    ('H1 at the lines (windowed Fourier sums, open loop)', array([1., 1.]))
    """
    time, i_a, theta = (np.asarray(x, dtype=float) for x in (time, i_a, theta_m))
    h = float(np.mean(np.diff(time)))
    top = sample_band(h) if top is None else top
    torque = k_t * i_a
    source = torque if reference is None else np.asarray(reference, dtype=float)
    spectrum = excitation_spectrum(source, h)
    warnings = []
    if spectrum.kind in ("lines", "periodic"):
        omega = spectrum.lines[(spectrum.lines <= top) & (spectrum.lines > 0)]
        torque_c, angle_c = _line_amplitudes(time - time[0], [torque, theta], omega)
        response = 1j * omega * angle_c / torque_c
        coherence = _line_coherence(time - time[0], source, theta, omega)
        name = "H1 at the lines (windowed Fourier sums, open loop)"
        if reference is not None:
            name = "indirect through the reference, at its lines (closed loop)"
        else:
            loop = _loop_coherence(torque, theta, h, spectrum.lines, top)
            if loop > LOOP_COHERENCE:
                warnings.append(_loop_warning(loop))
                name = "H1 at the lines (windowed Fourier sums; a closed loop seen, biased)"
    else:
        omega, response = _welch_response(source, torque, theta, h, spectrum.band[0], top)
        name = (
            "Welch H1 (open loop assumed)"
            if reference is None
            else "indirect through the reference, Welch"
        )
        coherence = _coherence(source, theta, h)(omega)
    # the timing contract: a row's current acted over the step ending at its time, so
    # it stands for the torque half a step earlier than the angle beside it
    response = response * np.exp(-0.5j * omega * h)
    return MeasuredResponse(omega, response, coherence, name, warnings)


def _line_amplitudes(
    t: np.ndarray, signals: Sequence[np.ndarray], omega: np.ndarray
) -> list[np.ndarray]:
    """Complex amplitudes (up to a common factor) of each signal at ``omega`` (rad/s):
    Hann-windowed Fourier sums at the lines themselves, off the grid, a cubic trend
    removed first; ``t`` (s) and each signal of shape ``(N,)``. The window keeps a line
    the spectrum did not resolve (two closer than two bins count as one) from leaking
    into the others' estimates, as a joint fit at the lines found would let it."""
    window = np.hanning(len(t))
    kernel = np.exp(-1j * np.outer(t - t[0], omega)) * window[:, None]
    out = []
    for x in signals:
        x = np.asarray(x, dtype=float)
        out.append((x - np.polyval(np.polyfit(t, x, 3), t)) @ kernel)
    return out


def _line_coherence(
    t: np.ndarray, source: np.ndarray, theta: np.ndarray, omega: np.ndarray
) -> np.ndarray:
    """Coherence of ``source`` with the angle at the lines ``omega`` (rad/s) over
    :data:`LINE_SEGMENTS` segments of the record, each by windowed Fourier sums at the
    lines: 1 when every segment shows the same ratio (dimensionless, shape ``(L,)``)."""
    size = len(t) // LINE_SEGMENTS
    pairs = []
    for j in range(LINE_SEGMENTS):
        part = slice(j * size, (j + 1) * size)
        pairs.append(_line_amplitudes(t[part], [source[part], theta[part]], omega))
    cross = sum(np.conj(s) * a for s, a in pairs)
    power_s = sum(np.abs(s) ** 2 for s, _ in pairs)
    power_a = sum(np.abs(a) ** 2 for _, a in pairs)
    return np.abs(cross) ** 2 / np.maximum(power_s * power_a, 1e-300)


def _segment(n: int) -> int:
    """Welch segment length (samples) for a record of ``n``: about n / :data:`SEGMENTS`."""
    return int(max(16, min(n, n // SEGMENTS)))


def _coherence(source: np.ndarray, theta: np.ndarray, h: float):
    """Welch coherence of ``source`` with the angle, as a function of ω (rad/s)."""
    f, c = signal.coherence(
        source, theta, fs=1.0 / h, nperseg=_segment(len(theta)), detrend="linear"
    )
    return lambda omega: np.interp(omega, 2 * np.pi * f, c)


def _welch_response(
    source: np.ndarray, torque: np.ndarray, theta: np.ndarray, h: float, low: float, top: float
) -> tuple[np.ndarray, np.ndarray]:
    """Welch's S_sθ/S_sτ · jω (rad/s per N·m) from ``low`` to ``top`` (rad/s)."""
    n = _segment(len(theta))
    f, s_angle = signal.csd(source, theta, fs=1.0 / h, nperseg=n, detrend="linear")
    _, s_torque = signal.csd(source, torque, fs=1.0 / h, nperseg=n, detrend="linear")
    omega = 2 * np.pi * f
    keep = (omega >= max(low, omega[1])) & (omega <= top) & (np.abs(s_torque) > 0)
    return omega[keep], 1j * omega[keep] * s_angle[keep] / s_torque[keep]


def _loop_coherence(
    torque: np.ndarray, theta: np.ndarray, h: float, lines: np.ndarray, top: float
) -> float:
    """Median Welch coherence of torque and angle between the lines (rad/s), below
    ``top`` (rad/s), the lines fitted out of both by least squares."""
    # the lines taken out of both first: what is left is the noise, which only a loop
    # correlates (the speed's noise fed back as current)
    t = np.arange(len(theta)) * h
    phase = np.outer(t, lines)
    X = np.hstack([np.cos(phase), np.sin(phase), np.vander(t / t[-1], 4)])
    both = np.column_stack([torque, theta])
    rest = both - X @ np.linalg.lstsq(X, both, rcond=None)[0]
    size = max(16, len(theta) // LOOP_SEGMENTS)
    f, c = signal.coherence(*rest.T, fs=1.0 / h, nperseg=size, detrend="linear")
    omega = 2 * np.pi * f
    width = 1.5 * omega[1]
    apart = np.all(np.abs(omega[:, None] - lines[None, :]) > width, axis=1) if len(lines) else True
    keep = apart & (omega > omega[1]) & (omega <= top)
    return float(np.median(c[keep])) if np.any(keep) else 0.0


def _loop_warning(coherence: float) -> str:
    """The closed-loop warning."""
    return (
        f"the current and the speed are correlated between the excitation's lines (median "
        f"coherence {coherence:.2f}): a closed loop feeds the speed's noise back as "
        "current, which biases the measured response toward the controller's inverse where "
        "that noise competes with the excitation; log the reference (or an added "
        "excitation) and give it with --reference for the indirect estimate"
    )


def model_response(
    omega: np.ndarray,
    J_m: float,
    J: Sequence[float],
    k: Sequence[float],
    B: Sequence[float],
    D_m: float = 0.0,
) -> np.ndarray:
    """The chain model's response from drive torque to motor speed (rad/s per N·m).

    Parameters
    ----------
    omega : ndarray
        Frequencies (rad/s), shape ``(F,)``.
    J_m : float
        Motor inertia (kg·m²).
    J, k, B : sequence of float
        Load inertias (kg·m²), springs (N·m/rad; k[0] from the motor to J[0]) and their
        dampers (N·m·s/rad), each of length n (n = 0: a rigid motor).
    D_m : float
        Motor viscous friction (N·m·s/rad); Coulomb friction is left out (not linear).

    Returns
    -------
    ndarray
        jω·[(K + jωC − ω²M)⁻¹]₀₀, complex, shape ``(F,)``.

    Examples
    --------
    >>> np.round(model_response(np.array([10.0]), 1e-3, [], [], []), 3)  # 1/(jωJ)
    array([0.-100.j])
    """
    m = len(J) + 1
    M = np.diag([J_m, *J])
    K, C = np.zeros((m, m)), np.zeros((m, m))
    for j, (kj, bj) in enumerate(zip(k, B)):
        for A, v in ((K, kj), (C, bj)):
            A[j : j + 2, j : j + 2] += v * np.array([[1.0, -1.0], [-1.0, 1.0]])
    C[0, 0] += D_m
    e0 = np.zeros(m)
    e0[0] = 1.0
    out = np.empty(len(omega), dtype=complex)
    for i, w in enumerate(np.asarray(omega, dtype=float)):
        out[i] = 1j * w * np.linalg.solve(K + 1j * w * C - w**2 * M, e0)[0]
    return out


def residual_spectrum(
    time: np.ndarray,
    i_a: np.ndarray,
    theta_m: np.ndarray,
    k_t: float,
    model: tuple[float, Sequence[float], Sequence[float], Sequence[float], float],
    current_noise: float,
    count: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The torque the model leaves unexplained, as a spectrum, and the noise floor.

    The residual e = τ − Z·ω_m (Z the model's impedance 1/response, ω_m = jω·θ) by
    periodogram (Hann window) averaged over :data:`BANDS` log-spaced bands,
    (N·m)²/(rad/s); the floor: the current noise k_t²·σ_i² and the encoder's
    counts q²/12 seen through Z·jω, both white over the step h.

    Parameters
    ----------
    time, i_a, theta_m : ndarray
        The log: times (s), current (A), motor angle (rad), each of shape ``(N,)``.
    k_t : float
        Torque constant (N·m/A).
    model : tuple
        ``(J_m, J, k, B, D_m)`` as :func:`model_response` takes them.
    current_noise : float
        The current's noise (A, standard deviation per sample).
    count : float
        One encoder count (rad); 0 for an angle not quantized.

    Returns
    -------
    omega : ndarray
        Frequencies (rad/s), shape ``(F,)``.
    residual : ndarray
        Its power spectral density ((N·m)² per rad/s), shape ``(F,)``.
    floor : ndarray
        The floor's ((N·m)² per rad/s), shape ``(F,)``.

    Examples
    --------
    A rigid body of 1e-3 kg·m² under one line, judged by its own model:

    >>> t = np.arange(20001) * 1e-3
    >>> theta = -np.sin(5.0 * t) / 25 / 1e-3
    >>> rigid = (1e-3, [], [], [], 0.0)
    >>> omega, residual, floor = residual_spectrum(t, np.sin(5.0 * t), theta, 1.0, rigid,
    ...                                            1e-3, 0.0)
    >>> omega.shape == residual.shape == floor.shape
    True
    """
    time, i_a, theta = (np.asarray(x, dtype=float) for x in (time, i_a, theta_m))
    h = float(np.mean(np.diff(time)))
    n = len(theta)
    window = np.hanning(n)
    t = time - time[0]
    trend = np.polyval(np.polyfit(t, theta, 3), t)
    omega = 2 * np.pi * np.fft.rfftfreq(n, h)
    Z = 1.0 / model_response(np.maximum(omega, omega[1]), *model)
    spectrum = np.fft.rfft(k_t * i_a * window) - Z * 1j * omega * np.fft.rfft(
        (theta - trend) * window
    )
    psd = np.abs(spectrum) ** 2 * h / np.sum(window**2) / np.pi  # one-sided, per rad/s
    white = h / np.pi  # a unit-variance white sequence, one-sided per rad/s
    floor = white * ((k_t * current_noise) ** 2 + np.abs(Z * 1j * omega) ** 2 * count**2 / 12.0)
    # averaged over log-spaced bands (BANDS of them): a line's leftover stays a peak
    edges = np.geomspace(omega[1], omega[-1], BANDS + 1)
    which = np.digitize(omega, edges) - 1
    centres, mean_psd, mean_floor = [], [], []
    for b in range(BANDS):
        inside = which == b
        if np.any(inside):
            centres.append(float(np.sqrt(edges[b] * edges[b + 1])))
            mean_psd.append(float(psd[inside].mean()))
            mean_floor.append(float(floor[inside].mean()))
    return np.array(centres), np.array(mean_psd), np.array(mean_floor)
