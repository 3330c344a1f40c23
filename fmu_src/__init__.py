"""Code that runs inside the project's Python FMUs (standard library only).

Bundled into each FMU under a name of its own; here importable as ``arcosim.fmu``:

- :mod:`~arcosim.fmu.fmukit`: what every FMU needs (variables with units, the
  compliant modelDescription writer, the failure convention, FMU state);
- :mod:`~arcosim.fmu.flexchain`: the algorithms, each a small filter with a
  ``step(h, …)`` method, reused offline;
- :mod:`~arcosim.fmu.arobserver`, :mod:`~arcosim.fmu.arsource`: the observer and the
  excitation source FMU classes.

Every module here imports its siblings relatively, so the bundled copy runs its own
code whatever the host has imported.
"""
