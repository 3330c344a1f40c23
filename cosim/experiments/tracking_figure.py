"""The figure of a tracked replay (``arcosim identify --set tracking=1 --plot FILE``):
each tracked parameter over time with its ±σ band and its commissioning value, the times
the drift alarm was raised shaded, and those the motion did not resolve the chain hatched.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from arcosim.host.tracking import TrackedChain
from arcosim.outputs import save_figure

#: The figure's resolution (dots per inch).
DPI = 120


def draw_tracking(tracked: TrackedChain, path: str | Path, force: bool = False) -> Path:
    """Draw ``tracked`` into ``path`` (.png, .svg or .pdf).

    Parameters
    ----------
    tracked : TrackedChain
        A tracked replay (:func:`arcosim.host.tracking.replay_tracking`).
    path : str or Path
        The figure's file.
    force : bool
        Replace an existing file.

    Returns
    -------
    Path
        The file written.

    Examples
    --------
    >>> import tempfile
    >>> from arcosim.host import TrackedChain
    >>> run = TrackedChain(np.array([0.0, 1.0]), ("k[1]",), ("N.m/rad",),
    ...     np.array([[1.0], [0.9]]), np.array([[0.1], [0.01]]), np.array([1.0]),
    ...     np.array([0, 1]), np.array([0, 1]))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     draw_tracking(run, Path(folder) / "tracked.png").name
    'tracked.png'
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    count = len(tracked.names)
    columns = 2
    rows = (count + 1) // columns
    fig, axes = plt.subplots(rows, columns, figsize=(10, 2.2 * rows), sharex=True, squeeze=False)
    t = tracked.time
    for j, ax in enumerate(axes.ravel()[:count]):
        value, std = tracked.values[:, j], tracked.stds[:, j]
        ax.fill_between(t, value - std, value + std, color="C0", alpha=0.25, lw=0, label="±σ")
        ax.plot(t, value, color="C0", lw=1.0, label="tracked")
        ax.axhline(tracked.commissioning[j], color="k", ls="--", lw=0.8, label="commissioning")
        _shade(ax, t, tracked.alarm > 0, "red", 0.12)
        _shade(ax, t, tracked.valid <= 0, "grey", 0.08)
        ax.set_ylabel(f"{tracked.names[j]} ({tracked.units[j]})", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes.ravel()[count:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("time (s)", fontsize=8)
    axes[0][0].legend(fontsize=7, loc="best")
    fig.suptitle(
        "tracked chain: red = drift alarm, grey = not resolved by the motion so far", fontsize=9
    )
    fig.tight_layout()
    out = save_figure(fig, path, dpi=DPI, force=force, option="--plot")
    plt.close(fig)
    return out


def _shade(ax, t: np.ndarray, where: np.ndarray, color: str, alpha: float) -> None:
    """Shade the spans of ``t`` where ``where`` holds."""
    if not where.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], where.astype(int), [0]])))
    for start, stop in zip(edges[::2], edges[1::2]):
        ax.axvspan(t[start], t[min(stop, len(t)) - 1], color=color, alpha=alpha, lw=0)
