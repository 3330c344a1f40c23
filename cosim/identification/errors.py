"""The errors the identification algorithms raise."""

from arcosim.errors import ArcosimError


class IdentificationError(ArcosimError, ValueError):
    """A record or setting the identification cannot work with; the message says why and
    what would fix it (more excitation, a longer record, a parameter to give)."""


class RefusedFitError(IdentificationError):
    """The record cannot support a whole-chain fit: the decision ``check`` reports as not
    ok (a log with no excitation, fewer modes than asked, a record too short), or a fit
    that found no chain. Not a usage error: the command was right and the data are not;
    ``arcosim identify`` exits with status 1 on it, as ``arcosim check`` does on the same
    log, and 2 on a usage error.

    Examples
    --------
    >>> from arcosim.identification.errors import RefusedFitError, IdentificationError
    >>> issubclass(RefusedFitError, IdentificationError)
    True
    """
