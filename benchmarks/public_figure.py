"""The motor bench's figure: its measured response beside the identified chains'.

:func:`bench_figure` draws, from a :func:`benchmarks.public_records.run_record` result
of the motor bench, the motor angle per unit current measured at the multi-sine's lines
(averaged over periods), the two-encoder reference's two-mass model and each whole-chain
fit's model, magnitude and phase, and writes the numbers beside it as CSV. Made from
our own estimates: the measured response is the periodic average at the excited lines,
not the record's samples.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from arcosim import write_csv
from benchmarks import public_loaders as loaders


def chain_frf(
    w: np.ndarray, J_m: float, J: list[float], k: list[float], B: list[float], D_m: float = 0.0
) -> np.ndarray:
    """Motor angle per unit motor torque of a chain of masses at ``w`` (rad/s).

    Parameters
    ----------
    w : ndarray
        Frequencies (rad/s), shape ``(L,)``.
    J_m : float
        Motor inertia (kg·m²).
    J, k, B : list of float
        Load inertias (kg·m²), the springs before each (N·m/rad) and their dampers
        (N·m·s/rad), length n each.
    D_m : float
        Motor viscous friction (N·m·s/rad).

    Returns
    -------
    ndarray
        θ_m/τ (rad/(N·m), complex), shape ``(L,)``.
    """
    inertia = np.diag([J_m, *J])
    n = len(J) + 1
    stiffness = np.zeros((n, n))
    damping = np.zeros((n, n))
    damping[0, 0] = D_m
    for i, (ki, bi) in enumerate(zip(k, B)):
        for matrix, value in ((stiffness, ki), (damping, bi)):
            matrix[i : i + 2, i : i + 2] += value * np.array([[1.0, -1.0], [-1.0, 1.0]])
    unit = np.zeros(n)
    unit[0] = 1.0
    out = []
    for wi in w:
        dynamic = -(wi**2) * inertia + 1j * wi * damping + stiffness
        out.append(np.linalg.solve(dynamic, unit)[0])
    return np.asarray(out)


def _chain_of(body: dict) -> tuple[list[float], list[float], list[float], float]:
    """J, k, B and D_m of a whole-chain ``--json`` result."""
    n = int(body["masses"])
    return (
        [body[f"J[{i}]"] for i in range(1, n + 1)],
        [body[f"k[{i}]"] for i in range(1, n + 1)],
        [body[f"B[{i}]"] for i in range(1, n + 1)],
        float(body.get("D_m", 0.0)),
    )


def bench_figure(result: dict, path: Path) -> list[Path]:
    """Draw the motor bench's measured and identified responses; write PNG and CSV.

    Parameters
    ----------
    result : dict
        :func:`benchmarks.public_records.run_record`'s result for ``motor-bench``.
    path : Path
        The PNG to write; the CSV goes beside it (same name, ``.csv``).

    Returns
    -------
    list of Path
        The PNG and the CSV.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    converted = loaders.load_motor_bench(Path(result["data_file"]))
    band = (converted.extra["f_low"], converted.extra["f_high"])
    w, measured = loaders.periodic_frf(
        converted.columns, int(converted.extra["period"]), band, "theta_m"
    )
    ref = result["reference"]
    curves = {"measured (periodic average)": measured}
    curves["two-encoder reference"] = loaders.two_mass_frf(
        w, ref["J_m"], ref["J[1]"], ref["k[1]"], ref["B[1]"], 0.0
    )[0]
    for run in result["runs"]:
        if run["json"]:
            J, k, B, D_m = _chain_of(run["json"])
            curves[f"arcosim, {run['label']} (n = {len(J)})"] = chain_frf(
                w, ref["J_m"], J, k, B, D_m
            )
    fig, (mag, phase) = plt.subplots(2, 1, figsize=(6.4, 4.8), sharex=True)
    for (label, frf), style in zip(curves.items(), (".", "-", "--", ":")):
        acc = -(w**2) * frf  # acceleration per unit torque: flat away from the modes
        mag.semilogx(w, 20 * np.log10(np.abs(acc)), style, ms=2, lw=1, label=label)
        phase.semilogx(w, np.degrees(np.angle(acc)), style, ms=2, lw=1)
    mag.set_ylabel("|α_m / i_a| (dB re 1 rad/s²/A)")
    phase.set_ylabel("phase (°)")
    phase.set_xlabel("ω (rad/s)")
    mag.legend(fontsize=7)
    mag.set_title("FdiTools motor bench: motor acceleration per unit current", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    columns = {"omega": w}
    for i, frf in enumerate(curves.values()):
        columns[f"mag_{i}"] = np.abs(frf)
        columns[f"phase_{i}"] = np.degrees(np.angle(frf))
    units = {name: "rad/A" if name.startswith("mag") else "deg" for name in columns}
    units["omega"] = "rad/s"
    table = write_csv(path.with_suffix(".csv"), columns, units=units, force=True)
    return [path, table]
