"""The model errors a controller is checked against: every J_i and k_i scaled.

The identification's errors the controller is held to: the model's load inertias and
stiffnesses each scaled by an independent factor uniform in ``[1 − e, 1 + e]`` (random
draws), plus the two corners, every J_i at ``1 + e`` with every k_i at ``1 − e`` and the
reverse. The motor's terms (J_mo, k_to, D_m) and the dampings B_i are left as they are.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

#: The relative error checked by default (dimensionless): ±10 %.
ERROR = 0.1
#: Random models checked besides the corners (a count).
RANDOM_MODELS = 20
#: The random draws' seed, so that a check repeats exactly.
RANDOM_SEED = 29


@dataclass(frozen=True)
class ModelError:
    """One model error: factors on every J_i and k_i.

    Parameters
    ----------
    name : str
        How the output names it, e.g. ``"J +10 %, k −10 %"``.
    J, k : tuple of float
        The factors on J_1 … J_n and k_1 … k_n (dimensionless), shape ``(n,)`` each.
    """

    name: str
    J: tuple[float, ...]
    k: tuple[float, ...]

    def apply(self, params: Mapping[str, float]) -> dict[str, float]:
        """``params`` with ``J[i]`` and ``k[i]`` scaled (a new dict; the rest as given)."""
        out = dict(params)
        for name, factors in (("J", self.J), ("k", self.k)):
            for i, f in enumerate(factors):
                out[f"{name}[{i + 1}]"] = float(params[f"{name}[{i + 1}]"]) * f
        return out


def corners(n: int, error: float = ERROR) -> list[ModelError]:
    """The two corners: every J_i at 1 + e with every k_i at 1 − e, and the reverse.

    Examples
    --------
    >>> [c.name for c in corners(2)]
    ['J +10 %, k −10 %', 'J −10 %, k +10 %']
    """
    pct = f"{100 * error:g} %"
    up, down = (1.0 + error,) * n, (1.0 - error,) * n
    return [
        ModelError(f"J +{pct}, k −{pct}", up, down),
        ModelError(f"J −{pct}, k +{pct}", down, up),
    ]


def model_errors(
    n: int, error: float = ERROR, random_models: int = RANDOM_MODELS
) -> list[ModelError]:
    """The corners, then ``random_models`` independent uniform scalings (seeded).

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    error : float
        e (dimensionless), 0 < e < 1.
    random_models : int
        How many random scalings (a count, ≥ 0).

    Returns
    -------
    list of ModelError
        ``2 + random_models`` of them.

    Examples
    --------
    >>> errors = model_errors(3)
    >>> len(errors), errors[2].name
    (22, 'random 1 of 20')
    """
    rng = np.random.default_rng(RANDOM_SEED)
    found = corners(n, error)
    for r in range(random_models):
        fJ, fk = rng.uniform(1.0 - error, 1.0 + error, (2, n))
        found.append(
            ModelError(f"random {r + 1} of {random_models}", tuple(fJ.tolist()), tuple(fk.tolist()))
        )
    return found
