"""The flexible-link plant FMU (plant_models/flexlink_c) against the continuous
Euler–Bernoulli beam and an independent finite-element model.

Frequencies are read off the FMU's free responses (its whole state is among its outputs)
and compared with the roots of the continuous boundary-value problem
(benchmarks/link_frequencies.py), hub locked (clamped–free) and hub free (coupled). The
tolerance is the consistent-mass Hermite element's own: its frequencies bound the exact
ones from above (Rayleigh–Ritz), and the leading relative error is (β ℓ)⁴ / 1440 for an
element of length ℓ and mode wavenumber β (eigenvalue error (β ℓ)⁴ / 720), allowed once
and a half where β ℓ <= 2.5 (the asymptotic range).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm, matrix_balance

from arcosim.build.clink import build_link
from arcosim.fmu.flexchain import defaults
from arcosim.host.instance import FmuInstance
from benchmarks.link_frequencies import (
    BETA,
    IDEAL,
    LINK,
    H,
    beam_frequencies,
    clamped_modes,
    coupled_modes,
    eq7_from_the_root_element,
    run,
)

#: (m_tip, J_tip): the bare beam, a tip mass, a tip mass with its own inertia
TIPS = [(0.0, 0.0), (defaults.LINK_M_TIP, 0.0), (defaults.LINK_M_TIP, 2e-5)]


def tolerance(omega: np.ndarray, elements: int) -> np.ndarray:
    """The relative frequency error allowed (see the module docstring); inf past β ℓ = 2.5."""
    beta_l = np.sqrt(omega / np.sqrt(LINK["EI"] / LINK["rhoA"])) * LINK["L"] / elements
    return np.where(beta_l <= 2.5, 1.5 * beta_l**4 / 1440.0, np.inf)


def relative_errors(got: np.ndarray, exact: np.ndarray, elements: int) -> np.ndarray:
    errors = got / exact - 1.0
    assert np.all(errors > -1e-8), f"below the exact frequencies: {errors}"
    assert np.all(errors <= tolerance(exact, elements)), (errors, tolerance(exact, elements))
    return errors


@pytest.fixture(scope="session")
def link_fmu(build_fmus) -> Path:
    """The link of ``make build`` (defaults.LINK_ELEMENTS elements)."""
    return build_fmus(3) / "FlexLinkPlant.fmu"


@pytest.fixture(scope="session")
def link_fmus(tmp_path_factory: pytest.TempPathFactory):
    """Links of 2, 4 and 8 elements, built once."""
    folder = tmp_path_factory.mktemp("links")
    return {e: build_link(e, folder / f"e{e}" / "FlexLinkPlant.fmu") for e in (2, 4, 8)}


@pytest.mark.parametrize(("m_tip", "J_tip"), TIPS)
def test_clamped_frequencies_match_the_continuous_beam(link_fmu, m_tip, J_tip) -> None:
    got = clamped_modes(link_fmu, defaults.LINK_ELEMENTS, m_tip, J_tip)
    exact = beam_frequencies(**LINK, m_tip=m_tip, J_tip=J_tip)
    relative_errors(got, exact, defaults.LINK_ELEMENTS)


def test_clamped_frequencies_of_the_classic_beam() -> None:
    """The test's own boundary-value solver: βL = 1.8751, 4.6941, 7.8548 without a tip
    mass; with one, the roots of 1 + cos cosh + μ βL (cos sinh − sin cosh) = 0."""
    scale = np.sqrt(LINK["EI"] / LINK["rhoA"]) / LINK["L"] ** 2
    bare = beam_frequencies(**LINK) / scale
    assert np.allclose(np.sqrt(bare), [1.8751041, 4.6940911, 7.8547574], atol=1e-6)
    mu = defaults.LINK_M_TIP / (LINK["rhoA"] * LINK["L"])
    bl = np.sqrt(beam_frequencies(**LINK, m_tip=defaults.LINK_M_TIP) / scale)
    residual = (
        1
        + np.cos(bl) * np.cosh(bl)
        + mu * bl * (np.cos(bl) * np.sinh(bl) - np.sin(bl) * np.cosh(bl))
    )
    assert np.all(np.abs(residual) < 1e-9 * np.cosh(bl))


@pytest.mark.parametrize(
    "parameters",
    [
        {},  # the defaults: a light hub, r = 1 cm, a tip mass
        {"J_m": 2e-3, "r_hub": 0.03, "J_tip": 2e-5},
        {"m_tip": 0.0, "r_hub": 0.0},
    ],
)
def test_coupled_frequencies_match_the_continuous_beam(link_fmu, parameters) -> None:
    value = {
        "J_m": defaults.J_M,
        "r": defaults.LINK_R_HUB,
        "m_tip": defaults.LINK_M_TIP,
        "J_tip": defaults.LINK_J_TIP,
    }
    value.update({("r" if k == "r_hub" else k): v for k, v in parameters.items()})
    got = coupled_modes(link_fmu, defaults.LINK_ELEMENTS, parameters)
    exact = beam_frequencies(**LINK, **value)
    relative_errors(got, exact, defaults.LINK_ELEMENTS)


@pytest.mark.slow
def test_frequencies_converge_as_the_fourth_power_of_the_element(link_fmus) -> None:
    """2, 4, 8 elements: each halving divides the error by about 16 (at least 8 asked)."""
    exact_clamped = beam_frequencies(**LINK, m_tip=defaults.LINK_M_TIP)
    exact_coupled = beam_frequencies(
        **LINK, m_tip=defaults.LINK_M_TIP, r=defaults.LINK_R_HUB, J_m=defaults.J_M
    )
    errors = {}
    for e, fmu in link_fmus.items():
        clamped = clamped_modes(fmu, e, defaults.LINK_M_TIP, 0.0)
        coupled = coupled_modes(fmu, e, {})
        errors[e] = np.array(
            [
                relative_errors(clamped[:2], exact_clamped[:2], e),
                relative_errors(coupled[:2], exact_coupled[:2], e),
            ]
        )
    assert np.all(errors[2] / errors[4] >= 8.0), errors
    assert np.all(errors[4] / errors[8] >= 8.0), errors


# -- the reaction torque ----------------------------------------------------------------


def test_hub_obeys_its_equation_with_the_reaction_torque(link_fmu) -> None:
    """Over every step, J_m Δω_m = k_t ∫ i dt − D_m Δθ_m − ∫ τ_reac dt: the sign
    convention of τ_reac (the chain plant's), with damping, current loop and tip. To
    rounding: τ_reac sums the root element's end forces, terms far larger than itself
    (EI/ℓ² times the nodal deflections), each exact to ~1e-13 of its size in the step's
    matrix exponential; 1e-7 of the motor's torque leaves room for 1e5 times less
    cancellation than that, and a wrong sign or a missing term is off by O(1)."""
    parameters = {**IDEAL, "D_m": 3e-4, "current_bandwidth": 500.0, "J_tip": 2e-5}
    t = np.arange(3000) * H
    current = 0.5 * np.sin(7.0 * t) + 0.3 * np.sin(95.0 * t) + 0.2 * np.sign(np.sin(40.0 * t))
    names = ["theta_m_true", "omega_m_true", "i_true", "tau_reac_mean"]
    x = run(link_fmu, parameters, current, H, names)
    theta = np.concatenate([[0.0], x[:, 0]])
    omega = np.concatenate([[0.0], x[:, 1]])
    lhs = defaults.J_M * np.diff(omega)
    rhs = defaults.K_T * x[:, 2] * H - 3e-4 * np.diff(theta) - x[:, 3] * H
    assert np.abs(lhs - rhs).max() <= 1e-7 * np.abs(defaults.K_T * x[:, 2] * H).max()


def j_link(m_tip: float, J_tip: float, r: float) -> float:
    """The link's rigid inertia about the axis (kg·m²)."""
    rhoA, L = LINK["rhoA"], LINK["L"]
    return rhoA * ((r + L) ** 3 - r**3) / 3.0 + m_tip * (r + L) ** 2 + J_tip


def test_reaction_torque_of_a_steady_acceleration_is_the_rigid_links(link_fmu) -> None:
    """A constant current: once the vibration has died out the link turns as a rigid
    body, τ_reac = J_link dω/dt = k_t i J_link / (J_m + J_link). With β = 2e-4 s the
    coupled first mode (about 200 rad/s) decays at β ω₁² / 2 ≈ 4 /s: 4 s leave e⁻¹⁶ of
    the start's ringing."""
    m_tip, J_tip, r = defaults.LINK_M_TIP, 2e-5, 0.03
    parameters = {**IDEAL, "J_tip": J_tip, "r_hub": r, "beta": 2e-4}
    x = run(link_fmu, parameters, np.full(5000, 0.2), H, ["tau_reac_mean", "tau_reac"])
    J = j_link(m_tip, J_tip, r)
    expected = defaults.K_T * 0.2 * J / (defaults.J_M + J)
    assert abs(x[-1000:, 0].mean() / expected - 1.0) < 1e-3
    assert abs(x[-1, 1] / expected - 1.0) < 1e-3


@pytest.mark.slow
def test_reaction_torque_converges_to_eq7_as_the_mesh_is_refined(link_fmus) -> None:
    """The FMU's τ_reac (the root element's end forces, its inertia share included)
    against eq. 7 evaluated on the root element's cubic: the gap is the root element's
    inertia and the cubic's curvature error, both vanishing as the element shrinks; and
    τ_reac itself converges."""
    r, beta = 0.02, BETA
    t = np.arange(1500) * H
    current = 0.4 * np.sin(20.0 * t) + 0.2 * np.sin(150.0 * t)
    names = ["w[1]", "w_slope[1]", "w_rate[1]", "w_slope_rate[1]", "tau_reac"]
    gaps, torques = {}, {}
    for e, fmu in link_fmus.items():
        x = run(fmu, {**IDEAL, "r_hub": r, "beta": beta}, current, H, names)
        torques[e] = x[:, 4]
        gaps[e] = np.abs(x[:, 4] - eq7_from_the_root_element(x, e, r, beta)).max()
    scale = np.abs(torques[8]).max()
    assert gaps[2] > gaps[4] > gaps[8], gaps
    assert gaps[8] < 0.05 * scale, (gaps, scale)
    assert np.abs(torques[4] - torques[8]).max() < np.abs(torques[2] - torques[8]).max()
    assert np.abs(torques[4] - torques[8]).max() < 1e-2 * scale


# -- an independent finite-element model ------------------------------------------------


def independent_link(elements: int, p: dict) -> tuple[np.ndarray, np.ndarray, callable]:
    """The link by finite elements in numpy: q = (θ, w₁, w₁', …), consistent masses, the
    tip's mass and inertia, C = β K + D_m on the hub; state (q, q', i). Returns the
    continuous A, B (input i_ref) and the reaction torque as a function of (x, ẋ): the
    rate of the link's angular momentum, J_link θ'' + M_θw w'' (not the end forces)."""
    le = p["L"] / elements
    nq = 2 * elements + 1
    M, K = np.zeros((nq, nq)), np.zeros((nq, nq))
    M[0, 0] = p["J_m"]
    for e in range(elements):
        a = e * le
        xs, ws = np.polynomial.legendre.leggauss(6)
        for xi, wi in zip(xs, ws, strict=True):
            x = a + (xi + 1) * le / 2
            s = (x - a) / le
            n = np.array(
                [
                    1 - 3 * s**2 + 2 * s**3,
                    le * (s - 2 * s**2 + s**3),
                    3 * s**2 - 2 * s**3,
                    le * (s**3 - s**2),
                ]
            )
            d2 = (
                np.array([(-6 + 12 * s), le * (-4 + 6 * s), (6 - 12 * s), le * (6 * s - 2)]) / le**2
            )
            # shape functions of (θ, the element's nodal DOFs): y = (r + x) θ + w
            g = np.zeros(nq)
            g[0] = p["r_hub"] + x
            dofs = [2 * e - 1, 2 * e, 2 * e + 1, 2 * e + 2]
            for k, dof in enumerate(dofs):
                if dof >= 1:
                    g[dof] += n[k]
            curv = np.zeros(nq)
            for k, dof in enumerate(dofs):
                if dof >= 1:
                    curv[dof] += d2[k]
            M += wi * le / 2 * p["rhoA"] * np.outer(g, g)
            K += wi * le / 2 * p["EI"] * np.outer(curv, curv)
    tip, slope = np.zeros(nq), np.zeros(nq)
    tip[0], tip[-2] = p["r_hub"] + p["L"], 1.0
    slope[0], slope[-1] = 1.0, 1.0
    M += p["m_tip"] * np.outer(tip, tip) + p["J_tip"] * np.outer(slope, slope)
    C = p["beta"] * K
    C[0, 0] += p["D_m"]
    Minv = np.linalg.inv(M)
    bw = p["current_bandwidth"]
    A = np.zeros((2 * nq + 1, 2 * nq + 1))
    A[:nq, nq : 2 * nq] = np.eye(nq)
    A[nq : 2 * nq, :nq] = -Minv @ K
    A[nq : 2 * nq, nq : 2 * nq] = -Minv @ C
    A[nq : 2 * nq, -1] = Minv[:, 0] * p["k_t"]
    A[-1, -1] = -bw
    B = np.zeros(2 * nq + 1)
    B[-1] = bw
    momentum = M[0].copy()
    momentum[0] -= p["J_m"]

    def reaction(xdot: np.ndarray) -> float:
        return float(momentum @ xdot[nq : 2 * nq])

    return A, B, reaction


def test_step_response_matches_an_independent_finite_element_model(link_fmu) -> None:
    """A current step through the current loop, damping, hub radius, tip mass and tip
    inertia: every output within 1e-9 of its range of the numpy model's exact
    zero-order-hold solution. Both exponentials are of balanced matrices (norm about 300
    instead of 1.4e7 in h = 1 ms): about 2⁹ squarings' rounding, 1e-13 a step, 1e-10
    over the 600 steps."""
    elements = defaults.LINK_ELEMENTS
    parameters = {
        **IDEAL,
        "D_m": 2e-4,
        "current_bandwidth": 300.0,
        "J_tip": 1e-5,
        "r_hub": 0.02,
        "beta": 1e-4,
    }
    p = {
        "J_m": defaults.J_M,
        "k_t": defaults.K_T,
        "m_tip": defaults.LINK_M_TIP,
        **LINK,
        **parameters,
    }
    A, B, reaction = independent_link(elements, p)
    n = len(A)
    big = np.zeros((n + 1, n + 1))
    big[:n, :n], big[:n, n] = A, B
    balanced, (scale, _) = matrix_balance(big * H, permute=False, separate=True)
    step = expm(balanced) * scale[:, None] / scale[None, :]
    x, rows = np.zeros(n), []
    current = np.where(np.arange(600) < 300, 0.5, -0.2)
    for i_ref in current:
        x = step[:n, :n] @ x + step[:n, n] * i_ref
        nq = 2 * elements + 1
        rows.append([x[0], x[nq], x[nq - 2], reaction(A @ x + B * i_ref)])
    expected = np.array(rows)
    names = ["theta_m_true", "omega_m_true", "w_tip", "tau_reac"]
    got = run(link_fmu, parameters, current, H, names)
    worst = np.abs(got - expected).max(axis=0) / np.abs(expected).max(axis=0)
    assert worst.max() <= 1e-9, dict(zip(names, worst, strict=True))
    alpha = run(link_fmu, parameters, current[:50], H, ["alpha_tip", "w_tip"])
    assert np.allclose(alpha[:, 0], alpha[:, 1] / LINK["L"], rtol=1e-15, atol=0.0)


# -- refusals ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("parameters", "message"),
    [
        ({"EI": 0.0}, "parameter EI = 0.0 must be > 0"),
        ({"m_tip": -1.0}, "parameter m_tip = -1.0 must be >= 0"),
        ({"beta": 1e-2}, "lower beta, or build with fewer elements"),
        ({"EI": 1e9, "rhoA": 1e-6}, "build with fewer elements, or soften the link"),
    ],
)
def test_bad_parameters_are_refused_with_their_reason(link_fmu, parameters, message) -> None:
    with FmuInstance(link_fmu, "bad") as link:
        with pytest.raises(Exception):  # noqa: B017 - fmpy raises its FMICallException
            link.initialize(parameters)
        assert any(message in m for m in link.messages), link.messages


@pytest.mark.parametrize("elements", ["0", "17"])
def test_build_refuses_an_element_count_out_of_range(tmp_path, capsys, elements) -> None:
    from arcosim.cli import main

    assert main(["build", "--elements", elements, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert (
        f"--elements {elements}: the number of the link's Hermite elements must be 1 to 16" in err
    )
    assert not list(tmp_path.iterdir())  # nothing built
