"""``plant_models/motorchain_c/`` installed as ``arcosim.plant.motorchain_c``: the plant
FMU's C sources (package data, compiled by :mod:`arcosim.build.cplant`).

* ``physics.h``, ``physics.c`` — the equations of motion and their exact step (the C port
  of :mod:`arcosim.plant.motorchain.physics`).
* ``fmu.c`` — the chain's parameters and outputs in the FMI shell; the variables' header is
  generated from :class:`arcosim.plant.motorchain.fmu.MotorChainPlant`.

Shared with the flexible link (``flexlink_c/``), header-only: ``fmi_shell.h`` (the FMI 2.0
functions: guards, messages, timing contract, trace file, FMU states), ``matrix_exp.h``
(the matrix exponential, balanced or not), ``friction_events.h`` (reversals and
breakaways on a Hermite interpolant) and ``sensor_noise.h`` (the current noise and the
encoder).
"""
