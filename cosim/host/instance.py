"""One FMU instance driven through fmpy's low-level FMI 2.0 calls.

:class:`FmuInstance` sets and gets variables by name (typed from the model
description), collects the FMU's log lines, and reports a refused step as a
status instead of an exception, so a master can carry on or stop cleanly.
"""

from __future__ import annotations

import atexit
import contextlib
import shutil
import zipfile
import zlib
from collections.abc import Iterable, Mapping, Sequence
from ctypes import CFUNCTYPE, c_int, c_size_t, c_void_p, cast
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Real,
    fmi2ValueReference,
)

from arcosim.errors import UserError

STATUS_NAMES = ("ok", "warning", "discard", "error", "fatal", "pending")

_EXTRACTED: dict[tuple[str, int, int], str] = {}


def extracted(path: Path) -> str:
    """The folder an FMU file is unzipped into, once per file (and version) per process.

    Every instance of one FMU then loads the same binary. pythonfmu 0.7's binary has
    a destructor that misbehaves at process exit (a use-after-free seen with
    valgrind), and each separately unzipped copy runs its own, so fewer copies mean
    fewer chances; it also spares an unzip per instance. The folders are removed at
    exit.
    """
    stat = path.stat()
    key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    folder = _EXTRACTED.get(key)
    if folder is None or not Path(folder).is_dir():
        try:  # extracting checks every member's CRC-32: a truncated or corrupt zip fails
            folder = extract(str(path))
        except (OSError, zipfile.BadZipFile, EOFError, zlib.error, ValueError) as error:
            raise UserError(
                f"{path}: not a complete FMU ({error}); rebuild it (`arcosim build`) or "
                "check the file"
            ) from None
        _EXTRACTED[key] = folder
        atexit.register(shutil.rmtree, folder, True)
    return folder


def raw_function(slave: FMU2Slave, name: str):
    """The FMI function ``name`` of ``slave`` as a bare ctypes pointer returning int.

    fmpy's own functions convert every argument through their ``argtypes`` (about
    0.5 µs a call); this one takes ctypes objects as they are, so the caller passes
    exactly the C types (``c_void_p`` component, arrays, ``c_size_t``, ``c_double``,
    int for ``fmi2Boolean``). For the per-step calls of a master only; the slave
    must outlive it (it points into the slave's loaded binary).
    """
    return CFUNCTYPE(c_int)(cast(slave._functions[name], c_void_p).value)


class RealPort:
    """One ``fmi2GetReal``/``fmi2SetReal`` of fixed value references, through
    :func:`raw_function` and preallocated arrays: no allocation, no conversion per call.

    Parameters
    ----------
    slave : FMU2Slave
        The instantiated FMU (it must outlive the port).
    vrs : sequence of int
        Value references of the Real variables, shape ``(M,)``.

    Attributes
    ----------
    values : ctypes array of fmi2Real
        Read into by :meth:`get` and sent by :meth:`send` (each in its variable's
        unit), shape ``(M,)``; a port's ``values`` may be another port's (connections).
    array : ndarray
        Numpy view of ``values`` (no copy), shape ``(M,)``.
    get_real, set_real : ctypes function
        ``fmi2GetReal`` and ``fmi2SetReal`` (:func:`raw_function`), for masters that
        make the call themselves: ``get_real(component, vrs, count, values)``.
    component, vrs, count : ctypes values
        The call's other arguments: the instance, the value references, their number.
    size : int
        The number of variables, M (a count).
    """

    def __init__(self, slave: FMU2Slave, vrs: Sequence[int]) -> None:
        self.size = len(vrs)
        self.count = c_size_t(self.size)
        self.vrs = (fmi2ValueReference * self.size)(*vrs)
        self.values = (fmi2Real * self.size)()
        self.array = np.ctypeslib.as_array(self.values) if self.size else np.empty(0)
        self.component = c_void_p(slave.component)
        self.get_real = raw_function(slave, "fmi2GetReal")
        self.set_real = raw_function(slave, "fmi2SetReal")

    def get(self) -> int:
        """Read the variables into :attr:`values`; return the FMI status."""
        return self.get_real(self.component, self.vrs, self.count, self.values)

    def send(self, values=None) -> int:
        """Set the variables from ``values`` (a ctypes array; default :attr:`values`)."""
        return self.set_real(
            self.component, self.vrs, self.count, self.values if values is None else values
        )


class FmuInstance:
    """An instantiated FMI 2.0 co-simulation FMU, driven through fmpy's FMI calls.

    Variables are set and read by name (typed from the model description); the
    FMU's log lines are collected; a refused step is a status, not an exception.
    Use it as a context manager (``with FmuInstance(...) as fmu:``), or call
    :meth:`close`.

    Parameters
    ----------
    path : str or Path
        The ``.fmu`` file.
    instance_name : str
        Name given to ``fmi2Instantiate`` (appears in log lines).
    echo_log : bool
        Also print every log line to standard output.

    Attributes
    ----------
    messages : list of str
        Log lines received, as ``"status: message"``.
    variables : dict
        Model variables by name (fmpy ``ScalarVariable``).

    Examples
    --------
    >>> folder = arcosim.ensure_built(3)
    >>> with arcosim.FmuInstance(folder / "MotorChainPlant.fmu", "plant") as plant:
    ...     plant.initialize({"k[1]": 0.2})
    ...     status = plant.do_step(0.0, 1e-3)  # 0 is fmi2OK
    ...     values = plant.get(["k[1]", "theta_m"])
    >>> status, values[0]
    (0, 0.2)
    """

    def __init__(self, path: str | Path, instance_name: str = "instance", echo_log: bool = False):
        path = Path(path)
        if not path.is_file():
            raise UserError(f"FMU not found: {path} (run `arcosim build` first)")
        self.path = path
        self.slave = None
        # The description is read from the unzipped copy whose binary is loaded, so the
        # two always match, even if the file is replaced (a rebuild) in between.
        self._unzipped = extracted(path)
        try:
            self.description = read_model_description(self._unzipped)
        except Exception as error:  # fmpy raises whatever its XML reader meets
            raise UserError(f"{path}: not a valid FMU ({error})") from None
        if self.description.fmiVersion != "2.0":
            raise UserError(
                f"{path}: an FMI {self.description.fmiVersion} FMU; arcosim runs FMI 2.0"
            )
        if self.description.coSimulation is None:
            raise UserError(f"{path}: not a co-simulation FMU (it has no <CoSimulation>)")
        self.variables = {v.name: v for v in self.description.modelVariables}
        self.messages: list[str] = []
        self._echo = echo_log
        self._callbacks = self._make_callbacks()
        self.slave = FMU2Slave(
            guid=self.description.guid,
            unzipDirectory=self._unzipped,
            modelIdentifier=self.description.coSimulation.modelIdentifier,
            instanceName=instance_name,
        )
        self.slave.instantiate(callbacks=self._callbacks, loggingOn=True)
        self.slave.setDebugLogging(True, [])
        self.time = 0.0

    # -- life cycle -------------------------------------------------------------------

    def initialize(
        self, parameters: Mapping[str, float | int | bool] | None = None, start_time: float = 0.0
    ) -> None:
        """Set parameters by name, then run initialization mode at ``start_time`` (s).

        Raises
        ------
        UserError
            When the FMU refuses a value or its initialization; its log lines (they
            name the parameters at fault) are the message.
        """
        before = len(self.messages)
        try:
            self.slave.setupExperiment(startTime=start_time)
            self.set(parameters or {})
            self.slave.enterInitializationMode()
            self.slave.exitInitializationMode()
        except FMICallException as error:
            said = [m.split(": ", 1)[-1] for m in self.messages[before:]]
            raise UserError(
                f"{self.path.name} refused its parameters: "
                + ("; ".join(said) if said else f"status {error.status}")
            ) from None
        self.time = start_time

    def do_step(self, t: float, h: float) -> int:
        """``fmi2DoStep(t, h)``; returns the FMI status (0 ok, 1 warning, 2 discard, …)."""
        try:
            self.slave.doStep(t, h)
        except FMICallException as error:
            return error.status
        self.time = t + h
        return 0

    def close(self) -> None:
        """Terminate and free the instance (the unzipped FMU stays for the next one)."""
        if getattr(self, "slave", None) is None:
            return
        with contextlib.suppress(FMICallException):
            self.slave.terminate()
        self.slave.freeInstance()
        self.slave = None

    def __enter__(self) -> FmuInstance:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- values -----------------------------------------------------------------------

    def output_names(self) -> list[str]:
        """Every output of the FMU, in declaration order."""
        return [v.name for v in self.description.modelVariables if v.causality == "output"]

    def unit(self, name: str) -> str:
        """The unit of variable ``name`` as its model description declares it (``"1"`` for
        an Integer, a Boolean or a Real without a unit)."""
        return getattr(self._variable(name), "unit", None) or "1"

    def vrs(self, names: Iterable[str]) -> list[int]:
        """Value references of ``names``; unknown names raise :class:`UserError`."""
        return [self._variable(n).valueReference for n in names]

    def set(self, values: Mapping[str, float | int | bool]) -> None:
        """Set variables by name, each with the FMI call of its type."""
        for name, value in values.items():
            var = self._variable(name)
            if var.type == "Real":
                self.slave.setReal([var.valueReference], [float(value)])
            elif var.type == "Integer":
                self.slave.setInteger([var.valueReference], [int(value)])
            elif var.type == "Boolean":
                self.slave.setBoolean([var.valueReference], [bool(value)])
            elif var.type == "String":
                self.slave.setString([var.valueReference], [str(value)])
            else:
                raise UserError(f"{name}: variables of type {var.type} cannot be set here")

    def reader(self, names: Sequence[str]):
        """A function returning ``names`` as floats, with one get call per FMI type."""
        groups = {"Real": [], "Integer": [], "Boolean": []}
        for position, name in enumerate(names):
            var = self._variable(name)
            groups[var.type].append((position, var.valueReference))
        calls = [
            (fn, [p for p, _ in group], [vr for _, vr in group])
            for fn, group in (
                (self.slave.getReal, groups["Real"]),
                (self.slave.getInteger, groups["Integer"]),
                (self.slave.getBoolean, groups["Boolean"]),
            )
            if group
        ]
        if len(calls) == 1 and calls[0][0] == self.slave.getReal:
            get, _, vrs = calls[0]
            return lambda: get(vrs)
        size = len(names)

        def read() -> list[float]:
            out = [0.0] * size
            for get, positions, vrs in calls:
                for p, x in zip(positions, get(vrs)):
                    out[p] = float(x)
            return out

        return read

    def real_writer(self, names: Sequence[str]):
        """A function setting the Real variables ``names`` with one ``fmi2SetReal`` call."""
        vrs = self._real_vrs(names)
        put = self.slave.setReal
        return lambda values: put(vrs, values)

    def _real_vrs(self, names: Sequence[str]) -> list[int]:
        for name in names:
            if self._variable(name).type != "Real":
                raise UserError(f"{name} is a {self._variable(name).type}, not a Real variable")
        return self.vrs(names)

    def real_port(self, names: Sequence[str]) -> RealPort:
        """Preallocated buffers for one batched get or set of the Real variables ``names``."""
        return RealPort(self.slave, self._real_vrs(names))

    def step_call(self) -> tuple:
        """``(do_step, component)`` for a master's hot loop: call
        ``do_step(component, t, h, 1)`` with ``t`` and ``h`` as ``c_double`` (see
        :func:`raw_function`); it returns the FMI status."""
        return raw_function(self.slave, "fmi2DoStep"), c_void_p(self.slave.component)

    def get(self, names: Sequence[str]) -> list[float]:
        """Values of ``names`` (Booleans and Integers converted to float)."""
        return list(self.reader(names)())

    def _variable(self, name: str):
        try:
            return self.variables[name]
        except KeyError:
            raise UserError(
                f"{self.path.name} has no variable {name!r} "
                f"(it has: {', '.join(sorted(self.variables)[:12])}, …)"
            ) from None

    def _make_callbacks(self) -> fmi2CallbackFunctions:
        from fmpy import calloc, free

        def logger(env, instance, status, category, message):
            text = (
                message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
            )
            line = f"{STATUS_NAMES[status] if 0 <= status < 6 else status}: {text}"
            self.messages.append(line)
            if self._echo:
                print(line)

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        return callbacks
