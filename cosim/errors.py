"""The errors ``arcosim`` raises for problems a user can fix.

Every one is reported by the command line as one line (``arcosim: error: …``) and
exit status 2, never as a traceback. Library callers catch :class:`ArcosimError`
(or a subclass) the same way.
"""


class ArcosimError(Exception):
    """A problem the user can fix; its message names the input and what to do."""


class UserError(ArcosimError):
    """A bad argument, file or datum given to a command or a library function."""


class BuildError(ArcosimError):
    """An FMU could not be built (no compiler, a failed compile, a locked folder)."""
