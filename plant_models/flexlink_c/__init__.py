"""``plant_models/flexlink_c/`` installed as ``arcosim.plant.flexlink_c``: the flexible-link
plant FMU's C sources (package data, compiled by :mod:`arcosim.build.clink`).

* ``beam.h``, ``beam.c`` — the hub and the Hermite finite-element beam, their exact step
  and the root element's reaction torque.
* ``fmu.c`` — the link's parameters and outputs in the FMI shell; the variables' header is
  generated from :func:`arcosim.build.clink.link_variables`.

The FMI shell, the matrix exponential, the friction events and the sensors are the chain
plant's (``motorchain_c/fmi_shell.h``, ``matrix_exp.h``, ``friction_events.h``,
``sensor_noise.h``).
"""
