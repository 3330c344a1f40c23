"""Figures and tables of ``arcosim reproduce``: the PNG figures 4 to 9, the response a
multi-sine record measures, and tables as Markdown or aligned text."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from arcosim.host.master import Recording
from arcosim.outputs import save_figure


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _legend_above(fig, ax, ncol: int) -> None:
    """One legend for the figure, of ``ax``'s lines, between the title and the plots
    (never over the data), and the layout made around it."""
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.955), ncol=ncol,
               fontsize=8, frameon=False)  # fmt: skip
    fig.tight_layout(rect=(0, 0, 1, 0.935))


def _symlog_if_diverging(ax, truth: np.ndarray, estimate: np.ndarray) -> None:
    """A symmetric-log y axis when ``estimate`` runs far beyond ``truth`` (a diverging
    recursion): linear over the truth's range, decades beyond it, so both show."""
    scale = float(np.max(np.abs(truth))) if truth.size else 0.0
    if scale > 0 and estimate.size and float(np.max(np.abs(estimate))) > 5 * scale:
        ax.set_yscale("symlog", linthresh=scale, linscale=4.0)
        truth_line, *others = ax.get_lines()
        truth_line.set_zorder(3)  # the truth over the diverged estimate
        for line in others:
            line.set(alpha=0.45, lw=0.5, ls="-")
        top = int(np.ceil(np.log10(float(np.max(np.abs(estimate))))))
        low = int(np.floor(np.log10(scale)))
        decades = range(top, low + 1, -max(1, (top - low) // 3))  # at most ~4 a side
        ticks = [*(10.0**k for k in decades), float(f"{scale:.1g}")]  # and the band's edge
        ax.set_yticks([*(-x for x in ticks), 0.0, *ticks[::-1]])
        ax.set_ylim(-(10.0**top), 10.0**top)
        ax.axhspan(-scale, scale, color="0.92", zorder=0)


def figure_reaction_torque(
    recording: Recording, reconstructed: np.ndarray, path: Path, k_hat: float, B_hat: float
) -> Path:
    """Fig. 4: τ̂_reac against the torque rebuilt from k̂, B̂ and the load's encoder.

    Parameters
    ----------
    recording : Recording
        A rigid maneuver's run (``observer.tau_reac_hat``, N·m).
    reconstructed : ndarray
        The torque rebuilt from k̂ and B̂ through G(s) (N·m), shape ``(N,)``.
    path : Path
        The PNG to write (replaced if it exists).
    k_hat, B_hat : float
        The identified stiffness (N·m/rad) and damping (N·m·s/rad).

    Returns
    -------
    Path
        ``path``.
    """
    plt = _pyplot()
    t = recording.time
    fig, (ax, zoom) = plt.subplots(2, 1, figsize=(9, 6.5))
    for a in (ax, zoom):
        a.plot(t, recording["observer.tau_reac_hat"] * 1e3, label="τ̂_reac (observer)")
        a.plot(
            t,
            reconstructed * 1e3,
            "--",
            label=f"G[k̂(θ_m − θ_1) + B̂(θ̇_m − θ̇_1)], k̂ = {k_hat:.4f} N·m/rad",
        )
        a.set_ylabel("torque (mN·m)")
        a.grid(True, alpha=0.3)
    mid = len(t) // 2
    window = slice(mid, min(len(t), mid + 3000))
    zoom.set_xlim(t[window][0], t[window][-1])
    ax.set_xlabel("time (s)")
    zoom.set_xlabel("time (s), magnified")
    fig.suptitle("Fig. 4 — reaction torque and its reconstruction from the identified k, B")
    _legend_above(fig, ax, ncol=2)
    save_figure(fig, path, dpi=110, force=True)
    plt.close(fig)
    return path


def figure_flexible_response(recording: Recording, n: int, path: Path) -> Path:
    """Fig. 5: true angles of the motor and every mass during the flexible maneuver.

    Parameters
    ----------
    recording : Recording
        The flexible maneuver's run (``plant.theta_m_true``, ``plant.theta[i]``, rad).
    n : int
        Number of load masses (a count).
    path : Path
        The PNG to write (replaced if it exists).

    Returns
    -------
    Path
        ``path``.
    """
    plt = _pyplot()
    t = recording.time
    fig, (ax, zoom) = plt.subplots(2, 1, figsize=(9, 6.5))
    for a in (ax, zoom):
        a.plot(t, recording["plant.theta_m_true"], label="θ_m (motor)")
        for i in range(1, n + 1):
            a.plot(t, recording[f"plant.theta[{i}]"], label=f"θ_{i}")
        a.set_ylabel("angle (rad)")
        a.grid(True, alpha=0.3)
    zoom.set_xlim(2.0, 3.0)
    inside = (t >= 2.0) & (t <= 3.0)
    if inside.any():
        shown = [recording["plant.theta_m_true"][inside]]
        shown += [recording[f"plant.theta[{i}]"][inside] for i in range(1, n + 1)]
        low, high = min(x.min() for x in shown), max(x.max() for x in shown)
        pad = 0.1 * (high - low) + 1e-9
        zoom.set_ylim(low - pad, high + pad)
    ax.set_xlabel("time (s)")
    zoom.set_xlabel("time (s), magnified")
    fig.suptitle("Fig. 5 — flexible response of the chain (plant truth)")
    _legend_above(fig, ax, ncol=n + 1)
    save_figure(fig, path, dpi=110, force=True)
    plt.close(fig)
    return path


def figure_state_estimates(
    recording: Recording,
    n: int,
    scores: Sequence[float],
    path: Path,
    model_based: Recording | None = None,
    model_scores: Sequence[float] = (),
    window: tuple[float, float] = (4.0, 6.0),
) -> Path:
    """Fig. 6: estimated against true angle of every mass, relative to the motor.

    Left, the paper's recursion (``recording``): it diverges from the second mass on,
    so a panel whose estimate runs far beyond the truth has a symmetric-log axis,
    linear over the truth's range (shaded) and in decades beyond; right, the
    model-based observer (``model_based``, the same maneuver) on the truth's scale.
    Both over ``window`` (s) of the run; each panel's score (rms error / rms flexible
    motion, over the whole run) is written above it, the legend above the plots.
    """
    plt = _pyplot()
    columns = 1 if model_based is None else 2
    fig, axes = plt.subplots(
        n, columns, figsize=(5.2 * columns, 2.2 * n + 1.2), sharex=True, squeeze=False
    )

    def panel(ax, run: Recording, i: int, label: str, color: str) -> None:
        shown = (run.time >= window[0]) & (run.time <= window[1])
        t = run.time[shown]
        motor = run["plant.theta_m_true"][shown]
        truth = (run[f"plant.theta[{i}]"][shown] - motor) * 1e3
        estimate = (run[f"observer.theta_hat[{i}]"][shown] - motor) * 1e3
        ax.plot(t, truth, color="C0", lw=1.4, label="true")
        ax.plot(t, estimate, color=color, lw=0.8, ls="--", label=label)
        ax.set_ylabel(f"θ_{i} − θ_m (mrad)")
        ax.grid(True, alpha=0.3)
        return truth, estimate

    for i in range(1, n + 1):
        left = axes[i - 1, 0]
        truth, estimate = panel(left, recording, i, "the paper's recursion (eq. 22–26)", "C1")
        _symlog_if_diverging(left, truth, estimate)
        diverged = left.get_yscale() == "symlog"
        note = f", up to {np.max(np.abs(estimate)):.1e} mrad: symlog axis" if diverged else ""
        left.set_title(f"mass {i}: recursion, score {scores[i - 1]:.3g}{note}", fontsize=8)
        if model_based is not None:
            right = axes[i - 1, 1]
            panel(right, model_based, i, "model-based, chain identified from the motor", "C3")
            score = f", score {model_scores[i - 1]:.3g}" if model_scores else ""
            right.set_title(f"mass {i}: model-based{score}", fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)")
    fig.suptitle("Fig. 6 — angle of each mass relative to the motor, estimated and true")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if model_based is not None:
        more, more_labels = axes[0, 1].get_legend_handles_labels()
        handles, labels = handles + more[1:], labels + more_labels[1:]
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.96), ncol=3,
               fontsize=8, frameon=False)  # fmt: skip
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    save_figure(fig, path, dpi=110, force=True)
    plt.close(fig)
    return path


def figure_whole_chain(
    identified: dict[str, float],
    std: dict[str, float],
    true: dict[str, float],
    response: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    path: Path,
) -> Path:
    """Fig. 7: the whole-chain result: every parameter against the truth, and the model.

    Parameters
    ----------
    identified, std, true : dict of str to float
        ``J[i]``, ``k[i]``, ``B[i]`` identified, their standard errors and the truth
        (kg·m², N·m/rad, N·m·s/rad).
    response : tuple of ndarray
        ``(lines, measured, w, model, truth)``: the excitation lines (rad/s, shape
        ``(L,)``) and the response τ̂_reac / θ_m measured there (N·m/rad, complex,
        shape ``(L,)``); a frequency grid (rad/s, shape ``(F,)``) and the identified
        and true chains' responses on it (N·m/rad, complex, shape ``(F,)``).
    path : Path
        The PNG to write.
    """
    plt = _pyplot()
    fig = plt.figure(figsize=(10, 7.5))
    grid = fig.add_gridspec(2, 2, height_ratios=(1, 1.3))
    for column, group, unit_note in ((0, ("J", "k"), "J_i, k_i"), (1, ("B",), "B_i")):
        ax = fig.add_subplot(grid[0, column])
        names = [name for name in identified if name.split("[")[0] in group and name in true]
        errors = [100 * (identified[x] - true[x]) / true[x] for x in names]
        bars = [200 * std[x] / true[x] for x in names]
        ax.errorbar(range(len(names)), errors, yerr=bars, fmt="o", capsize=4, color="C3")
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xticks(range(len(names)), names)
        ax.set_ylabel("error against the truth (%)")
        ax.set_title(f"{unit_note}: identified − true, bars ±2σ", fontsize=9)
        ax.grid(True, alpha=0.3)
    lines, measured, w, model, truth = response
    magnitude = fig.add_subplot(grid[1, :])
    magnitude.loglog(
        lines, np.abs(measured), "o", ms=4, color="0.4", label="measured τ̂_reac / θ_m (lines)"
    )
    magnitude.loglog(w, np.abs(truth), color="C0", lw=1.5, label="true chain")
    magnitude.loglog(w, np.abs(model), "--", color="C3", lw=1.2, label="identified chain")
    magnitude.set_xlabel("frequency (rad/s)")
    magnitude.set_ylabel("|τ / θ_m| through G(s) (N·m/rad)")
    magnitude.grid(True, which="both", alpha=0.3)
    magnitude.legend(fontsize=8)
    fig.suptitle("Fig. 7 — the whole chain from the motor's current and encoder alone")
    fig.tight_layout()
    save_figure(fig, path, dpi=110, force=True)
    plt.close(fig)
    return path


def figure_load_torque(
    time: np.ndarray, truth: np.ndarray, estimates: dict[str, np.ndarray], path: Path
) -> Path:
    """Fig. 8: the load torque on the last mass, estimated from the motor against the truth.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    truth : ndarray
        The torque applied (N·m), shape ``(N,)``.
    estimates : dict of str to ndarray
        Label → the estimate (N·m), each of shape ``(N,)``.
    path : Path
        The PNG to write (replaced if it exists).

    Returns
    -------
    Path
        ``path``.
    """
    plt = _pyplot()
    fig, (ax, err) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    ax.plot(time, truth * 1e3, color="k", lw=1.4, label="applied (plant tau_ext[3])")
    for j, (label, estimate) in enumerate(estimates.items()):
        style = {"color": f"C{j}", "ls": "-" if j == 0 else "--"}
        ax.plot(time, estimate * 1e3, lw=1.0, label=f"estimated, {label}", **style)
        err.plot(time, (estimate - truth) * 1e3, lw=0.8, label=label, **style)
    size = float(np.max(np.abs(truth)))
    for a in (ax, err):
        a.grid(True, alpha=0.3)
        a.set_ylabel("torque (mN·m)")
    for bound in (-0.05 * size, 0.05 * size):
        err.axhline(bound * 1e3, color="0.5", ls="--", lw=0.8)
    largest = max((float(np.max(np.abs(e - truth))) for e in estimates.values()), default=0.0)
    reach = 1.1 * max(largest, 0.1 * size) * 1e3  # the whole error, the sine's lag included
    err.set_ylim(-reach, reach)
    err.set_xlabel("time (s)")
    err.set_title("estimate − applied (grey: ±5 % of the step)", fontsize=9)
    err.legend(loc="upper left", fontsize=8)
    ax.legend(loc="lower left", fontsize=8)
    fig.suptitle("Fig. 8 — load torque on mass 3 from the motor alone (model-based observer)")
    fig.tight_layout()
    save_figure(fig, path, dpi=110, force=True)
    plt.close(fig)
    return path


def figure_flexible_link(
    time: np.ndarray,
    truth: dict[str, np.ndarray],
    estimate: dict[str, np.ndarray],
    path: Path,
    window: tuple[float, float] = (5.0, 7.0),
) -> Path:
    """Fig. 9: the flexible link's reaction torque and tip angle from the hub alone over
    the plant's (two seconds of the record, so the modes show).

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``.
    truth, estimate : dict of str to ndarray
        ``tau_reac`` (N·m) and ``alpha_tip`` (rad), each of shape ``(N,)``: the plant's
        and the estimate from the hub.
    path : Path
        The PNG to write (replaced if it exists).
    window : tuple of float
        The span of the record drawn (s).

    Returns
    -------
    Path
        ``path``.
    """
    plt = _pyplot()
    show = (time >= window[0]) & (time <= window[1])
    fig, axes = plt.subplots(2, 1, figsize=(9, 6.0), sharex=True)
    panels = (("tau_reac", "reaction torque, eq. 7 (mN·m)"), ("alpha_tip", "tip angle (mrad)"))
    for ax, (name, label) in zip(axes, panels):
        ax.plot(time[show], truth[name][show] * 1e3, color="k", lw=1.4, label="plant")
        ax.plot(time[show], estimate[name][show] * 1e3, color="C1", lw=1.0, ls="--",
                label="from the hub's current and encoder")  # fmt: skip
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle("Fig. 9 — flexible link: estimate over plant (FlexLinkPlant.fmu)")
    _legend_above(fig, axes[0], 2)
    save_figure(fig, path, dpi=110, force=True)
    plt.close(fig)
    return path


def measured_response(
    time: np.ndarray, theta_m: np.ndarray, tau_hat: np.ndarray, lines: np.ndarray
) -> np.ndarray:
    """The response τ̂_reac / θ_m of a multi-sine record, at its excitation lines.

    The ratio of the two signals' Hann-windowed Fourier transforms at each line.

    Parameters
    ----------
    time : ndarray
        Sample times (s), shape ``(N,)``, a constant step.
    theta_m, tau_hat : ndarray
        Motor angle (rad) and reaction torque estimate (N·m), shape ``(N,)``.
    lines : ndarray
        The excitation's frequencies (rad/s), shape ``(F,)``.

    Returns
    -------
    ndarray
        Complex response (N·m/rad) at each line, shape ``(F,)``.
    """
    window = np.hanning(len(time))
    phasors = np.exp(-1j * np.outer(lines, time - time[0])) * window
    return (phasors @ (tau_hat - tau_hat.mean())) / (phasors @ (theta_m - theta_m.mean()))


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A GitHub markdown table.

    Parameters
    ----------
    header : sequence of str
        The column titles.
    rows : sequence of sequences
        The cells, one sequence per row, each as long as ``header``; shown with ``str``.

    Returns
    -------
    str
        The table, one line per row after the header and its rule, no trailing newline.

    Examples
    --------
    >>> print(markdown_table(["a", "b"], [[1, 2]]))
    | a | b |
    |---|---|
    | 1 | 2 |
    """
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def text_table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """The same table as aligned plain text, for the terminal.

    Examples
    --------
    >>> print(text_table(["a", "bb"], [[1, 2]]))
    a  bb
    -  --
    1   2
    """
    cells = [list(map(str, header))] + [[str(c) for c in row] for row in rows]
    widths = [max(len(r[j]) for r in cells) for j in range(len(header))]
    out = ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    out.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(out)
