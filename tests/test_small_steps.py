"""Steps shorter than a nanosecond: taken by every FMU, never refused.

A host that sums its time (t += 1e-3 ten thousand times) ends a 10 s run on a step of
1.03e-13 s. FMI 2.0 asks only h > 0. The Python FMUs hold their state and outputs over
a step below ``SMALLEST_STEP`` and only advance time; the C plant integrates it exactly
(and takes no new sample). The plant's sub-steps too short for its ladder of
precomputed exponentials are summed as a Taylor series, exact to rounding: checked
here against the exponential in 50-digit decimal arithmetic.
"""

from __future__ import annotations

import itertools
import shutil
import subprocess
import zipfile
from decimal import Decimal, localcontext
from pathlib import Path

import numpy as np
import pytest

from arcosim.build.ssp import BENCH, CONNECTIONS
from arcosim.fmu.fmukit.checks import SMALLEST_STEP
from arcosim.host.instance import FmuInstance
from tests.chain_harness import compile_c_host

#: C test programs and hosts compiled and run in subprocesses (the system tier).
pytestmark = pytest.mark.system

HERE = Path(__file__).parent / "hosts"
COMPONENTS = {
    "source": "ExcitationSource",
    "plant": "MotorChainPlant",
    "observer": "ReactionTorqueObserver",
}


def _summed(h: float, count: int) -> float:
    """``t += h`` ``count`` times from 0, as a host sums its time (not ``sum()``: since
    CPython 3.12 it compensates the rounding a host's loop keeps)."""
    t = 0.0
    for _ in range(count):
        t += h
    return t


#: what a host that sums 1 ms steps is left with at 10 s
RESIDUE = 10.0 - _summed(1e-3, 10_000)
#: the plant's outputs that are samples (measured, or means over a step): kept over a
#: step below SMALLEST_STEP
SAMPLED = ("i_a", "theta_m", "omega_m", "i_true", "tau_reac_mean")


def test_the_residue_of_a_summing_host_is_below_the_threshold() -> None:
    assert 0.0 < RESIDUE < SMALLEST_STEP
    assert RESIDUE == pytest.approx(1.03e-13, rel=1e-2)


# -- the plant's sub-steps, against an exponential in 50 digits ----------------------


def _compile(tmp_path: Path, n: int) -> Path:
    from arcosim.build.cplant import compiler, source_dir

    (tmp_path / "chain_size.h").write_text(f"#define N_MASSES {n}\n")
    binary = tmp_path / "physics_probe"
    command = [
        compiler(),
        "-std=c99",
        "-O2",
        "-Wall",
        "-Wextra",
        "-pedantic",
        f"-I{tmp_path}",
        f"-I{source_dir()}",
        str(HERE / "physics_probe.c"),
        "-lm",
        "-o",
        str(binary),
    ]
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode == 0 and not result.stderr.strip(), result.stderr
    return binary


def _probe(binary: Path, h: float, bandwidth: float, taus: list[float]) -> dict:
    result = subprocess.run(
        [str(binary), repr(h), repr(bandwidth), *map(repr, taus)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    out: dict = {"a": [], "b": [], "tau": []}
    for line in result.stdout.splitlines():
        tag, *rest = line.split()
        values = [float.fromhex(v) for v in rest]
        if tag in ("a", "b"):
            out[tag].append(values[1:])
        elif tag == "tau":
            out["tau"].append((values[0], values[1:]))
        else:
            out[tag] = values if tag != "rate" else values[0]
    return out


def _exact(a: list, b: list, x: list, u: list, tau: float) -> list[Decimal]:
    """e^{[A B; 0 0] τ} [x; u] by its Taylor series in 50-digit decimals, to 1e-45."""
    with localcontext() as context:
        context.prec = 50
        A = [[Decimal(v) for v in row] for row in a]
        Bu = [sum(Decimal(v) * Decimal(w) for v, w in zip(row, u)) for row in b]
        T = Decimal(tau)
        term = [T * (sum(r * Decimal(v) for r, v in zip(row, x)) + bu) for row, bu in zip(A, Bu)]
        total = [Decimal(v) + d for v, d in zip(x, term)]
        k = 1
        while max(abs(d) for d in term) > Decimal("1e-45") * max(abs(s) for s in total):
            k += 1
            term = [T / k * sum(r * d for r, d in zip(row, term)) for row in A]
            total = [s + d for s, d in zip(total, term)]
            assert k < 500
        return total


def _errors(probe: dict, tau: float, got: list[float]) -> tuple[float, float]:
    """Largest error of ``got`` and of an Euler step over ``tau``, each component against
    its scale (its largest magnitude before and after)."""
    want = _exact(probe["a"], probe["b"], probe["x"], probe["u"], tau)
    x, u = probe["x"], probe["u"]
    euler = [
        Decimal(x0)
        + Decimal(tau)
        * (
            sum(Decimal(a) * Decimal(v) for a, v in zip(ra, x))
            + sum(Decimal(b) * Decimal(v) for b, v in zip(rb, u))
        )
        for x0, ra, rb in zip(x, probe["a"], probe["b"])
    ]
    worst = [0.0, 0.0]
    for g, e, w, x0 in zip(got, euler, want, x):
        scale = Decimal(max(abs(float(w)), abs(x0)))
        worst[0] = max(worst[0], float(abs(Decimal(g) - w) / scale))
        worst[1] = max(worst[1], float(abs(e - w) / scale))
    return worst[0], worst[1]


@pytest.mark.parametrize("bandwidth", [0.0, 300.0])
@pytest.mark.parametrize(
    "h, fraction",
    [
        (1e-3, 1.03e-13 / 1e-3),  # a summing host's residue within a 1 ms step
        (50e-3, 2e-8 / 50e-3),  # under the ladder's last digit (h / 2^20 = 48 ns)
        (50e-3, 2.0**-21),
        (1e-9, 0.4),  # a part of a nanosecond step (no ladder for it)
    ],
)
def test_a_sub_step_below_the_ladder_is_exact_to_rounding(tmp_path, h, fraction, bandwidth):
    """By its Taylor series: within 1e-15 of each component's scale (measured at most
    1.5e-16, also on θ_3, which starts at 0: exact relative to its own increment); the
    Euler step that took its place before missed by 3e-11 (1e-13 s) to 6e-6 (24 ns)."""
    probe = _probe(_compile(tmp_path, 3), h, bandwidth, [fraction * h])
    ((tau, got),) = probe["tau"]
    error, euler = _errors(probe, tau, got)
    assert error <= 1e-15, error
    assert euler > 1e-13, euler  # the old way fails this test


@pytest.mark.parametrize("bandwidth", [0.0, 300.0])
@pytest.mark.parametrize(
    "h, fraction",
    [
        (1e-3, 0.37),  # a 1 ms step, short for the bench's chain: the series for any part
        (50e-3, 0.3),  # along the ladder of h/2 ... h/2^20, the rest by the series
        (50e-3, 0.5 + 2.0**-20 + 0.3 * 2.0**-21),
    ],
)
def test_a_sub_step_along_the_ladder_is_as_exact_as_its_exponentials(
    tmp_path, h, fraction, bandwidth
):
    """Within 1e-11 of each component's scale (measured 2.7e-12: the accuracy of the
    rungs' own matrix exponentials; a 1 ms part by the series 2e-16)."""
    probe = _probe(_compile(tmp_path, 3), h, bandwidth, [fraction * h])
    ((tau, got),) = probe["tau"]
    error, _ = _errors(probe, tau, got)
    assert error <= 1e-11, error


def test_sub_steps_of_a_short_step_never_build_the_ladder(tmp_path) -> None:
    """A 1 ns step with a friction event inside costs no twenty matrix exponentials."""
    probe = _probe(_compile(tmp_path, 3), 1e-9, 0.0, [0.4e-9])
    assert probe["rate"] * 1e-9 <= 0.5  # the series' condition, so the ladder is skipped


# -- the FMUs in hosts that sum their time ------------------------------------------


def _jacobi_summing(fmus: Path, stop: float, h: float) -> tuple[list, dict, dict, list]:
    """source → plant → observer with the bench's parameters, time summed (t += h, the
    last step stop − t). Returns the steps taken, the outputs before and after the last
    step, and every log line."""
    instances = {c: FmuInstance(fmus / f"{name}.fmu", c) for c, name in COMPONENTS.items()}
    try:
        for component, fmu in instances.items():
            fmu.initialize(BENCH[component])
        names = {c: fmu.output_names() for c, fmu in instances.items()}
        t, steps, before = 0.0, [], {}
        while t < stop:
            step = min(h, stop - t)
            for a, out, b, inp in CONNECTIONS:
                instances[b].set({inp: instances[a].get([out])[0]})
            if stop - t <= h:  # the last step comes: what it must leave as it is
                before = {c: dict(zip(names[c], fmu.get(names[c]))) for c, fmu in instances.items()}
            for component, fmu in instances.items():
                status = fmu.do_step(t, step)
                assert status == 0, (component, t, step, fmu.messages[-3:])
            steps.append(step)
            t += step
        after = {c: dict(zip(names[c], fmu.get(names[c]))) for c, fmu in instances.items()}
        messages = [m for fmu in instances.values() for m in fmu.messages]
    finally:
        for fmu in instances.values():
            fmu.close()
    return steps, before, after, messages


def _held(before: dict, after: dict) -> None:
    """The Python FMUs' outputs equal to the bit, the plant's samples too, the plant's
    true state within what it moves in 1e-13 s (1e-9 of each output's scale)."""
    for component in ("source", "observer"):
        assert after[component] == before[component], component
    for name, value in after["plant"].items():
        if name.split("[")[0] in SAMPLED:
            assert value == before["plant"][name], name
        else:
            assert value == pytest.approx(before["plant"][name], rel=1e-9, abs=1e-12), name


def test_fmpy_host_that_sums_its_time_ends_on_a_sub_nanosecond_step(fmus) -> None:
    steps, before, after, messages = _jacobi_summing(fmus, 10.0, 1e-3)
    assert steps[-1] == pytest.approx(RESIDUE, rel=1e-12) and steps[-1] < SMALLEST_STEP
    assert not messages, messages[:5]  # no Discard, no error, not a word
    _held(before, after)


def test_steps_down_to_the_smallest_double_are_taken(fmus) -> None:
    """From 1e-10 s down to 5e-324 s: status OK, time advanced (where it can be), the
    Python FMUs' outputs unchanged to the bit."""
    for name in ("ReactionTorqueObserver", "ExcitationSource", "MotorChainPlant"):
        with FmuInstance(fmus / f"{name}.fmu", "tiny") as fmu:
            fmu.initialize()
            assert fmu.do_step(0.0, 1e-3) == 0
            names = fmu.output_names()
            first = fmu.get(names)
            t = 1e-3
            for h in (1e-10, 1e-13, 1e-200, 1e-308, 5e-324):
                assert fmu.do_step(t, h) == 0, (name, h, fmu.messages[-1:])
                t += h
            assert not fmu.messages
            now = dict(zip(names, fmu.get(names)))
            if name != "MotorChainPlant":
                assert list(now.values()) == first
            assert fmu.do_step(t, 1e-3) == 0  # and on with ordinary steps


def test_a_plant_step_of_a_femtosecond_from_rest_is_exact(fmus) -> None:
    """From rest with 1 A, after h = 1e-15 s: ω_m = α h and θ_m = α h² / 2 with α =
    (k_t i − f_c) / J_m, to 1e-12 (each a number far below the rounding of a running
    state, so only an exact integration gets its digits)."""
    h = 1e-15
    with FmuInstance(fmus / "MotorChainPlant.fmu", "rest") as plant:
        plant.initialize({"i_noise_std": 0.0})
        plant.set({"i_ref": 1.0})
        assert plant.do_step(0.0, h) == 0
        omega, theta = plant.get(["omega_m_true", "theta_m_true"])
        k_t, f_c, J_m, D_m = plant.get(["k_t", "f_c", "J_m", "D_m"])
    alpha = (k_t * 1.0 - f_c) / J_m
    assert omega == pytest.approx(alpha * h, rel=1e-12)
    assert theta == pytest.approx(alpha * h * h / 2, rel=1e-12)
    assert D_m * omega * h < 1e-30  # damping adds nothing visible at this step


# -- a C host that sums its time -------------------------------------------------------


def test_c_host_that_sums_its_time_ends_on_a_sub_nanosecond_step(fmus, tmp_path) -> None:
    from fmpy import read_model_description

    if shutil.which("cc") is None and shutil.which("gcc") is None:
        pytest.skip("needs a C compiler")
    lines, variables, order = [], {}, []
    for component, name in COMPONENTS.items():
        target = tmp_path / component
        with zipfile.ZipFile(fmus / f"{name}.fmu") as z:
            z.extractall(target)
        md = read_model_description(str(target))
        variables[component] = {v.name: v for v in md.modelVariables}
        lines.append(f"fmu {component} {target} {md.coSimulation.modelIdentifier} {md.guid}")
    kinds = {"Real": "real", "Integer": "int", "Boolean": "bool", "String": "string"}
    for component, values in BENCH.items():
        for name, value in values.items():
            v = variables[component][name]
            lines.append(f"{kinds[v.type]} {component} {v.valueReference} {value}")
    for a, out, b, inp in CONNECTIONS:
        va, vb = variables[a][out].valueReference, variables[b][inp].valueReference
        lines.append(f"link {a} {va} {b} {vb}")
    for component in COMPONENTS:
        for v in variables[component].values():
            if v.causality == "output" and v.type == "Real":
                lines.append(f"out {component} {v.valueReference} r")
                order.append((component, v.name))
    lines += ["run 10 0.001", "sum"]
    (tmp_path / "spec.txt").write_text("\n".join(lines) + "\n")
    result = subprocess.run(
        [str(compile_c_host(tmp_path)), "spec.txt", "out.txt"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert not result.stderr.strip(), result.stderr[:2000]  # the logger heard nothing
    rows = [
        line.split(",")
        for line in (tmp_path / "out.txt").read_text().splitlines()
        if line[0].isdigit()
    ]
    data = np.array(rows, dtype=float)
    assert data[-1, 0] == 10.0 and 0.0 < data[-1, 0] - data[-2, 0] < SMALLEST_STEP
    before = {c: {} for c in COMPONENTS}
    after = {c: {} for c in COMPONENTS}
    for (component, name), x0, x1 in zip(order, data[-2, 1:], data[-1, 1:]):
        before[component][name], after[component][name] = x0, x1
    _held(before, after)


# -- a host's clock rounding: the same step on every host ------------------------------


def _closed_loop(folder: Path, steps: list[float]) -> dict[str, list[float]]:
    """MotionControl's ``move`` (controller ↔ plant, Jacobi) over ``steps`` (s)."""
    from arcosim.build.ssp import MOTION_CONTROL, motion_control_sets

    sets = motion_control_sets(3)["move"]
    instances = {c: FmuInstance(folder / f"{stem}.fmu", c) for c, stem in MOTION_CONTROL.components}
    try:
        for component, fmu in instances.items():
            fmu.initialize(sets.get(component, {}))
        names = {c: fmu.output_names() for c, fmu in instances.items()}
        t, log = 0.0, {f"{c}.{n}": [] for c in instances for n in names[c]}
        for h in steps:
            values = {a: dict(zip(names[a], instances[a].get(names[a]))) for a in instances}
            for a, out, b, inp in MOTION_CONTROL.connections:
                instances[b].set({inp: values[a][out]})
            for fmu in instances.values():
                assert fmu.do_step(t, h) == 0, fmu.messages[-3:]
            t += h
            for c, fmu in instances.items():
                for n, v in zip(names[c], fmu.get(names[c])):
                    log[f"{c}.{n}"].append(v)
    finally:
        for fmu in instances.values():
            fmu.close()
    return log


def test_a_nanosecond_clock_gives_the_results_of_exact_steps(build_fmus) -> None:
    """libcosim keeps its time in integer nanoseconds and hands the FMUs
    t_k+1 − t_k: 1 ms give or take units in the last place. The closed loop through the
    encoder's counts must not follow that rounding (STEP_JITTER): the same outputs, to
    the bit, as with every step exactly 1 ms. Without it the two runs part after about
    0.6 s (the controller's current by 0.4 A)."""
    from arcosim.fmu.fmukit.checks import STEP_JITTER

    folder = build_fmus(3)
    n = 1000
    clock = [k * 1_000_000 / 1e9 for k in range(n + 1)]  # ns → s, as libcosim converts
    jittered = [b - a for a, b in itertools.pairwise(clock)]
    assert len(set(jittered)) > 1  # the host's steps do differ in their last places
    assert max(abs(h - 1e-3) for h in jittered) <= STEP_JITTER * 1e-3
    exact = _closed_loop(folder, [1e-3] * n)
    rounded = _closed_loop(folder, jittered)
    differ = [name for name in exact if exact[name] != rounded[name]]
    assert not differ, differ
    assert max(exact["plant.theta[3]"]) > 0.3  # the move is under way
