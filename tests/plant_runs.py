"""Drive the plant FMU step by step from tests (fixed step, inputs held per step)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from arcosim.host.instance import FmuInstance


def run_plant(
    fmu: Path,
    i_ref: Sequence[float],
    h: float,
    outputs: Sequence[str],
    parameters: Mapping[str, float | int | bool] | None = None,
    tau_ext: Mapping[str, float] | None = None,
) -> dict[str, np.ndarray]:
    """Step the plant once per entry of ``i_ref`` (A) with step ``h`` (s).

    Returns every name of ``outputs`` as an array of ``len(i_ref) + 1`` samples
    (the sample at t0 first) and ``"time"``.
    """
    samples = np.empty((len(i_ref) + 1, len(outputs)))
    with FmuInstance(fmu, "plant") as plant:
        plant.initialize(parameters)
        plant.set(dict(tau_ext or {}))
        samples[0] = plant.get(outputs)
        for k, current in enumerate(i_ref):
            plant.set({"i_ref": current})
            status = plant.do_step(k * h, h)
            assert status == 0, plant.messages
            samples[k + 1] = plant.get(outputs)
        assert not plant.messages, plant.messages
    result = {name: samples[:, j] for j, name in enumerate(outputs)}
    result["time"] = np.arange(len(i_ref) + 1) * h
    return result


IDEAL = {"encoder_cpr": 0, "i_noise_std": 0.0}
