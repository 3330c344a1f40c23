"""The baselines a sensorless motion controller is compared with: a drive's cascade.

A drive tuned out of the box closes a velocity PI loop on the motor's encoder, at a
bandwidth below the first mode on the total inertia, and a position P loop around it at
a quarter of that bandwidth, on a smooth profile of the move, with the profile's
velocity and torque fed forward; nothing in it knows the load is flexible.
:class:`CascadeController` is that drive; with a :class:`Shaper` (ZV or ZVD on the
modes of the identified chain under the cascade, convolved with the profile) it is the
vendor's vibration suppression.
Both have the controller's ``step(h, theta_ref, i_a, omega_m, theta_m) -> i_ref``.

Parameters come by the observer FMU's names (``J_mo``, ``k_to``, ``J[i]``, ``k[i]``,
``B[i]``), as :meth:`arcosim.DriveIdentification.observer_parameters` gives the chain.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from arcosim.fmu.flexchain.chain import Chain, spring_matrix

#: The cascade's velocity bandwidth as a fraction of the chain's lowest mode.
VELOCITY_FRACTION = 0.5
#: The position loop's gain, and the velocity PI's zero, as fractions of the velocity
#: bandwidth: a quarter each.
OUTER_FRACTION = 0.25
#: The velocity feedback's first-order filter, in multiples of the velocity bandwidth:
#: the encoder's backward difference jumps by a whole count per step (3.1 rad/s at 2000
#: counts and 1 ms).
VELOCITY_FILTER = 5.0


def chain_modes(params: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """The flexible modes of the free motor and its chain, lowest first.

    Parameters
    ----------
    params : mapping of str to float
        ``J_mo`` (kg·m²), ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]`` (N·m·s/rad),
        ``D_m`` (N·m·s/rad, optional, 0 if absent).

    Returns
    -------
    frequencies : ndarray
        Undamped natural frequencies (rad/s), shape ``(n,)``.
    damping : ndarray
        Damping ratios (dimensionless), shape ``(n,)``.

    Examples
    --------
    >>> f, z = chain_modes({"J_mo": 1.0, "J[1]": 1.0, "k[1]": 2.0, "B[1]": 0.0})
    >>> round(float(f[0]), 6), abs(float(z[0])) < 1e-12  # sqrt(k (1/J_m + 1/J_1)), undamped
    (2.0, True)
    """
    chain = Chain.from_parameters(params)  # D_m absent: 0 (Chain.state_space)
    poles = np.linalg.eigvals(np.array(chain.state_space()[0]))
    size = np.abs(poles)
    # one of each oscillating pair; the rigid body's two poles at (or rounded near) 0 drop
    poles = poles[(poles.imag > 1e-9) & (size > 1e-6 * np.max(size))]
    poles = poles[np.argsort(np.abs(poles))]
    return np.abs(poles), -poles.real / np.abs(poles)


def total_inertia(params: Mapping[str, float]) -> float:
    """Motor and every load mass (kg·m²): what a rigid-body tuning sees.

    Examples
    --------
    >>> total_inertia({"J_mo": 1e-5, "J[1]": 2e-4, "J[2]": 3e-4})
    0.00051
    """
    loads = [float(v) for name, v in params.items() if name.startswith("J[")]
    return float(params["J_mo"]) + sum(loads)


@dataclass(frozen=True)
class CascadeGains:
    """A cascade's gains, as a drive's manual states them.

    Attributes
    ----------
    velocity_bandwidth : float
        ω_v (rad/s): the velocity loop's crossover on the total inertia.
    kv : float
        Velocity proportional gain (A·s/rad): J_total ω_v / k_t.
    ki : float
        Velocity integral gain (A/rad): kv ω_v / 4.
    kp : float
        Position gain (1/s): ω_v / 4.
    inertia : float
        The total inertia tuned for (kg·m²).
    k_t : float
        Torque constant (N·m/A).
    velocity_filter : float
        Bandwidth of the velocity feedback's low-pass (rad/s).
    """

    velocity_bandwidth: float
    kv: float
    ki: float
    kp: float
    inertia: float
    k_t: float
    velocity_filter: float

    def text(self) -> str:
        """One line: every gain with its unit."""
        return (
            f"ω_v = {self.velocity_bandwidth:.3g} rad/s, Kv = {self.kv:.3g} A·s/rad, "
            f"Ki = {self.ki:.3g} A/rad, Kp = {self.kp:.3g} 1/s, "
            f"J_total = {self.inertia:.4g} kg·m², velocity filter {self.velocity_filter:.3g} rad/s"
        )


def cascade_gains(params: Mapping[str, float], bandwidth: float | None = None) -> CascadeGains:
    """The out-of-the-box cascade for a chain: ω_v = :data:`VELOCITY_FRACTION` × its first mode.

    Parameters
    ----------
    params : mapping of str to float
        ``J_mo``, ``k_to`` and the chain (:func:`chain_modes`).
    bandwidth : float, optional
        ω_v (rad/s) instead of the fraction of the first mode (a rigid inertia has no mode).

    Returns
    -------
    CascadeGains
        The gains (a rigid inertia J_total under ``kv`` closes its velocity loop at ω_v).

    Examples
    --------
    >>> g = cascade_gains({"J_mo": 1e-4, "k_to": 0.05, "J[1]": 4e-4}, bandwidth=10.0)
    >>> round(g.kv, 6), g.kp  # A·s/rad, 1/s
    (0.1, 2.5)
    """
    if bandwidth is None:
        bandwidth = VELOCITY_FRACTION * float(chain_modes(params)[0][0])
    inertia = total_inertia(params)
    k_t = float(params["k_to"])
    kv = inertia * bandwidth / k_t
    return CascadeGains(
        velocity_bandwidth=bandwidth,
        kv=kv,
        ki=kv * OUTER_FRACTION * bandwidth,
        kp=OUTER_FRACTION * bandwidth,
        inertia=inertia,
        k_t=k_t,
        velocity_filter=VELOCITY_FILTER * bandwidth,
    )


def smooth_profile(t: np.ndarray | float, distance: float, move_time: float):
    """The minimum-jerk move: position, velocity, acceleration at times ``t`` after its start.

    s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ with τ = t / ``move_time`` clipped to [0, 1]: zero velocity
    and acceleration at both ends; the peak acceleration is 5.77 ``distance`` / T².

    Parameters
    ----------
    t : ndarray or float
        Time since the move's start (s), any shape.
    distance : float
        Length of the move (rad).
    move_time : float
        Its duration T (s), > 0.

    Returns
    -------
    tuple of ndarray
        Position (rad), velocity (rad/s), acceleration (rad/s²), the shape of ``t``.

    Examples
    --------
    >>> p, v, a = smooth_profile(np.array([0.0, 0.5, 2.0]), 1.0, 1.0)
    >>> p.tolist(), v.tolist()
    ([0.0, 0.5, 1.0], [0.0, 1.875, 0.0])
    """
    tau = np.clip(np.asarray(t, dtype=float) / move_time, 0.0, 1.0)
    p = distance * tau**3 * (10 - 15 * tau + 6 * tau**2)
    v = distance / move_time * 30 * tau**2 * (1 - tau) ** 2
    a = distance / move_time**2 * 60 * tau * (1 - tau) * (1 - 2 * tau)
    return p, v, a


@dataclass(frozen=True)
class Shaper:
    """An input shaper: impulses of ``amplitudes`` (summing to 1) at ``times`` (s).

    Examples
    --------
    >>> s = Shaper.zv(2 * np.pi, 0.0)  # 1 Hz undamped: half and half, half a period apart
    >>> s.amplitudes, s.times
    ((0.5, 0.5), (0.0, 0.5))
    """

    times: tuple[float, ...]
    amplitudes: tuple[float, ...]

    @staticmethod
    def _k(omega: float, zeta: float) -> tuple[float, float]:
        """K = exp(−ζπ/√(1−ζ²)) and the damped half period π/ω_d (s)."""
        root = math.sqrt(1.0 - zeta**2)
        return math.exp(-zeta * math.pi / root), math.pi / (omega * root)

    @classmethod
    def zv(cls, omega: float, zeta: float) -> Shaper:
        """Zero vibration at one mode (ω rad/s, ζ dimensionless): two impulses."""
        K, half = cls._k(omega, zeta)
        return cls((0.0, half), (1 / (1 + K), K / (1 + K)))

    @classmethod
    def zvd(cls, omega: float, zeta: float) -> Shaper:
        """Zero vibration and derivative at one mode: three impulses, robust to ±20 % of ω."""
        K, half = cls._k(omega, zeta)
        d = (1 + K) ** 2
        return cls((0.0, half, 2 * half), (1 / d, 2 * K / d, K**2 / d))

    def then(self, other: Shaper) -> Shaper:
        """The two shapers in series (their convolution), impulses sorted by time."""
        pairs = sorted(
            (t1 + t2, a1 * a2)
            for t1, a1 in zip(self.times, self.amplitudes)
            for t2, a2 in zip(other.times, other.amplitudes)
        )
        return Shaper(tuple(t for t, _ in pairs), tuple(a for _, a in pairs))

    @property
    def duration(self) -> float:
        """The delay the shaper adds to a move (s): its last impulse's time."""
        return self.times[-1]


def cascade_modes(
    params: Mapping[str, float], gains: CascadeGains
) -> tuple[np.ndarray, np.ndarray]:
    """The oscillating modes of the chain under the cascade, lowest first (friction left out).

    What the load rings at after a move: the loop moves the chain's modes (the bench's
    16.8, 30.2 rad/s become 20.1, 31.2 and a loop mode at 5.4 rad/s appears).

    Parameters
    ----------
    params : mapping of str to float
        ``J_mo``, ``D_m`` (optional) and the chain (:func:`chain_modes`).
    gains : CascadeGains
        The cascade's gains.

    Returns
    -------
    frequencies : ndarray
        Natural frequencies (rad/s), shape ``(M,)``.
    damping : ndarray
        Damping ratios (dimensionless), shape ``(M,)``.
    """
    chain = Chain.from_parameters(params)
    J, k, B = chain.J, chain.k, chain.B
    m = len(J) + 1
    inverse = np.linalg.inv(np.diag([float(params["J_mo"]), *J]))
    C = np.array(spring_matrix(B))
    C[0, 0] += float(params.get("D_m", 0.0))
    # states: angles (m), velocities (m), the PI's integral (A), the filtered velocity
    A = np.zeros((2 * m + 2, 2 * m + 2))
    A[:m, m : 2 * m] = np.eye(m)
    A[m : 2 * m, :m] = -inverse @ np.array(spring_matrix(k))
    A[m : 2 * m, m : 2 * m] = -inverse @ C
    error = np.zeros(2 * m + 2)  # the velocity error at rest at the target
    error[0], error[-1] = -gains.kp, -1.0
    current = gains.kv * error
    current[2 * m] += 1.0
    A[m : 2 * m] += np.outer(inverse[:, 0] * gains.k_t, current)
    A[2 * m] = gains.ki * error
    A[-1, m], A[-1, -1] = gains.velocity_filter, -gains.velocity_filter
    poles = np.linalg.eigvals(A)
    poles = poles[poles.imag > 1e-9]
    poles = poles[np.argsort(np.abs(poles))]
    return np.abs(poles), -poles.real / np.abs(poles)


def cascade_shaper(params: Mapping[str, float], gains: CascadeGains, kind: str = "zv") -> Shaper:
    """A shaper for every mode of the chain under the cascade below its velocity filter.

    The modes are the cascade's (:func:`cascade_modes`) on the identified chain: a
    shaper on the free chain's modes leaves the bench's last mass ringing as much as
    none (14 against 16 mrad rms), on the cascade's it settles (2.6 mrad rms, ZV).

    Parameters
    ----------
    params : mapping of str to float
        The (identified) chain (:func:`chain_modes`).
    gains : CascadeGains
        The cascade's gains.
    kind : {"zv", "zvd"}
        The shaper per mode: ZV adds half a period of each mode to the move, ZVD a whole
        one (the bench: 0.86 s and 1.71 s).

    Returns
    -------
    Shaper
        The product of one shaper per mode.
    """
    if kind not in ("zv", "zvd"):
        raise ValueError(f"kind must be 'zv' or 'zvd', got {kind!r}")
    shaper = Shaper((0.0,), (1.0,))
    for omega, zeta in shaped_modes(params, gains):
        shaper = shaper.then(getattr(Shaper, kind)(omega, zeta))
    return shaper


def shaped_modes(params: Mapping[str, float], gains: CascadeGains) -> list[tuple[float, float]]:
    """The modes :func:`cascade_shaper` shapes: (ω rad/s, ζ) of every mode under the
    cascade below its velocity filter."""
    return [
        (float(omega), float(zeta))
        for omega, zeta in zip(*cascade_modes(params, gains))
        if omega < gains.velocity_filter
    ]


class CascadeController:
    """A drive's position–velocity cascade on the motor encoder, with feedforward.

    On each new ``theta_ref`` it starts a :func:`smooth_profile` from the last target,
    optionally shaped (:class:`Shaper`); position P → velocity PI → current, plus the
    profile's velocity and torque (J_total × acceleration) fed forward; the current
    clipped to ±``i_max`` with the integrator held while clipped (anti-windup).

    Parameters
    ----------
    gains : CascadeGains
        The loop gains (:func:`cascade_gains`).
    move_time : float
        Duration of the profile (s), > 0.
    i_max : float
        Current limit (A), > 0.
    shaper : Shaper, optional
        Input shaping of the profile (none by default).

    Attributes
    ----------
    i_ff, i_fb : float
        The last command's feedforward and feedback parts (A).

    Examples
    --------
    >>> params = {"J_mo": 1e-4, "k_to": 0.05, "J[1]": 4e-4}
    >>> cascade = CascadeController(cascade_gains(params, bandwidth=10.0), 1.0, 3.0)
    >>> cascade.reset()
    >>> [round(cascade.step(1e-3, 1.0, 0.0, 0.0, 0.0), 4) for _ in range(3)]  # A
    [0.0, 0.0006, 0.0012]
    """

    def __init__(
        self, gains: CascadeGains, move_time: float, i_max: float, shaper: Shaper | None = None
    ) -> None:
        self.gains = gains
        self.move_time = move_time
        self.i_max = i_max
        self.shaper = shaper or Shaper((0.0,), (1.0,))
        self.reset()

    def reset(self, theta_m0: float = 0.0) -> None:
        """Start at rest at ``theta_m0`` (rad), the target there."""
        self.t = 0.0
        self.start, self.target, self.t0 = theta_m0, theta_m0, 0.0
        self.integral = 0.0
        self.omega_f = 0.0
        self.i_ff = self.i_fb = 0.0

    def reference(self, t: float) -> tuple[float, float, float]:
        """The shaped profile at time ``t`` (s): position (rad), velocity, acceleration."""
        p = v = a = 0.0
        T, distance = self.move_time, self.target - self.start
        for delay, weight in zip(self.shaper.times, self.shaper.amplitudes):
            tau = min(max((t - self.t0 - delay) / T, 0.0), 1.0)
            p += weight * tau**3 * (10 - 15 * tau + 6 * tau**2)
            v += weight * 30 * tau**2 * (1 - tau) ** 2
            a += weight * 60 * tau * (1 - tau) * (1 - 2 * tau)
        return self.start + distance * p, distance * v / T, distance * a / T**2

    def step(self, h: float, theta_ref: float, i_a: float, omega_m: float, theta_m: float) -> float:
        """The current command (A) to hold over [t_k, t_k + h] from the sample of t_k.

        Parameters
        ----------
        h : float
            The step (s).
        theta_ref : float
            The target (rad); a change starts a new move.
        i_a, omega_m, theta_m : float
            Measured current (A, unused), velocity (rad/s) and angle (rad) at t_k.

        Returns
        -------
        float
            i_ref (A), within ±``i_max``.
        """
        g = self.gains
        if theta_ref != self.target:
            self.start, _, _ = self.reference(self.t)
            self.target, self.t0 = theta_ref, self.t
        p, v, a = self.reference(self.t)
        self.t += h
        alpha = 1.0 - math.exp(-g.velocity_filter * h)
        self.omega_f += alpha * (omega_m - self.omega_f)
        error = g.kp * (p - theta_m) + v - self.omega_f
        self.i_ff = g.inertia * a / g.k_t
        unclipped = self.i_ff + g.kv * error + self.integral
        i_ref = min(max(unclipped, -self.i_max), self.i_max)
        if i_ref == unclipped or (unclipped > 0) != (error > 0):
            self.integral += g.ki * error * h  # anti-windup: hold while pushing the limit
        self.i_fb = i_ref - self.i_ff
        return i_ref
