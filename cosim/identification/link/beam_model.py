"""A flexible link's modal model from its geometry: Euler–Bernoulli beam on a hub (offline).

A hub (everything rigid on the motor shaft, J_m) turns by θ; an Euler–Bernoulli beam
(bending stiffness EI, mass per length ρA, length L) is clamped to it at radius r, with
an optional tip mass m_tip and tip inertia J_tip. Small deflection w(x, t) in the
rotating frame: a point of the beam is at y(x, t) = (r + x) θ + w(x, t), with
w(0) = w'(0) = 0. In the hub-locked (clamped) modes φ_i (mass-normalized, frequencies
ω_i) the link obeys (docs/method.md, eq. 7)::

    J_total θ̈ + Σ b_i q̈_i = τ_m − friction
    q̈_i + 2 ζ_i ω_i q̇_i + ω_i² q_i = −b_i θ̈
    b_i = ∫ ρA (r + x) φ_i dx + m_tip (r + L) φ_i(L) + J_tip φ_i'(L)

and the torque the link exerts on the hub is ``τ_reac = J_link θ̈ + Σ b_i q̈_i``
(J_link the link's rigid inertia about the shaft); the tip deflects by
``w_tip = Σ φ_i(L) q_i`` (m), ``α_tip = w_tip / L`` (rad).

:func:`modal_model` finds ω_i, φ_i(L), b_i by Hermite cubic finite elements (the
clamped eigenproblem of the link alone). :meth:`ModalModel.star` writes the same link
as the drive models of :mod:`arcosim.identification.fit.kalman` take it: each mode a mass
b_i² on its own spring b_i² ω_i² and damper 2 ζ_i ω_i b_i² to the hub (then
``q_i = b_i (θ_i − θ)``), the modes left out of the model rigid on the hub
(``J_rest = J_link − Σ b_i²``): exactly the modal equations above.
:func:`equivalent_chain` is the lumped chain with the same modes seen from the hub (the
cross-check a report carries), :func:`modal_report` the model as a report gives it,
:func:`observer_parameters` the observer FMU's parameters for it (the tip online).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.codes import Estimator
from arcosim.fmu.flexchain.link_observer import star_chain
from arcosim.identification.errors import IdentificationError
from arcosim.identification.modes.chain_modes import chain_from_modes
from arcosim.identification.modes.detection import Modes, modal_damping

#: Hermite elements the modal model uses by default: the first four clamped modes
#: within 1e-4 (relative) of the analytic ones (tests/test_beam_model.py).
ELEMENTS = 24


@dataclass(frozen=True)
class Link:
    """A flexible link's geometry and material: what :func:`modal_model` needs.

    Attributes
    ----------
    EI : float
        Bending stiffness (N·m²), > 0.
    rhoA : float
        Mass per length (kg/m), > 0.
    L : float
        Length from the clamp to the tip (m), > 0.
    m_tip : float
        Tip mass (kg), ≥ 0.
    J_tip : float
        Tip mass's own inertia about its centre (kg·m²), ≥ 0.
    r_hub : float
        Radius of the clamp from the shaft (m), ≥ 0.

    Examples
    --------
    >>> Link(EI=0.04, rhoA=0.03, L=0.3, m_tip=0.005)  # N·m², kg/m, m, kg
    Link(EI=0.04, rhoA=0.03, L=0.3, m_tip=0.005, J_tip=0.0, r_hub=0.0)
    """

    EI: float
    rhoA: float
    L: float
    m_tip: float = 0.0
    J_tip: float = 0.0
    r_hub: float = 0.0

    def rigid_inertia(self) -> float:
        """The link's inertia about the shaft, rigid (kg·m²): beam, tip mass, tip
        inertia."""
        r, L = self.r_hub, self.L
        beam = self.rhoA * ((r + L) ** 3 - r**3) / 3.0
        return beam + self.m_tip * (r + L) ** 2 + self.J_tip


@dataclass(frozen=True)
class ModalModel:
    """A link's hub-locked modes and what the hub and tip see of them.

    Attributes
    ----------
    frequency : ndarray
        Clamped frequencies ω_i (rad/s), ascending, shape ``(M,)``.
    participation : ndarray
        Hub participation b_i (kg·m per mass-normalized unit, i.e. √(kg)·m), shape
        ``(M,)``; the sign of each mode shape is chosen so that b_i > 0.
    tip : ndarray
        Tip deflection per modal coordinate φ_i(L) (m per unit q_i), shape ``(M,)``.
    damping : ndarray
        Modal damping ratios ζ_i (dimensionless), shape ``(M,)``.
    J_link : float
        The link's rigid inertia about the shaft (kg·m²).
    L : float
        Link length (m): α_tip = w_tip / L.
    tip_static : float
        Tip deflection per hub acceleration of the modes left out, quasi-static
        (m per rad/s²): ``−Σ φ_i(L) b_i / ω_i²`` over them (0 when none were computed).

    Examples
    --------
    >>> model = modal_model(Link(EI=1.0, rhoA=1.0, L=1.0), modes=2)
    >>> model.frequency.shape, round(model.J_link, 6)  # ρA L³ / 3 (kg·m²)
    ((2,), 0.333333)
    """

    frequency: np.ndarray
    participation: np.ndarray
    tip: np.ndarray
    damping: np.ndarray
    J_link: float
    L: float
    tip_static: float = 0.0

    def first(self, count: int) -> ModalModel:
        """The model with its first ``count`` modes (the rest rigid on the hub, their
        quasi-static tip deflection in :attr:`tip_static`)."""
        part, rest = slice(0, count), slice(count, None)
        left = self.tip[rest] * self.participation[rest] / self.frequency[rest] ** 2
        return ModalModel(
            self.frequency[part],
            self.participation[part],
            self.tip[part],
            self.damping[part],
            self.J_link,
            self.L,
            self.tip_static - float(np.sum(left)),
        )

    def with_damping(self, damping: np.ndarray | float) -> ModalModel:
        """The same modes with damping ratios ``damping`` (dimensionless; one or per mode)."""
        zeta = np.broadcast_to(np.asarray(damping, dtype=float), self.frequency.shape).copy()
        return ModalModel(
            self.frequency, self.participation, self.tip, zeta, self.J_link, self.L, self.tip_static
        )

    @property
    def J_rest(self) -> float:
        """The link's inertia not in the modes kept, rigid on the hub (kg·m²)."""
        return self.J_link - float(np.sum(self.participation**2))

    def star(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The modes as masses on their own springs to the hub: ``(J, k, B)`` (kg·m²,
        N·m/rad, N·m·s/rad), shape ``(M,)`` each; with :attr:`J_rest` on the hub this
        is the modal model exactly (:func:`~arcosim.fmu.flexchain.link_observer.star_chain`,
        the observer FMU's arithmetic)."""
        J, k, B = star_chain(
            self.frequency.tolist(), self.damping.tolist(), self.participation.tolist()
        )
        return np.array(J), np.array(k), np.array(B)

    def residues(self) -> np.ndarray:
        """Driving-point residues r_i = b_i² ω_i⁴ (N·m/rad·s⁻²) of
        ``τ/θ = k_1 − Σ r_i/(s² + ω_i²)`` (:mod:`arcosim.identification.modes.chain_modes`),
        shape ``(M,)``."""
        return self.participation**2 * self.frequency**4


def modal_report(model: ModalModel) -> dict:
    """The modal model and its equivalent chain, JSON-able: ``modes_rad_s``,
    ``damping_ratios``, ``participation`` (√kg·m), ``tip_shape_m`` (m), ``J_rest``
    (kg·m²) and ``chain`` (``J[i]``, ``k[i]``, ``B[i]``, :func:`equivalent_chain`)."""
    return {
        "modes_rad_s": [float(w) for w in model.frequency],
        "damping_ratios": [float(z) for z in model.damping],
        "participation": [float(b) for b in model.participation],
        "tip_shape_m": [float(p) for p in model.tip],
        "J_rest": float(model.J_rest),
        "chain": equivalent_chain(model),
    }


def observer_parameters(model: ModalModel) -> dict[str, float | int]:
    """The observer FMU's parameters for the link (``ReactionTorqueObserver``, estimator 1
    on ``link_modes`` modes; docs/fmus/observer.md), by the FMU's names: ``estimator``,
    ``link_modes``, ``omega_link[i]`` (rad/s), ``zeta_link[i]``, ``b_link[i]`` (√kg·m),
    ``phi_tip[i]`` (m per modal unit), ``J_link_rigid`` (kg·m²) and ``L_link`` (m).

    At most :data:`~arcosim.fmu.flexchain.defaults.LINK_MODES_MAX` modes (the FMU's
    arrays): the modes past them count rigid on the hub, in ``J_link_rigid``, which is
    the link's inertia outside the modes kept (0 if the fit left it negative).

    Parameters
    ----------
    model : ModalModel
        The link's modal model (:func:`modal_model`, or an identification's).

    Returns
    -------
    dict of str to float or int
        Name → value, for ``--set NAME=VALUE`` or an FMU's start values.

    Examples
    --------
    >>> model = modal_model(Link(EI=1.0, rhoA=0.1, L=0.4), modes=1)
    >>> sorted(observer_parameters(model))  # doctest: +NORMALIZE_WHITESPACE
    ['J_link_rigid', 'L_link', 'b_link[1]', 'estimator', 'link_modes', 'omega_link[1]',
     'phi_tip[1]', 'zeta_link[1]']
    """
    kept = model.first(min(len(model.frequency), defaults.LINK_MODES_MAX))
    out: dict[str, float | int] = {
        "estimator": int(Estimator.MODEL_BASED),
        "link_modes": len(kept.frequency),
    }
    columns = (
        ("omega_link", kept.frequency),
        ("zeta_link", kept.damping),
        ("b_link", kept.participation),
        ("phi_tip", kept.tip),
    )
    for name, values in columns:
        out.update({f"{name}[{i}]": float(v) for i, v in enumerate(values, start=1)})
    out.update(J_link_rigid=max(float(kept.J_rest), 0.0), L_link=float(kept.L))
    return out


def equivalent_chain(model: ModalModel) -> dict[str, float]:
    """The lumped chain with the link's modes (the Lanczos inverse of their frequencies
    and residues, :func:`~arcosim.identification.modes.chain_modes.chain_from_modes`), its
    spring dampers from the modal damping: ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad),
    ``B[i]`` (N·m·s/rad), ``masses``. The link's inertia outside the modes is not in it
    (it belongs to the hub)."""
    J, k = chain_from_modes(model.frequency, model.residues())
    modes = Modes(model.frequency, model.damping, model.residues(), np.ones(1), np.inf)
    B = modal_damping(J, k, modes)
    out: dict[str, float] = {"masses": len(J)}
    for name, values in (("J", J), ("k", k), ("B", B)):
        out.update({f"{name}[{i}]": float(v) for i, v in enumerate(values, start=1)})
    return out


def modal_model(link: Link, modes: int = 4, elements: int = ELEMENTS) -> ModalModel:
    """The link's first ``modes`` clamped modes by Hermite cubic finite elements.

    Parameters
    ----------
    link : Link
        Geometry and material.
    modes : int
        Modes kept (a count), 1 … 2·``elements``.
    elements : int
        Beam elements of equal length (a count).

    Returns
    -------
    ModalModel
        ω_i (rad/s), b_i, φ_i(L) (m), ζ_i = 0, J_link (kg·m²), L (m).

    Raises
    ------
    IdentificationError
        For a non-positive EI, ρA or L, a negative tip mass, tip inertia or hub radius,
        or more modes than the mesh has.

    Examples
    --------
    >>> model = modal_model(Link(EI=1.0, rhoA=1.0, L=1.0), modes=2)
    >>> np.round(np.sqrt(model.frequency), 4).tolist()  # βL of the clamped-free beam
    [1.8751, 4.6941]
    """
    _check(link)
    if not 1 <= modes <= 2 * elements:
        raise IdentificationError(
            f"a mesh of {elements} elements has 1 … {2 * elements} modes, asked for {modes}"
        )
    K, M, coupling = assemble(link, elements)
    eigenvalues, shapes = scipy.linalg.eigh(K, M, subset_by_index=[0, modes - 1])
    b = shapes.T @ coupling
    sign = np.where(b < 0, -1.0, 1.0)
    shapes = shapes * sign
    return ModalModel(
        frequency=np.sqrt(eigenvalues),
        participation=b * sign,
        tip=shapes[-2].copy(),
        damping=np.zeros(modes),
        J_link=link.rigid_inertia(),
        L=link.L,
    )


def assemble(link: Link, elements: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness K (N·m per unit dof), mass M and hub coupling M_wθ of the clamped
    beam's free dofs ``[w_1, w'_1, …, w_E, w'_E]`` (node 0 at the clamp removed):
    shapes ``(2E, 2E)``, ``(2E, 2E)``, ``(2E,)``; tip mass and inertia on the last
    node."""
    size = 2 * (elements + 1)
    K = np.zeros((size, size))
    M = np.zeros((size, size))
    coupling = np.zeros(size)
    h = link.L / elements
    k_e = (link.EI / h**3) * np.array(
        [
            [12.0, 6 * h, -12.0, 6 * h],
            [6 * h, 4 * h * h, -6 * h, 2 * h * h],
            [-12.0, -6 * h, 12.0, -6 * h],
            [6 * h, 2 * h * h, -6 * h, 4 * h * h],
        ]
    )
    m_e = (link.rhoA * h / 420.0) * np.array(
        [
            [156.0, 22 * h, 54.0, -13 * h],
            [22 * h, 4 * h * h, 13 * h, -3 * h * h],
            [54.0, 13 * h, 156.0, -22 * h],
            [-13 * h, -3 * h * h, -22 * h, 4 * h * h],
        ]
    )
    # ∫ (r + x) N_j dx over an element from x_a: (r + x_a) ∫N + h ∫ξN, ξ ∈ [0, 1]
    mean = h * np.array([0.5, h / 12.0, 0.5, -h / 12.0])
    moment = h * h * np.array([3.0 / 20.0, h / 30.0, 7.0 / 20.0, -h / 20.0])
    for e in range(elements):
        dofs = slice(2 * e, 2 * e + 4)
        K[dofs, dofs] += k_e
        M[dofs, dofs] += m_e
        coupling[dofs] += link.rhoA * ((link.r_hub + e * h) * mean + moment)
    M[-2, -2] += link.m_tip
    M[-1, -1] += link.J_tip
    coupling[-2] += link.m_tip * (link.r_hub + link.L)
    coupling[-1] += link.J_tip
    return K[2:, 2:], M[2:, 2:], coupling[2:]


def _check(link: Link) -> None:
    positive = {"EI": link.EI, "rhoA": link.rhoA, "L": link.L}
    for name, value in positive.items():
        if not np.isfinite(value) or value <= 0:
            raise IdentificationError(f"the link's {name} must be a finite number > 0, got {value}")
    for name in ("m_tip", "J_tip", "r_hub"):
        value = getattr(link, name)
        if not np.isfinite(value) or value < 0:
            raise IdentificationError(f"the link's {name} must be a finite number ≥ 0, got {value}")
