"""What the project builds: one recipe per FMU, and the numbers of masses it supports."""

from __future__ import annotations

from dataclasses import dataclass

from arcosim.errors import UserError

#: Numbers of load masses an FMU can be built for.
MIN_MASSES, MAX_MASSES = 1, 20
#: Numbers of Hermite elements the flexible-link FMU can be built for.
MIN_ELEMENTS, MAX_ELEMENTS = 1, 16


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


@dataclass(frozen=True)
class LinkRecipe:
    """The flexible-link plant FMU (C, :mod:`arcosim.build.clink`): its identifier carries
    the number of Hermite elements, not of masses.

    Examples
    --------
    >>> LINK.identifier(8)
    'FlexLinkPlant_e8'
    """

    name: str

    def identifier(self, elements: int) -> str:
        """Model identifier for a link of ``elements`` elements, e.g. ``FlexLinkPlant_e8``."""
        return f"{self.name}_e{elements}"

    @property
    def file_name(self) -> str:
        """The FMU's file name, ``"FlexLinkPlant.fmu"``."""
        return f"{self.name}.fmu"


LINK = LinkRecipe("FlexLinkPlant")
#: The SSP system of the three FMUs, written beside them.
SSP_NAME = "ActionReaction.ssp"
#: The closed loop of the controller and the plant, written beside them.
CONTROL_SSP_NAME = "MotionControl.ssp"


def check_masses(n: int) -> int:
    """Return ``n`` if it is a supported number of load masses.

    Parameters
    ----------
    n : int
        Number of load masses (a count), as given to ``--masses``.

    Returns
    -------
    int
        ``n`` itself.

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


def check_elements(elements: int) -> int:
    """Return ``elements`` if the link FMU can be built with that many elements.

    Parameters
    ----------
    elements : int
        Number of the link's Hermite finite elements (a count), as given to
        ``--elements``.

    Returns
    -------
    int
        ``elements`` itself.

    Raises
    ------
    UserError
        When ``elements`` is not an integer from :data:`MIN_ELEMENTS` to :data:`MAX_ELEMENTS`.

    Examples
    --------
    >>> check_elements(8)
    8
    """
    if (
        isinstance(elements, bool)
        or not isinstance(elements, int)
        or not MIN_ELEMENTS <= elements <= MAX_ELEMENTS
    ):
        raise UserError(
            f"--elements {elements}: the number of the link's Hermite elements must be "
            f"{MIN_ELEMENTS} to {MAX_ELEMENTS}"
        )
    return elements
