"""What ``arcosim identify`` and ``arcosim check`` know of a drive: the actuator among
the observer's parameters (:func:`arcosim.host.observer_values`: ``--set NAME=VALUE``
over the observer FMU's own defaults), and the note naming those left at the paper
bench's value.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from arcosim import Actuator, UserError
from arcosim.host import parse_assignment


def actuator_of(values: Mapping[str, float]) -> Actuator:
    """The actuator terms among the observer's parameters.

    Parameters
    ----------
    values : mapping of str to float
        The observer's parameters (:func:`arcosim.host.observer_values`): ``J_mo`` (kg·m²), ``k_to``
        (N·m/A), ``dkt``, ``dJm``, ``D_m`` (N·m·s/rad), ``f_c`` (N·m), ``g_dist`` (rad/s).

    Returns
    -------
    Actuator
        ``J_mo``, ``k_to``, ``dkt``, ``dJm``, ``D_m``, ``f_c``.

    Raises
    ------
    UserError
        When ``J_mo``, ``k_to`` or ``g_dist`` is not > 0.
    """
    for name in ("J_mo", "k_to", "g_dist"):
        if not values[name] > 0:
            raise UserError(f"{name} = {float(values[name]):g} must be > 0")
    return Actuator(
        values["J_mo"], values["k_to"], values["dkt"], values["dJm"], values["D_m"], values["f_c"]
    )


def set_names(assignments: Sequence[str]) -> set[str]:
    """The parameter names of ``--set NAME=VALUE`` assignments.

    Examples
    --------
    >>> sorted(set_names(["k_to=0.04", "J[1]=5e-4"]))
    ['J[1]', 'k_to']
    """
    return {parse_assignment(text)[0] for text in assignments}


def drive_parameters(n: int, chain: bool = True) -> list[str]:
    """The observer parameters that describe the drive: the ones whose default is the
    paper bench's, not a tuning choice.

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    chain : bool
        Whether the ``n``-mass chain's ``J[i]``, ``k[i]``, ``B[i]`` are among them.

    Returns
    -------
    list of str
        Observer parameter names.

    Examples
    --------
    >>> drive_parameters(1)
    ['J_mo', 'k_to', 'D_m', 'f_c', 'encoder_cpr', 'J[1]', 'k[1]', 'B[1]']
    """
    names = ["J_mo", "k_to", "D_m", "f_c", "encoder_cpr"]
    if chain:
        names += [f"{p}[{i}]" for p in "JkB" for i in range(1, n + 1)]
    return names


def defaults_note(values: Mapping[str, float], names: Sequence[str], given: set[str]) -> str | None:
    """One sentence naming the parameters among ``names`` left at their default.

    Parameters
    ----------
    values : mapping of str to float
        The parameters used, by name (each in its unit).
    names : sequence of str
        The parameters that describe the drive (:func:`drive_parameters`).
    given : set of str
        The names the user gave (:func:`set_names`).

    Returns
    -------
    str or None
        The sentence; None when every one was given. A chain left whole at its
        default is named as one.

    Examples
    --------
    >>> defaults_note({"k_to": 0.0406, "D_m": 0.0}, ["k_to", "D_m"], {"k_to"})
    "not given, so the paper bench's value was used: D_m = 0 (give your drive's with --set)"
    """
    missing = [name for name in names if name not in given]
    if not missing:
        return None
    chain = [name for name in names if "[" in name]
    parts = [f"{name} = {values[name]:g}" for name in missing if "[" not in name]
    if chain and set(chain) <= set(missing):
        kinds = dict.fromkeys(f"{name.split('[')[0]}[i]" for name in chain)
        parts.append(f"the bench's chain ({', '.join(kinds)})")
    else:
        parts += [f"{name} = {values[name]:g}" for name in missing if "[" in name]
    return (
        "not given, so the paper bench's value was used: "
        + ", ".join(parts)
        + " (give your drive's with --set)"
    )
