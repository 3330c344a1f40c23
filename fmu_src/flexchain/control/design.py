"""The motion and vibration controller's design: the discrete plant, the state feedback
and the reference shaping's constants, from the chain and the user's goals.

The design model is the motor and its chain with the current as input, held over each
step (exact by one matrix exponential), state ``x = [θ_0 … θ_n, ω_0 … ω_n]`` (body 0 the
motor, rad and rad/s), Coulomb friction left out (the controller cancels it). The state
feedback ``u = −K x`` (A) is the discrete linear-quadratic regulator of that model with

* the controlled mass's angle weighted so that the rigid motion alone would close at the
  bandwidth ω_c with a damping of 1/√2 (for a rigid body of inertia J_tot,
  ``q / r = (J_tot ω_c² / k_t)²`` puts its poles there);
* the chain's mechanical energy weighted as much at ω_c (every flexible mode costs);
* a prescribed decay rate α = ``DECAY_RATIO`` · ω_c: the Riccati equation of the model
  scaled by e^{α h} (Anderson & Moore), so every closed-loop pole, each flexible mode's
  included, decays at least as e^{−α t}: every mode is actively damped.

The gain comes from one Riccati equation solved in pure Python
(:func:`~arcosim.fmu.flexchain.riccati.solve_doubling`, the observers' solver).
``move_time`` T and ``bandwidth`` ω_c are tied by ``T ω_c = MOVE_BANDWIDTH_PRODUCT``: the
user gives one, the design takes the other from it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from .. import defaults, linalg
from ..chain import MOTOR_INERTIA, Chain, spring_matrix
from ..linalg import Matrix
from ..riccati import solve_doubling

#: ω_c · T: the feedback's bandwidth (rad/s) times the move time (s) (dimensionless).
MOVE_BANDWIDTH_PRODUCT = 8.0
#: The decay rate every closed-loop pole is given, as a fraction of ω_c (dimensionless).
DECAY_RATIO = 0.5
#: The weight of the chain's mechanical energy against the controlled angle's (dimensionless).
ENERGY_WEIGHT = 1.0


@dataclass(frozen=True)
class ControllerDesign:
    """Everything the controller runs with, computed once from the chain and the goals.

    Parameters
    ----------
    h : float
        The step the discrete model and the gain are for (s).
    J_m, k_t, D_m, f_c : float
        Motor inertia (kg·m²), torque constant (N·m/A), viscous (N·m·s/rad) and Coulomb
        (N·m) friction.
    J, k, B : tuple of float
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape ``(n,)``.
    g_dist : float
        The observer's DOB bandwidth (rad/s).
    encoder_cpr : int
        Encoder counts per revolution (0 = exact angle).
    control_mass : int
        The load mass moved to the target, 1 … n (an index).
    move_time : float
        Duration of the shaped move (s).
    bandwidth : float
        ω_c (rad/s).
    i_max : float
        Current limit (A).
    hold_dither : float
        The hold's dither (encoder counts peak to peak; 0 = off;
        :mod:`~arcosim.fmu.flexchain.control.hold_dither`).
    F : Matrix
        State transition over ``h``, shape ``(2n + 2, 2n + 2)``.
    g : list of float
        Input column over ``h`` (per A), shape ``(2n + 2,)``.
    K : list of float
        State feedback gain (A per unit of state), shape ``(2n + 2,)``.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> design = arcosim.design_controller(chain, h=1e-3)
    >>> offset, i_hold = design.load_offset(1e-3)  # 1 mN·m on the load
    >>> offset[0], round(i_hold, 4)  # the motor 1/k_1 mrad behind the target (rad), A
    (-0.00625, -0.0246)
    """

    h: float
    J_m: float
    k_t: float
    D_m: float
    f_c: float
    J: tuple[float, ...]
    k: tuple[float, ...]
    B: tuple[float, ...]
    g_dist: float
    encoder_cpr: int
    control_mass: int
    move_time: float
    bandwidth: float
    i_max: float
    hold_dither: float
    F: Matrix
    g: list[float]
    K: list[float]

    @property
    def n(self) -> int:
        """Number of load masses."""
        return len(self.J)

    @property
    def chain(self) -> Chain:
        """The chain the design is for: J_m, every J_i, k_i, B_i, D_m and f_c."""
        return Chain(self.J, self.k, self.B, J_m=self.J_m, D_m=self.D_m, f_c=self.f_c)

    @property
    def dither_steps(self) -> int:
        """The hold's dither period P in steps of h: ``defaults.HOLD_DITHER_PERIOD`` as a
        multiple of four steps, at least four."""
        return 4 * max(1, round(defaults.HOLD_DITHER_PERIOD / (4.0 * self.h)))

    @property
    def dither_current(self) -> float:
        """Amplitude A (A) of the hold's square current, 0 when off or without an encoder.

        The free motor moves ``A k_t (P h)² / (16 J_m)`` peak to peak under ``±A`` over
        P steps of h (:attr:`dither_steps`); A makes that ``hold_dither`` counts
        (:mod:`~arcosim.fmu.flexchain.control.hold_dither`).
        """
        if self.hold_dither <= 0.0 or self.encoder_cpr <= 0:
            return 0.0
        period = self.dither_steps * self.h
        count = 2.0 * math.pi / self.encoder_cpr
        return 16.0 * self.hold_dither * count * self.J_m / (self.k_t * period * period)

    @property
    def inertia(self) -> float:
        """Motor and load inertia together, J_tot (kg·m²)."""
        return self.J_m + math.fsum(self.J)

    def load_offset(self, d: float) -> tuple[list[float], float]:
        """Where the chain rests when a torque d holds the controlled mass at its target.

        Parameters
        ----------
        d : float
            Constant torque on the controlled mass (N·m, positive accelerates it).

        Returns
        -------
        tuple of (list of float, float)
            The state relative to the target, shape ``(2n + 2,)`` (angles, then zero
            velocities), and the current that holds it, −d/k_t (A).
        """
        n, L = self.n, self.control_mass
        x = [0.0] * (2 * n + 2)
        compliance = 0.0
        for j in range(L - 1, -1, -1):  # body j sits behind springs j+1 … L
            compliance += 1.0 / self.k[j]
            x[j] = -d * compliance
        return x, -d / self.k_t


def hold_discretize(A: Matrix, b: Sequence[float], h: float) -> tuple[Matrix, list[float]]:
    """``x ← F x + g u`` for ``ẋ = A x + b u`` with u held over a step of ``h`` s.

    Parameters
    ----------
    A : Matrix
        Shape ``(m, m)``.
    b : Sequence[float]
        Shape ``(m,)``.
    h : float
        Step (s).

    Returns
    -------
    tuple of (Matrix, list of float)
        ``F``, shape ``(m, m)``, and ``g``, shape ``(m,)``.
    """
    F, G = linalg.hold(A, [[x] for x in b], h)
    return F, [row[0] for row in G]


def regulator_gain(F: Matrix, g: Sequence[float], Q: Matrix, r: float) -> list[float]:
    """The discrete LQR gain of ``x ← F x + g u`` for the cost ``Σ xᵀ Q x + r u²``.

    Parameters
    ----------
    F : Matrix
        Shape ``(m, m)``.
    g : Sequence[float]
        Shape ``(m,)``.
    Q : Matrix
        State weight, shape ``(m, m)``, symmetric, ≥ 0.
    r : float
        Input weight, > 0.

    Returns
    -------
    list of float
        ``K``, shape ``(m,)``: ``u = −K x``.

    Raises
    ------
    ValueError
        If the Riccati iteration fails.
    """
    m = len(F)
    G = [[g[i] * g[j] / r for j in range(m)] for i in range(m)]
    X = solve_doubling(F, G, Q)
    Xg = linalg.matvec(X, list(g))
    denominator = r + math.fsum(a * b for a, b in zip(g, Xg))
    gXF = linalg.matvec(linalg.transpose(F), Xg)  # Fᵀ X g = (gᵀ X F)ᵀ
    return [v / denominator for v in gXF]


def cost_weights(
    J_m: float, k_t: float, J: Sequence[float], k: Sequence[float], L: int, bandwidth: float
) -> Matrix:
    """The state weight Q (per A² of input weight): the controlled angle and the energy.

    Parameters
    ----------
    J_m, k_t : float
        Motor inertia (kg·m²) and torque constant (N·m/A).
    J, k : Sequence[float]
        Load inertias (kg·m²) and stiffnesses (N·m/rad), shape ``(n,)``.
    L : int
        The controlled mass, 1 … n (an index).
    bandwidth : float
        ω_c (rad/s).

    Returns
    -------
    Matrix
        Q, shape ``(2n + 2, 2n + 2)`` (A² per unit of state squared).
    """
    n = len(J)
    m = n + 1
    stiffness = J_m + math.fsum(J)
    stiffness *= bandwidth**2  # J_tot ω_c² (N·m/rad): the rigid loop's
    q_angle = (stiffness / k_t) ** 2
    q_energy = ENERGY_WEIGHT * q_angle / stiffness
    Q = linalg.zeros(2 * m, 2 * m)
    Ks = spring_matrix(k)
    inertia = [J_m, *J]
    for i in range(m):
        Q[m + i][m + i] = q_energy * inertia[i]
        for j in range(m):
            Q[i][j] = q_energy * Ks[i][j]
    Q[L][L] += q_angle
    return Q


def goals(move_time: float, bandwidth: float) -> tuple[float, float]:
    """The move time and the bandwidth, one given (> 0), the other 0.

    Parameters
    ----------
    move_time : float
        T (s), or 0.
    bandwidth : float
        ω_c (rad/s), or 0.

    Returns
    -------
    tuple of float
        (T, ω_c), with ``T ω_c = MOVE_BANDWIDTH_PRODUCT``.

    Raises
    ------
    ValueError
        Unless exactly one of them is > 0 (and finite).
    """
    given = [x > 0.0 and math.isfinite(x) for x in (move_time, bandwidth)]
    if sum(given) != 1 or min(move_time, bandwidth) < 0.0:
        raise ValueError(
            f"parameters move_time = {move_time!r} s and bandwidth = {bandwidth!r} rad/s: "
            "set exactly one of them > 0 and the other 0"
        )
    if given[0]:
        return move_time, MOVE_BANDWIDTH_PRODUCT / move_time
    return MOVE_BANDWIDTH_PRODUCT / bandwidth, bandwidth


def indexed_values(params: Mapping[str, float], name: str) -> tuple[float, ...]:
    """``params["name[1]"], params["name[2]"], …`` for as many as there are."""
    values = []
    while f"{name}[{len(values) + 1}]" in params:
        values.append(float(params[f"{name}[{len(values) + 1}]"]))
    return tuple(values)


def design_controller(
    chain: Chain | Mapping[str, float],
    *,
    h: float,
    k_t: float | None = None,
    g_dist: float = defaults.G_DIST,
    encoder_cpr: int = defaults.ENCODER_CPR,
    control_mass: int | None = None,
    move_time: float = defaults.MOVE_TIME,
    bandwidth: float = defaults.BANDWIDTH,
    i_max: float = defaults.I_MAX,
    hold_dither: float = defaults.HOLD_DITHER,
) -> ControllerDesign:
    """The controller for a chain and the user's goals.

    Parameters
    ----------
    chain : Chain or Mapping[str, float]
        The chain, with its motor inertia ``J_m`` (kg·m²) and friction ``D_m``
        (N·m·s/rad), ``f_c`` (N·m) known. At the controller FMU's boundary, its
        parameters by name instead: ``J_mo``, ``k_to`` (N·m/A), ``D_m``, ``f_c``,
        ``J[1]`` … ``J[n]``, ``k[1]`` …, ``B[1]`` …, optionally ``g_dist`` and
        ``encoder_cpr`` (which then replace the arguments of those names).
    h : float
        The control step (s), > 0.
    k_t : float or None
        The motor's torque constant (N·m/A), > 0; with a Chain it must be given.
    g_dist : float
        The observer's DOB bandwidth (rad/s).
    encoder_cpr : int
        Encoder counts per revolution (a count; 0 = exact angle).
    control_mass : int or None
        The load mass to move, 1 … n (an index); None = the last.
    move_time : float
        T (s) of the shaped move, or 0 when ``bandwidth`` is given.
    bandwidth : float
        ω_c (rad/s) of the feedback, or 0 when ``move_time`` is given.
    i_max : float
        Current limit (A), > 0.
    hold_dither : float
        The dither at rest (encoder counts peak to peak, ≥ 0; 0 = off); used only with an
        encoder (``encoder_cpr`` > 0).

    Returns
    -------
    ControllerDesign
        The discrete model, the gain and the settings; its ``chain`` is the chain given.

    Raises
    ------
    ValueError
        For goals or a chain the design cannot use (the message names the parameter).

    Examples
    --------
    >>> chain = arcosim.Chain(J=(5e-4,), k=(0.16,), B=(1e-5,), J_m=2.09e-5, D_m=2e-5, f_c=2e-3)
    >>> design = arcosim.design_controller(chain, k_t=0.0406, h=1e-3)
    >>> design.bandwidth, design.move_time, len(design.K)  # rad/s, s, states
    (8.0, 1.0, 4)
    >>> design.chain == chain
    True
    """
    T, wc = goals(move_time, bandwidth)
    if not isinstance(chain, Chain):  # the FMU's parameters
        params = chain
        g_dist = float(params.get("g_dist", g_dist))
        encoder_cpr = int(params.get("encoder_cpr", encoder_cpr))
        chain, k_t = _chain_of(params), float(params["k_to"])
    if k_t is None:
        raise ValueError("give the torque constant k_t (N·m/A) with the chain")
    for name in ("J_m", "D_m", "f_c"):
        if getattr(chain, name) is None:
            raise ValueError(f"the chain's {name} is not known: give it (Chain({name}=…))")
    J, k, B = chain.J, chain.k, chain.B
    n = len(J)
    L = n if control_mass is None else int(control_mass)
    if not 1 <= L <= n:
        raise ValueError(f"parameter control_mass = {L} is not allowed (use a load mass 1 … {n})")
    if not k_t > 0.0:
        raise ValueError(f"parameter k_to = {k_t!r} must be > 0")
    if not (h > 0.0 and i_max > 0.0):
        raise ValueError(f"step h = {h!r} s and i_max = {i_max!r} A must be > 0")
    if not (math.isfinite(hold_dither) and hold_dither >= 0.0):
        raise ValueError(f"parameter hold_dither = {hold_dither!r} counts must be ≥ 0 (0 = off)")
    J_m, D_m = chain.J_m, chain.D_m
    A, b = chain.state_space(k_t)
    F, g = hold_discretize(A, b, h)
    grow = math.exp(DECAY_RATIO * wc * h)
    Q = cost_weights(J_m, k_t, J, k, L, wc)
    K = regulator_gain(linalg.scaled(F, grow), [grow * x for x in g], Q, 1.0)
    design = ControllerDesign(
        h=h,
        J_m=J_m,
        k_t=k_t,
        D_m=D_m,
        f_c=chain.f_c,
        J=J,
        k=k,
        B=B,
        g_dist=g_dist,
        encoder_cpr=encoder_cpr,
        control_mass=L,
        move_time=T,
        bandwidth=wc,
        i_max=i_max,
        hold_dither=float(hold_dither),
        F=F,
        g=g,
        K=K,
    )
    if not design.dither_current <= 0.5 * i_max:
        raise ValueError(
            f"parameter hold_dither = {hold_dither!r} counts needs ±{design.dither_current:.3g} A "
            f"at rest, more than half of i_max = {i_max!r} A: lower hold_dither (0 = off)"
        )
    return design


def _chain_of(params: Mapping[str, float]) -> Chain:
    """The chain in the controller FMU's parameters; refuse what the design cannot use,
    naming the parameter (ValueError)."""
    J, k, B = (indexed_values(params, name) for name in ("J", "k", "B"))
    n = len(J)
    if n == 0 or len(k) != n or len(B) != n:
        raise ValueError("give J[1] … J[n], k[1] … k[n] and B[1] … B[n] for the same n ≥ 1")
    for name in ("J_mo", "k_to"):
        if not float(params[name]) > 0.0:
            raise ValueError(f"parameter {name} = {params[name]!r} must be > 0")
    if min(J) <= 0.0 or min(k) <= 0.0 or min(B) < 0.0:
        raise ValueError("every J[i] and k[i] must be > 0 and every B[i] ≥ 0")
    J_m, D_m, f_c = (float(params[name]) for name in (MOTOR_INERTIA, "D_m", "f_c"))
    return Chain(J, k, B, J_m=J_m, D_m=D_m, f_c=f_c)
