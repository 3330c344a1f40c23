"""The flexible link's modal model against the analytic clamped-free beam, and its star
form (masses on springs to the hub) against the finite-element model it comes from."""

import numpy as np
import pytest
from scipy import optimize

from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.kalman import Drive
from arcosim.identification.link.beam_model import Link, assemble, modal_model

#: βL of the clamped-free Euler–Bernoulli beam, first four modes (Blevins, table 8-1).
CLAMPED_FREE = (1.8751040687, 4.6940911330, 7.8547574382, 10.9955407349)


def tip_mass_roots(mu: float, count: int) -> np.ndarray:
    """βL of a clamped beam with a tip mass μ·ρAL (no tip inertia): roots of
    1 + cos βL cosh βL + μ βL (cos βL sinh βL − sin βL cosh βL) = 0."""

    def f(x: float) -> float:
        c, s, ch, sh = np.cos(x), np.sin(x), np.cosh(x), np.sinh(x)
        return (1.0 + c * ch) / ch + mu * x * (c * sh - s * ch) / ch  # scaled by cosh

    grid = np.linspace(0.05, 15.0, 3000)
    values = [f(x) for x in grid]
    roots = [
        optimize.brentq(f, a, b)
        for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:])
        if fa * fb < 0
    ]
    return np.array(roots[:count])


@pytest.mark.parametrize("EI, rhoA, L", [(1.0, 1.0, 1.0), (2.95e-3, 0.02, 0.3), (40.0, 3.0, 1.2)])
def test_clamped_frequencies_match_the_analytic_beam(EI, rhoA, L):
    model = modal_model(Link(EI, rhoA, L), modes=4)
    analytic = np.array(CLAMPED_FREE) ** 2 * np.sqrt(EI / (rhoA * L**4))
    # cubic Hermite elements converge as h⁴: 24 elements leave 3e-5 on the fourth mode
    np.testing.assert_allclose(model.frequency, analytic, rtol=1e-4)
    np.testing.assert_allclose(model.frequency[:2], analytic[:2], rtol=2e-6)


@pytest.mark.parametrize("mu", [0.2, 1.0, 5.0])
def test_clamped_frequencies_with_a_tip_mass(mu):
    EI, rhoA, L = 0.02, 0.03, 0.4
    model = modal_model(Link(EI, rhoA, L, m_tip=mu * rhoA * L), modes=3)
    analytic = tip_mass_roots(mu, 3) ** 2 * np.sqrt(EI / (rhoA * L**4))
    np.testing.assert_allclose(model.frequency, analytic, rtol=1e-5)


def test_a_tip_mass_lowers_every_mode_and_its_limit_is_a_spring():
    light = modal_model(Link(1.0, 1.0, 1.0), 2).frequency
    heavy = modal_model(Link(1.0, 1.0, 1.0, m_tip=100.0), 2).frequency
    assert np.all(heavy < light)
    # a heavy tip on a light beam: the tip mass on the beam's tip stiffness 3EI/L³
    np.testing.assert_allclose(heavy[0], np.sqrt(3.0 / 100.0), rtol=2e-3)


def test_participations_sum_to_the_link_inertia():
    link = Link(0.02, 0.03, 0.4, m_tip=0.02, J_tip=2e-6, r_hub=0.02)
    every = modal_model(link, modes=48, elements=24)
    assert np.all(every.participation > 0)
    # every mode of the mesh: the rigid motion (r + x)θ projected on the clamped modes,
    # exact as the mesh refines (1.7e-5 short at 24 elements)
    np.testing.assert_allclose(np.sum(every.participation**2), link.rigid_inertia(), rtol=5e-5)
    rigid = 0.03 * (0.42**3 - 0.02**3) / 3 + 0.02 * 0.42**2 + 2e-6
    np.testing.assert_allclose(link.rigid_inertia(), rigid, rtol=1e-12)


def test_the_star_form_is_the_finite_element_link_seen_from_the_hub():
    """τ_reac/θ for a prescribed hub angle: the FE model against the star of ten modes
    with the rest rigid (J_rest), below, between and above the first modes; the rigid
    limit is J_link θ̈ (this project's sign: the torque the link exerts on the hub)."""
    link = Link(0.02, 0.03, 0.4, m_tip=0.02, J_tip=2e-6, r_hub=0.02)
    K, M, coupling = assemble(link, 24)
    model = modal_model(link, modes=10)  # the rest (J_rest) rigid: 1e-4 at 300 rad/s
    J, k, _ = model.star()
    for w in (0.05, 20.0, 150.0, 300.0):
        deflection = np.linalg.solve(K - w**2 * M, w**2 * coupling)  # per unit θ
        fe = -(w**2) * (link.rigid_inertia() + coupling @ deflection)
        star = -(w**2) * (model.J_rest + np.sum(J * k / (k - w**2 * J)))
        np.testing.assert_allclose(star, fe, rtol=2e-4)
        if w < 1.0:  # far below the first mode: τ_reac = J_link θ̈ = −ω² J_link θ
            assert fe == pytest.approx(-(w**2) * link.rigid_inertia(), rel=1e-3)


def test_quasi_static_tip_of_the_modes_left_out():
    link = Link(1.0, 1.0, 1.0, m_tip=0.3)
    every = modal_model(link, modes=40)
    kept = every.first(2)
    left = -np.sum(every.tip[2:] * every.participation[2:] / every.frequency[2:] ** 2)
    assert kept.tip_static == pytest.approx(left)
    first_two = np.sum(every.tip[:2] * every.participation[:2] / every.frequency[:2] ** 2)
    assert 0 < abs(kept.tip_static) < 0.05 * abs(first_two)


def test_a_star_of_one_mass_is_a_chain_of_one():
    chain = Drive(np.array([2e-4]), np.array([0.3]), np.array([1e-5]), 0.0, 0.0)
    star = Drive(np.array([2e-4]), np.array([0.3]), np.array([1e-5]), 0.0, 0.0, star=True)
    np.testing.assert_array_equal(chain.coupling(chain.k), star.coupling(star.k))
    three = Drive(np.ones(3), np.array([1.0, 2.0, 3.0]), np.zeros(3), 0.0, 0.0, star=True)
    np.testing.assert_array_equal(
        three.coupling(three.k), [[6, -1, -2, -3], [-1, 1, 0, 0], [-2, 0, 2, 0], [-3, 0, 0, 3]]
    )


@pytest.mark.parametrize(
    "link",
    [Link(0.0, 1.0, 1.0), Link(1.0, -1.0, 1.0), Link(1.0, 1.0, np.nan), Link(1.0, 1.0, 1.0, -1.0)],
)
def test_a_link_that_is_no_beam_is_refused(link):
    with pytest.raises(IdentificationError, match="must be a finite number"):
        modal_model(link)
