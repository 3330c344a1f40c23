"""Algorithms of the action-reaction method for flexible drives.

Pure Python (standard library only): the package is bundled into the FMUs and runs
in any host that has a Python 3. Modules:

* :mod:`arcosim.fmu.flexchain.linalg` — small dense matrices as lists of lists, matrix exponential.
* :mod:`arcosim.fmu.flexchain.chain` — the motor–spring–mass chain as a linear model.
"""
