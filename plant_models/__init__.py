"""``plant_models/`` installed as ``arcosim.plant``: the plant, a motor driving a chain of
masses on springs.

- :mod:`~arcosim.plant.motorchain`: the Python reference (physics, then the FMU class
  whose variable list defines the plant's interface);
- ``motorchain_c/``: the shipped plant FMU's C sources (package data), compiled at
  build time (:mod:`arcosim.build.cplant`);
- ``flexlink_c/``: the flexible-link plant FMU's C sources, compiled by
  :mod:`arcosim.build.clink`.
"""
