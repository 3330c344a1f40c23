"""Sweep specifications: reading, checking and drawing the runs.

The format (TOML)::

    name = "noise-encoder-gdist"
    scenario = "rigid"          # any scenario of `arcosim simulate`
    masses = 3
    runs = 200                  # random draws (a grid's size comes from the grid)
    seed = 42
    metrics = ["k_error", "B_error", "runtime"]
    duration = 12.0             # optional: shorten the scenario (s)

    [fixed]
    "observer.D_m" = 2e-5

    [vary]
    "plant.i_noise_std" = { distribution = "uniform", low = 0.0, high = 0.02 }
    "plant.encoder_cpr" = { distribution = "choice", values = [500, 2000, 8192] }
    "observer.g_dist" = { distribution = "loguniform", low = 50.0, high = 400.0 }
    "plant.seed" = { distribution = "randint", low = 1, high = 1000000 }

Distributions: ``uniform``, ``loguniform`` (low, high), ``normal`` (mean, std),
``randint`` (low, high, high excluded), ``choice`` (values), ``grid`` (values; all
varied parameters must then be grids, and the runs are their product). Every run's
values are drawn up front from ``seed``, so a spec gives the same runs every time.

Metrics: ``k_error``, ``B_error`` (mode 1, % against the plant's k[1], B[1]),
``D_m_error``, ``f_c_error`` (mode 0, %), ``theta_error`` (mode 2, METHOD.md's score
per mass), ``runtime`` (s per run).
"""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from arcosim.build.recipes import check_masses
from arcosim.errors import UserError
from arcosim.host.overrides import check_name, typed_value

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

KEYS = {
    "name",
    "scenario",
    "masses",
    "runs",
    "seed",
    "metrics",
    "fixed",
    "vary",
    "duration",
    "step",
    "ideal",
}
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "loguniform": ("low", "high"),
    "normal": ("mean", "std"),
    "randint": ("low", "high"),
    "choice": ("values",),
    "grid": ("values",),
}
METRICS = ("k_error", "B_error", "D_m_error", "f_c_error", "theta_error", "runtime")


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep specification (see module doc)."""

    name: str
    scenario: str
    masses: int
    runs: int
    seed: int
    metrics: tuple[str, ...]
    fixed: dict[str, object] = field(default_factory=dict)
    vary: dict[str, dict] = field(default_factory=dict)
    duration: float | None = None
    step: float = 1e-3
    ideal: bool = False


def load_spec(path: Path) -> SweepSpec:
    """Read and check a spec; every mistake is a :class:`UserError` naming it."""
    from arcosim.experiments.scenarios import SCENARIOS

    path = Path(path)
    if not path.is_file():
        raise UserError(f"{path}: no such file")
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as error:
        raise UserError(f"{path}: not valid TOML ({error})") from None
    unknown = set(raw) - KEYS
    if unknown:
        raise UserError(
            f"{path}: unknown key {', '.join(sorted(unknown))} (known: {', '.join(sorted(KEYS))})"
        )
    scenario = raw.get("scenario", "rigid")
    if scenario not in SCENARIOS:
        raise UserError(f"{path}: scenario {scenario!r} is not one of {', '.join(SCENARIOS)}")
    metrics = tuple(raw.get("metrics", ["k_error", "B_error", "runtime"]))
    for metric in metrics:
        if metric not in METRICS:
            raise UserError(f"{path}: metric {metric!r} is not one of {', '.join(METRICS)}")
    vary = raw.get("vary", {})
    for name, dist in vary.items():
        _check_distribution(path, name, dist)
    grids = [n for n, d in vary.items() if d["distribution"] == "grid"]
    if grids and len(grids) != len(vary):
        raise UserError(
            f"{path}: a grid cannot be mixed with random distributions "
            f"({', '.join(grids)} are grids)"
        )
    runs = int(raw.get("runs", 0 if grids else 1))
    if not grids and runs < 1:
        raise UserError(f"{path}: runs = {runs}: at least one run")
    for name in [*vary, *raw.get("fixed", {})]:
        if name.split(".", 1)[0] not in ("plant", "observer") or "." not in name:
            raise UserError(f"{path}: {name!r}: name the FMU first (plant.NAME or observer.NAME)")
    duration = raw.get("duration")
    if duration is not None and not duration > 0:
        raise UserError(f"{path}: duration = {duration}: it must be > 0 s")
    return SweepSpec(
        name=str(raw.get("name", path.stem)),
        scenario=scenario,
        masses=check_masses(int(raw.get("masses", 3))),
        runs=runs,
        seed=int(raw.get("seed", 0)),
        metrics=metrics,
        fixed=dict(raw.get("fixed", {})),
        vary=dict(vary),
        duration=duration,
        step=float(raw.get("step", 1e-3)),
        ideal=bool(raw.get("ideal", False)),
    )


def _check_distribution(path: Path, name: str, dist: object) -> None:
    if not isinstance(dist, dict) or "distribution" not in dist:
        raise UserError(f'{path}: {name}: write {{ distribution = "uniform", low = …, high = … }}')
    kind = dist["distribution"]
    if kind not in DISTRIBUTIONS:
        raise UserError(
            f"{path}: {name}: unknown distribution {kind!r} (use {', '.join(DISTRIBUTIONS)})"
        )
    missing = [k for k in DISTRIBUTIONS[kind] if k not in dist]
    if missing:
        raise UserError(f"{path}: {name}: a {kind} distribution needs {', '.join(missing)}")
    if kind in ("choice", "grid") and (not isinstance(dist["values"], list) or not dist["values"]):
        raise UserError(f"{path}: {name}: values must be a non-empty list")
    if kind in ("uniform", "loguniform", "randint") and not dist["low"] < dist["high"]:
        raise UserError(f"{path}: {name}: low = {dist['low']} must be below high = {dist['high']}")
    if kind == "loguniform" and not dist["low"] > 0:
        raise UserError(f"{path}: {name}: a loguniform distribution needs low > 0")
    if kind == "normal" and not dist["std"] > 0:
        raise UserError(f"{path}: {name}: std = {dist['std']} must be > 0")


def check_names(spec: SweepSpec, variables: Mapping[str, Mapping[str, object]]) -> None:
    """Refuse parameter names the FMUs do not have, and values of the wrong type."""
    for qualified, value in [*spec.fixed.items(), *((n, None) for n in spec.vary)]:
        fmu, name = qualified.split(".", 1)
        check_name(name, variables[fmu], fmu)
        var = variables[fmu][name]
        if var.causality != "parameter":
            raise UserError(f"{qualified} is an {var.causality}, not a parameter")
        if value is not None:
            typed_value(qualified, str(value), var.type)


def draw_runs(spec: SweepSpec) -> list[dict[str, object]]:
    """Every run's varied values, drawn from ``spec.seed`` (the same every time)."""
    names = list(spec.vary)
    if names and all(spec.vary[n]["distribution"] == "grid" for n in names):
        combos = itertools.product(*(spec.vary[n]["values"] for n in names))
        return [dict(zip(names, c)) for c in combos]
    rng = np.random.default_rng(spec.seed)
    runs = []
    for _ in range(spec.runs):
        values = {}
        for name in names:
            d = spec.vary[name]
            kind = d["distribution"]
            if kind == "uniform":
                values[name] = float(rng.uniform(d["low"], d["high"]))
            elif kind == "loguniform":
                values[name] = float(math.exp(rng.uniform(math.log(d["low"]), math.log(d["high"]))))
            elif kind == "normal":
                values[name] = float(rng.normal(d["mean"], d["std"]))
            elif kind == "randint":
                values[name] = int(rng.integers(d["low"], d["high"]))
            else:
                values[name] = d["values"][int(rng.integers(len(d["values"])))]
        runs.append(values)
    return runs


def metric_columns(spec: SweepSpec) -> list[str]:
    """Result columns of the requested metrics (theta_error gives one per mass)."""
    columns = []
    for metric in spec.metrics:
        if metric == "theta_error":
            columns += [f"theta_error[{i}]" for i in range(1, spec.masses + 1)]
        else:
            columns.append(metric)
    return columns
