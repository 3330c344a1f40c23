"""The motion controller checked before it runs: its loops' margins on numpy.

The controller itself (design and per-sample code) lives with the FMUs' algorithms in
:mod:`arcosim.fmu.flexchain` (standard library); this package analyses it, for a chain
and the user's goals, in the order the check goes:

model_errors    -- the model errors checked: the two corners and random J_i, k_i scalings
full_state      -- the state feedback's loop: margins at the current, decays under errors
sensorless_loop -- the sensorless loop linearized from the controller's and the plant's code
margins         -- both together for one chain (``controller_margins``), with a verdict

``arcosim control`` prints :func:`~arcosim.control.margins.controller_margins`.
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "ERROR": "arcosim.control.model_errors",
    "RANDOM_MODELS": "arcosim.control.model_errors",
    "sensorless_decay": "arcosim.control.sensorless_loop",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
