"""``cosim/fleet/`` installed as ``arcosim.fleet``: condition monitoring of many axes,
each identified from its logs over time (``arcosim fleet``).

Modules, in the order data flows:

layout   -- a fleet's folder read and checked: its axes, their ``axis.toml``, logs by date
identify -- every log not yet in the store identified on Dask, one row each
store    -- the rows in ``OUT/fleet.csv``, written atomically after each log
drift    -- each axis's parameters against its baseline, and the alarms

Sits above :mod:`arcosim.identification` and :mod:`arcosim.sweeps` (the folder's lock).
"""
