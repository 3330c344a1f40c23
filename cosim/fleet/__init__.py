"""``cosim/fleet/`` installed as ``arcosim.fleet``: condition monitoring of many axes,
each identified from its logs over time (``arcosim fleet``).

Modules, in the order data flows:

layout   -- a fleet's folder read and checked: its axes, their ``axis.toml``, logs by date
identify -- every log not yet in the store identified on Dask, one row each
store    -- the rows in ``OUT/fleet.csv``, one appended and synced per log
drift    -- each axis's parameters against its baseline, and the alarms
figures  -- the drift drawn: a figure per alarmed axis, an overview of every axis

Sits above :mod:`arcosim.identification` and :mod:`arcosim.sweeps` (the folder's lock).
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "THRESHOLD": "arcosim.fleet.drift",
    "read_store": "arcosim.fleet.store",
    "write_store": "arcosim.fleet.store",
    "append_store": "arcosim.fleet.store",
    "AxisDrift": "arcosim.fleet.drift",
    "DriftReport": "arcosim.fleet.drift",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
