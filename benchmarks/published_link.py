"""A link we did not write: Quanser's Rotary Flexible Link on its SRV02 servo (high gear),
from the parameters Quanser publishes, simulated by the link plant FMU and, apart from
it, by the continuous beam's own modes (``benchmarks/simulators/modal_link.py``), and identified
from the hub alone.

Published (Quanser's courseware for the rig: ``config_flexgage_exp.m`` of the Rotary
Flexible Link experiment, and the SRV02's ``config_srv02`` constants):

* the link: length 15 in (0.381 m), mass 0.065 kg, natural frequency "experimentally
  determined to be 3 Hz" (Quanser's lumped model: the link as a rigid bar of inertia
  m L²/3 on a spring K = (2π·3 Hz)² J_l to a held base, i.e. the first clamped mode);
* the servo: rotor 3.9·10⁻⁷ kg·m², tachometer 7.06·10⁻⁸ kg·m², gear ratio 14 × 5,
  gearbox efficiency 0.90, motor efficiency 0.69, torque constant 7.68·10⁻³ N·m/A, the
  external gears (24-tooth 5 g, r = 0.25 in; two 72-tooth 30 g, r = 0.75 in; 120-tooth
  83 g, r = 1.25 in), viscous friction 0.015 N·m·s/rad at the load shaft, a 1024-line
  quadrature encoder (4096 counts per revolution).

Derived here (the beam the FMU needs): ρA = m / L; EI from the 3 Hz as the first
clamped mode of a uniform beam, EI = ρA (ω₁ L² / 1.8751²)²; the hub's inertia at the
load shaft J_eq = K_g² η_g (J_rotor + J_tach) + J_24 + 2 J_72 + J_120 (Quanser's sum);
the torque per ampere at the load shaft η_g K_g η_m k_t. Assumed (not published): a
current-driven servo (the SRV02 is voltage-driven; a current loop takes the back-EMF),
no Coulomb friction, no tip mass, the link clamped on the shaft's axis (r = 0),
stiffness-proportional damping β = 5·10⁻⁴ s (ζ₁ ≈ 0.5 %), 5 mA current noise.

The fit gets what a user of the rig knows (k_t, J_eq, the friction, the counts, L,
m_tip = 0) and finds EI, ρA and the damping; the modes, EI, ρA and the tip angle
(rms(α̂ − α)/rms(α) after the first second) against the published values and the plant.

Run: ``python -m benchmarks.published_link [--seeds 3] [--fmus dist] [--simulator
plant|modal|both] [--out FILE.json]`` (prints the markdown tables of
docs/identification.md, one per simulator).
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from arcosim import ensure_built
from arcosim.experiments import (
    LINK_FMU,
    LinkRig,
    clamped_frequencies,
    markdown_table,
    score_link,
    simulate_link,
)
from benchmarks.simulators.modal_link import simulate_modal_link

INCH = 0.0254
#: The link (config_flexgage_exp.m): length (m), mass (kg), measured frequency (rad/s).
LINK_LENGTH = 15 * INCH
LINK_MASS = 0.065
LINK_FREQUENCY = 2 * math.pi * 3.0
#: The SRV02, high gear: rotor and tachometer (kg·m²), gear ratio, efficiencies,
#: torque constant (N·m/A), viscous friction at the load (N·m·s/rad), encoder counts.
J_ROTOR, J_TACH = 3.9e-7, 7.06e-8
K_G, ETA_G, ETA_M, K_T = 14 * 5, 0.90, 0.69, 7.68e-3
B_EQ = 0.015
COUNTS = 4 * 1024
#: The external gears: mass (kg) and radius (m) of the 24-, 72- (two) and 120-tooth gears.
GEARS = ((0.005, 0.25 * INCH, 1), (0.030, 0.75 * INCH, 2), (0.083, 1.25 * INCH, 1))
#: The first clamped mode's βL of a uniform beam without a tip mass.
BETA_L1 = 1.8751040687


def rho_a() -> float:
    """Mass per length (kg/m): the link's mass over its length."""
    return LINK_MASS / LINK_LENGTH


def bending_stiffness() -> float:
    """EI (N·m²) whose first clamped mode is the published 3 Hz."""
    return rho_a() * (LINK_FREQUENCY * LINK_LENGTH**2 / BETA_L1**2) ** 2


def hub_inertia() -> float:
    """J_eq (kg·m²) at the load shaft: the motor through the gears plus the gears."""
    gears = sum(count * m * r**2 / 2 for m, r, count in GEARS)
    return K_G**2 * ETA_G * (J_ROTOR + J_TACH) + gears


def torque_constant() -> float:
    """Torque at the load shaft per ampere (N·m/A)."""
    return ETA_G * K_G * ETA_M * K_T


#: The rig as the plant FMU runs it, and its identification multi-sine (0.6 A peak, 30
#: lines 3–250 rad/s: the hub below 0.3 × the first mode).
RIG = LinkRig(
    "Quanser Rotary Flexible Link on SRV02 (high gear)",
    {
        "J_m": hub_inertia(),
        "k_t": torque_constant(),
        "D_m": B_EQ,
        "f_c": 0.0,
        "EI": bending_stiffness(),
        "rhoA": rho_a(),
        "L": LINK_LENGTH,
        "m_tip": 0.0,
        "J_tip": 0.0,
        "r_hub": 0.0,
        "beta": 5e-4,
        "encoder_cpr": COUNTS,
    },
    tuple(np.geomspace(3.0, 250.0, 30)),
    0.6,
)


#: The simulators of the rig: the link plant FMU (finite elements) and the continuous
#: beam's modes, written apart from it.
SIMULATORS = ("plant", "modal")


def score(fmu: Path, seeds: Sequence[int], simulator: str = "plant") -> list[dict]:
    """The rig simulated by ``simulator`` (one of :data:`SIMULATORS`) and identified from
    its hub, one dict per seed (JSON-able)."""
    rows = []
    for seed in seeds:
        rig = replace(RIG, seed=seed)
        run = simulate_link(fmu, rig) if simulator == "plant" else simulate_modal_link(rig)
        found = score_link(run, rig)
        rows.append({"seed": seed, "simulator": simulator, **found.as_dict()})
    return rows


def markdown(rows: list[dict]) -> str:
    """The published rig's table: published or derived value, the fit's worst over seeds."""
    modes = clamped_frequencies(RIG, 2)
    fitted = {k: [r[k] for r in rows] for k in ("EI", "rhoA", "alpha_ratio", "tau_ratio")}
    errors = {k: [r["errors_percent"][k] for r in rows] for k in rows[0]["errors_percent"]}

    def worst(name: str) -> str:
        return f"{max(errors[name], key=abs):+.2f} %"

    cells = [
        ["EI (N·m²)", f"{RIG.value('EI'):.4g} (from 3 Hz)", _span(fitted["EI"]), worst("EI")],
        ["ρA (kg/m)", f"{RIG.value('rhoA'):.4g} (65 g / 15 in)", _span(fitted["rhoA"]),
         worst("rhoA")],
    ]  # fmt: skip
    for i, w in enumerate(modes, start=1):
        found = _span([r["modes_rad_s"][i - 1] for r in rows])
        cells.append([f"clamped mode {i} (rad/s)", f"{w:.4g}", found, worst(f"mode[{i}]")])
    cells.append(["tip angle rms(α̂ − α)/rms(α)", "—", f"≤ {max(fitted['alpha_ratio']):.3f}", "—"])
    tau = f"≤ {max(fitted['tau_ratio']):.3f}"
    cells.append(["τ_reac (eq. 7) rms(τ̂ − τ)/rms(τ)", "—", tau, "—"])
    header = ["quantity", "published / derived", f"from the hub ({len(rows)} seeds)", "worst error"]
    return markdown_table(header, cells) + "\n"


def _span(values: Sequence[float]) -> str:
    """``lo … hi`` of ``values`` (4 significant digits), or the one value."""
    lo, hi = min(values), max(values)
    return f"{lo:.4g}" if f"{lo:.4g}" == f"{hi:.4g}" else f"{lo:.4g} … {hi:.4g}"


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m benchmarks.published_link``: print the table, optionally write JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--fmus", type=Path, help="folder of the FMUs (default: the cache)")
    parser.add_argument(
        "--simulator", choices=(*SIMULATORS, "both"), default="both",
        help="the link plant FMU, the continuous beam's modes, or both (default)",
    )  # fmt: skip
    parser.add_argument("--out", type=Path)
    args = parser.parse_args(argv)
    fmu = ensure_built(3, args.fmus) / LINK_FMU
    p = RIG.plant
    print(
        f"{RIG.name}: J_eq = {p['J_m']:.4g} kg.m², k_t = {p['k_t']:.4g} N.m/A, "
        f"EI = {p['EI']:.4g} N.m², rhoA = {p['rhoA']:.4g} kg/m, L = {p['L']:.4g} m, "
        f"clamped modes {np.round(clamped_frequencies(RIG, 3), 2).tolist()} rad/s"
    )
    every = []
    for simulator in SIMULATORS if args.simulator == "both" else (args.simulator,):
        rows = score(fmu, list(range(1, args.seeds + 1)), simulator)
        print(f"simulated by the {'link plant FMU' if simulator == 'plant' else 'beam modes'}:")
        for r in rows:
            print(f"  seed {r['seed']}: peak hub speed {r['peak_speed_rad_s']:.2f} rad/s, "
                  f"fit {r['seconds']:.1f} s")  # fmt: skip
        print(markdown(rows))
        every += rows
    if args.out:
        args.out.write_text(json.dumps(every, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
