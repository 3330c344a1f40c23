"""One chain throughout: a Chain identified, written, read, given to the observer, the
controller and ``--set`` comes back the same value.

Every leg copies floats (or writes them with ``repr`` / JSON, which round-trip a double
exactly), so every comparison is exact equality.
"""

from __future__ import annotations

import dataclasses
import json
import random
from pathlib import Path

import pytest

import arcosim
from arcosim.chainfile import ChainFileError, read_chain
from arcosim.cli.identify.options import chain_assignments
from arcosim.fmu.arcontroller.fmu import ActionReactionController
from arcosim.fmu.arobserver.fmu import ReactionTorqueObserver
from arcosim.fmu.flexchain.chain import Chain
from arcosim.fmu.flexchain.control.design import design_controller
from arcosim.fmu.flexchain.observer import ObserverSettings
from arcosim.host import observer_values

K_T = 0.0406  #: the bench motor's torque constant (N·m/A)
ROOT = Path(__file__).resolve().parents[1]


def random_chain(rng: random.Random, n: int, std: bool = True) -> Chain:
    """A chain of n masses with values spread over decades, as drives have them."""

    def draw(low: float, high: float) -> float:
        return 10.0 ** rng.uniform(low, high)

    values = dict(
        J=tuple(draw(-5, -2) for _ in range(n)),
        k=tuple(draw(-2, 3) for _ in range(n)),
        B=tuple(draw(-6, -2) for _ in range(n)),
        J_m=draw(-6, -3),
        D_m=draw(-6, -3),
        f_c=draw(-4, -1),
    )
    if std:  # one σ missing, as a parameter at its bound has none
        values.update(
            J_std=tuple(draw(-8, -5) for _ in range(n)),
            k_std=(None, *(draw(-4, 0) for _ in range(n - 1))),
            B_std=tuple(draw(-8, -4) for _ in range(n)),
            f_c_std=draw(-6, -4),
        )
    return Chain(**values)


@pytest.mark.parametrize(
    ("values", "message"),
    [
        (dict(J=(), k=(), B=()), "at least one load mass"),
        (dict(J=(1.0, 2.0), k=(1.0,), B=(0.0, 0.0)), "k has 1 values and J has 2"),
        (dict(J=(1.0,), k=(0.0,), B=(0.0,)), "k[1] = 0 must be > 0"),
        (dict(J=(1.0,), k=(1.0,), B=(-1e-3,)), "B[1] = -0.001 must be >= 0"),
        (dict(J=(1.0,), k=(1.0,), B=(0.0,), J_m=0.0), "J_m = 0 must be > 0"),
        (dict(J=(1.0,), k=(1.0,), B=(0.0,), f_c=-1.0), "f_c = -1 must be >= 0"),
        (dict(J=(float("nan"),), k=(1.0,), B=(0.0,)), "J[1] = nan is not finite"),
        (dict(J=("1",), k=(1.0,), B=(0.0,)), "J[1] = '1' is not a number"),
        (dict(J=(1.0,), k=(1.0,), B=(0.0,), k_std=(1.0, 1.0)), "k_std has 2 values for 1"),
        (dict(J=(1.0,), k=(1.0,), B=(0.0,), J_std=(-1.0,)), "J_std[1] = -1 must be >= 0"),
    ],
)
def test_a_chain_no_drive_has_is_refused_naming_the_value(values: dict, message: str) -> None:
    with pytest.raises(ValueError, match=r"^Chain: ") as error:
        Chain(**values)
    assert message in str(error.value)


def test_the_fmu_names_and_the_json_file_give_the_same_chain_back(tmp_path: Path) -> None:
    rng = random.Random(49)
    for n in (1, 2, 3, 7, 20):
        chain = random_chain(rng, n)
        bare = dataclasses.replace(chain, J_std=(), k_std=(), B_std=(), f_c_std=None)
        assert Chain.from_parameters(chain.parameters(), chain.std()) == chain
        assert Chain.from_parameters(chain.parameters(motor="J_m"), motor="J_m") == bare
        path = tmp_path / f"chain{n}.json"
        path.write_text(json.dumps(chain.to_json()))
        assert read_chain(path) == chain
        assert Chain.from_json(json.loads(path.read_text())) == chain


def test_a_chain_reaches_the_observer_the_controller_and_set_unchanged(tmp_path: Path) -> None:
    rng = random.Random(7)
    for n in (1, 3, 5):
        written = random_chain(rng, n)
        path = tmp_path / "chain.json"
        path.write_text(json.dumps(written.to_json()))
        chain = read_chain(path)
        assert chain == written
        bare = dataclasses.replace(chain, J_std=(), k_std=(), B_std=(), f_c_std=None)
        settings = ObserverSettings.for_chain(chain, k_to=K_T, estimator=1)
        assert settings.chain == bare and settings.problems() == []
        design = design_controller(settings.chain, k_t=K_T, h=1e-3)
        assert design.chain == bare
        # the FMUs' own names: both FMUs declare every one as a parameter
        parameters = chain.parameters()
        for fmu in (ReactionTorqueObserver, ActionReactionController):
            declared = fmu.interface(n)
            assert all(declared[name].causality == "parameter" for name in parameters)
        # --set text, parsed as the CLI parses it, over the observer's defaults
        values = observer_values(n, chain_assignments(chain, []))
        assert Chain.from_parameters(values, n=n) == bare
        # the controller FMU's parameters give the very same design
        fmu_params = {**parameters, "k_to": K_T}
        assert design_controller(fmu_params, h=1e-3) == design


def test_a_chain_without_its_motor_cannot_be_designed_for() -> None:
    chain = Chain(J=(5e-4,), k=(0.16,), B=(1e-5,), D_m=0.0, f_c=0.0)
    with pytest.raises(ValueError, match="J_m is not known"):
        design_controller(chain, k_t=K_T, h=1e-3)
    with pytest.raises(ValueError, match="k_t"):
        design_controller(dataclasses.replace(chain, J_m=2e-5), h=1e-3)
    with pytest.raises(ValueError, match="give the motor"):
        ObserverSettings.for_chain(chain, k_to=K_T)


def test_a_chain_file_with_a_bad_standard_error_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "chain.json"
    path.write_text(json.dumps({"J[1]": 1e-3, "k[1]": 1.0, "B[1]": 0.0, "std": {"k[1]": -1}}))
    with pytest.raises(ChainFileError, match=r"chain.json: std: k_std\[1\] = -1 must be >= 0"):
        read_chain(path)


@pytest.mark.slow
def test_the_identified_chain_is_the_chain_its_report_file_holds(tmp_path: Path) -> None:
    """identify_drive on the sample log, its report written as ``--out chain.json`` does,
    read back: the same Chain, standard errors included; then the observer's and the
    controller's with the datasheet's J_m."""
    log = arcosim.read_log(
        ROOT / "examples" / "data" / "belt_drive.csv",
        scales={"i_a": 1e-3, "theta_m": 0.0031415926535897933, "omega_m": 0.0031415926535897933},
    )
    result = arcosim.identify_drive(
        *(log.columns[c] for c in ("time", "i_a", "omega_m", "theta_m")),
        k_t=K_T,
        J_m=2.09e-5,
        encoder_cpr=2000,
    )
    identified = result.chain
    assert identified is not None and identified.n == result.masses
    fitted = result.choice.chain  # the fit's; the result adds the friction it rests on
    assert (identified.J, identified.k, identified.B) == (fitted.J, fitted.k, fitted.B)
    path = tmp_path / "chain.json"
    path.write_text(json.dumps(result.report(), indent=2))
    assert read_chain(path) == identified
    motor = dataclasses.replace(identified, J_m=2.09e-5)
    settings = ObserverSettings.for_chain(motor, k_to=K_T, estimator=1)
    assert design_controller(settings.chain, k_t=K_T, h=1e-3).chain == settings.chain
    assert {**motor.parameters(), "estimator": 1} == {
        "J_mo": 2.09e-5,
        **result.observer_parameters(),
    }


def test_every_parameter_a_chain_or_a_fit_names_has_its_unit() -> None:
    """The report prints a unit beside every value: each name the chain gives the FMUs
    (both motor-inertia spellings), and the fit's own (a rigid drive's load inertia, a
    load torque), has one, and the inertias, stiffnesses and torques read as such."""
    from arcosim.identification.drive_identification import DriveIdentification

    chain = Chain(J=(1e-3, 2e-3), k=(0.5, 0.3), B=(1e-4, 2e-4), J_m=2e-5, D_m=1e-5, f_c=2e-3)
    names = {*chain.parameters(), *chain.parameters(motor="J_m")}
    units = {name: Chain.unit(name) for name in names}
    assert {units[n] for n in ("J[2]", "J_mo", "J_m")} == {"kg·m²"}
    assert units["k[1]"] == "N·m/rad" and units["f_c"] == "N·m"
    rigid = DriveIdentification(0, {"J_load": 1e-4, "tau_load": 0.1}, {}, {}, friction={"f_c": 0})
    assert rigid.units == {"J_load": "kg·m²", "tau_load": "N·m", "f_c": "N·m"}
    with pytest.raises(KeyError):
        Chain.unit("g_dist")
