"""Whole-chain rows on drives the project never tuned on (part of the accuracy benchmark).

Logs come from :mod:`benchmarks.simulators.field_sim`, a drive simulator written apart from the
project's plant; the chains are not the project's. Per row: a drive, an excitation and
what the user gives (k_t, J_m, the encoder's counts; the friction or not; a load torque
modelled or not); ``masses="auto"`` every time. Per seed (the seed changes the current
noise and the multi-sine's phases): the n chosen, the errors of every J_i, k_i, B_i
(and D_m, f_c, the load torque when fitted) and their standard errors, the wall and CPU
time of the identification.

Run: ``python -m benchmarks.field_accuracy [--seeds 20] [--first-seed 1] [--rows NAME ...]
[--out FILE.json]``
(prints the markdown table; ``--merge A.json B.json …`` tabulates runs made in parts);
``--speed`` times the identification instead (five-mass and
three-mass at 1 kHz, three-mass at 4 kHz, 20 s; five-mass 10 and 40 s for the growth
with record length).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from arcosim import IdentificationError, identify_drive
from arcosim.experiments import markdown_table
from arcosim.fmu.flexchain import G_DIST
from arcosim.identification import chain_from_modes, driving_point_modes
from benchmarks.simulators import field_sim

#: The motor of most rows: the paper bench's EC motor class (kg·m², N·m/A, N·m·s/rad, N·m).
J_M, K_T, D_M, F_C = 2.09e-5, 0.0406, 2e-5, 2e-3
#: Identification multi-sine of most rows: 40 log-spaced lines 3–150 rad/s, 3 A peak, 20 s.
LINES = np.geomspace(3.0, 150.0, 40)
AMPLITUDE = 3.0
DURATION = 20.0


def _modal_chain(p: Sequence[float], shares: Sequence[float]):
    """The chain with clamped modes ``p`` (rad/s) and residue shares r_i/p_i² (N·m/rad)."""
    p = np.asarray(p, dtype=float)
    J, k = chain_from_modes(p, p**2 * np.asarray(shares, dtype=float))
    return tuple(float(x) for x in J), tuple(float(x) for x in k)


def _damped(J: Sequence[float], k: Sequence[float], zeta: float) -> tuple[float, ...]:
    """Spring dampers proportional to the springs, ζ = ``zeta`` on the first clamped mode."""
    first = float(driving_point_modes(J, k)[0][0])
    return tuple(2.0 * zeta * float(x) / first for x in k)


@dataclass(frozen=True)
class Row:
    """One benchmark row.

    Attributes:
        name: row label.
        drive: the simulated drive (truth).
        h: sample step (s).
        g_dist: DOB bandwidth for the modal start (rad/s).
        lines: multi-sine lines (rad/s).
        amplitude: current peak (A), or speed reference peak (rad/s) with ``speed_loop``.
        speed_loop: PI gains (kp A·s/rad, ki A/rad) of a closed speed loop, or None.
        friction_given: the user gives D_m, f_c.
        load: the load model the user asks for; None: ``--load`` not given, the
            selection rule chooses it.
        note: one line for the table.
        mistake: a field mistake the user makes, or None: ``"time_ms"`` (the time
            column in ms), ``"k_t"`` / ``"J_m"`` (the datasheet value given 10 % high),
            ``"short"`` (a 3 s record), ``"i_a_scale"`` (the current logged in A but
            read with the README's ``--scale i_a=0.001``: 1000 × too small).
        expect: for a row with a mistake or an unmodelled effect, a regular expression
            the refusal or a warning must match (the cause named).
        J_load: a rigid drive's load inertia (kg·m²; the drive's J_m holds motor and
            load, the user gives the motor's ``J_m − J_load``).
    """

    name: str
    drive: field_sim.Drive
    h: float = 1e-3
    g_dist: float = G_DIST
    lines: np.ndarray = field(default_factory=lambda: LINES)
    amplitude: float = AMPLITUDE
    speed_loop: tuple[float, float] | None = None
    friction_given: bool = True
    load: str | None = None
    note: str = ""
    mistake: str | None = None
    expect: str | None = None
    J_load: float = 0.0

    def log(self, seed: int, duration: float = DURATION) -> field_sim.Log:
        """Simulate the row's record (``duration`` s) for ``seed``."""
        if self.speed_loop is None:
            current = field_sim.multisine(self.lines, self.amplitude, seed=seed)
            return field_sim.simulate(self.drive, self.h, duration, current=current, seed=seed)
        kp, ki = self.speed_loop
        # speed lines ∝ frequency: about equal torque per line, as an open-loop current
        reference = field_sim.multisine(self.lines, self.amplitude, seed=seed, slope=1.0)
        loop = field_sim.SpeedLoop(kp, ki, reference, limit=10.0)
        return field_sim.simulate(self.drive, self.h, duration, speed_loop=loop, seed=seed)


def _drive(J, k, zeta=0.002, **kw) -> field_sim.Drive:
    base = dict(J_m=J_M, k_t=K_T, D_m=D_M, f_c=F_C, current_noise=0.005, counts=2000)
    base.update(kw)
    return field_sim.Drive(J=tuple(J), k=tuple(k), B=_damped(J, k, zeta), **base)


#: Clamped modes 14.3 … 106.6 rad/s; residue shares r_i/p_i² sum to k_1 = 0.385 N·m/rad.
_FIVE = _modal_chain((14.3, 42.3, 70.0, 86.8, 106.6), (0.2, 0.1, 0.05, 0.03, 0.005))
_THREE = ((3e-4, 5e-4, 4e-4), (0.25, 0.4, 0.15))
_CLOSE = _modal_chain((20.0, 40.0, 42.0), (0.3, 0.1, 0.1))  # two modes 5 % apart
_BELT = ((6e-4, 3e-4), (20.0, 10.0))
#: A ball-screw axis: the table's inertia rigidly on the motor (kg·m²).
_SCREW = 6e-4

ROWS: dict[str, Row] = {
    r.name: r
    for r in (
        Row("five-mass, weak top mode", _drive(*_FIVE), note="modes 14.3–106.6, top share 0.5 %"),
        Row(
            "five-mass, friction fitted",
            _drive(*_FIVE),
            friction_given=False,
            note="only k_t, J_m given",
        ),
        Row("three-mass, 4 kHz", _drive(*_THREE), h=2.5e-4),
        Row("three-mass, 10 kHz", _drive(*_THREE), h=1e-4),
        Row(
            "closely spaced modes",
            _drive(*_CLOSE),
            note="clamped modes 20, 40, 42 rad/s",
        ),
        Row(
            "belt-like two-mass, 4 kHz, friction",
            _drive(
                *_BELT, J_m=1.2e-4, k_t=0.1, D_m=1e-4, f_c=0.01, current_noise=0.01, counts=2**14
            ),
            h=2.5e-4,
            g_dist=400.0,
            lines=np.geomspace(10.0, 600.0, 40),
            amplitude=6.0,
            note="J_m 1.2e-4, k 20/10, 16384 counts, lines 10–600",
        ),
        Row(
            "five-mass, PI speed loop",
            _drive(*_FIVE),
            amplitude=40.0,
            speed_loop=(0.3, 2.25),
            note="closed loop, speed lines ∝ frequency, 40 rad/s peak",
        ),
        Row(
            "three-mass, slow load torque",
            _drive(*_THREE, load_sine=(0.01, 0.3)),
            load="slow",
            note="0.01 N·m sine at 0.3 rad/s on the last mass",
        ),
        Row(
            "three-mass, PI loop, constant load",
            _drive(*_THREE, load_torque=0.01),
            amplitude=40.0,
            speed_loop=(0.3, 2.25),
            load="constant",
            note="0.01 N·m on the last mass, held by the speed loop",
        ),
        Row(
            "belt, 2^17 counts, Coulomb friction",
            _drive(
                *_BELT, J_m=1.2e-4, k_t=0.1, D_m=0.0, f_c=0.01, current_noise=0.01, counts=2**17
            ),
            h=2.5e-4,
            g_dist=400.0,
            lines=np.geomspace(10.0, 600.0, 40),
            amplitude=6.0,
            note="high-resolution encoder, Coulomb friction only (given), lines 10–600, 6 A",
        ),
        Row(
            "three-mass, slow load, no --load",
            _drive(*_THREE, load_sine=(0.01, 0.3)),
            expect="load torque",
            note="0.01 N·m sine at 0.3 rad/s on the last mass, --load not given: the rule "
            "must take it, fit it and say so",
        ),
        Row(
            "three-mass, viscous-only motor, friction fitted",
            _drive(*_THREE, f_c=0.0),
            friction_given=False,
            note="D_m 2e-5, f_c 0; only k_t, J_m given",
        ),
        Row(
            "three-mass, Coulomb-only motor, friction fitted",
            _drive(*_THREE, D_m=0.0),
            friction_given=False,
            note="D_m 0, f_c 2e-3; only k_t, J_m given",
        ),
        Row(
            "rigid drive (ball screw), friction fitted",
            field_sim.Drive(
                J_m=J_M + _SCREW,
                k_t=K_T,
                J=(),
                k=(),
                B=(),
                D_m=D_M,
                f_c=F_C,
                current_noise=0.005,
            ),
            friction_given=False,
            J_load=_SCREW,
            note="J_load 6e-4 rigid on the motor, no mode; only k_t, J_m given",
        ),
        Row(
            "mistake: time in ms",
            _drive(*_THREE),
            mistake="time_ms",
            expect=r"--scale time=0\.001",
            note="the log's time column in ms, no --scale",
        ),
        Row(
            "mistake: k_t +10 %",
            _drive(*_THREE),
            mistake="k_t",
            expect=r"noise floor.*check k_t and J_m",
            note="k_t given 10 % high; lines to 150 rad/s = 2.8 × the top mode 53",
        ),
        Row(
            "mistake: J_m +10 %",
            _drive(*_THREE),
            mistake="J_m",
            expect=r"noise floor.*check k_t and J_m",
            note="J_m given 10 % high; lines to 150 rad/s = 2.8 × the top mode 53",
        ),
        Row(
            "mistake: 3 s record",
            _drive(*_THREE),
            mistake="short",
            expect=r"the record lasts .* periods of its lowest mode",
            note="the README's excitation (40 lines 3–150 rad/s, 3 A), 3 s",
        ),
        Row(
            "mistake: current in A, --scale i_a=0.001",
            _drive(*_THREE),
            mistake="i_a_scale",
            expect=r"--scale i_a",
            note="the current logged in A, read as mA (the README's --scale left in)",
        ),
    )
}

#: The rows where a refusal or a warning must name the cause (``Row.expect``).
CAUSE_ROWS = tuple(name for name, row in ROWS.items() if row.expect)


def run_row(row: Row, seed: int, duration: float = DURATION) -> dict:
    """Identify one record of ``row``: errors (%) and standard errors (%) per parameter."""
    return score_log(row, row.log(seed, 3.0 if row.mistake == "short" else duration), seed)


def score_log(row: Row, log: field_sim.Log, seed: int) -> dict:
    """Identify ``log`` (a record of ``row``): errors (%) and standard errors (%) per
    parameter, the warnings, or the refusal (``error``)."""
    d = row.drive
    friction = {"D_m": d.D_m, "f_c": d.f_c} if row.friction_given else {}
    k_t, J_m = d.k_t * (1.1 if row.mistake == "k_t" else 1.0), d.J_m - row.J_load
    J_m *= 1.1 if row.mistake == "J_m" else 1.0
    times = log.time * (1e3 if row.mistake == "time_ms" else 1.0)
    current = log.i_a * (1e-3 if row.mistake == "i_a_scale" else 1.0)
    wall, cpu = time.perf_counter(), time.process_time()
    out: dict = {"seed": seed, "stuck_fraction": log.stuck_fraction}
    try:
        result = identify_drive(
            times,
            current,
            log.omega_m,
            log.theta_m,
            k_t=k_t,
            J_m=J_m,
            encoder_cpr=d.counts,
            load=row.load,
            g_dist=row.g_dist,
            **friction,
        )
    except IdentificationError as error:
        out.update(n=None, error=str(error))
        result = None
    out["seconds"] = time.perf_counter() - wall
    out["cpu_seconds"] = time.process_time() - cpu
    if row.expect:
        said = [out["error"]] if result is None else [*result.warnings, *result.verdict.reasons]
        out["cause_named"] = any(re.search(row.expect, text) for text in said)
        out["said"] = said
        out["extend_the_lines"] = any("extend the lines" in text for text in said)
    if result is None:
        return out
    choice = result.choice
    n = choice.n
    out["warnings"] = list(result.warnings)
    out["verdict"], out["reasons"] = result.verdict.word, list(result.verdict.reasons)
    out.update(n=n, modes=choice.fit.extra["modes_rad_s"], weak=choice.fit.extra["weak_modes"])
    if n != d.n:
        return out
    if n == 0:
        return _rigid_scores(out, result, row)
    fit = choice.fit
    J, k, B = (list(fit.values[i * n : (i + 1) * n]) for i in range(3))  # stacked J, k, B
    std = fit.std
    truth = {"J": d.J, "k": d.k, "B": d.B}
    for key, values, offset in (("J", J, 0), ("k", k, n), ("B", B, 2 * n)):
        out[key] = [100.0 * (v / t - 1.0) for v, t in zip(values, truth[key])]
        out[key + "_std"] = [100.0 * s / t for s, t in zip(std[offset : offset + n], truth[key])]
    values = fit.as_dict()
    stds = fit.std_dict()
    bounds = fit.extra.get("bounds", {})
    if not row.friction_given:
        for name, t in (("D_m", d.D_m), ("f_c", d.f_c)):
            out[name] = covered(name, values, stds, bounds, t)
    if "tau_load" in fit.names:  # given or chosen by the rule
        t = d.load_torque
        out["tau_load"] = {"value": values["tau_load"], "std": stds["tau_load"], "truth": t}
    return out


def covered(name: str, values: dict, stds: dict, bounds: dict[str, float], truth: float) -> dict:
    """A fitted term against ``truth``: its value and σ, or the bound reported for it
    (at its bound, or left out by the friction form); ``covered``: within 2σ, or the
    truth inside [0, bound] (a bound counts as covering the truth that lies within it).

    Examples
    --------
    >>> covered("D_m", {"D_m": 1e-14}, {"D_m": 0.0}, {"D_m": 3e-5}, 2e-5)["covered"]
    True
    >>> covered("D_m", {"D_m": 1.0}, {"D_m": 0.1}, {}, 1.3)["covered"]
    False
    """
    if name in bounds:
        return {"bound": bounds[name], "truth": truth, "covered": bool(truth <= bounds[name])}
    if name not in values:  # neither fitted nor bounded: nothing reported covers it
        return {"truth": truth, "covered": False}
    value, sigma = values[name], stds[name]
    inside = abs(value - truth) <= 2.0 * sigma
    return {"value": value, "std": sigma, "truth": truth, "covered": bool(inside)}


def _rigid_scores(out: dict, result, row: Row) -> dict:
    """A rigid drive's numbers: J_load's error (%), and D_m, f_c against their σ or
    their bound."""
    values, std = result.parameters, result.std
    bounds = result.report().get("bounds", {})
    truth = row.J_load
    out["J_load_error_percent"] = 100.0 * (values["J_load"] / truth - 1.0)
    out["J_load_std_percent"] = 100.0 * std["J_load"] / truth
    for name, t in (("D_m", row.drive.D_m), ("f_c", row.drive.f_c)):
        out[name] = covered(name, values, std, bounds, t)
        out[name + "_covered"] = out[name]["covered"]
    return out


def summary(results: list[dict], row: Row) -> dict:
    """Counts over seeds: trusted (and each untrusted seed's reasons), n right, largest
    |J_i|, |k_i| error, B_i (and J_i, k_i) within 2σ."""
    right = [r for r in results if r.get("n") == row.drive.n]

    def inside(key: str) -> tuple[int, int]:
        hits = sum(abs(e) <= 2 * s for r in right for e, s in zip(r[key], r[key + "_std"]))
        return int(hits), len(right) * row.drive.n

    def worst(key: str) -> float:
        return max((abs(e) for r in right for e in r.get(key, ())), default=float("nan"))

    trusted = sum(r.get("verdict") == "trusted" for r in results)
    untrusted = {str(r["seed"]): r["reasons"] for r in results if r.get("verdict") == "untrusted"}
    if row.expect:
        return {
            "seeds": len(results),
            "trusted": trusted,
            "untrusted_reasons": untrusted,
            "cause_named": sum(bool(r.get("cause_named")) for r in results),
            "refused": sum("error" in r for r in results),
            "extend_the_lines": sum(bool(r.get("extend_the_lines")) for r in results),
            "n_right": len(right),
            "JkB_inside_2_sigma": [sum(x) for x in zip(*(inside(key) for key in "JkB"))],
            "B_inside_2_sigma": inside("B"),
            "max_abs_J_error_percent": worst("J"),
            "max_abs_k_error_percent": worst("k"),
            "n_chosen": [r.get("n") for r in results],
            "seconds_median": float(np.median([r["seconds"] for r in results])),
        }
    if row.drive.n == 0:
        errors = [abs(r["J_load_error_percent"]) for r in right]
        return {
            "seeds": len(results),
            "trusted": trusted,
            "untrusted_reasons": untrusted,
            "n_right": len(right),
            "n_chosen": [r.get("n") for r in results],
            "max_abs_J_load_error_percent": max(errors, default=float("nan")),
            "D_m_covered": sum(bool(r.get("D_m_covered")) for r in right),
            "f_c_covered": sum(bool(r.get("f_c_covered")) for r in right),
            "seconds_median": float(np.median([r["seconds"] for r in results])),
        }

    return {
        "seeds": len(results),
        "trusted": trusted,
        "untrusted_reasons": untrusted,
        "n_right": len(right),
        "n_chosen": [r.get("n") for r in results],
        "max_abs_J_error_percent": worst("J"),
        "max_abs_k_error_percent": worst("k"),
        "B_inside_2_sigma": inside("B"),
        "friction_covered": friction_covered(right),
        "J_inside_2_sigma": inside("J"),
        "k_inside_2_sigma": inside("k"),
        "J_k_z": z_scores(right, row.drive.n),
        "median_abs_B_error_percent": float(np.median([abs(e) for r in right for e in r["B"]]))
        if right
        else float("nan"),
        "seconds_median": float(np.median([r["seconds"] for r in results])),
        "seconds_max": float(np.max([r["seconds"] for r in results])),
        "cpu_seconds_median": float(np.median([r["cpu_seconds"] for r in results])),
        "stuck_fraction_median": float(np.median([r["stuck_fraction"] for r in results])),
    }


def z_scores(right: list[dict], n: int) -> dict[str, dict[str, float]]:
    """Per J_i, k_i over the seeds ``right``: the mean and standard deviation of its
    z-score (error / σ, dimensionless). With honest σ they are 0 and 1; a mean away from
    0 is a bias the σ leave out, a spread above 1 a σ too small.

    Examples
    --------
    >>> runs = [{"J": [0.1], "J_std": [0.1], "k": [-0.2], "k_std": [0.1]},
    ...         {"J": [0.3], "J_std": [0.1], "k": [0.0], "k_std": [0.1]}]
    >>> z_scores(runs, 1)["J[1]"]
    {'mean': 2.0, 'sd': 1.414}
    """
    out = {}
    for key in "Jk":
        for i in range(n):
            z = [r[key][i] / r[key + "_std"][i] for r in right if r[key + "_std"][i] > 0]
            mean = float(np.mean(z)) if z else float("nan")
            sd = float(np.std(z, ddof=1)) if len(z) > 1 else float("nan")
            out[f"{key}[{i + 1}]"] = {"mean": round(mean, 3), "sd": round(sd, 3)}
    return out


def friction_covered(right: list[dict]) -> tuple[int, int]:
    """D_m and f_c fitted (not given) over the seeds ``right``: how many within 2σ or
    inside their reported bound (:func:`covered`), of how many."""
    marks = [r[name]["covered"] for r in right for name in ("D_m", "f_c") if name in r]
    return int(sum(marks)), len(marks)


def markdown(summaries: dict[str, dict]) -> str:
    """The table."""
    header = [
        "row",
        "trusted",
        "n right",
        "max abs J_i err %",
        "max abs k_i err %",
        "B_i within 2σ",
        "D_m, f_c within 2σ or bound",
        "J_i, k_i within 2σ",
        "B_i err % (median abs)",
        "s wall (median / max)",
        "s CPU (median)",
    ]
    rows = []
    for name, s in summaries.items():
        if "J_inside_2_sigma" not in s:
            continue  # a cause row or the rigid drive: their own table
        b, j, k = s["B_inside_2_sigma"], s["J_inside_2_sigma"], s["k_inside_2_sigma"]
        f = s.get("friction_covered", (0, 0))
        rows.append(
            [
                name,
                f"{s['trusted']} of {s['seeds']}",
                f"{s['n_right']} of {s['seeds']}",
                f"{s['max_abs_J_error_percent']:.2f}",
                f"{s['max_abs_k_error_percent']:.2f}",
                f"{b[0]} of {b[1]}",
                f"{f[0]} of {f[1]}" if f[1] else "given",
                f"{j[0] + k[0]} of {j[1] + k[1]}",
                f"{s['median_abs_B_error_percent']:.1f}",
                f"{s['seconds_median']:.1f} / {s['seconds_max']:.1f}",
                f"{s['cpu_seconds_median']:.1f}",
            ]
        )
    out = markdown_table(header, rows) + "\n"
    other = [_other_line(name, s) for name, s in summaries.items() if "J_inside_2_sigma" not in s]
    return out + ("\n" + "\n".join(other) + "\n" if other else "")


def _other_line(name: str, s: dict) -> str:
    """One line for a row scored on its cause named, or the rigid drive."""
    if "cause_named" in s:
        return (
            f"- {name}: cause named on {s['cause_named']} of {s['seeds']}, trusted on "
            f"{s['trusted']} (refused "
            f"{s['refused']}, 'extend the lines' {s['extend_the_lines']}, n {s['n_chosen']}; "
            f"J_i, k_i, B_i within 2σ {s['JkB_inside_2_sigma'][0]} of "
            f"{s['JkB_inside_2_sigma'][1]}, B_i {s['B_inside_2_sigma'][0]} of "
            f"{s['B_inside_2_sigma'][1]}; max |J_i|, |k_i| err "
            f"{s['max_abs_J_error_percent']:.2f}, {s['max_abs_k_error_percent']:.2f} %)"
        )
    return (
        f"- {name}: n = 0 on {s['n_right']} of {s['seeds']}, trusted on {s['trusted']}, "
        f"max |J_load err| "
        f"{s['max_abs_J_load_error_percent']:.2f} %, D_m covered {s['D_m_covered']}, "
        f"f_c covered {s['f_c_covered']} of {s['n_right']}"
    )


#: Speed rows: (label, row, record length s).
SPEED = (
    ("five-mass, 1 kHz, 20 s", "five-mass, weak top mode", 20.0),
    ("three-mass, 1 kHz, 20 s", "three-mass, slow load torque", 20.0),
    ("three-mass, 4 kHz, 20 s", "three-mass, 4 kHz", 20.0),
    ("five-mass, 1 kHz, 10 s", "five-mass, weak top mode", 10.0),
    ("five-mass, 1 kHz, 40 s", "five-mass, weak top mode", 40.0),
)


def speed(repeats: int = 3, quick: bool = False) -> list[dict]:
    """Wall and CPU seconds of the identification (log → result, simulation excluded),
    median of ``repeats``; the three-mass 1 kHz row without its load (``quick``:
    that row only)."""
    out = []
    for label, name, seconds in SPEED[1:2] if quick else SPEED:
        row = ROWS[name]
        if row.load is not None:
            row = replace(row, load=None, drive=replace(row.drive, load_sine=(0.0, 0.0)))
        runs = [run_row(row, seed, seconds) for seed in range(1, repeats + 1)]
        out.append(
            {
                "what": label,
                "n_right": sum(r.get("n") == row.drive.n for r in runs),
                "runs": repeats,
                "seconds": float(np.median([r["seconds"] for r in runs])),
                "cpu_seconds": float(np.median([r["cpu_seconds"] for r in runs])),
                "load_average": os.getloadavg()[0],
            }
        )
    return out


def speed_markdown(rows: list[dict]) -> str:
    """The speed table."""
    header = ["what", "n right", "s wall (median)", "s CPU", "load average"]
    cells = [
        [
            r["what"],
            f"{r['n_right']} of {r['runs']}",
            f"{r['seconds']:.2f}",
            f"{r['cpu_seconds']:.2f}",
            f"{r['load_average']:.1f}",
        ]
        for r in rows
    ]
    return markdown_table(header, cells) + "\n"


def score_rows(
    names: Sequence[str], seeds: Sequence[int], progress: Callable[[str], None] = print
) -> tuple[dict[str, dict], dict[str, list[dict]]]:
    """Every row of ``names`` over ``seeds``: the summaries, and every run's numbers."""
    results: dict[str, list[dict]] = {}
    summaries: dict[str, dict] = {}
    for name in names:
        row = ROWS[name]
        results[name] = []
        for seed in seeds:
            r = run_row(row, seed)
            results[name].append(r)
            progress(f"{name}, seed {seed}: n = {r.get('n')}, {r['seconds']:.1f} s")
            progress("  " + json.dumps(r, default=float))  # every run's numbers, as they come
        summaries[name] = summary(results[name], row)
    return summaries, results


def pooled_runs(paths: Sequence[Path]) -> dict[str, list[dict]]:
    """The per-seed runs of several runs' JSON files (``--out`` of runs over other seeds
    or rows), pooled per row name, in the files' order."""
    runs: dict[str, list[dict]] = {}
    for path in paths:
        for name, rows in json.loads(path.read_text())["runs"].items():
            runs.setdefault(name, []).extend(rows)
    return runs


def merged(paths: Sequence[Path]) -> dict[str, dict]:
    """The summaries of several runs' JSON files (:func:`pooled_runs`), in the order of
    :data:`ROWS`."""
    runs = pooled_runs(paths)
    return {name: summary(runs[name], row) for name, row in ROWS.items() if name in runs}


def main(argv: Sequence[str] | None = None, progress: Callable[[str], None] = print) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--rows", nargs="*", default=list(ROWS))
    parser.add_argument("--out", type=Path)
    parser.add_argument("--speed", action="store_true", help="time the speed rows instead")
    parser.add_argument("--merge", type=Path, nargs="*", help="only tabulate these --out files")
    args = parser.parse_args(argv)
    if args.speed:
        print(speed_markdown(speed()))
        return 0
    if args.merge:
        print(markdown(merged(args.merge)))
        return 0
    summaries, results = score_rows(
        args.rows, range(args.first_seed, args.first_seed + args.seeds), progress
    )
    if args.out:
        args.out.write_text(json.dumps({"summary": summaries, "runs": results}, indent=1))
    print(markdown(summaries))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
