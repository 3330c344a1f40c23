"""A package's public names, each loaded from its module on first use.

``import arcosim`` and its subpackages stay fast: a public name's module is imported
only when the name is first read.

Examples
--------
>>> from arcosim.lazy import public_api
>>> __all__, __getattr__, __dir__ = public_api("demo", {"sqrt": "math"}, globals())
>>> __all__, __getattr__("sqrt")(4.0)
(['sqrt'], 2.0)
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, MutableMapping


def public_api(
    package: str, api: dict[str, str], namespace: MutableMapping[str, object]
) -> tuple[list[str], Callable[[str], object], Callable[[], list[str]]]:
    """A package's ``__all__``, ``__getattr__`` and ``__dir__`` from its name table.

    Parameters
    ----------
    package : str
        The package's dotted name, for the error a missing name raises.
    api : dict of str to str
        Public name → the dotted module that defines it.
    namespace : mutable mapping
        The package's ``globals()``: a loaded name is cached there.

    Returns
    -------
    tuple
        ``(__all__, __getattr__, __dir__)`` for the package to bind at module level.
    """

    def getattr_(name: str) -> object:
        if name not in api:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(api[name]), name)
        namespace[name] = value
        return value

    names = list(api)

    def dir_() -> list[str]:
        return sorted(set(namespace) | set(names))

    return names, getattr_, dir_
