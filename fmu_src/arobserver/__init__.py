"""The observer FMU class (a thin FMI wrapper around :mod:`arcosim.fmu.flexchain.observer`)."""
