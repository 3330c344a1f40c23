"""The tip's motion online: the model-based observer on a flexible link's modal model
(flexchain.link_observer, the observer FMU's ``link_modes``), against the link plant FMU."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from arcosim.cli import main
from arcosim.errors import UserError
from arcosim.experiments.flexible_link import EXPERIMENT_RIG, LINK_FMU, STEP, simulate_link
from arcosim.fmu.arobserver.fmu import ReactionTorqueObserver
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.driven_chain import continuous_matrices
from arcosim.fmu.flexchain.link_observer import StarLink
from arcosim.fmu.flexchain.observer import Observer, ObserverSettings
from arcosim.host.instance import FmuInstance
from arcosim.identification.link.beam_model import (
    Link,
    ModalModel,
    modal_model,
    observer_parameters,
)
from arcosim.logs import write_csv

#: Scores skip the first second (the observer's start from rest, the excitation's).
SETTLE = 1.0
#: Seconds of the plant run the tests score.
DURATION = 4.0


def link_model(rig=EXPERIMENT_RIG, modes: int = 3) -> ModalModel:
    """The plant's link as beam_model gives it, damped as the plant (ζ = β ω / 2)."""
    geometry = {p: rig.value(p) for p in ("EI", "rhoA", "L", "m_tip", "J_tip", "r_hub")}
    model = modal_model(Link(**geometry), modes)
    return model.with_damping(rig.value("beta") * model.frequency / 2.0)


def star_link(parameters: dict) -> StarLink:
    """The observer's link from ``observer_parameters``' names."""
    m = parameters["link_modes"]
    pick = [
        tuple(parameters[f"{name}[{i}]"] for i in range(1, m + 1))
        for name in ("omega_link", "zeta_link", "b_link", "phi_tip")
    ]
    return StarLink(*pick, parameters["J_link_rigid"], parameters["L_link"])


def ratio(estimate: np.ndarray, truth: np.ndarray, time: np.ndarray) -> float:
    """rms(estimate − truth) / rms(truth) after :data:`SETTLE` s."""
    keep = time >= SETTLE
    error = estimate[keep] - truth[keep]
    return float(np.sqrt(np.mean(error**2) / np.mean(truth[keep] ** 2)))


@pytest.fixture(scope="module")
def plant_run(fmus: Path):
    return simulate_link(fmus / LINK_FMU, EXPERIMENT_RIG, DURATION)


def test_the_star_is_the_modal_model_hub_locked() -> None:
    """The star of ``star=True`` with the hub held has the link's clamped modes, and its
    masses, springs and dampers are beam_model's (one home: star_chain)."""
    model = link_model(modes=4)
    J, k, B = model.star()
    parameters = observer_parameters(model)
    assert np.allclose(star_link(parameters).chain(), (J, k, B), rtol=1e-15, atol=0.0)
    A, _ = continuous_matrices(list(J), list(k), list(B), star=True)
    poles = scipy.linalg.eigvals(np.array(A))
    upper = poles[poles.imag > 0]
    upper = upper[np.argsort(np.abs(upper))]
    assert np.allclose(np.abs(upper), np.sort(model.frequency), rtol=1e-12)
    assert np.allclose(-upper.real / np.abs(upper), np.sort(model.damping), rtol=1e-9)


def test_observer_parameters_are_the_fmus() -> None:
    declared = ReactionTorqueObserver.interface(3)
    parameters = observer_parameters(link_model(modes=6))  # more modes than the FMU's arrays
    assert parameters["link_modes"] == defaults.LINK_MODES_MAX
    for name in parameters:
        assert declared[name].causality == "parameter", name
    assert declared["link_modes"].start == 0  # the chain, as before, unless told
    assert parameters["J_link_rigid"] > 0.0 and parameters["L_link"] == EXPERIMENT_RIG.value("L")


def test_tip_angle_online_within_ten_percent_and_the_fmu_runs_the_same(
    fmus: Path, plant_run
) -> None:
    """FlexLinkPlant.fmu under a multi-sine; the observer on beam_model's modes of the
    plant's link: rms(α̂ − α) ≤ 0.1 rms(α) after the first second, in the algorithm and
    in the observer FMU (the same numbers)."""
    signals = plant_run.signals
    parameters = observer_parameters(link_model())
    actuator = EXPERIMENT_RIG.actuator
    settings = ObserverSettings(
        mode=2,
        actuator=actuator,
        g_dist=defaults.G_DIST,
        g_lpf=defaults.G_LPF,
        J=(1.0,),
        k=(1.0,),
        B=(0.0,),
        estimator=1,
        encoder_cpr=int(EXPERIMENT_RIG.value("encoder_cpr")),
        link=star_link(parameters),
    )
    columns = [signals[c].tolist() for c in ("i_a", "omega_m", "theta_m")]
    observer = Observer(settings, columns[2][0], columns[1][0])
    alpha = np.zeros(len(plant_run.time))
    for k in range(1, len(alpha)):
        observer.step(STEP, columns[0][k], columns[1][k], columns[2][k])
        alpha[k] = observer.estimator.alpha_tip
    score = ratio(alpha, signals["alpha_tip"], plant_run.time)
    assert score <= 0.1, score

    start = {"J_mo": actuator.J_mo, "k_to": actuator.k_to, "D_m": actuator.D_m}
    start.update(f_c=actuator.f_c, encoder_cpr=settings.encoder_cpr, **parameters)
    online = run_observer_fmu(fmus / "ReactionTorqueObserver.fmu", start, signals)
    assert np.allclose(online[:, 0], alpha, rtol=1e-9, atol=1e-12)
    assert np.allclose(online[:, 1], online[:, 0] * parameters["L_link"], rtol=1e-12)
    assert ratio(online[:, 0], signals["alpha_tip"], plant_run.time) <= 0.1


def run_observer_fmu(fmu: Path, start: dict, signals: dict) -> np.ndarray:
    """The observer FMU over a plant run: ``alpha_tip_hat`` (rad) and ``w_tip_hat`` (m)
    after each step, shape ``(N, 2)``."""
    columns = [signals[c].tolist() for c in ("i_a", "omega_m", "theta_m")]
    tip = np.zeros((len(columns[0]), 2))
    with FmuInstance(fmu, "observer") as o:
        o.set({"omega_m": columns[1][0], "theta_m": columns[2][0]})
        o.initialize(start)
        read = o.reader(["alpha_tip_hat", "w_tip_hat"])
        for k in range(1, len(tip)):
            o.set({"i_a": columns[0][k], "omega_m": columns[1][k], "theta_m": columns[2][k]})
            assert o.do_step((k - 1) * STEP, STEP) == 0
            tip[k] = read()
        assert not o.messages, o.messages
    return tip


@pytest.mark.slow
def test_the_identified_link_sets_the_observer(fmus: Path, tmp_path, capsys) -> None:
    """``arcosim identify --method beam --json`` from the hub's log alone; its
    ``observer_parameters`` set on the observer FMU as they are: the tip angle within
    10 % of the plant's after the first second."""
    rig = EXPERIMENT_RIG
    run = simulate_link(fmus / LINK_FMU, rig, 20.0)
    units = {"time": "s", "i_a": "A", "omega_m": "rad/s", "theta_m": "rad"}
    path = write_csv(tmp_path / "link.csv", run.log(), units=units)
    motor = {"k_to": rig.value("k_t"), "J_mo": rig.value("J_m"), "D_m": rig.value("D_m")}
    motor.update(f_c=rig.value("f_c"), encoder_cpr=int(rig.value("encoder_cpr")))
    known = {p: rig.value(p) for p in ("L", "m_tip", "r_hub")}
    given = [x for name, v in {**motor, **known}.items() for x in ("--set", f"{name}={v}")]
    assert main(["identify", str(path), *given, "--method", "beam", "--json"]) == 0
    parameters = json.loads(capsys.readouterr().out)["observer_parameters"]
    tip = run_observer_fmu(
        fmus / "ReactionTorqueObserver.fmu", {**motor, **parameters}, run.signals
    )
    score = ratio(tip[:, 0], run.signals["alpha_tip"], run.time)
    assert score <= 0.1, score


@pytest.mark.parametrize(
    ("parameters", "phrase"),
    [
        ({"link_modes": 2}, "link_modes > 0 needs mode = 2 and estimator = 1"),
        ({"estimator": 1, "link_modes": 5}, "link_modes = 5 is not allowed"),
        ({"estimator": 1, "link_modes": 1, "omega_link[1]": 0.0}, "omega_link[1] = 0.0"),
        ({"estimator": 1, "link_modes": 1, "b_link[1]": 0.0}, "b_link[1] = 0: a mode"),
        ({"estimator": 1, "link_modes": 1, "omega_link[1]": 2e6}, "omega_link[1] = 2e+06 and"),
        (
            {"estimator": 1, "link_modes": 1, "load_mass": 1},
            "link_modes > 0 and load_mass > 0 exclude each other",
        ),
    ],
)
def test_a_link_the_observer_cannot_run_is_refused(fmus: Path, parameters, phrase) -> None:
    with (
        FmuInstance(fmus / "ReactionTorqueObserver.fmu", "observer") as o,
        pytest.raises(UserError, match=re.escape(phrase)),
    ):
        o.initialize(parameters)
