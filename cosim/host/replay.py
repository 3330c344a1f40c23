"""Feed a recorded drive log to the observer FMU, sample by sample.

:func:`replay_log` drives a ReactionTorqueObserver instance with a log's rows as a
Gauss–Seidel master would (the timing contract: row k ends the step from row k − 1,
and the step may vary); :func:`parameter_sets` and :func:`observer_parameters` type
``NAME=VALUE`` texts against the observer's variables. ``arcosim identify`` is the
command line.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from arcosim.errors import UserError
from arcosim.host.instance import FmuInstance
from arcosim.host.master import MEASURED, Recording
from arcosim.host.overrides import check_name, parse_assignment, typed_value
from arcosim.logs import DriveLog


def replay_log(
    observer: FmuInstance,
    log: DriveLog,
    parameters: Mapping[str, float | int | bool] | None = None,
    outputs: Sequence[str] | None = None,
) -> Recording:
    """Feed every sample of a drive log to a fresh observer FMU instance.

    The first row is the initial sample (set before initialization); row k ends the
    step from row k−1, so ``doStep(t_{k−1}, t_k − t_{k−1})`` receives it, as with a
    Gauss–Seidel master. The step may vary; the observer gets the step taken.

    Parameters
    ----------
    observer : FmuInstance
        A ReactionTorqueObserver instance, not yet initialized.
    log : DriveLog
        The samples (``time`` s, ``i_a`` A, ``omega_m`` rad/s, ``theta_m`` rad).
    parameters : mapping of str to value, optional
        Observer parameters by name (in each parameter's unit), e.g.
        ``{"mode": 2, "k[1]": 0.16}``.
    outputs : sequence of str, optional
        Outputs to record (default: every output).

    Returns
    -------
    Recording
        One sample per log row, signals named ``"observer.<name>"``.

    Raises
    ------
    UserError
        When the observer refuses a sample (its log line is in the message).

    Examples
    --------
    >>> from pathlib import Path
    >>> t = np.arange(200) * 1e-3
    >>> log = arcosim.DriveLog(Path("synthetic.csv"), {
    ...     "time": t, "i_a": np.full(200, 0.2), "omega_m": 10.0 * t, "theta_m": 5.0 * t**2})
    >>> folder = arcosim.ensure_built(3)
    >>> with arcosim.FmuInstance(folder / "ReactionTorqueObserver.fmu") as observer:
    ...     run = arcosim.replay_log(observer, log, {"mode": 2}, ["d_hat"])
    >>> run.signals["observer.d_hat"].shape
    (200,)
    """
    if outputs is None:
        outputs = observer.output_names()
    write = observer.real_writer(list(MEASURED))
    read = observer.reader(outputs)
    inputs = np.column_stack([log.columns[c] for c in MEASURED])
    t = log.time
    write(list(inputs[0]))
    observer.initialize(parameters, float(t[0]))
    samples = np.empty((len(t), len(outputs)))
    samples[0] = read()
    for k in range(1, len(t)):
        write(list(inputs[k]))
        status = observer.do_step(float(t[k - 1]), float(t[k] - t[k - 1]))
        if status > 1:
            raise UserError(
                f"{log.path}, sample at t = {float(t[k]):.10g} s: the observer refused it: "
                + (observer.messages[-1] if observer.messages else f"status {status}")
            )
        samples[k] = read()
    recording = Recording(time=t.copy())
    for j, name in enumerate(outputs):
        recording.signals[f"observer.{name}"] = samples[:, j]
        recording.units[f"observer.{name}"] = observer.unit(name)
    return recording


def final_values(fmu: FmuInstance, recording: Recording, prefix: str = "observer") -> dict:
    """Last value of every recorded output, typed as JSON likes it.

    Parameters
    ----------
    fmu : FmuInstance
        The instance recorded (its variables' types).
    recording : Recording
        Its run; signals named ``"prefix.name"``.
    prefix : str
        The FMU's prefix in the signal names.

    Returns
    -------
    dict
        Name → last value (in the variable's unit): a bool, an int or a float by the
        variable's FMI type.

    Examples
    --------
    Any object with the instance's ``variables`` stands in for the FMU here:

    >>> from types import SimpleNamespace
    >>> fmu = SimpleNamespace(variables={"tau_reac_hat": SimpleNamespace(type="Real")})
    >>> run = Recording(np.array([0.0, 0.001]), {"observer.tau_reac_hat": np.array([0.0, 0.25])})
    >>> final_values(fmu, run)
    {'tau_reac_hat': 0.25}
    """
    result = {}
    for key, series in recording.signals.items():
        name = key.split(".", 1)[1]
        vtype = fmu.variables[name].type
        x = series[-1]
        result[name] = bool(x) if vtype == "Boolean" else int(x) if vtype == "Integer" else float(x)
    return result


def parameter_sets(
    variables: Mapping[str, object], assignments: Sequence[str], owner: str = "the observer"
) -> dict:
    """``--set`` texts (parameters of ``owner``, no prefix) as typed values, checked against
    its variables (anything with ``causality`` and ``type``, by name)."""
    parameters: dict[str, float | int | bool] = {}
    for text in assignments:
        name, value = parse_assignment(text)
        check_name(name, variables, owner)
        var = variables[name]
        if var.causality != "parameter":
            raise UserError(f"--set {text!r}: {name} is an {var.causality}, not a parameter")
        parameters[name] = typed_value(name, value, var.type)
    return parameters


def observer_parameters(fmu: FmuInstance, assignments: Sequence[str], mode: int | None) -> dict:
    """``--set`` texts (observer parameters, no prefix) and ``--mode`` as typed values.

    Parameters
    ----------
    fmu : FmuInstance
        The observer instance whose variables (their ``causality`` and FMI ``type``)
        the texts are checked and typed against.
    assignments : sequence of str
        ``NAME=VALUE`` texts as given to ``--set``, e.g. ``"g_dist=200"`` (the value in
        the variable's unit).
    mode : int or None
        The observer's ``mode`` parameter as given to ``--mode``; ``None`` leaves it
        at the FMU's start value.

    Returns
    -------
    dict
        Parameter name → its typed start value (a bool, an int or a float by the
        variable's FMI type), with ``"mode"`` when ``mode`` is given.

    Raises
    ------
    UserError
        A text without ``=``, naming no variable of the observer or no parameter, or
        with a value of the wrong type.

    Examples
    --------
    Any object with the instance's ``variables`` stands in for the FMU here:

    >>> from types import SimpleNamespace
    >>> gain = SimpleNamespace(type="Real", causality="parameter")
    >>> observer = SimpleNamespace(variables={"g_dist": gain})
    >>> observer_parameters(observer, ["g_dist=200"], mode=1)
    {'g_dist': 200.0, 'mode': 1}
    """
    parameters = parameter_sets(fmu.variables, assignments)
    if mode is not None:
        parameters["mode"] = mode
    return parameters
