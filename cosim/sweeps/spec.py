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
``D_m_error``, ``f_c_error`` (mode 0, %), ``theta_error`` (mode 2, docs/method.md's score
per mass), ``runtime`` (s per run).
"""

from __future__ import annotations

import itertools
import math
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from arcosim.build.recipes import MAX_MASSES, MIN_MASSES
from arcosim.errors import UserError
from arcosim.host.master import MAX_STEPS, MAX_TIME, MIN_STEP
from arcosim.host.overrides import check_name, typed_value
from arcosim.sweeps.toml_values import (
    check_scalar,
    integer_value,
    one_line,
    real_value,
    shown,
    shown_key,
    table_value,
    text_value,
)

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
#: Most runs one sweep may ask for.
MAX_RUNS = 1_000_000
#: A sweep's name: it names the folder ``sweeps/<name>``, so one plain folder name.
NAME = re.compile(r"[A-Za-z0-9._-]{1,100}")


@dataclass(frozen=True)
class SweepSpec:
    """A checked sweep specification (the format in the module's docstring).

    Parameters
    ----------
    name : str
        The sweep's name, a plain folder name (``sweeps/<name>``).
    scenario : str
        A scenario of :data:`arcosim.SCENARIOS`.
    masses : int
        Number of load masses (a count).
    runs : int
        Number of runs (a count): the draws, or a grid's size.
    seed : int
        Seed every run's values are drawn from (an index).
    metrics : tuple of str
        Metrics of :data:`METRICS`, each once.
    fixed : dict of str to object
        ``"fmu.name"`` → the value every run takes (in the variable's unit).
    vary : dict of str to dict
        ``"fmu.name"`` → its distribution (``{"distribution": "uniform", "low": …,
        "high": …}``), in the variable's unit.
    duration : float or None
        Length of each run (s); None: the scenario's.
    step : float
        Communication step (s).
    ideal : bool
        Whether the sensors are ideal.
    """

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
    """Read and check a spec; every mistake is a :class:`UserError` naming it.

    Every field is checked for its type and range: whole numbers are TOML integers
    (``runs = 2.5`` and ``runs = "ten"`` are refused), numbers are finite, the name is
    a plain folder name (it names ``sweeps/<name>``: no ``/``, no ``..``), and a spec
    asks for 1 to :data:`MAX_RUNS` runs of 1 to :data:`MAX_STEPS` steps each.

    Parameters
    ----------
    path : Path
        The TOML file (format in the module's docstring).

    Returns
    -------
    SweepSpec
        The checked specification, defaults filled in.

    Raises
    ------
    UserError
        The first mistake found, naming the file and the key; an empty spec (no key at
        all) too.

    Examples
    --------
    >>> import tempfile
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = Path(folder.name) / "gains.toml"
    >>> _ = path.write_text('''scenario = "rigid"
    ... duration = 0.5
    ... [vary]
    ... "observer.g_dist" = { distribution = "grid", values = [100.0, 200.0] }
    ... ''', encoding="utf-8")
    >>> spec = load_spec(path)
    >>> spec.name, spec.scenario, spec.masses, spec.runs, spec.metrics
    ('gains', 'rigid', 3, 2, ('k_error', 'B_error', 'runtime'))
    >>> folder.cleanup()
    """
    from arcosim.experiments.scenarios import SCENARIOS

    path = Path(path)
    raw = _read_toml(path)
    where = f"{path}:"
    if not raw:  # the defaults alone would run a sweep nobody asked for
        raise UserError(
            f"{where} the spec is empty; write at least its scenario, runs and a [vary] "
            "table (the format: the docs' Sweeps page)"
        )
    _check_keys(where, raw)
    name = _name(where, raw.get("name", path.stem))
    scenario = text_value(where, "scenario", raw.get("scenario", "rigid"))
    if scenario not in SCENARIOS:
        raise UserError(f"{where} scenario {shown(scenario)} is not one of {', '.join(SCENARIOS)}")
    metrics = _metrics(where, raw.get("metrics", ["k_error", "B_error", "runtime"]))
    fixed, vary = _parameters(path, raw)
    runs = _runs(where, raw, vary)
    masses = integer_value(where, "masses", raw.get("masses", 3), MIN_MASSES, MAX_MASSES)
    seed = integer_value(where, "seed", raw.get("seed", 0), 0, 2**63 - 1)
    step = real_value(where, "step", raw.get("step", 1e-3), MIN_STEP, MAX_TIME)
    duration = _duration(where, raw.get("duration"), step, SCENARIOS[scenario].duration)
    ideal = raw.get("ideal", False)
    if not isinstance(ideal, bool):
        raise UserError(f"{where} ideal = {shown(ideal)}: write true or false")
    return SweepSpec(
        name=name,
        scenario=scenario,
        masses=masses,
        runs=runs,
        seed=seed,
        metrics=metrics,
        fixed=dict(fixed),
        vary=dict(vary),
        duration=duration,
        step=step,
        ideal=ideal,
    )


def _read_toml(path: Path) -> dict:
    """The TOML table of a UTF-8 file."""
    from arcosim.logs import read_text_file

    text = read_text_file(path, "sweep spec")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise UserError(f"{path}: not valid TOML ({one_line(str(error))})") from None


def _check_keys(where: str, raw: dict) -> None:
    """Refuse a key that is not one of :data:`KEYS`."""
    unknown = set(raw) - KEYS
    if unknown:
        raise UserError(
            f"{where} unknown key {', '.join(sorted(shown_key(k) for k in unknown))} "
            f"(known: {', '.join(sorted(KEYS))})"
        )


def _name(where: str, value: object) -> str:
    """The sweep's name: a plain folder name (:data:`NAME`)."""
    name = text_value(where, "name", value)
    if not NAME.fullmatch(name) or name in (".", ".."):
        raise UserError(
            f"{where} name = {shown(name)}: use letters, digits, '.', '_' and '-' only (it "
            "names the folder sweeps/<name>), at most 100 characters, not '.' or '..'"
        )
    return name


def _metrics(where: str, metrics: object) -> tuple[str, ...]:
    """A non-empty list of :data:`METRICS`, each kept once in its first place."""
    if not isinstance(metrics, list) or not metrics:
        raise UserError(f'{where} metrics: write a list, e.g. metrics = ["k_error", "runtime"]')
    for metric in metrics:
        if not isinstance(metric, str) or metric not in METRICS:
            raise UserError(f"{where} metric {shown(metric)} is not one of {', '.join(METRICS)}")
    return tuple(dict.fromkeys(metrics))


def _parameters(path: Path, raw: dict) -> tuple[dict, dict]:
    """The ``[fixed]`` and ``[vary]`` tables: FMU-qualified names, each in one table,
    fixed values that are scalars, distributions that are complete."""
    where = f"{path}:"
    fixed = table_value(where, "fixed", raw.get("fixed", {}))
    vary = table_value(where, "vary", raw.get("vary", {}))
    for qualified in [*vary, *fixed]:
        if qualified.split(".", 1)[0] not in ("plant", "observer") or "." not in qualified:
            raise UserError(
                f"{where} {shown_key(qualified)!r}: name the FMU first "
                "(plant.NAME or observer.NAME)"
            )
    both = sorted(set(vary) & set(fixed))
    if both:
        raise UserError(f"{where} {both[0]} is both fixed and varied; keep one")
    for qualified, value in fixed.items():
        check_scalar(where, qualified, value)
    for qualified, dist in vary.items():
        _check_distribution(path, qualified, dist)
    return fixed, vary


def _runs(where: str, raw: dict, vary: dict) -> int:
    """The number of runs: the grid's size when every varied parameter is a grid (a
    ``runs`` given beside it is checked, not used), else ``runs``."""
    grids = [n for n, d in vary.items() if d["distribution"] == "grid"]
    if grids and len(grids) != len(vary):
        raise UserError(
            f"{where} a grid cannot be mixed with random distributions "
            f"({', '.join(grids)} are grids)"
        )
    if not grids:
        return integer_value(where, "runs", raw.get("runs", 1), 1, MAX_RUNS)
    runs = math.prod(len(vary[n]["values"]) for n in grids)
    if runs > MAX_RUNS:
        raise UserError(f"{where} the grid has {runs:,} runs, more than {MAX_RUNS:,}")
    if "runs" in raw:
        integer_value(where, "runs", raw["runs"], 1, MAX_RUNS)
    return runs


def _duration(where: str, duration: object, step: float, length: float) -> float | None:
    """The run's length (s) if the spec shortens the scenario's ``length`` (s); refuse a
    ``step`` (s) that gives no step or more than :data:`MAX_STEPS`."""
    if duration is not None:
        duration = length = real_value(where, "duration", duration, 0.0, MAX_TIME, low_open=True)
    steps = round(length / step)
    if not 1 <= steps <= MAX_STEPS:
        raise UserError(
            f"{where} step = {step:g} s gives {steps:.3g} steps in {length:g} s; "
            f"a run takes 1 to {MAX_STEPS:,} steps"
        )
    return duration


def _check_distribution(path: Path, name: str, dist: object) -> None:
    """A ``[vary]`` entry: a known distribution with exactly its keys, each valid."""
    where = f"{path}: {name}:"
    if not isinstance(dist, dict) or "distribution" not in dist:
        raise UserError(f'{where} write {{ distribution = "uniform", low = …, high = … }}')
    kind = dist["distribution"]
    if not isinstance(kind, str) or kind not in DISTRIBUTIONS:
        raise UserError(
            f"{where} unknown distribution {shown(kind)} (use {', '.join(DISTRIBUTIONS)})"
        )
    missing = [k for k in DISTRIBUTIONS[kind] if k not in dist]
    if missing:
        raise UserError(f"{where} a {kind} distribution needs {', '.join(missing)}")
    extra = sorted(shown_key(k) for k in set(dist) - {"distribution", *DISTRIBUTIONS[kind]})
    if extra:
        raise UserError(f"{where} a {kind} distribution takes no {', '.join(extra)}")
    if kind in ("choice", "grid"):
        _check_values(path, name, dist["values"])
    else:
        _check_bounds(path, name, kind, dist)


def _check_values(path: Path, name: str, values: object) -> None:
    """A ``choice`` or ``grid``'s values: a non-empty list of at most :data:`MAX_RUNS`
    scalars."""
    where = f"{path}: {name}:"
    if not isinstance(values, list) or not values:
        raise UserError(f"{where} values must be a non-empty list")
    if len(values) > MAX_RUNS:
        raise UserError(f"{where} at most {MAX_RUNS:,} values")
    for value in values:
        check_scalar(f"{path}:", f"{name} value", value)


def _check_bounds(path: Path, name: str, kind: str, dist: dict) -> None:
    """A random distribution's numbers: integers for ``randint``, finite numbers else;
    low below high, a positive low for ``loguniform``, a positive std for ``normal``."""
    where = f"{path}: {name}:"
    for key in DISTRIBUTIONS[kind]:
        if kind == "randint":
            integer_value(where, key, dist[key], -(2**63), 2**63 - 1)
        else:
            real_value(where, key, dist[key], -1e300, 1e300)
    if kind in ("uniform", "loguniform", "randint") and not dist["low"] < dist["high"]:
        raise UserError(f"{where} low = {dist['low']} must be below high = {dist['high']}")
    if kind == "loguniform" and not dist["low"] > 0:
        raise UserError(f"{where} a loguniform distribution needs low > 0")
    if kind == "normal" and not dist["std"] > 0:
        raise UserError(f"{where} std = {dist['std']} must be > 0")


def check_names(spec: SweepSpec, variables: Mapping[str, Mapping[str, object]]) -> None:
    """Refuse parameter names the FMUs do not have, and values of the wrong type.

    Parameters
    ----------
    spec : SweepSpec
        The checked spec.
    variables : mapping of str to mapping
        ``"plant"`` and ``"observer"`` → their variables by name (fmpy
        ``ScalarVariable`` objects, :func:`arcosim.build.builder.fmu_variables`).

    Raises
    ------
    UserError
        A name that is not a variable of its FMU, or not a parameter, or a fixed value
        of the wrong type.
    """
    for qualified, value in [*spec.fixed.items(), *((n, None) for n in spec.vary)]:
        fmu, name = qualified.split(".", 1)
        check_name(name, variables[fmu], fmu)
        var = variables[fmu][name]
        if var.causality != "parameter":
            raise UserError(f"{qualified} is an {var.causality}, not a parameter")
        if value is not None:
            typed_value(qualified, str(value), var.type)


def draw_runs(spec: SweepSpec) -> list[dict[str, object]]:
    """Every run's varied values, drawn from ``spec.seed`` (the same every time).

    Parameters
    ----------
    spec : SweepSpec
        The checked spec.

    Returns
    -------
    list of dict
        One ``{"fmu.name": value}`` per run (in each variable's unit): the grid's
        product when every varied parameter is a grid, else ``spec.runs`` draws.
    """
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
