"""Flexible-link rows of the accuracy benchmark: EI, ρA, the modes and the tip from the hub.

Three links of our own (no tip mass; a heavy tip mass with tip inertia and a hub radius;
a stiff link with a light tip mass), 2–4 clamped modes below the record's band. Each log
comes from :mod:`benchmarks.simulators.field_sim` (the drive simulator written apart from the
plant: Coulomb friction with sticking, the current's noise, the encoder's counts) with
the link as its modes on their own springs to the hub (``star=True``; 8 modes, more than
the fit's, the rest rigid), driven by a 20 s multi-sine of log-spaced lines across the
modes. Only k_t, J_m, the encoder's counts, L, m_tip (J_tip, r_hub) and the friction
are given; the fit (:func:`arcosim.identification.link.beam_fit.fit_link`) finds EI, ρA and
the damping. Per link, over the seeds: the largest |error| of the first two clamped
modes, of EI and ρA, and rms(α̂ − α)/rms(α) of the tip angle after the first second
(:func:`arcosim.identification.link.beam_motion.tip_motion`).

With ``--one-mode`` (:func:`score_one_mode`): each link's log holds only its first
clamped mode in the band (40 lines from 2 rad/s to 0.7 × the second mode, the band at
0.8 × it), and the fit is given ρA: EI from that one mode.

Run: ``python -m benchmarks.beam_accuracy [--seeds 20] [--one-mode] [--out FILE.json]``
(prints the markdown table), or ``arcosim bench accuracy --beam-only``.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from arcosim import Actuator, encoder_record, motor_record
from arcosim.experiments import markdown_table
from arcosim.identification import (
    Geometry,
    Link,
    ModalModel,
    fit_link,
    modal_model,
    modal_of,
    single_threaded,
    tip_motion,
)
from benchmarks.simulators import field_sim

#: The motor (kg·m², N·m/A, N·m·s/rad, N·m) and the sensors: field_sim's rows'.
J_M, K_T, D_M, F_C = 2.09e-5, 0.0406, 2e-5, 2e-3
CPR = 2000
CURRENT_NOISE = 0.005
H = 1e-3
G_DIST = 100.0
DURATION = 20.0
#: Modes the simulated link has (the rest of it rigid on the hub).
TRUE_MODES = 5
#: Modal damping ratio of the simulated links (dimensionless).
ZETA = 0.005


@dataclass(frozen=True)
class BeamCase:
    """One link, its excitation, and the truth.

    Attributes:
        name: row label.
        link: the simulated link.
        lines: multi-sine lines (rad/s).
        amplitude: current peak (A).
        slope: line j's amplitude ∝ lines_j^slope (:func:`field_sim.multisine`): more
            current at the higher modes, less speed at the lowest lines.
    """

    name: str
    link: Link
    lines: np.ndarray = field(default_factory=lambda: np.geomspace(2.0, 280.0, 50))
    amplitude: float = 1.0
    slope: float = 0.0

    @property
    def geometry(self) -> Geometry:
        return Geometry(self.link.L, self.link.m_tip, self.link.J_tip, self.link.r_hub)

    def modes(self, count: int = TRUE_MODES) -> ModalModel:
        """The link's true modes, damped by :data:`ZETA`."""
        return modal_model(self.link, count).with_damping(ZETA)


LINKS = (
    BeamCase("no tip mass, 3 modes in band", Link(EI=2.95e-3, rhoA=0.02, L=0.3)),
    BeamCase(
        "heavy tip mass, tip inertia, hub radius",
        Link(EI=0.02, rhoA=0.03, L=0.4, m_tip=0.02, J_tip=2e-6, r_hub=0.02),
    ),
    BeamCase(
        "stiff, light tip mass, 2 modes",
        Link(EI=0.04, rhoA=0.05, L=0.25, m_tip=0.005),
        amplitude=2.0,
    ),
)


@dataclass(frozen=True)
class BeamLog:
    """A simulated log and its truth: the drive's columns, the tip angle (rad) and the
    reaction torque (N·m) over time."""

    columns: dict[str, np.ndarray]
    alpha_tip: np.ndarray
    w_tip: np.ndarray


@single_threaded
def simulate(case: BeamCase, seed: int, duration: float = DURATION) -> BeamLog:
    """The log of ``case`` for ``seed`` (current noise and the multi-sine's phases)."""
    model = case.modes()
    J, k, B = model.star()
    drive = field_sim.Drive(
        J_m=J_M + model.J_rest,
        k_t=K_T,
        J=tuple(J),
        k=tuple(k),
        B=tuple(B),
        D_m=D_M,
        f_c=F_C,
        current_noise=CURRENT_NOISE,
        counts=CPR,
        star=True,
    )
    current = field_sim.multisine(case.lines, case.amplitude, seed=seed, slope=case.slope)
    log = field_sim.simulate(drive, H, duration, current=current, seed=seed)
    q = model.participation * (log.theta_true[:, 1:] - log.theta_true[:, :1])
    w_tip = q @ model.tip
    columns = {"time": log.time, "i_a": log.i_a, "omega_m": log.omega_m, "theta_m": log.theta_m}
    return BeamLog(columns, w_tip / case.link.L, w_tip)


#: Where the one-mode records put their band and their top line, as fractions of the
#: link's second clamped mode (dimensionless): the band holds the first mode only.
ONE_MODE_BAND, ONE_MODE_TOP = 0.8, 0.7


def one_mode(case: BeamCase) -> tuple[BeamCase, float]:
    """``case`` with only its first clamped mode in the record's band, and the g_dist
    (rad/s) that puts the band there.

    The multi-sine's 40 lines run from 2 rad/s to :data:`ONE_MODE_TOP` × the second
    clamped mode; g_dist puts the band (3·g_dist) at :data:`ONE_MODE_BAND` × it.

    Parameters
    ----------
    case : BeamCase
        A link of :data:`LINKS`.

    Returns
    -------
    tuple of (BeamCase, float)
        The band-limited case and g_dist (rad/s).

    Examples
    --------
    >>> case, g_dist = one_mode(LINKS[0])
    >>> round(float(case.lines[-1]), 1), round(g_dist, 1)
    (65.8, 25.1)
    """
    second = float(case.modes(2).frequency[1])
    lines = np.geomspace(2.0, ONE_MODE_TOP * second, 40)
    name = ", ".join(part for part in case.name.split(", ") if "mode" not in part)
    return replace(case, name=name + ", one mode in band", lines=lines), (
        ONE_MODE_BAND * second / 3.0
    )


def actuator(friction: bool = True) -> Actuator:
    """The motor as the user gives it (with or without its friction)."""
    return Actuator(J_M, K_T, 0.0, 0.0, D_M if friction else 0.0, F_C if friction else 0.0)


def score(
    case: BeamCase,
    seeds: Sequence[int],
    progress: Callable[[str], None],
    g_dist: float = G_DIST,
    rhoA_given: bool = False,
) -> dict:
    """Fit ``case`` on each seed's log (JSON-able summary); ``g_dist`` (rad/s) sets the
    band, ``rhoA_given`` gives the fit the link's true ρA (its ρA error is then 0)."""
    truth = case.modes(2).frequency
    rows: dict[str, list] = {
        k: [] for k in ("mode_error_percent", "EI_error_percent", "rhoA_error_percent")
    }
    rows.update(alpha_ratio=[], seconds=[], modes_fitted=[], EI_std_percent=[])
    for seed in seeds:
        progress(f"flexible link, {case.name}: seed {seed}")
        log = simulate(case, seed)
        c = log.columns
        motor = motor_record(c["time"], c["i_a"], c["omega_m"], c["theta_m"], actuator(), g_dist)
        encoder = encoder_record(
            c["time"], c["i_a"], c["theta_m"], actuator(), CPR, True, "none", g_dist
        )
        started = time.perf_counter()
        rhoA = case.link.rhoA if rhoA_given else None
        result = fit_link(encoder, motor, case.geometry, rhoA=rhoA)
        fitted = modal_of(result, case.geometry)
        tip = tip_motion(encoder, fitted, D_M, F_C)
        rows["seconds"].append(time.perf_counter() - started)
        values, std = result.as_dict(), result.std_dict()
        modes = modal_of(result, case.geometry, 2).frequency
        rows["mode_error_percent"].append([float(100 * (a / b - 1)) for a, b in zip(modes, truth)])
        rows["EI_error_percent"].append(float(100 * (values["EI"] / case.link.EI - 1)))
        rhoA = values.get("rhoA", result.extra["rhoA_given"])
        rows["rhoA_error_percent"].append(float(100 * (rhoA / case.link.rhoA - 1)))
        rows["EI_std_percent"].append(float(100 * std["EI"] / values["EI"]))
        rows["modes_fitted"].append(len(fitted.frequency))
        after = c["time"] >= 1.0
        error = tip.alpha_tip[after] - log.alpha_tip[after]
        rows["alpha_ratio"].append(_rms(error) / _rms(log.alpha_tip[after]))
    return {"seeds": len(seeds), "true_modes_rad_s": case.modes(4).frequency.tolist(), **rows}


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def markdown(rows: dict[str, dict]) -> str:
    """The flexible-link table."""
    header = [
        "link",
        "clamped modes (rad/s)",
        "modes fitted",
        "max abs mode 1, 2 error %",
        "max abs EI error %",
        "max abs ρA error %",
        "max rms(α̂−α)/rms(α)",
        "seconds (median / max)",
    ]
    cells = []
    for name, r in rows.items():
        modes = np.abs(np.array(r["mode_error_percent"]))
        cells.append(
            [
                name,
                ", ".join(f"{w:.1f}" for w in r["true_modes_rad_s"]),
                "/".join(str(n) for n in sorted(set(r["modes_fitted"]))),
                f"{modes[:, 0].max():.3f}, {modes[:, 1].max():.3f}",
                f"{np.max(np.abs(r['EI_error_percent'])):.2f}",
                f"{np.max(np.abs(r['rhoA_error_percent'])):.2f}",
                f"{np.max(r['alpha_ratio']):.3f}",
                f"{np.median(r['seconds']):.1f} / {np.max(r['seconds']):.1f}",
            ]
        )
    return markdown_table(header, cells) + "\n"


def score_links(seeds: Sequence[int], progress: Callable[[str], None]) -> dict[str, dict]:
    """Every link of :data:`LINKS` over ``seeds``."""
    return {case.name: score(case, seeds, progress) for case in LINKS}


def score_one_mode(seeds: Sequence[int], progress: Callable[[str], None]) -> dict[str, dict]:
    """Every link of :data:`LINKS` with only its first clamped mode in the band
    (:func:`one_mode`) and ρA given, over ``seeds``: EI from that mode."""
    rows = {}
    for case in LINKS:
        limited, g_dist = one_mode(case)
        rows[limited.name] = score(limited, seeds, progress, g_dist, rhoA_given=True)
    return rows


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m benchmarks.beam_accuracy``: print the table, optionally write JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--out", type=Path)
    parser.add_argument(
        "--one-mode",
        action="store_true",
        help="only the first clamped mode in the band, ρA given: EI from that mode",
    )
    args = parser.parse_args(argv)
    scorer = score_one_mode if args.one_mode else score_links
    rows = scorer(list(range(1, args.seeds + 1)), lambda text: print(f"  … {text}"))
    print(markdown(rows))
    if args.out:
        args.out.write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
