"""The excitation source FMU class (a thin FMI wrapper around
:mod:`arcosim.fmu.flexchain.excitation`)."""
