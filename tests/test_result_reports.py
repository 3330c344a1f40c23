"""The results the commands print carry their own report: the library builds the JSON and
the text (``.to_json()``, ``.text()``), the command line only prints them.

Checked on results built by hand, so each number in a report is known exactly: the
uniform chain's fit, the load torque's summary, a tracked replay's end, and the FMU
classes' parameters with ``--set`` applied.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import arcosim
from arcosim.host import TrackedChain, controller_problems, controller_values, observer_values
from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.uniform_identification import check_start_k


def _fit(names: list[str], values: list[float], std: list[float]) -> ParameterFit:
    return ParameterFit(
        names=names,
        values=np.array(values),
        std=np.array(std),
        start=np.array(values),
        start_note="given",
        rms_residual=1e-4,
        rms_data=1e-2,
        lag=7,
        evaluations=42,
    )


def test_the_uniform_chain_report_and_chain() -> None:
    J = (1e-4, 2e-4, 3e-4)
    fit = _fit(["k", "B", "J_scale"], [0.2, 1e-3, 1.1], [0.01, 1e-4, 0.05])
    found = arcosim.UniformChainIdentification(fit, J, 1000, "encoder", 1.0)
    chain = found.chain
    assert chain.k == (0.2,) * 3 and chain.B == (1e-3,) * 3
    assert chain.J == pytest.approx([1.1 * x for x in J], rel=1e-15)
    assert chain.J_std == pytest.approx([0.05 * x for x in J], rel=1e-15)
    report = found.to_json()
    assert [k for k in report if k.endswith("_hat") or k == "J_scale"] == [
        "k_hat",
        "B_hat",
        "J_scale",
    ]
    assert report["std"] == {"k_hat": 0.01, "B_hat": 1e-4, "J_scale": 0.05}
    assert report["newey_west_lag"] == 7 and "assumptions" not in report
    noted = found.with_assumption("defaults", "J_mo = 1")
    assert noted.to_json()["assumptions"] == {"defaults": "J_mo = 1"}
    text = noted.text().splitlines()
    assert text[0] == "1000 samples, output-error fit of the uniform chain (3 masses):"
    assert text[1].split() == ["k_hat", "0.2", "±", "0.01"]
    assert text[-1] == "  assumption, defaults: J_mo = 1"


def test_a_start_stiffness_outside_the_records_band_is_refused() -> None:
    """One load mass J on a spring k has its clamped mode at √(k/J): the record shows it
    from one period in its length (2π/T) to the Nyquist frequency (π/h)."""
    J, record = [1e-3], SimpleNamespace(duration=10.0, h=1e-3)
    low = (2.0 * math.pi / record.duration) ** 2 * J[0]
    high = (math.pi / record.h) ** 2 * J[0]
    for k in (low * 1.01, math.sqrt(low * high), high * 0.99):
        check_start_k(k, J, record)
    for k in (low * 0.99, high * 1.01):
        with pytest.raises(arcosim.IdentificationError, match="give a stiffness from"):
            check_start_k(k, J, record)


def test_a_uniform_chain_needs_positive_inertias() -> None:
    t = np.arange(10) * 1e-3
    motor = arcosim.Actuator(J_mo=2e-5, k_to=0.04)
    with pytest.raises(arcosim.IdentificationError, match="load inertias must be > 0"):
        arcosim.identify_uniform_chain(t, t, t, t, motor, [1e-4, 0.0])


def test_the_load_torque_summary() -> None:
    """A torque that steps to 0.5 N·m at 2 s: the last second (2 … 3 s) is all 0.5."""
    time = np.arange(3001) * 1e-3
    tau = np.where(time >= 1.5, 0.5, 0.0)
    theta = np.zeros((len(time), 2))
    innovation = np.full(len(time), 0.1)
    estimate = arcosim.LoadEstimate(time, tau, tau, theta, theta, innovation, 2, 20.0)
    report = estimate.to_json()
    assert report["masses"] == 2 and report["load_mass"] == 2 and report["samples"] == 3001
    assert report["final"] == 0.5 and report["mean_last_second"] == 0.5
    assert report["std_last_second"] == 0.0
    assert report["rms_innovation"] == pytest.approx(0.1, rel=1e-12)
    text = estimate.with_assumption("defaults", "D_m = 0").text().splitlines()
    assert text[0] == "3001 samples, load torque on mass 2 of 2 (bandwidth 20 rad/s):"
    assert text[-1] == "  assumption, defaults: D_m = 0"


def test_a_tracked_replay_reports_its_end() -> None:
    run = TrackedChain(
        np.array([0.0, 1.0, 2.0]),
        ("k[1]", "f_c"),
        ("N.m/rad", "N.m"),
        np.array([[1.0, 0.1], [0.9, 0.1], [0.8, 0.2]]),
        np.array([[0.1, 0.01], [0.05, 0.01], [0.02, 0.02]]),
        np.array([1.0, 0.1]),
        np.array([0, 1, 1]),
        np.array([0, 0, 1]),
    )
    summary = run.to_json()
    assert summary["tracked"]["k[1]"] == {"value": 0.8, "std": 0.02, "commissioning": 1.0}
    assert summary["first_alarm_time"] == 1.0
    assert (summary["drift_alarm"], summary["tracking_valid"]) == (1, 1)
    assert run.text().splitlines()[-2] == "  drift_alarm 1, first raised at 1 s"


def test_an_fmu_classes_parameters_with_set_applied() -> None:
    from arcosim.fmu.arobserver.fmu import ReactionTorqueObserver

    declared = ReactionTorqueObserver.interface(2)
    values = observer_values(2, ["k_to=0.05", "J[2]=3e-4"])
    assert values["k_to"] == 0.05 and values["J[2]"] == 3e-4
    assert values["g_dist"] == float(declared["g_dist"].start)
    with pytest.raises(arcosim.UserError, match="nothing"):
        observer_values(2, ["nothing=1"])
    assert controller_problems(3, controller_values(3, [])) == []
    assert controller_problems(3, controller_values(3, ["move_time=-1"]))
