"""The observer FMU class (a thin FMI wrapper around :mod:`flexchain.observer`)."""
