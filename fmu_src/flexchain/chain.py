"""The motor–spring–mass chain: its values (:class:`Chain`) and its linear model.

Bodies 0 … n: body 0 is the motor (inertia ``J_m``), bodies 1 … n the load masses.
Spring i (1-based) joins body i−1 and body i with stiffness ``k[i-1]`` (N·m/rad)
and damping ``B[i-1]`` (N·m·s/rad). Sign convention of docs/method.md: the
torque of spring i is ``τ_i = k_i (θ_{i−1} − θ_i) + B_i (θ̇_{i−1} − θ̇_i)``.

A chain travels through the project as one :class:`Chain`: identified, written to and
read from a chain file, given to the observer and the controller. Its values take the
FMUs' parameter names (``J[i]``, ``k[i]``, ``B[i]``, ``J_mo``, ``D_m``, ``f_c``) only at
the FMU, command-line and file boundary (:meth:`Chain.parameters`,
:meth:`Chain.from_parameters`, :meth:`Chain.to_json`, :meth:`Chain.from_json`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from .linalg import Matrix, zeros

#: The chain's indexed parameters, by their name before ``[``: ``J[i]``, ``k[i]``, ``B[i]``.
INDEXED = ("J", "k", "B")
#: The motor inertia's parameter name in the observer and controller FMUs (the plant's is
#: ``J_m``); the observer adds its identified error ``dJm`` to it.
MOTOR_INERTIA = "J_mo"
#: The SI unit of each parameter, by its name before ``[`` (the FMUs' parameter names; the
#: plant's motor inertia is ``J_m``).
UNITS = {
    "J": "kg·m²",
    "k": "N·m/rad",
    "B": "N·m·s/rad",
    MOTOR_INERTIA: "kg·m²",
    "J_m": "kg·m²",
    "D_m": "N·m·s/rad",
    "f_c": "N·m",
}


@dataclass(frozen=True)
class Chain:
    """A motor driving n masses through n springs: every value, with σ where known.

    Parameters
    ----------
    J : tuple of float
        Load inertias J_1 … J_n (kg·m², each > 0), mass 1 (next to the motor) first,
        shape ``(n,)``, n ≥ 1.
    k : tuple of float
        Spring stiffnesses k_1 … k_n (N·m/rad, each > 0), spring i joining body i−1 and
        body i, shape ``(n,)``.
    B : tuple of float
        Spring dampings B_1 … B_n (N·m·s/rad, each ≥ 0), shape ``(n,)``.
    J_m : float or None
        Motor inertia (kg·m², > 0); None when not known here (given with the motor, e.g.
        the datasheet's ``J_mo``).
    D_m : float or None
        Motor viscous friction (N·m·s/rad, ≥ 0); None when not known.
    f_c : float or None
        Motor Coulomb friction (N·m, ≥ 0); None when not known.
    J_std, k_std, B_std : tuple of (float or None)
        Standard errors of ``J``, ``k``, ``B`` (same units), shape ``(n,)``, None for a
        value without one; ``()`` (the default) when none is known (all None is kept as
        ``()``).
    D_m_std, f_c_std : float or None
        Standard errors of ``D_m`` (N·m·s/rad) and ``f_c`` (N·m); None when not known.

    Raises
    ------
    ValueError
        When a value is not a finite number, an inertia or stiffness is not > 0, a
        damping, friction or standard error is < 0, or the shapes differ; the message
        names the value and says what to give.

    Examples
    --------
    >>> chain = arcosim.Chain(J=(4e-4, 8e-4), k=(0.3, 0.2), B=(1e-4, 1e-4), J_m=2.09e-5)
    >>> chain.n, chain.J_total  # masses, kg·m²
    (2, 0.0012209)
    >>> arcosim.Chain.from_parameters(chain.parameters()) == chain
    True
    """

    J: tuple[float, ...]
    k: tuple[float, ...]
    B: tuple[float, ...]
    J_m: float | None = None
    D_m: float | None = None
    f_c: float | None = None
    J_std: tuple[float | None, ...] = field(default=())
    k_std: tuple[float | None, ...] = field(default=())
    B_std: tuple[float | None, ...] = field(default=())
    D_m_std: float | None = None
    f_c_std: float | None = None

    def __post_init__(self) -> None:
        self._coerce()
        self._check_shapes()
        _sign(_labelled("J", self.J), positive=True)
        _sign(_labelled("k", self.k), positive=True)
        if self.J_m is not None:
            _sign([("J_m", self.J_m)], positive=True)
        _sign([*_labelled("B", self.B), ("D_m", self.D_m), ("f_c", self.f_c)])
        stds = [s for p in INDEXED for s in _labelled(f"{p}_std", getattr(self, f"{p}_std"))]
        _sign([*stds, ("D_m_std", self.D_m_std), ("f_c_std", self.f_c_std)])

    def _coerce(self) -> None:
        """Every value as a float (sequences as tuples), or a ValueError naming it."""
        for name in ("J", "k", "B", "J_std", "k_std", "B_std"):
            values = getattr(self, name)
            if isinstance(values, (str, bytes)) or not isinstance(values, Sequence):
                raise ValueError(f"Chain: {name} = {values!r:.40} must be a sequence of numbers")
            object.__setattr__(
                self, name, tuple(_number(name, i, v) for i, v in enumerate(values, 1))
            )
        for name in ("J_std", "k_std", "B_std"):  # no σ known: one way to say it, ()
            if all(value is None for value in getattr(self, name)):
                object.__setattr__(self, name, ())
        for name in ("J_m", "D_m", "f_c", "D_m_std", "f_c_std"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _number(name, None, value))

    def _check_shapes(self) -> None:
        """n ≥ 1, and J, k, B (and each σ given) of n values, or a ValueError."""
        n = len(self.J)
        if n < 1:
            raise ValueError("Chain: give at least one load mass (J, k, B of length n ≥ 1)")
        for name in ("k", "B"):
            if len(getattr(self, name)) != n:
                raise ValueError(
                    f"Chain: {name} has {len(getattr(self, name))} values and J has {n}: "
                    f"give J, k and B for the same n masses"
                )
        for name in ("J_std", "k_std", "B_std"):
            if len(getattr(self, name)) not in (0, n):
                raise ValueError(
                    f"Chain: {name} has {len(getattr(self, name))} values for {n} masses: "
                    f"give one per mass (None where unknown) or none"
                )

    @property
    def n(self) -> int:
        """The number of load masses (a count)."""
        return len(self.J)

    @property
    def J_total(self) -> float:
        """The whole inertia J_m + J_1 + … + J_n (kg·m²); needs ``J_m``."""
        if self.J_m is None:
            raise ValueError("Chain: J_m is not known: give the motor inertia (J_m)")
        return math.fsum((self.J_m, *self.J))

    def state_space(self, gain: float = 1.0) -> tuple[Matrix, list[float]]:
        """``ẋ = A x + b u`` of the motor and this chain (:func:`state_space`); needs
        ``J_m``, and ``D_m`` (an unknown friction is taken as 0).

        Parameters
        ----------
        gain : float
            The motor torque per unit of u: k_t (N·m/A) for a current, 1 for a torque.

        Returns
        -------
        tuple of (Matrix, list of float)
            ``A``, shape ``(2n + 2, 2n + 2)``, and ``b``, shape ``(2n + 2,)``.
        """
        if self.J_m is None:
            raise ValueError("Chain: J_m is not known: give the motor inertia (J_m)")
        D_m = 0.0 if self.D_m is None else self.D_m
        return state_space(self.J_m, gain, D_m, self.J, self.k, self.B)

    @staticmethod
    def unit(name: str) -> str:
        """The SI unit of a chain parameter named as the FMUs name it (:data:`UNITS`).

        Parameters
        ----------
        name : str
            ``J[i]``, ``k[i]``, ``B[i]``, ``J_mo``, ``J_m``, ``D_m`` or ``f_c``.

        Returns
        -------
        str
            Its unit, e.g. ``"N·m/rad"``.

        Raises
        ------
        KeyError
            For a name that is not a chain parameter.

        Examples
        --------
        >>> Chain.unit("k[2]"), Chain.unit("f_c")
        ('N·m/rad', 'N·m')
        """
        return UNITS[name.split("[", 1)[0]]

    def parameters(self, motor: str = MOTOR_INERTIA) -> dict[str, float]:
        """The values under the FMUs' parameter names, as ``--set`` and the FMUs take them.

        Parameters
        ----------
        motor : str
            The motor inertia's name: ``"J_mo"`` (the observer's and controller's, the
            default) or ``"J_m"`` (the plant's).

        Returns
        -------
        dict of str to float
            ``J[1]`` … ``J[n]`` (kg·m²), ``k[1]`` … (N·m/rad), ``B[1]`` … (N·m·s/rad),
            then, where known, the motor inertia (kg·m²), ``D_m`` (N·m·s/rad) and ``f_c``
            (N·m); the values copied exactly.

        Examples
        --------
        >>> Chain(J=(1e-3,), k=(0.5,), B=(1e-4,), f_c=2e-3).parameters()
        {'J[1]': 0.001, 'k[1]': 0.5, 'B[1]': 0.0001, 'f_c': 0.002}
        """
        out = {f"{p}[{i}]": v for p in INDEXED for i, v in enumerate(getattr(self, p), 1)}
        for name, value in ((motor, self.J_m), ("D_m", self.D_m), ("f_c", self.f_c)):
            if value is not None:
                out[name] = value
        return out

    def std(self) -> dict[str, float]:
        """The standard errors known, under the parameters' names (same units).

        Returns
        -------
        dict of str to float
            ``J[i]``, ``k[i]``, ``B[i]``, ``D_m``, ``f_c`` for each value with one; empty
            when none is known.

        Examples
        --------
        >>> Chain(J=(1e-3,), k=(0.5,), B=(1e-4,), k_std=(0.01,)).std()
        {'k[1]': 0.01}
        """
        out = {
            f"{p}[{i}]": v
            for p in INDEXED
            for i, v in enumerate(getattr(self, f"{p}_std"), 1)
            if v is not None
        }
        for name in ("D_m", "f_c"):
            if getattr(self, f"{name}_std") is not None:
                out[name] = getattr(self, f"{name}_std")
        return out

    @classmethod
    def from_parameters(
        cls,
        values: Mapping[str, float],
        std: Mapping[str, float] | None = None,
        n: int | None = None,
        motor: str = MOTOR_INERTIA,
    ) -> Chain:
        """The chain in parameters named as the FMUs name them (``--set``, a report).

        Parameters
        ----------
        values : Mapping[str, float]
            ``J[1]`` … ``J[n]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]`` (N·m·s/rad) and
            optionally the motor inertia (kg·m², named ``motor``), ``D_m`` (N·m·s/rad),
            ``f_c`` (N·m). Other names are ignored.
        std : Mapping[str, float] or None
            Standard errors under the same names (same units); None: none known.
        n : int or None
            The number of masses (a count); None: as many as there are ``J[i]``.
        motor : str
            The motor inertia's name: ``"J_mo"`` (the observer's and the controller's,
            the default) or ``"J_m"`` (the plant's, a chain file's).

        Returns
        -------
        Chain
            The values, copied exactly.

        Raises
        ------
        ValueError
            When a ``J[i]``, ``k[i]`` or ``B[i]`` of the n masses is missing (the
            message names them), or a value is not allowed (:class:`Chain`).

        Examples
        --------
        >>> Chain.from_parameters({"J[1]": 1e-3, "k[1]": 0.5, "B[1]": 1e-4, "J_mo": 2e-5}).J_m
        2e-05
        """
        if n is None:
            n = 0
            while f"J[{n + 1}]" in values:
                n += 1
        names = [[f"{p}[{i}]" for i in range(1, n + 1)] for p in INDEXED]
        missing = [name for group in names for name in group if name not in values]
        if missing:
            raise ValueError(f"Chain: missing {', '.join(missing)}: give every J[i], k[i], B[i]")
        std = std or {}
        sigmas = {
            f"{p}_std": tuple(std.get(name) for name in group)
            for p, group in zip(INDEXED, names)
            if any(name in std for name in group)
        }
        return cls(
            *(tuple(values[name] for name in group) for group in names),
            J_m=values.get(motor),
            D_m=values.get("D_m"),
            f_c=values.get("f_c"),
            **sigmas,
            D_m_std=std.get("D_m"),
            f_c_std=std.get("f_c"),
        )

    def to_json(self) -> dict[str, object]:
        """The chain as a chain file's JSON object (what :meth:`from_json` reads).

        The keys of ``arcosim identify --method whole-chain --out chain.json``: ``masses``,
        the parameters (:meth:`parameters`, the motor inertia as ``J_m``), and ``std``
        when a standard error is known.

        Returns
        -------
        dict of str to object
            JSON-able: ``masses`` (a count), floats in SI units, ``std`` a dict of floats.

        Examples
        --------
        >>> Chain(J=(1e-3,), k=(0.5,), B=(1e-4,)).to_json()
        {'masses': 1, 'J[1]': 0.001, 'k[1]': 0.5, 'B[1]': 0.0001}
        """
        out: dict[str, object] = {"masses": self.n, **self.parameters(motor="J_m")}
        if self.std():
            out["std"] = self.std()
        return out

    @classmethod
    def from_json(cls, data: Mapping[str, object]) -> Chain:
        """The chain of a chain file's JSON object (:meth:`to_json`, a whole-chain report).

        Parameters
        ----------
        data : Mapping[str, object]
            ``masses`` (a count, optional), ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]``
            (N·m·s/rad), optionally ``J_m`` (kg·m²), ``D_m`` (N·m·s/rad), ``f_c`` (N·m)
            and ``std`` (their standard errors by the same names); other keys are ignored.

        Returns
        -------
        Chain
            The values, copied exactly.

        Raises
        ------
        ValueError
            As :meth:`from_parameters`.

        Examples
        --------
        >>> Chain.from_json({"masses": 1, "J[1]": 1e-3, "k[1]": 0.5, "B[1]": 1e-4}).k
        (0.5,)
        """
        std = data.get("std")
        std = std if isinstance(std, Mapping) else {}
        masses = data.get("masses")
        n = None if masses is None else int(masses)
        return cls.from_parameters(data, std, n, motor="J_m")


def _number(name: str, i: int | None, value: object) -> float | None:
    """A finite float (None kept inside a standard-error tuple), or a ValueError."""
    label = name if i is None else f"{name}[{i}]"
    if value is None and name.endswith("_std") and i is not None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"Chain: {label} = {value!r:.40} is not a number: give a finite float")
    if not math.isfinite(value):
        raise ValueError(f"Chain: {label} = {value} is not finite: give a finite float")
    return float(value)


def _labelled(name: str, values: Sequence[float | None]) -> list[tuple[str, float | None]]:
    """``(name[i], value)`` for i from 1, as the parameters name them."""
    return [(f"{name}[{i}]", v) for i, v in enumerate(values, 1)]


def _sign(values: Sequence[tuple[str, float | None]], positive: bool = False) -> None:
    """Refuse a value below zero, or at zero when ``positive``, naming it (ValueError);
    None (not known) passes."""
    for label, value in values:
        if value is None:
            continue
        if positive and not value > 0.0:
            raise ValueError(f"Chain: {label} = {value:g} must be > 0")
        if not value >= 0.0:
            raise ValueError(f"Chain: {label} = {value:g} must be >= 0")


def state_space(
    J_m: float, gain: float, D_m: float, J: Sequence[float], k: Sequence[float], B: Sequence[float]
) -> tuple[Matrix, list[float]]:
    """``ẋ = A x + b u`` for the motor and its chain, Coulomb friction left out: the
    chain's one state space (the controller's design, its margins; numpy's twin with a
    load torque and a slow load is :func:`arcosim.identification.fit.kalman.discrete_drive`).

    State ``x = [θ_0 … θ_n, ω_0 … ω_n]`` (body 0 the motor; rad, rad/s).

    Parameters
    ----------
    J_m : float
        Motor inertia (kg·m²).
    gain : float
        The motor torque per unit of the input u: the torque constant k_t (N·m/A) for a
        current, 1 for a torque (N·m).
    D_m : float
        Motor viscous friction (N·m·s/rad).
    J, k, B : Sequence[float]
        Load inertias (kg·m²), stiffnesses (N·m/rad), dampings (N·m·s/rad), shape ``(n,)``.

    Returns
    -------
    tuple of (Matrix, list of float)
        ``A``, shape ``(2n + 2, 2n + 2)`` (1/s, 1/s²), and ``b``, shape ``(2n + 2,)``
        (rad/s² per unit of u in the motor's row).

    Examples
    --------
    >>> A, b = state_space(1.0, 2.0, 0.0, [1.0], [4.0], [0.0])
    >>> A[2][:2], b[2]  # the motor's acceleration: −k (θ_0 − θ_1) / J_m, gain / J_m
    ([-4.0, 4.0], 2.0)
    """
    n = len(J)
    m = n + 1
    inertia = [J_m, *J]
    Ks, Cs = spring_matrix(k), spring_matrix(B)
    Cs[0][0] += D_m
    A = zeros(2 * m, 2 * m)
    for i in range(m):
        A[i][m + i] = 1.0
        for j in range(m):
            A[m + i][j] = -Ks[i][j] / inertia[i]
            A[m + i][m + j] = -Cs[i][j] / inertia[i]
    b = [0.0] * (2 * m)
    b[m] = gain / J_m
    return A, b


def spring_matrix(gains: Sequence[float]) -> Matrix:
    """The ``(n+1) × (n+1)`` Laplacian of a chain of n springs.

    For stiffnesses it is the stiffness matrix K, for dampings the damping matrix:
    the torque on the bodies is ``−K θ − C θ̇``.

    Parameters
    ----------
    gains : Sequence[float]
        ``k_1 … k_n`` (N·m/rad) or ``B_1 … B_n`` (N·m·s/rad), one per spring, shape
        ``(n,)``.

    Returns
    -------
    Matrix
        The Laplacian, shape ``(n + 1, n + 1)``, in the unit of ``gains``.

    Examples
    --------
    >>> spring_matrix([2.0, 3.0])  # N·m/rad: motor, mass 1, mass 2
    [[2.0, -2.0, 0.0], [-2.0, 5.0, -3.0], [0.0, -3.0, 3.0]]
    """
    return _laplacian(gains, [(i - 1, i) for i in range(1, len(gains) + 1)])


def star_matrix(gains: Sequence[float]) -> Matrix:
    """The ``(n+1) × (n+1)`` Laplacian of a star of n springs, each from body 0 (the
    hub) to its own body i (a link's modes, :mod:`arcosim.fmu.flexchain.link`).

    Parameters
    ----------
    gains : Sequence[float]
        ``k_1 … k_n`` (N·m/rad) or ``B_1 … B_n`` (N·m·s/rad), one per spring, shape
        ``(n,)``.

    Returns
    -------
    Matrix
        The Laplacian, shape ``(n + 1, n + 1)``, in the unit of ``gains``.

    Examples
    --------
    >>> star_matrix([1.0, 2.0])
    [[3.0, -1.0, -2.0], [-1.0, 1.0, 0.0], [-2.0, 0.0, 2.0]]
    """
    return _laplacian(gains, [(0, i) for i in range(1, len(gains) + 1)])


def _laplacian(gains: Sequence[float], ends: Sequence[tuple[int, int]]) -> Matrix:
    """The ``(n+1) × (n+1)`` Laplacian of n springs, spring j joining bodies ``ends[j]``.

    Parameters
    ----------
    gains : Sequence[float]
        One gain per spring, shape ``(n,)``, in any unit.
    ends : Sequence[tuple[int, int]]
        The two bodies (0 … n) each spring joins, shape ``(n, 2)``.

    Returns
    -------
    Matrix
        The Laplacian, shape ``(n + 1, n + 1)``, in the unit of ``gains``.

    Examples
    --------
    >>> _laplacian([2.0], [(0, 1)])
    [[2.0, -2.0], [-2.0, 2.0]]
    """
    m = zeros(len(gains) + 1, len(gains) + 1)
    for g, (a, b) in zip(gains, ends):
        m[a][a] += g
        m[b][b] += g
        m[a][b] -= g
        m[b][a] -= g
    return m


def spring_torques(
    k: Sequence[float], B: Sequence[float], theta: Sequence[float], omega: Sequence[float]
) -> list[float]:
    """Torques ``τ_1 … τ_n`` carried by the springs.

    Parameters
    ----------
    k, B : Sequence[float]
        Per-spring stiffness (N·m/rad) and damping (N·m·s/rad), shape ``(n,)`` each.
    theta, omega : Sequence[float]
        Angles (rad) and velocities (rad/s) of bodies 0 … n, shape ``(n + 1,)`` each.

    Returns
    -------
    list of float
        The spring torques (N·m), shape ``(n,)``.
    """
    return [
        k[i] * (theta[i] - theta[i + 1]) + B[i] * (omega[i] - omega[i + 1]) for i in range(len(k))
    ]
