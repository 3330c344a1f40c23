"""Errors that ``arcosim`` reports to the user as one line (no traceback)."""


class UserError(Exception):
    """A problem the user can fix: bad argument, missing file, bad data."""
