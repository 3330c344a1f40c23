"""What the project builds: one recipe per FMU, and the numbers of masses it supports."""

from __future__ import annotations

from dataclasses import dataclass

from arcosim.errors import UserError

#: Numbers of load masses an FMU can be built for.
MIN_MASSES, MAX_MASSES = 1, 20


@dataclass(frozen=True)
class FmuRecipe:
    """How to build one kind of FMU.

    Attributes
    ----------
    name : str
        File name stem, e.g. ``"MotorChainPlant"`` → ``MotorChainPlant.fmu``.
    base : str
        ``module:Class`` (inside :mod:`arcosim.fmu` or :mod:`arcosim.plant`) of the
        slave class; for the C plant, the reference class whose interface it implements.
    packages : tuple of str
        Subpackages of :mod:`arcosim.fmu` bundled into ``resources/``.
    language : {"python", "c"}
        ``"python"`` (pythonfmu) or ``"c"`` (compiled, :mod:`arcosim.build.cplant`).

    Examples
    --------
    >>> OBSERVER.identifier(5)
    'ReactionTorqueObserver_n5'
    """

    name: str
    base: str
    packages: tuple[str, ...]
    language: str = "python"

    def identifier(self, n: int) -> str:
        """Model identifier for n load masses, e.g. ``MotorChainPlant_n3``."""
        return f"{self.name}_n{n}"

    @property
    def file_name(self) -> str:
        """The FMU's file name, e.g. ``"MotorChainPlant.fmu"``."""
        return f"{self.name}.fmu"


PLANT = FmuRecipe("MotorChainPlant", "arcosim.plant.motorchain.fmu:MotorChainPlant", (), "c")
OBSERVER = FmuRecipe(
    "ReactionTorqueObserver",
    "arobserver.fmu:ReactionTorqueObserver",
    ("fmukit", "flexchain", "arobserver"),
)
SOURCE = FmuRecipe(
    "ExcitationSource", "arsource.fmu:ExcitationSource", ("fmukit", "flexchain", "arsource")
)
CONTROLLER = FmuRecipe(
    "ActionReactionController",
    "arcontroller.fmu:ActionReactionController",
    ("fmukit", "flexchain", "arcontroller"),
)
RECIPES = (PLANT, OBSERVER, SOURCE, CONTROLLER)
#: The SSP system of the three FMUs, written beside them.
SSP_NAME = "ActionReaction.ssp"
#: The closed loop of the controller and the plant, written beside them.
CONTROL_SSP_NAME = "MotionControl.ssp"


def check_masses(n: int) -> int:
    """Return ``n`` if it is a supported number of load masses.

    Raises
    ------
    UserError
        When ``n`` is not an integer from :data:`MIN_MASSES` to :data:`MAX_MASSES`.

    Examples
    --------
    >>> check_masses(3)
    3
    """
    if isinstance(n, bool) or not isinstance(n, int) or not MIN_MASSES <= n <= MAX_MASSES:
        raise UserError(
            f"--masses {n}: the number of load masses must be {MIN_MASSES} to {MAX_MASSES}"
        )
    return n
