"""What every FMU of the project needs: variables with units, a compliant
modelDescription.xml, and one way of reporting failures.

Standard library (plus the pythonfmu runtime that every FMU carries) only: this
package is bundled into each FMU's ``resources/`` folder.
"""

from fmukit.checks import choice_problem, range_problems
from fmukit.model_description import model_description
from fmukit.slave import FmuSlave
from fmukit.variables import Variable, array, indexed, inp, out, par

__all__ = [
    "FmuSlave",
    "Variable",
    "array",
    "choice_problem",
    "indexed",
    "inp",
    "model_description",
    "out",
    "par",
    "range_problems",
]
