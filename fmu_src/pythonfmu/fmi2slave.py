"""The installed pythonfmu's ``fmi2slave`` (see the package docstring)."""

from pythonfmu.fmi2slave import Fmi2Slave

__all__ = ["Fmi2Slave"]
