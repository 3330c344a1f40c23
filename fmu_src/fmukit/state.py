"""FMU state as plain JSON-serializable data, and back.

:func:`snapshot` copies a tree of the project's algorithm objects (plain classes,
``__slots__`` classes, frozen dataclasses, lists, tuples, dicts with string keys,
numbers, strings, Booleans, None) into new JSON-able values; :func:`restore` builds
new objects from them. Nothing is shared between a snapshot and the live objects,
so a stored state cannot change when the FMU steps on, and the same state can be
restored any number of times. Fields a class lists in ``_transient`` (derived
caches) are left out and come back empty.
"""

from __future__ import annotations

import importlib
from typing import Any

_CLASS, _FIELDS, _TUPLE = "__class__", "__fields__", "__tuple__"
#: Classes a state may name: this FMU's own modules (``<bundle>.`` inside an FMU).
_OWN = __package__.rpartition(".")[0] + "."


def snapshot(value: Any) -> Any:
    """A JSON-able deep copy.

    Parameters
    ----------
    value : Any
        A tree of algorithm objects (see the module doc for what it may contain).

    Returns
    -------
    Any
        Lists, dicts, strings, numbers, Booleans and None only.

    Raises
    ------
    TypeError
        For a dict whose keys are not all strings.
    """
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, list):
        return [snapshot(x) for x in value]
    if isinstance(value, tuple):
        return {_TUPLE: [snapshot(x) for x in value]}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise TypeError("FMU state dicts need string keys")
        return {k: snapshot(x) for k, x in value.items()}
    cls = type(value)
    transient = set(getattr(cls, "_transient", ()))
    fields = {
        name: snapshot(getattr(value, name))
        for name in _field_names(value)
        if name not in transient
    }
    return {_CLASS: f"{cls.__module__}:{cls.__qualname__}", _FIELDS: fields}


def restore(data: Any) -> Any:
    """New objects from a :func:`snapshot`.

    Parameters
    ----------
    data : Any
        What :func:`snapshot` returned (possibly through JSON).

    Returns
    -------
    Any
        New objects equal to the ones snapshotted.

    Raises
    ------
    ValueError
        If the data names a class outside this FMU's own package.
    """
    if data is None or isinstance(data, (bool, int, float, str)):
        return data
    if isinstance(data, list):
        return [restore(x) for x in data]
    if _TUPLE in data:
        return tuple(restore(x) for x in data[_TUPLE])
    if _CLASS not in data:
        return {k: restore(x) for k, x in data.items()}
    module, qualname = data[_CLASS].split(":")
    if not module.startswith(_OWN):
        raise ValueError(f"the state names class {data[_CLASS]!r}, not one of this FMU's")
    cls: Any = importlib.import_module(module)
    for part in qualname.split("."):
        cls = getattr(cls, part)
    obj = object.__new__(cls)
    for name, value in data[_FIELDS].items():
        object.__setattr__(obj, name, restore(value))
    for name in getattr(cls, "_transient", ()):
        object.__setattr__(obj, name, {})
    return obj


def _field_names(value: Any) -> list[str]:
    names = list(getattr(value, "__dict__", {}))
    for klass in type(value).__mro__:
        for name in getattr(klass, "__slots__", ()):
            if name not in names and hasattr(value, name):
                names.append(name)
    return names
