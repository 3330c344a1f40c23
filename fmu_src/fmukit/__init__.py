"""What every FMU of the project needs: variables with units, a compliant
modelDescription.xml, and one way of reporting failures.

Standard library (plus the pythonfmu runtime that every FMU carries) only: this
package is bundled into each FMU's ``resources/`` folder.
"""

from .checks import choice_problem, range_problems
from .model_description import model_description
from .slave import FmuSlave
from .variables import Variable, array, indexed, inp, out, par

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
