"""``cosim/build/`` installed as ``arcosim.build``: building the project's FMUs and their
SSP system.

Modules, in the order data flows:

recipes    -- what is built: one ``FmuRecipe`` per FMU, the numbers of masses supported
cache      -- where FMUs go (per-user cache or a folder), their source digest and lock
cplant     -- the plant FMU compiled from C (``plant_models/motorchain_c/``)
clink      -- the flexible-link plant FMU compiled from C (``plant_models/flexlink_c/``)
exit_fix   -- pythonfmu 0.7's exit-time use-after-free removed from its Linux binary
portable   -- pythonfmu's FMU rewritten to run anywhere: one bundle, the C trampoline
ssp        -- the SSP system source → plant → observer (``ActionReaction.ssp``)
builder    -- all of it, into a folder that is then current (``build_all``, ``ensure_built``)
native     -- the C sources compiled at build time (``fmu_trampoline.c``)

Imports nothing of :mod:`arcosim.host`, :mod:`arcosim.experiments` or the CLI.
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "MIN_MASSES": "arcosim.build.recipes",
    "MAX_MASSES": "arcosim.build.recipes",
    "MIN_ELEMENTS": "arcosim.build.recipes",
    "MAX_ELEMENTS": "arcosim.build.recipes",
    "check_masses": "arcosim.build.recipes",
    "check_elements": "arcosim.build.recipes",
    "OBSERVER": "arcosim.build.recipes",
    "fmu_variables": "arcosim.build.builder",
    "PLANT": "arcosim.build.recipes",
    "CONTROLLER": "arcosim.build.recipes",
    "build_link": "arcosim.build.clink",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
