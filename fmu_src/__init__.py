"""``fmu_src/`` installed as ``arcosim.fmu``: the code inside the project's Python FMUs
(standard library only).

Bundled into each FMU under a name of its own; here importable as ``arcosim.fmu``.
Subpackages, in the order data flows:

- :mod:`~arcosim.fmu.flexchain`: the algorithms (every default of the project, the codes,
  the chain model, the waveforms, the DOB, identification and state estimation), each a
  small filter with a ``step(h, …)`` method, reused offline;
- :mod:`~arcosim.fmu.fmukit`: what every FMU needs (variables with units, the compliant
  modelDescription writer, the parameter checks, the failure convention, FMU state);
- :mod:`~arcosim.fmu.arsource`: the excitation source FMU class (the current command);
- :mod:`~arcosim.fmu.arobserver`: the observer FMU class (from the plant's measured
  current and encoder to the estimates);
- :mod:`~arcosim.fmu.arcontroller`: the controller FMU class (from the motor's current
  and encoder to the current command that moves the last mass);
- :mod:`~arcosim.fmu.pythonfmu`: in the source tree only, a stand-in for the pythonfmu
  runtime each FMU bundles.

The plant FMU's classes are :mod:`arcosim.plant` (``plant_models/``). Every module here
imports its siblings relatively, so the bundled copy runs its own code whatever the host
has imported.
"""
