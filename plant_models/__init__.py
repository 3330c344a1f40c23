"""The plant: the motor–spring–mass chain.

- :mod:`~arcosim.plant.motorchain`: the Python reference (physics, sensor models, and
  the FMU class whose variable list defines the plant's interface);
- ``motorchain_c/``: the shipped plant FMU's C sources (package data), compiled at
  build time (:mod:`arcosim.build.cplant`).
"""
