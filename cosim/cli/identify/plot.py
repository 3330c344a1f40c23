"""``arcosim identify --method whole-chain --plot FILE.png``: the engineer's view.

The measured frequency response from drive torque to motor speed
(:func:`arcosim.identification.checks.frf.measured_response`: its estimator named in the
title), its coherence, the identified chain's response over it with its modes marked
(resonances dashed, the clamped modes, the anti-resonances, dotted), and in a second
panel the torque the model leaves unexplained against the floor the encoder and the
current noise explain (:func:`arcosim.identification.checks.frf.residual_spectrum`). Beside
the figure, ``FILE.csv`` (and its units sidecar): ω, the measured magnitude and phase,
the coherence, the model's magnitude and phase.
"""

from __future__ import annotations

import argparse
import csv
import io
from pathlib import Path

import numpy as np

from arcosim import (
    DriveIdentification,
    DriveLog,
    UserError,
    check_output,
    read_text_file,
    save_figure,
    write_csv,
)
from arcosim.identification import (
    MeasuredResponse,
    current_noise,
    measured_response,
    model_response,
    residual_spectrum,
)

#: The CSV's columns and their units.
UNITS = {
    "omega": "rad/s",
    "measured_magnitude": "rad/s/(N.m)",
    "measured_phase": "deg",
    "coherence": "1",
    "model_magnitude": "rad/s/(N.m)",
    "model_phase": "deg",
}


def check_plot(args: argparse.Namespace) -> None:
    """Refuse ``--plot`` (and its CSV) before any fit when they cannot be written."""
    if args.plot is None:
        if args.reference:
            raise UserError("--reference goes with --plot FILE.png (the measured response)")
        return
    plot = Path(args.plot)
    if plot.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise UserError(f"--plot {plot}: name a .png, .svg or .pdf file")
    for path in (plot, plot.with_suffix(".csv")):
        check_output(path, inputs=[args.log], force=args.force, option="--plot")


def reference_column(path: Path, name: str, rows: int) -> np.ndarray:
    """The column ``name`` of the log (its unit cancels in the indirect estimate)."""
    reader = csv.reader(io.StringIO(read_text_file(path, "log"), newline=""))
    header = [cell.strip() for cell in next(reader, [])]
    if name not in header:
        raise UserError(f"--reference {name}: the log has no such column ({', '.join(header)})")
    j = header.index(name)
    try:
        values = np.array([float(row[j]) for row in reader if row and any(c.strip() for c in row)])
    except (ValueError, IndexError):
        raise UserError(f"--reference {name}: a cell is not a number") from None
    if len(values) != rows or not np.all(np.isfinite(values)):
        raise UserError(f"--reference {name}: needs a finite number on every row")
    return values


def write_plot(
    args: argparse.Namespace,
    log: DriveLog,
    result: DriveIdentification,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    band: float,
) -> list[str]:
    """Write the figure and its CSV; return the measured response's warnings.

    Parameters
    ----------
    args : argparse.Namespace
        ``plot`` (the figure's path), ``reference`` (a column name or None), ``log``,
        ``force``.
    log : DriveLog
        The log (SI units).
    result : DriveIdentification
        The identified chain.
    k_t, J_m : float
        Torque constant (N·m/A) and motor inertia (kg·m²) the fit used.
    encoder_cpr : int
        Encoder counts per revolution (a count; 0: not quantized).
    band : float
        Highest frequency shown (rad/s).

    Returns
    -------
    list of str
        Warnings of the measured response (a closed loop biasing it).
    """
    c = log.columns
    reference = reference_column(log.path, args.reference, len(log)) if args.reference else None
    measured = measured_response(log.time, c["i_a"], c["theta_m"], k_t, reference, band)
    n = result.masses
    stacked = np.array([result.parameters[name] for name in _names(n)])
    J, k, B = list(stacked[:n]), list(stacked[n : 2 * n]), list(stacked[2 * n : 3 * n])
    D_m = float(result.friction.get("D_m", 0.0))
    model = (J_m, J, k, B, D_m)
    modelled = model_response(measured.omega, *model)
    plot = Path(args.plot)
    write_csv(
        plot.with_suffix(".csv"),
        {
            "omega": measured.omega,
            "measured_magnitude": np.abs(measured.response),
            "measured_phase": np.degrees(np.angle(measured.response)),
            "coherence": measured.coherence,
            "model_magnitude": np.abs(modelled),
            "model_phase": np.degrees(np.angle(modelled)),
        },
        units=UNITS,
        force=args.force,
        option="--plot",
    )
    count = 2 * np.pi / encoder_cpr if encoder_cpr > 0 else 0.0
    residual = residual_spectrum(
        log.time, c["i_a"], c["theta_m"], k_t, model, current_noise(c["i_a"]), count
    )
    figure = _figure(measured, model, result, residual, band)
    save_figure(figure, plot, dpi=120, force=args.force, option="--plot")
    return list(measured.warnings)


def _names(n: int) -> list[str]:
    return [f"{p}[{i}]" for p in ("J", "k", "B") for i in range(1, n + 1)]


def _figure(
    measured: MeasuredResponse,
    model: tuple,
    result: DriveIdentification,
    residual: tuple[np.ndarray, np.ndarray, np.ndarray],
    band: float,
) -> object:
    """The figure: magnitude (with the coherence), phase, and the residual's spectrum."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    low = max(float(measured.omega.min()) / 1.5, 0.1) if len(measured.omega) else 1.0
    dense = np.geomspace(low, band, 800)
    modelled = model_response(dense, *model)
    figure, (mag, phase, rest) = plt.subplots(
        3, 1, figsize=(8, 9), height_ratios=(3, 1.5, 2), constrained_layout=True
    )
    mag.loglog(dense, np.abs(modelled), "C0-", lw=1.2, label=f"model ({result.masses} masses)")
    mag.loglog(measured.omega, np.abs(measured.response), "C1.", ms=5, label="measured")
    mag.set_ylabel("|ω_m / τ| (rad/s per N·m)")
    mag.set_title(f"drive torque → motor speed; measured: {measured.estimator}", fontsize=10)
    coherence = mag.twinx()
    coherence.semilogx(measured.omega, measured.coherence, "C7x", ms=3, label="coherence")
    coherence.set_ylim(0, 1.05)
    coherence.set_ylabel("coherence")
    phase.semilogx(dense, np.degrees(np.angle(modelled)), "C0-", lw=1.2)
    phase.semilogx(measured.omega, np.degrees(np.angle(measured.response)), "C1.", ms=5)
    phase.set_ylabel("phase (deg)")
    phase.set_ylim(-200, 200)
    J_m, J, k = model[:3]
    if result.masses:
        free = _free_modes(J_m, J, k)
        for axis in (mag, phase):
            for w in free:
                axis.axvline(w, color="C2", ls="--", lw=0.8)
            for w in result.report()["modes_rad_s"]:
                axis.axvline(w, color="C3", ls=":", lw=0.8)
        mag.plot([], [], "C2--", lw=0.8, label="resonances (model)")
        mag.plot([], [], "C3:", lw=0.8, label="clamped modes (fitted)")
    mag.legend(loc="lower left", fontsize=8)
    for axis in (mag, phase):
        axis.set_xlim(low, band)
        axis.grid(True, which="both", lw=0.3)
    omega, psd, floor = residual
    keep = (omega >= low) & (omega <= band)
    rest.loglog(omega[keep], psd[keep], "C1-", lw=0.8, label="residual torque")
    rest.loglog(omega[keep], floor[keep], "k--", lw=1.0, label="noise floor (encoder, current)")
    rest.set_xlabel("ω (rad/s)")
    rest.set_ylabel("PSD ((N·m)² per rad/s)")
    rest.set_xlim(low, band)
    rest.grid(True, which="both", lw=0.3)
    rest.legend(loc="upper left", fontsize=8)
    return figure


def _free_modes(J_m: float, J: list[float], k: list[float]) -> np.ndarray:
    """Resonances (rad/s) of motor and chain, free: the model's response peaks."""
    m = len(J) + 1
    M = np.diag([J_m, *J])
    K = np.zeros((m, m))
    for j, kj in enumerate(k):
        K[j : j + 2, j : j + 2] += kj * np.array([[1.0, -1.0], [-1.0, 1.0]])
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    return np.sqrt(np.maximum(w2[1:], 0.0))
