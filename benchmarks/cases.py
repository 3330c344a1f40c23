"""The chains and sensors the accuracy benchmarks score on, and how one run is made."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from arcosim import Actuator, ObserverSettings, Scenario, run_scenario
from arcosim.fmu.flexchain import ENCODER_CPR, G_DIST, defaults, spring_matrix

ACTUATOR = Actuator(defaults.J_M, defaults.K_T, 0.0, 0.0, defaults.D_M, defaults.F_C)


@dataclass(frozen=True)
class Case:
    """One plant: load inertias (kg·m²), spring stiffnesses (N·m/rad) and dampings."""

    name: str
    J: tuple[float, ...]
    k: tuple[float, ...]
    B: tuple[float, ...]

    @property
    def n(self) -> int:
        return len(self.J)

    def plant_values(self) -> dict[str, float]:
        values: dict[str, float] = {}
        for i in range(self.n):
            values[f"J[{i + 1}]"] = self.J[i]
            values[f"k[{i + 1}]"] = self.k[i]
            values[f"B[{i + 1}]"] = self.B[i]
        return values

    def first_mode(self) -> float:
        """Lowest flexible mode of motor + chain (rad/s)."""
        M = np.diag([defaults.J_M, *self.J])
        K = np.array(spring_matrix(self.k))
        w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
        return float(np.sqrt(w2[1]))


CASES = (
    Case("bench (n=3)", defaults.J, (defaults.K,) * 3, (defaults.B,) * 3),
    Case("two-mass", (4e-4, 8e-4), (0.3, 0.3), (2e-5, 2e-5)),
    Case("five-mass", (2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4), (0.4,) * 5, (1.5e-5,) * 5),
    Case("bench, non-uniform k", defaults.J, (0.12, defaults.K, 0.21), (defaults.B,) * 3),
)


def run_case(case: Case, scenario: Scenario, seed: int) -> dict[str, np.ndarray]:
    """Co-simulate ``scenario`` on ``case``'s plant with noise ``seed``; the plant's
    signals (and the truth) by name, plus ``time``."""
    truth = [f"theta[{i}]" for i in range(1, case.n + 1)]
    recording = run_scenario(
        scenario,
        case.n,
        plant={**case.plant_values(), "seed": seed},
        record_plant=["i_a", "omega_m", "theta_m", "theta_m_true", *truth],
        record_observer=["tau_reac_hat"],
    )
    signals = {k.split(".", 1)[1]: v for k, v in recording.signals.items() if k.startswith("plant")}
    signals["time"] = recording.time
    return signals


def settings_for(case: Case, mode: int, **kw: object) -> ObserverSettings:
    base = {
        "mode": mode,
        "actuator": ACTUATOR,
        "g_dist": G_DIST,
        "g_lpf": G_DIST,
        "J": case.J,
        "k": case.k,
        "B": case.B,
        "encoder_cpr": ENCODER_CPR,
    }
    base.update(kw)
    return ObserverSettings(**base)
