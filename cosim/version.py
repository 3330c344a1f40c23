"""The installed package's version (``0.0.0+unknown`` in a source tree not installed)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("arcosim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"
