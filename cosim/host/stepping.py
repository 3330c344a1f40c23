"""What every fixed-step loop over FMUs needs (:mod:`arcosim.host.master`'s and
:mod:`arcosim.host.control_loop`'s): the step's checks, the plant's further inputs, the
points and readers of the recording, and a status that stops the run with the FMU's log.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from arcosim.errors import UserError
from arcosim.host.instance import FmuInstance


def check_step(h: float) -> None:
    """Refuse a step ``h`` (s) that is not finite and > 0."""
    if not (h > 0.0 and np.isfinite(h)):
        raise UserError(f"step size {float(h)!r} s: it must be a finite number > 0")


def plant_inputs(
    plant: FmuInstance, inputs: Mapping[str, Sequence[float]], steps: int
) -> dict[str, list[float]]:
    """The plant's other Real inputs as floats, one per step; refuse a name that is not
    such an input, or a length that is not ``steps``."""
    extra = {name: [float(x) for x in values] for name, values in inputs.items()}
    for name, values in extra.items():
        var = plant.variables.get(name)
        if name == "i_ref" or var is None or var.causality != "input" or var.type != "Real":
            raise UserError(f"plant input {name!r}: not a Real input of the plant besides i_ref")
        if len(values) != steps:
            raise UserError(f"plant input {name!r}: {len(values)} values for {steps} steps")
    return extra


def record_points(steps: int, record_every: int) -> list[int]:
    """The steps after which a run of ``steps`` steps records: 0 (the initial values),
    every ``record_every``-th, and always the last.

    Examples
    --------
    >>> record_points(10, 4)
    [0, 4, 8, 10]
    """
    recorded = [0, *range(record_every, steps + 1, record_every)]
    if recorded[-1] != steps:
        recorded.append(steps)
    return recorded


def signals(prefix: str, names: Sequence[str], log: np.ndarray) -> dict[str, np.ndarray]:
    """The columns of ``log`` (shape ``(R, len(names))``) as ``"prefix.name"`` signals."""
    return {f"{prefix}.{name}": log[:, j] for j, name in enumerate(names)}


def recorder(fmu: FmuInstance, names: Sequence[str]) -> Callable[[], Sequence[float]]:
    """Reads ``names`` as floats: one preallocated get when all are Real."""
    if not names:
        return lambda: ()
    if all(fmu.variables[n].type == "Real" for n in names if n in fmu.variables):
        port = fmu.real_port(names)

        def read() -> np.ndarray:
            check_status(port.get(), fmu, "reading outputs", fmu.time)
            return port.array

        return read
    return fmu.reader(names)


def check_status(
    status: int, fmu: FmuInstance, doing: str, t: float, component: str | None = None
) -> None:
    """Raise :class:`UserError` with the FMU's last log lines if ``status`` > warning.

    The message names the FMU's file, after ``component`` (a system's name for it) when
    given."""
    if status > 1:
        log = "\n  ".join(fmu.messages[-5:])
        refused = "refused the step" if doing == "stepping" else f"failed {doing}"
        who = fmu.path.name if component is None else f"{component} ({fmu.path.name})"
        raise UserError(f"{who} {refused} at t = {float(t):.10g} s:\n  {log}")
