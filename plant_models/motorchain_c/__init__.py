"""``plant_models/motorchain_c/`` installed as ``arcosim.plant.motorchain_c``: the plant
FMU's C sources (package data, compiled by :mod:`arcosim.build.cplant`).

* ``physics.h``, ``physics.c`` — the equations of motion and their exact step (the C port
  of :mod:`arcosim.plant.motorchain.physics`).
* ``fmu.c`` — the FMI 2.0 functions around them; the variables' header is generated from
  :class:`arcosim.plant.motorchain.fmu.MotorChainPlant`.
"""
