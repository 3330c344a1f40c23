"""Figures and the markdown report of ``arcosim reproduce``."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from cosim.master import Recording


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure_reaction_torque(
    recording: Recording, reconstructed: np.ndarray, path: Path, k_hat: float, B_hat: float
) -> Path:
    """Fig. 4: τ̂_reac against the torque rebuilt from k̂, B̂ and the load's encoder."""
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
    ax.legend(loc="upper right", fontsize=8)
    fig.suptitle("Fig. 4 — reaction torque and its reconstruction from the identified k, B")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def figure_flexible_response(recording: Recording, n: int, path: Path) -> Path:
    """Fig. 5: true angles of the motor and every mass during the flexible maneuver."""
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
    ax.legend(loc="upper left", fontsize=8, ncol=n + 1)
    fig.suptitle("Fig. 5 — flexible response of the chain (plant truth)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def figure_state_estimates(
    recording: Recording, n: int, scores: Sequence[float], path: Path
) -> Path:
    """Fig. 6: estimated against true angle of every mass, relative to the motor."""
    plt = _pyplot()
    t = recording.time
    motor = recording["plant.theta_m_true"]
    fig, axes = plt.subplots(n, 1, figsize=(9, 2.2 * n + 1), sharex=True, squeeze=False)
    for i, ax in enumerate(axes[:, 0], start=1):
        truth = recording[f"plant.theta[{i}]"] - motor
        estimate = recording[f"observer.theta_hat[{i}]"] - motor
        ax.plot(
            t,
            estimate * 1e3,
            color="C1",
            lw=0.6,
            alpha=0.7,
            label=f"θ̂_{i} − θ_m estimated (score {scores[i - 1]:.3g})",
        )
        ax.plot(t, truth * 1e3, color="C0", lw=1.2, zorder=3, label=f"θ_{i} − θ_m true")
        span = np.max(np.abs(truth)) * 1e3
        ax.set_ylim(-3 * span, 3 * span)
        ax.set_ylabel("mrad")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle("Fig. 6 — estimated and true angle of each mass, relative to the motor")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def figure_load_torque(
    time: np.ndarray, truth: np.ndarray, estimates: dict[str, np.ndarray], path: Path
) -> Path:
    """Fig. 7: the load torque on the last mass, estimated from the motor against the truth."""
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
    err.set_ylim(-0.3 * size * 1e3, 0.3 * size * 1e3)
    err.set_xlabel("time (s)")
    err.set_title("estimate − applied (grey: ±5 % of the step)", fontsize=9)
    err.legend(loc="lower left", fontsize=8)
    ax.legend(loc="lower left", fontsize=8)
    fig.suptitle("Fig. 7 — load torque on mass 3 from the motor alone (model-based observer)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A GitHub markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def text_table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """The same table as aligned plain text, for the terminal."""
    cells = [list(map(str, header))] + [[str(c) for c in row] for row in rows]
    widths = [max(len(r[j]) for r in cells) for j in range(len(header))]
    out = ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    out.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(out)
