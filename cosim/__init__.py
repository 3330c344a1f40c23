"""Co-simulation orchestration for the action-reaction toolkit (``arcosim``)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("arcosim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"
