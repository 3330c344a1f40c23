"""``fmu_src/arcontroller/`` installed as ``arcosim.fmu.arcontroller``: the controller FMU class.

* :mod:`~arcosim.fmu.arcontroller.fmu` — ``ActionReactionController``, a thin FMI wrapper
  around :mod:`arcosim.fmu.flexchain.control.controller`: its parameters are the chain and
  the goals, its inputs the target and the plant's measured current and encoder, its
  output the current command.
"""
