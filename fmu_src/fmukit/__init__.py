"""``fmu_src/fmukit/`` installed as ``arcosim.fmu.fmukit``: what every FMU of the project
needs: variables with units, a compliant modelDescription.xml, parameter checks, FMU
state and one way of reporting failures.

Standard library (plus the pythonfmu runtime that every FMU carries) only: this
package is bundled into each FMU's ``resources/`` folder. Modules, in the order a
declaration flows to a running FMU:

* :mod:`~arcosim.fmu.fmukit.units` — the SI units as FMI ``<Unit>`` definitions.
* :mod:`~arcosim.fmu.fmukit.variables` — a variable's declaration (``par``, ``inp``,
  ``out``, ``array``).
* :mod:`~arcosim.fmu.fmukit.model_description` — the modelDescription.xml writer.
* :mod:`~arcosim.fmu.fmukit.checks` — parameter checks that name the parameter, and the
  limits every FMU computes in.
* :mod:`~arcosim.fmu.fmukit.state` — FMU state as JSON-able data, and back.
* :mod:`~arcosim.fmu.fmukit.slave` — ``FmuSlave``, the base class: values by value
  reference, the checks at initialization, the failure convention.
"""

from .checks import range_problems
from .model_description import model_description
from .slave import FmuSlave
from .variables import Variable, array, indexed, inp, out, par

__all__ = [
    "FmuSlave",
    "Variable",
    "array",
    "indexed",
    "inp",
    "model_description",
    "out",
    "par",
    "range_problems",
]
