"""The error the identification algorithms raise."""

from arcosim.errors import ArcosimError


class IdentificationError(ArcosimError, ValueError):
    """A record or setting the identification cannot work with; the message says why and
    what would fix it (more excitation, a longer record, a parameter to give)."""
