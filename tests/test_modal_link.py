"""The link simulated apart from the plant FMU (benchmarks/simulators/modal_link.py): the continuous
beam's modes on a free hub, against the boundary-value problem, the finite-element plant
and, identified from the hub, against Quanser's published link (a link we did not
write)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from arcosim.experiments.flexible_link import score_link, simulate_link
from benchmarks.link_frequencies import beam_frequencies
from benchmarks.published_link import RIG
from benchmarks.simulators.modal_link import link_modes, simulate_modal_link


def test_the_modes_are_the_continuous_beams_and_orthonormal() -> None:
    """Frequencies against benchmarks.link_frequencies' roots of the hub–beam
    characteristic equation (a different formulation: both exact, so to 1e-9), the modes
    orthonormal in the system's kinetic energy to rounding, and the rigid mode's hub
    participation 1/√J_total."""
    p = RIG.plant
    modes = link_modes(p["EI"], p["rhoA"], p["L"], p["J_m"], count=5)
    exact = beam_frequencies(p["EI"], p["rhoA"], p["L"], J_m=p["J_m"], count=5)
    np.testing.assert_allclose(modes.omega[1:], exact, rtol=1e-9)
    assert modes.orthogonality < 1e-10
    J_total = p["J_m"] + p["rhoA"] * p["L"] ** 3 / 3
    assert modes.hub[0] == pytest.approx(J_total**-0.5, rel=1e-12)


def test_it_refuses_what_it_does_not_model() -> None:
    with pytest.raises(ValueError, match=r"m_tip = 0\.005: the modal simulator has none"):
        simulate_modal_link(replace(RIG, plant={**RIG.plant, "m_tip": 0.005}), duration=0.01)


@pytest.mark.slow
def test_it_agrees_with_the_finite_element_plant(build_fmus) -> None:
    """2 s of the Quanser rig's multi-sine: the two simulators, written apart, agree to
    1 % in rms on the hub's speed, the tip angle and the reaction torque (the plant's six
    elements put its second mode 1e-4 high, its third 1e-3: measured 1e-4 … 5e-4)."""
    rig = replace(RIG, seed=2)
    modal = simulate_modal_link(rig, duration=2.0)
    plant = simulate_link(build_fmus(3) / "FlexLinkPlant.fmu", rig, duration=2.0)
    for name in ("omega_m_true", "alpha_tip", "tau_reac"):
        a, b = modal.signals[name], plant.signals[name]
        assert np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2)) < 1e-2, name


@pytest.mark.slow
def test_the_published_link_from_the_modal_simulator() -> None:
    """The link's targets on a simulator the fit shares nothing with: modes within 1 %,
    EI and ρA within 5 %, rms(α̂ − α) ≤ 0.1 rms(α) (measured, seed 1: 0.04 %, 0.01 %,
    0.014 %, 0.010)."""
    rig = replace(RIG, seed=1)
    found = score_link(simulate_modal_link(rig), rig)
    errors = found.errors()
    assert abs(errors["EI"]) < 5 and abs(errors["rhoA"]) < 5, errors
    assert abs(errors["mode[1]"]) < 1 and abs(errors["mode[2]"]) < 1, errors
    assert found.alpha_ratio <= 0.1
