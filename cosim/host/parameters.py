"""An FMU class's parameters with ``--set NAME=VALUE`` applied, without a built FMU.

The defaults come from the FMU class's own declaration (``interface(n)``), so the
offline methods and the controller's check need no FMU built: the observer's
(:func:`observer_values`, what the offline identifications start from) and the
controller's (:func:`controller_values`), with the controller's own initialization check
(:func:`controller_problems`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from arcosim.errors import UserError
from arcosim.host.replay import parameter_sets


def observer_values(n: int, assignments: Sequence[str]) -> dict[str, float]:
    """The observer's parameters for ``n`` masses: its defaults with ``--set`` applied.

    The defaults come from the observer FMU's own declaration, so the offline methods
    need no built FMU.

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    assignments : sequence of str
        ``--set`` texts, ``"NAME=VALUE"`` (the value in the parameter's unit).

    Returns
    -------
    dict of str to float
        Every Real and Integer parameter of the observer by name, in its unit.

    Raises
    ------
    UserError
        When an assignment names no parameter of the observer or its value does not fit.

    Examples
    --------
    >>> from arcosim.host import observer_values
    >>> values = observer_values(2, ["k_to=0.05"])
    >>> values["k_to"], "J[2]" in values
    (0.05, True)
    """
    from arcosim.fmu.arobserver.fmu import ReactionTorqueObserver

    variables = ReactionTorqueObserver.interface(n)
    values = _defaults(variables)
    values.update({k: float(v) for k, v in parameter_sets(variables, assignments).items()})
    return values


def controller_values(n: int, assignments: Sequence[str]) -> dict[str, float]:
    """The controller FMU's Real and Integer parameters for ``n`` masses: its defaults with
    ``--set`` applied (each in its unit).

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    assignments : sequence of str
        ``--set`` texts, ``"NAME=VALUE"`` (the value in the parameter's unit).

    Returns
    -------
    dict of str to float
        Every Real and Integer parameter of the controller by name, in its unit.

    Raises
    ------
    UserError
        When an assignment names no parameter of the controller or its value does not fit.

    Examples
    --------
    >>> from arcosim.host import controller_values
    >>> controller_values(3, ["move_time=0.5"])["move_time"]
    0.5
    """
    from arcosim.fmu.arcontroller.fmu import ActionReactionController

    variables = ActionReactionController.interface(n)
    values = _defaults(variables)
    for name, value in parameter_sets(variables, assignments, "the controller").items():
        if name not in values:
            raise UserError(f"--set {name}: not a Real or Integer parameter of the controller")
        values[name] = float(value)
    return values


def controller_problems(n: int, values: Mapping[str, float]) -> list[str]:
    """What the controller FMU would refuse at initialization, one sentence each: its own
    check (``ActionReactionController.check_parameters``) on these values.

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    values : mapping of str to float
        The controller's parameters by name (:func:`controller_values`), each in its unit.

    Returns
    -------
    list of str
        The problems; empty when the FMU would start.

    Examples
    --------
    >>> from arcosim.host import controller_problems, controller_values
    >>> controller_problems(3, controller_values(3, []))
    []
    """
    from arcosim.fmu.arcontroller.fmu import ActionReactionController

    checked = type(
        "Checked", (ActionReactionController,), {"n_masses": n, "value": lambda _, k: values[k]}
    )
    return checked.check_parameters(checked.__new__(checked))


def _defaults(variables: Mapping) -> dict[str, float]:
    """An FMU class's Real and Integer parameters at their start values (each in its unit)."""
    return {
        name: float(v.start)
        for name, v in variables.items()
        if v.causality == "parameter" and v.type in ("Real", "Integer")
    }
