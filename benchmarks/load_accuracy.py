"""Accuracy rows of the load torque estimate (part of ``arcosim bench accuracy``).

The accuracy benchmark's two- and five-mass chains, realistic sensors, the
``load-torque`` scenario's profile (:class:`arcosim.experiments.scenarios.LoadProfile`:
the broadband multi-sine at 1 A, a step of a tenth of the drive's peak torque, then a 2
rad/s sine) on the last mass and on a middle one, one run per seed. The estimate is the
observer FMU's own code run offline on the recorded log
(:func:`arcosim.identification.load_torque.estimate_load_torque`) with the true chain
and the plant's actuator terms, and once more with every spring of the model 5 % stiff
(the model is wrong). Per row: the step's settled error (mean over seeds, and the worst
|error| of any seed in the settled window), the settling time, the rms error during the
flexible motion, the sine's amplitude ratio and lag.

Then the bandwidth's trade-off on the bench (seed 1): for ``load_torque_bandwidth`` of
2.5 … 20 rad/s, the same scores with the true chain and with every inertia 1 % high.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from arcosim import estimate_load_torque
from arcosim.experiments import LoadProfile, LoadScore, markdown_table, score_profile
from arcosim.fmu.flexchain import Estimator, Mode
from benchmarks.cases import CASES, Case, run_case, settings_for


@dataclass(frozen=True)
class LoadRow:
    """One row: a chain, the mass the torque acts on, and the model's errors.

    Attributes:
        name: shown in the table.
        case: the plant.
        load_mass: 1 … n.
        k_scale, J_scale: factors on the model's stiffnesses and inertias (1: true).
    """

    name: str
    case: Case
    load_mass: int
    k_scale: float = 1.0
    J_scale: float = 1.0

    def profile(self) -> LoadProfile:
        return LoadProfile(mass=self.load_mass)


ROWS = (
    LoadRow("two-mass, load on mass 2 (last)", CASES[1], 2),
    LoadRow("two-mass, load on mass 1", CASES[1], 1),
    LoadRow("five-mass, load on mass 5 (last)", CASES[2], 5),
    LoadRow("five-mass, load on mass 3 (middle)", CASES[2], 3),
    LoadRow("five-mass, load on mass 5, springs 5 % stiff in the model", CASES[2], 5, 1.05),
)
#: Bandwidths (rad/s) of the trade-off rows.
BANDWIDTHS = (2.5, 5.0, 10.0, 20.0)


def plant_log(case: Case, profile: LoadProfile, seed: int) -> dict[str, np.ndarray]:
    """Co-simulate the profile on ``case`` (the observer FMU idles in mode 2 with the
    paper's recursion: the estimate is computed offline, :func:`score_row`)."""
    scenario = dataclasses.replace(profile.scenario(), observer={"mode": 2})
    return run_case(case, scenario, seed)


def row_estimate(
    row: LoadRow, log: dict[str, np.ndarray], bandwidth: float | None = None
) -> LoadScore:
    """Score the estimate of ``row``'s model on one log."""
    case = row.case
    extra = {} if bandwidth is None else {"load_torque_bandwidth": bandwidth}
    settings = settings_for(
        case,
        Mode.STATE_ESTIMATION,
        estimator=Estimator.MODEL_BASED,
        load_mass=row.load_mass,
        J=tuple(row.J_scale * x for x in case.J),
        k=tuple(row.k_scale * x for x in case.k),
        **extra,
    )
    result = estimate_load_torque(settings, log["time"], log["i_a"], log["omega_m"], log["theta_m"])
    return score_profile(log["time"], result.tau_load, row.profile())


def score_rows(
    rows: Sequence[LoadRow], seeds: Sequence[int], progress: Callable[[str], None]
) -> dict[str, dict]:
    """Every row over ``seeds`` (rows on the same plant and mass share its runs)."""
    logs: dict[tuple, dict[str, np.ndarray]] = {}
    results = {}
    for row in rows:
        scores = []
        for seed in seeds:
            key = (row.case.name, row.load_mass, seed)
            if key not in logs:
                progress(f"load torque, {row.case.name}, mass {row.load_mass}: seed {seed}")
                logs[key] = plant_log(row.case, row.profile(), seed)
            scores.append(row_estimate(row, logs[key]).as_dict())
        results[row.name] = {"seeds": len(seeds), "scores": scores}
    return results


def bandwidth_rows(progress: Callable[[str], None], seed: int = 1) -> dict[str, dict]:
    """The bench, seed 1: scores per bandwidth, true chain and inertias 1 % high."""
    bench = CASES[0]
    true, heavy = LoadRow("bench", bench, 3), LoadRow("bench", bench, 3, J_scale=1.01)
    progress("load torque, bench: bandwidth trade-off")
    log = plant_log(bench, true.profile(), seed)
    return {
        f"{w:g}": {
            "true chain": row_estimate(true, log, w).as_dict(),
            "inertias 1 % high": row_estimate(heavy, log, w).as_dict(),
        }
        for w in BANDWIDTHS
    }


def markdown(rows: dict[str, dict]) -> str:
    """The load torque table (errors in % of the step)."""
    header = [
        "chain, load",
        "settled error % (mean ± std over seeds)",
        "worst settled abs error %",
        "settling s (median / max)",
        "rms error % (mean)",
        "sine amplitude (median)",
        "sine lag ms (median)",
    ]
    cells = []
    for name, r in rows.items():
        s = r["scores"]
        mean = np.array([x["settled_mean_percent"] for x in s])
        worst = max(x["settled_max_percent"] for x in s)
        settling = np.array([x["settling_s"] for x in s])
        never = int(np.isnan(settling).sum())
        finite = settling[~np.isnan(settling)]
        settle = (f"{np.median(finite):.2f} / {np.max(finite):.2f}" if len(finite) else "never") + (
            f" ({never} of {len(s)} never)" if never else ""
        )
        cells.append(
            [
                name,
                f"{mean.mean():+.2f} ± {mean.std():.2f}",
                f"{worst:.2f}",
                settle,
                f"{np.mean([x['settled_rms_percent'] for x in s]):.2f}",
                f"{np.median([x['sine_amplitude_ratio'] for x in s]):.3f}",
                f"{1e3 * np.median([x['sine_lag_s'] for x in s]):.0f}",
            ]
        )
    return markdown_table(header, cells) + "\n"


def bandwidth_markdown(rows: dict[str, dict]) -> str:
    """The bandwidth trade-off table."""
    header = [
        "load_torque_bandwidth (rad/s)",
        "model",
        "settling s",
        "settled max abs error %",
        "rms error %",
        "sine amplitude",
        "sine lag ms",
    ]
    cells = []
    for w, models in rows.items():
        for model, x in models.items():
            settling = "never" if math.isnan(x["settling_s"]) else f"{x['settling_s']:.2f}"
            cells.append(
                [
                    w,
                    model,
                    settling,
                    f"{x['settled_max_percent']:.2f}",
                    f"{x['settled_rms_percent']:.2f}",
                    f"{x['sine_amplitude_ratio']:.3f}",
                    f"{1e3 * x['sine_lag_s']:.0f}",
                ]
            )
    return markdown_table(header, cells) + "\n"
