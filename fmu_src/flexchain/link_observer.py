"""The model-based observer on a flexible link's modal model: the tip's motion online.

A link clamped to the hub, in its hub-locked (clamped) modes ω_i, ζ_i with hub
participation b_i and tip shape value φ_i(L) (what ``arcosim identify --method beam``
reports; no eigen-solver here), obeys (docs/method.md, eq. 7)::

    q̈_i + 2 ζ_i ω_i q̇_i + ω_i² q_i = −b_i θ̈_m
    τ_reac = J_rigid θ̈_m + Σ b_i² θ̈_m + Σ b_i q̈_i,     w_tip = Σ φ_i(L) q_i

Written as a star of masses on their own springs to the hub (:func:`star_chain`: mass
b_i², spring b_i² ω_i², damper 2 ζ_i ω_i b_i², angle ``θ_i = θ_m + q_i / b_i``, the
convention of ``arcosim.identification.link.beam_model.ModalModel.star``), the modes are
exactly the model-based observer's driven spring–mass model
(:func:`~arcosim.fmu.flexchain.model_observer.step_model` with ``star=True``): the same
Kalman design and step, the star's momentum Σ b_i² ω̇_i its reaction torque. The link's
inertia outside the modes, ``J_rigid``, turns with the hub: the observer takes it off
τ̂_reac as the DOB would with J_mo + J_rigid (``τ̂_reac − J_rigid α̂_m``, the same G(s)).
After each step the tip follows from the star's angles:

    w_tip = Σ φ_i(L) b_i (θ̂_i − θ_m)   (m),      α_tip = w_tip / L   (rad)

Standard library only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .model_observer import ModelObserver, NoiseModel, StepModel, step_model


@dataclass(frozen=True)
class StarLink:
    """A link's modal model as the observer takes it.

    Parameters
    ----------
    omega : tuple of float
        Hub-locked frequencies ω_i (rad/s), > 0, shape ``(M,)``.
    zeta : tuple of float
        Damping ratios ζ_i (dimensionless), ≥ 0, shape ``(M,)``.
    b : tuple of float
        Hub participation b_i (kg·m per modal unit, i.e. √kg·m), ≠ 0, shape ``(M,)``.
    phi : tuple of float
        Tip shape values φ_i(L) (m per modal unit), shape ``(M,)``.
    J_rigid : float
        The link's inertia outside the modes, rigid on the hub beyond J_mo (kg·m²), ≥ 0.
    L : float
        Link length (m), > 0: α_tip = w_tip / L.
    """

    omega: tuple[float, ...]
    zeta: tuple[float, ...]
    b: tuple[float, ...]
    phi: tuple[float, ...]
    J_rigid: float
    L: float

    def chain(self) -> tuple[list[float], list[float], list[float]]:
        """The modes as a star of masses on springs to the hub (:func:`star_chain`)."""
        return star_chain(self.omega, self.zeta, self.b)

    def tip_gains(self) -> list[float]:
        """``φ_i(L) b_i`` (m per rad of θ_i − θ_m), shape ``(M,)``."""
        return [p * b for p, b in zip(self.phi, self.b)]


def star_chain(
    omega: Sequence[float], zeta: Sequence[float], b: Sequence[float]
) -> tuple[list[float], list[float], list[float]]:
    """A link's modes as masses on their own springs and dampers to the hub.

    Parameters
    ----------
    omega, zeta, b : Sequence[float]
        Hub-locked frequencies (rad/s), damping ratios (dimensionless) and hub
        participations (√kg·m), shape ``(M,)`` each.

    Returns
    -------
    tuple of list of float
        ``J_i = b_i²`` (kg·m²), ``k_i = b_i² ω_i²`` (N·m/rad) and
        ``B_i = 2 ζ_i ω_i b_i²`` (N·m·s/rad), shape ``(M,)`` each.

    Examples
    --------
    >>> star_chain([10.0], [0.01], [0.1])
    ([0.010000000000000002], [1.0000000000000002], [0.0020000000000000005])
    """
    J = [x * x for x in b]
    k = [j * w * w for j, w in zip(J, omega)]
    B = [2.0 * z * w * j for j, w, z in zip(J, omega, zeta)]
    return J, k, B


class LinkObserver(ModelObserver):
    """The link's modal coordinates, tip deflection and tip angle from θ_m and τ̂_reac.

    Parameters
    ----------
    link : StarLink
        The modal model.
    g_dist : float
        DOB bandwidth (rad/s), the ``G(s)`` of τ̂_reac.
    noise : NoiseModel
        Noise levels for the Kalman gain (``torque_noise_std`` on each star mass).
    theta0 : float
        Motor angle at start (rad); the link starts at rest, undeflected.

    Attributes
    ----------
    theta, omega : list of float
        After :meth:`step`: the star's angles θ̂_i (rad) and velocities (rad/s), shape
        ``(M,)``.
    w_tip : float
        Estimated tip deflection (m).
    alpha_tip : float
        Estimated tip deflection angle w_tip / L (rad).
    """

    def __init__(self, link: StarLink, g_dist: float, noise: NoiseModel, theta0: float) -> None:
        J, k, B = link.chain()
        super().__init__(J, k, B, g_dist, noise, theta0)
        self.link = link
        self.gains = link.tip_gains()
        self.w_tip = 0.0
        self.alpha_tip = 0.0

    def design(self, h: float) -> StepModel:
        """The step model for ``h`` (s): :func:`step_model` of the star."""
        return step_model(self.J, self.k, self.B, self.g_dist, self.noise, h, star=True)

    def step(self, h: float, tau_reac_hat: float, theta_m: float) -> None:
        """Take the sample that ends a step.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        tau_reac_hat : float
            τ̂_reac without the link's rigid share (N·m): ``τ̂_reac − J_rigid α̂_m``.
        theta_m : float
            The measured motor angle (rad).
        """
        super().step(h, tau_reac_hat, theta_m)
        u = self.u_prev
        self.w_tip = w = math.fsum(g * (x - u) for g, x in zip(self.gains, self.s))
        self.alpha_tip = w / self.link.L
