"""The installed pythonfmu's ``enums`` (see the package docstring)."""

from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Type, Fmi2Variability

__all__ = ["Fmi2Causality", "Fmi2Initial", "Fmi2Status", "Fmi2Type", "Fmi2Variability"]
