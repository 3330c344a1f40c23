"""The figures of ``arcosim reproduce`` (Figs. 4–9) from its runs and results.

:func:`paper_figures` draws the paper's Figs. 4–6, :func:`whole_chain_figure` Fig. 7
(experiment 4's chain against the truth), :func:`load_torque_figure` Fig. 8 (experiment
5's load torque), :func:`link_figure` Fig. 9 (experiment 6's flexible link); the drawing
itself is in :mod:`arcosim.experiments.report`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from arcosim.experiments.findings import N_MASSES, TRUE_CHAIN, Results
from arcosim.experiments.flexible_link import LinkRun
from arcosim.experiments.load_scores import step_truth
from arcosim.experiments.report import (
    figure_flexible_link,
    figure_flexible_response,
    figure_load_torque,
    figure_reaction_torque,
    figure_state_estimates,
    figure_whole_chain,
    measured_response,
)
from arcosim.experiments.scenarios import IDENTIFICATION_LINES, LOAD_PROFILE
from arcosim.fmu.flexchain.defaults import G_DIST
from arcosim.host.master import Recording
from arcosim.identification.fit.output_error import through_g
from arcosim.identification.modes.chain_modes import driving_point_response


def paper_figures(
    out: Path,
    rigid: Recording,
    flexible: Recording,
    results: Results,
    k_hat: float,
    b_hat: float,
    model_based: Recording | None,
) -> list[Path]:
    """Figs. 4, 5 and 6: the reaction torque of a rigid maneuver against the one
    rebuilt from k̂ and B̂, the flexible response, the angles.

    Parameters
    ----------
    out : Path
        Folder the PNG files go into.
    rigid, flexible : Recording
        Experiment 2's first rigid maneuver and experiment 3's flexible one.
    results : Results
        What the experiments found (the recursion's and the model-based scores).
    k_hat, b_hat : float
        Table II's mean stiffness (N·m/rad) and damping (N·m·s/rad).
    model_based : Recording or None
        Experiment 4's model-based estimates over the flexible maneuver, if it ran.

    Returns
    -------
    list of Path
        The three figures written.
    """
    raw = k_hat * (rigid["plant.theta_m_true"] - rigid["plant.theta[1]"]) + b_hat * (
        rigid["plant.omega_m_true"] - rigid["plant.omega[1]"]
    )
    rebuilt = through_g(raw, G_DIST, float(rigid.time[1] - rigid.time[0]))
    return [
        figure_reaction_torque(rigid, rebuilt, out / "fig4_reaction_torque.png", k_hat, b_hat),
        figure_flexible_response(flexible, N_MASSES, out / "fig5_flexible_response.png"),
        figure_state_estimates(
            flexible,
            N_MASSES,
            results.scores,
            out / "fig6_state_estimates.png",
            model_based,
            results.whole_scores,
        ),
    ]


def whole_chain_figure(out: Path, identification: Recording, results: Results) -> Path:
    """Fig. 7: experiment 4's parameters against the truth, and its model's response.

    Parameters
    ----------
    out : Path
        Folder the PNG file goes into.
    identification : Recording
        Experiment 4's identification run (its multi-sine's lines, rad/s, are
        ``IDENTIFICATION_LINES``).
    results : Results
        Experiment 4's fitted chain and standard errors (SI units).

    Returns
    -------
    Path
        The figure written.
    """
    true = dict(TRUE_CHAIN)
    lines = IDENTIFICATION_LINES
    measured = measured_response(
        identification.time,
        identification["plant.theta_m"],
        identification["observer.tau_reac_hat"],
        lines,
    )
    w = np.geomspace(lines[0], lines[-1], 1500)
    g = G_DIST / (1j * w + G_DIST)  # what τ̂_reac carries: τ_reac through G(s)

    def model(values: dict[str, float]) -> np.ndarray:
        J, k, B = ([values[f"{p}[{i}]"] for i in range(1, N_MASSES + 1)] for p in "JkB")
        return g * driving_point_response(J, k, B, w)

    fitted = results.whole_chain
    return figure_whole_chain(
        fitted,
        results.whole_chain_std,
        true,
        (lines, measured, w, model(fitted), model(true)),
        out / "fig7_whole_chain.png",
    )


def load_torque_figure(out: Path, runs: dict[str, Recording]) -> Path:
    """Fig. 8: experiment 5's load torque estimates by chain against the truth.

    Parameters
    ----------
    out : Path
        Folder the PNG file goes into.
    runs : dict of str to Recording
        Experiment 5's runs by the chain they estimated with (``"true chain"`` first).

    Returns
    -------
    Path
        The figure written (torques in N·m).
    """
    estimates = {label: rec["observer.tau_load_hat"] for label, rec in runs.items()}
    rec = runs["true chain"]
    truth = step_truth(rec.time, LOAD_PROFILE.torque(rec.time))
    return figure_load_torque(rec.time, truth, estimates, out / "fig8_load_torque.png")


def link_figure(out: Path, run: LinkRun, estimates: dict[str, np.ndarray]) -> Path:
    """Fig. 9: experiment 6's reaction torque and tip angle from the hub over the plant's.

    Parameters
    ----------
    out : Path
        Folder the PNG file goes into.
    run : LinkRun
        Experiment 6's run of the link plant (its ``tau_reac``, N·m, and ``alpha_tip``,
        rad).
    estimates : dict of str to ndarray
        ``tau_reac`` (N·m) and ``alpha_tip`` (rad) from the hub, each shape ``(N,)``.

    Returns
    -------
    Path
        The figure written.
    """
    return figure_flexible_link(run.time, run.signals, estimates, out / "fig9_flexible_link.png")
