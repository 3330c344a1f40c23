"""``fmu_src/arobserver/`` installed as ``arcosim.fmu.arobserver``: the observer FMU class.

* :mod:`~arcosim.fmu.arobserver.fmu` — ``ReactionTorqueObserver``, a thin FMI wrapper
  around :mod:`arcosim.fmu.flexchain.observer`: its parameters are the observer's
  settings, its inputs the plant's measured current and encoder, its outputs the
  estimates.
"""
