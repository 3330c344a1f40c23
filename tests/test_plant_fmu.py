"""The built plant FMU: compliance, physics against independent solutions, sensors,
failure handling, and several FMUs in one process."""

from __future__ import annotations

import math
import re
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pytest
from fmpy.validation import validate_fmu
from scipy.linalg import eig

from arcosim import __version__
from arcosim.errors import UserError
from arcosim.host.instance import FmuInstance
from tests.plant_runs import IDEAL, run_plant

BENCH_J = [2.09e-5, 5.15299e-4, 5.15299e-4, 6.192707e-4]
K, B = 0.1627, 8.88e-6


@pytest.mark.parametrize(
    "n", [pytest.param(1, marks=pytest.mark.slow), 3, pytest.param(20, marks=pytest.mark.slow)]
)
def test_plant_validates_without_problems(build_fmus, n: int) -> None:
    assert validate_fmu(str(build_fmus(n) / "MotorChainPlant.fmu")) == []


def test_model_description_carries_units_structure_and_version(plant_fmu: Path) -> None:
    with zipfile.ZipFile(plant_fmu) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    assert root.get("generationTool") == f"arcosim {__version__}"
    assert root.get("version") == __version__
    units = {u.get("name") for u in root.iter("Unit")}
    variables = root.find("ModelVariables").findall("ScalarVariable")
    outputs = []
    for index, sv in enumerate(variables, start=1):
        assert sv.get("description"), sv.get("name")
        real = sv.find("Real")
        if real is not None:
            assert real.get("unit") in units, sv.get("name")
        if sv.get("causality") == "output":
            outputs.append(str(index))
    listed = root.find("ModelStructure/Outputs").findall("Unknown")
    assert [u.get("index") for u in listed] == outputs
    assert all(u.get("dependencies") == "" for u in listed)
    initial = root.find("ModelStructure/InitialUnknowns").findall("Unknown")
    assert [u.get("index") for u in initial] == outputs
    names = [sv.get("name") for sv in variables]
    for required in (
        "i_ref",
        "tau_ext[3]",
        "J_m",
        "k[3]",
        "attached",
        "encoder_cpr",
        "i_a",
        "theta_m",
        "omega_m",
        "theta[3]",
        "omega[3]",
        "tau_reac",
        "twist",
    ):
        assert required in names


@pytest.mark.slow
def test_natural_frequencies_match_chain_eigenvalues(plant_fmu: Path) -> None:
    """Free response after a current pulse → poles by the eigensystem realization
    algorithm → natural frequencies within 0.1 % of the undamped chain's."""
    h, pulse, free = 1e-3, 10, 3000
    current = [0.5] * pulse + [0.0] * free
    names = ["omega_m_true", "omega[1]", "omega[2]", "omega[3]"]
    run = run_plant(plant_fmu, current, h, names, {**IDEAL, "f_c": 0.0})
    y = np.column_stack([run[n] for n in names])[pulse + 1 :]
    rows, cols, order = 30, 2000, 7  # 2n + 1 states are seen from the velocities
    hankel = np.vstack([y[i : i + cols].T for i in range(rows + 1)])
    p = y.shape[1]
    u, s, vt = np.linalg.svd(hankel[: rows * p], full_matrices=False)
    u, s, vt = u[:, :order], s[:order], vt[:order]
    shifted = hankel[p : (rows + 1) * p]
    a = np.diag(s**-0.5) @ u.T @ shifted @ vt.T @ np.diag(s**-0.5)
    poles = np.log(np.linalg.eigvals(a).astype(complex)) / h
    measured = np.sort(np.abs(poles[poles.imag > 1e-6]))

    inertia = np.diag(BENCH_J)
    stiffness = np.zeros((4, 4))
    for i in range(1, 4):
        stiffness[i - 1 : i + 1, i - 1 : i + 1] += K * np.array([[1, -1], [-1, 1]])
    w2 = np.sort(eig(stiffness, inertia, right=False).real)
    expected = np.sqrt(w2[w2 > 1e-9])
    assert expected == pytest.approx([16.8, 30.2, 90.1], abs=0.05)  # docs/method.md's figures
    np.testing.assert_allclose(measured, expected, rtol=1e-3)


def test_momentum_balance_holds_every_step(plant_fmu: Path) -> None:
    """Σ J_j Δω_j / h = k_t ī − D_m Δθ_m / h + Σ τ_ext (friction off), every step."""
    h, steps = 1e-3, 1500
    t = np.arange(steps) * h
    current = 0.2 * np.sin(14 * t) + 0.1 * np.sin(95 * t)
    tau_ext = {"tau_ext[1]": 1e-3, "tau_ext[2]": -2e-3, "tau_ext[3]": 5e-4}
    names = ["omega_m_true", "omega[1]", "omega[2]", "omega[3]", "theta_m_true", "i_true"]
    run = run_plant(plant_fmu, current, h, names, {**IDEAL, "f_c": 0.0}, tau_ext)
    omega = np.column_stack([run[n] for n in names[:4]])
    lhs = (np.diff(omega, axis=0) @ np.array(BENCH_J)) / h
    rhs = (
        0.0406 * run["i_true"][1:] - 2e-5 * np.diff(run["theta_m_true"]) / h + sum(tau_ext.values())
    )
    assert np.max(np.abs(lhs - rhs)) < 1e-9 * np.max(np.abs(rhs))


def test_momentum_balance_with_coulomb_friction_while_moving_forward(plant_fmu: Path) -> None:
    h, steps = 1e-3, 400
    names = ["omega_m_true", "omega[1]", "omega[2]", "omega[3]", "theta_m_true", "i_true"]
    run = run_plant(plant_fmu, [1.0] * steps, h, names, IDEAL)
    forward = (run["omega_m_true"][:-1] > 0) & (run["omega_m_true"][1:] > 0)
    assert forward.sum() > steps / 2  # the chain's swing reverses the motor now and then
    omega = np.column_stack([run[n] for n in names[:4]])
    lhs = (np.diff(omega, axis=0) @ np.array(BENCH_J)) / h
    rhs = 0.0406 * run["i_true"][1:] - 2e-5 * np.diff(run["theta_m_true"]) / h - 2e-3
    assert np.max(np.abs(lhs - rhs)[forward]) < 1e-9 * 0.0406


def test_sticking_friction_holds_the_motor_under_small_torque(plant_fmu: Path) -> None:
    run = run_plant(plant_fmu, [0.04] * 500, 1e-3, ["theta_m_true", "omega_m_true", "theta[3]"])
    assert 0.04 * 0.0406 < 2e-3  # drive torque below f_c
    assert np.all(run["theta_m_true"] == 0.0) and np.all(run["omega_m_true"] == 0.0)
    assert np.all(run["theta[3]"] == 0.0)


def test_encoder_quantizes_and_differentiates(plant_fmu: Path) -> None:
    h, cpr = 1e-3, 2000
    names = ["theta_m", "theta_m_true", "omega_m"]
    run = run_plant(plant_fmu, [0.3] * 300, h, names, {"encoder_cpr": cpr})
    step = 2 * math.pi / cpr
    counts = run["theta_m"] / step
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-9)
    error = run["theta_m_true"] - run["theta_m"]
    assert np.all(error >= -1e-12) and np.all(error < step)
    np.testing.assert_allclose(run["omega_m"][1:], np.diff(run["theta_m"]) / h, rtol=1e-12)
    assert len(np.unique(run["theta_m"])) > 20


def test_current_noise_has_the_set_spread_and_follows_the_seed(plant_fmu: Path) -> None:
    steps, std = 4000, 0.005
    names = ["i_a", "i_true"]

    def noise(seed: int) -> np.ndarray:
        run = run_plant(plant_fmu, [0.02] * steps, 1e-3, names, {"seed": seed})
        return (run["i_a"] - run["i_true"])[1:]

    a, b, c = noise(1), noise(1), noise(2)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    # sample std of N normals: relative standard error 1/sqrt(2N) = 1.1 %; allow 5 σ
    assert np.std(a) == pytest.approx(std, rel=5 / math.sqrt(2 * steps))
    assert abs(np.mean(a)) < 5 * std / math.sqrt(steps)
    assert abs(np.corrcoef(a[:-1], a[1:])[0, 1]) < 5 / math.sqrt(steps)


def test_outputs_follow_the_timing_contract(plant_fmu: Path) -> None:
    """After doStep(t, h): the sample at t + h, with the current of [t, t + h]."""
    run = run_plant(plant_fmu, [0.3, 0.6, -0.2], 1e-3, ["i_a", "i_true"], IDEAL)
    np.testing.assert_allclose(run["i_a"], [0.0, 0.3, 0.6, -0.2], rtol=1e-15)


@pytest.mark.slow
def test_plants_for_three_and_five_masses_run_side_by_side(build_fmus) -> None:
    with (
        FmuInstance(build_fmus(3) / "MotorChainPlant.fmu", "three") as three,
        FmuInstance(build_fmus(5) / "MotorChainPlant.fmu", "five") as five,
        FmuInstance(build_fmus(3) / "MotorChainPlant.fmu", "three-b") as three_b,
    ):
        three.initialize(IDEAL)
        five.initialize(IDEAL)
        three_b.initialize({**IDEAL, "k[1]": 0.3})
        for k in range(200):
            for plant in (three, five, three_b):
                plant.set({"i_ref": 0.3})
                assert plant.do_step(k * 1e-3, 1e-3) == 0
        assert "theta[5]" in five.variables and "theta[4]" not in three.variables
        angles = [p.get(["theta[1]"])[0] for p in (three, five, three_b)]
        assert len(set(angles)) == 3  # three different plants, none sharing state


@pytest.mark.parametrize(
    ("name", "value", "phrase"),
    [
        ("J[2]", -1.0, "J[2] = -1.0 must be > 0"),
        ("J_m", 0.0, "J_m = 0.0 must be > 0"),
        ("k[1]", -0.1, "k[1] = -0.1 must be >= 0"),
        ("B[3]", float("nan"), "B[3] = nan is not a finite number"),
        ("encoder_cpr", -5, "encoder_cpr = -5 must be >= 0"),
    ],
)
def test_invalid_parameter_is_refused_with_a_message(plant_fmu, name, value, phrase) -> None:
    with FmuInstance(plant_fmu, "bad") as plant:
        with pytest.raises(UserError, match=re.escape(phrase)):  # fmi2Error, not fatal
            plant.initialize({name: value})
        assert any(phrase in m and m.startswith("error") for m in plant.messages), plant.messages
        assert plant.do_step(0.0, 1e-3) == 2  # every step refused with the same message
        assert plant.do_step(0.0, 1e-3) == 2
    with FmuInstance(plant_fmu, "good") as plant:  # the host carries on
        plant.initialize()
        assert plant.do_step(0.0, 1e-3) == 0


@pytest.mark.parametrize(
    ("inputs", "t", "h", "phrase"),
    [
        ({"i_ref": float("nan")}, 0.0, 1e-3, "input i_ref = nan is not finite"),
        ({"tau_ext[2]": float("inf")}, 0.0, 1e-3, "input tau_ext[2] = inf is not finite"),
        ({}, 0.0, 0.0, "step size 0.0 s refused"),
        ({}, 0.0, -1e-3, "step size -0.001 s refused"),
        ({}, 0.0, float("nan"), "step size nan s refused"),
        ({}, 0.5, 1e-3, "communication point 0.5 s refused"),
    ],
)
def test_bad_step_is_discarded_and_state_kept(plant_fmu, inputs, t, h, phrase) -> None:
    with FmuInstance(plant_fmu, "plant") as plant:
        plant.initialize(IDEAL)
        plant.set({"i_ref": 0.2})
        assert plant.do_step(0.0, 1e-3) == 0
        before = plant.get(["theta_m_true", "omega_m_true"])
        plant.set(inputs)
        assert plant.do_step(t + 1e-3 if t == 0.0 else t, h) == 2
        assert any(phrase in m for m in plant.messages), plant.messages
        assert plant.get(["theta_m_true", "omega_m_true"]) == before
        plant.set({"i_ref": 0.2, "tau_ext[2]": 0.0})
        assert plant.do_step(1e-3, 1e-3) == 0


def test_plant_is_compiled_c_with_nothing_else_needed(plant_fmu: Path) -> None:
    """No Python inside: no resources, needsExecutionTool false, the C sources
    shipped, and a binary that needs nothing beyond the C library and libm."""
    with zipfile.ZipFile(plant_fmu) as z:
        names = z.namelist()
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
        binary = z.read("binaries/linux64/MotorChainPlant_n3.so")
    assert not any(n.startswith("resources/") for n in names)
    assert {"sources/physics.c", "sources/fmu.c", "sources/plant_variables.h"} <= set(names)
    assert root.find("CoSimulation").get("needsExecutionTool") == "false"
    assert b"libpython" not in binary and b"Py_Initialize" not in binary


def test_step_before_initialization_is_refused(plant_fmu: Path) -> None:
    from fmpy.fmi1 import FMICallException

    with FmuInstance(plant_fmu, "early") as plant:
        with pytest.raises(FMICallException) as refused:
            plant.slave.doStep(0.0, 1e-3)
        assert refused.value.status == 2  # fmi2Discard, not fatal
        assert any("before initialization" in m for m in plant.messages)
        plant.initialize()
        assert plant.do_step(0.0, 1e-3) == 0


def test_trace_file_records_outputs_and_never_overwrites(plant_fmu: Path, tmp_path) -> None:
    trace = tmp_path / "plant.csv"
    with FmuInstance(plant_fmu, "traced") as plant:
        plant.initialize({**IDEAL, "trace_file": str(trace)})
        plant.set({"i_ref": 0.3})
        for k in range(5):
            assert plant.do_step(k * 1e-3, 1e-3) == 0
        last = plant.get(["theta_m_true"])[0]
    lines = trace.read_text().splitlines()
    assert len(lines) == 7 and lines[0].startswith("time,i_a,theta_m")
    column = lines[0].split(",").index("theta_m_true")
    assert float(lines[-1].split(",")[column]) == last  # full precision
    with FmuInstance(plant_fmu, "again") as plant:
        with pytest.raises(UserError, match="exists; choose a new name"):
            plant.initialize({"trace_file": str(trace)})
        assert plant.do_step(0.0, 1e-3) == 2
        assert any("exists; choose a new name" in m for m in plant.messages)
    assert len(trace.read_text().splitlines()) == 7  # the user's file is intact


@pytest.mark.slow
def test_every_fmu_for_several_n_loads_in_one_process(build_fmus) -> None:
    """Nine FMUs (three kinds × n = 1, 3, 5) instantiated, initialized and stepped
    together: model identifiers carry n, bundled packages are identical copies."""
    from contextlib import ExitStack

    with ExitStack() as stack:
        fmus = [
            stack.enter_context(FmuInstance(build_fmus(n) / f"{name}.fmu", f"{name}-{n}"))
            for n in (1, 3, 5)
            for name in ("MotorChainPlant", "ReactionTorqueObserver", "ExcitationSource")
        ]
        for fmu in fmus:
            fmu.initialize()
        for k in range(20):
            assert all(fmu.do_step(k * 1e-3, 1e-3) == 0 for fmu in fmus)
        identifiers = {fmu.description.coSimulation.modelIdentifier for fmu in fmus}
        assert len(identifiers) == 9


def test_instances_of_one_fmu_share_one_unzipped_copy(plant_fmu: Path) -> None:
    with FmuInstance(plant_fmu, "a") as a, FmuInstance(plant_fmu, "b") as b:
        assert a._unzipped == b._unzipped
        a.initialize(IDEAL)
        b.initialize({**IDEAL, "k[1]": 0.3})
        a.set({"i_ref": 0.3})
        b.set({"i_ref": 0.3})
        for k in range(50):
            assert a.do_step(k * 1e-3, 1e-3) == 0 and b.do_step(k * 1e-3, 1e-3) == 0
        assert a.get(["theta[1]"]) != b.get(["theta[1]"])  # separate instances
    with FmuInstance(plant_fmu, "c") as c:
        assert c._unzipped == a._unzipped and Path(c._unzipped).is_dir()
