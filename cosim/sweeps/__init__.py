"""``cosim/sweeps/`` installed as ``arcosim.sweeps``: Monte Carlo and grid sweeps of
co-simulations (``arcosim sweep``).

Modules, in the order data flows:

toml_values -- a TOML file's values checked one by one, and shown as the file writes them
spec        -- a sweep's TOML specification read and checked, its runs drawn from a seed
runner      -- the runs on Dask, each a co-simulation scored by the spec's metrics
summary     -- the metrics' quantiles per varied parameter, and plots

Sits above :mod:`arcosim.host`, :mod:`arcosim.build` and :mod:`arcosim.experiments`.
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "load_spec": "arcosim.sweeps.spec",
    "sweep": "arcosim.sweeps.runner",
    "RESULTS": "arcosim.sweeps.runner",
    "SUMMARY": "arcosim.sweeps.runner",
    "read_results": "arcosim.sweeps.summary",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
