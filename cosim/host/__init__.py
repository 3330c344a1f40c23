"""``cosim/host/`` installed as ``arcosim.host``: the FMI host side, the project's FMUs run
on fmpy.

Modules, in the order data flows:

overrides  -- ``plant.k[2]=0.2`` texts typed and checked against an FMU's variables
parameters -- the observer's and the controller's parameters with ``--set`` applied, no FMU built
instance   -- one FMU instance through fmpy's FMI 2.0 calls (``FmuInstance``), ctypes ports
stepping   -- what every fixed-step loop over FMUs needs (the step grid, the recording)
master     -- the fixed-step master of plant and observer (``cosimulate``, ``Recording``)
control_loop -- a fixed-step master for the closed loop controller → plant → controller
replay     -- a drive log fed to the observer FMU, sample by sample (``replay_log``)
tracking   -- a log replayed with the observer tracking the chain (``replay_tracking``)
ssp        -- an SSP 1.0 system read and run by a Jacobi master (``run_ssp``)
ecos       -- the ecos C++ engine in a separate process: the FMUs in a host not Python
validate   -- the checks a strict FMI host runs on an FMU (``arcosim validate``)

Imports of the project: :mod:`arcosim.errors`, :mod:`arcosim.logs`, :mod:`arcosim.fmu`,
:mod:`arcosim.portability`, :mod:`arcosim.version` (``tests/test_layout.py``).
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "INT_MAX": "arcosim.host.overrides",
    "parse_assignment": "arcosim.host.overrides",
    "split_overrides": "arcosim.host.overrides",
    "observer_values": "arcosim.host.parameters",
    "controller_values": "arcosim.host.parameters",
    "controller_problems": "arcosim.host.parameters",
    "MIN_STEP": "arcosim.host.master",
    "MAX_STEPS": "arcosim.host.master",
    "MAX_TIME": "arcosim.host.master",
    "ORDERINGS": "arcosim.host.master",
    "observer_parameters": "arcosim.host.replay",
    "final_values": "arcosim.host.replay",
    "TrackedChain": "arcosim.host.tracking",
    "replay_tracking": "arcosim.host.tracking",
    "untracked_outputs": "arcosim.host.tracking",
    "not_an_fmu": "arcosim.host.validate",
    "MEASURED": "arcosim.host.master",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
