"""Base class of every FMU of the project.

Conventions it settles (see README, "FMU conventions"):

* Values live in one list indexed by value reference; ``get_*``/``set_*`` read and
  write it directly (no per-variable Python objects on the hot path).
* A failure is never a Python exception escaping to pythonfmu (that becomes
  fmi2Fatal). Invalid parameters are found at ``exitInitializationMode``, logged,
  and every later ``doStep`` answers fmi2Discard with the same message. A bad
  step (non-finite input, step size ≤ 0, communication point that is not the
  current time) is refused with fmi2Discard and a log line naming the problem,
  and leaves the state untouched. A step below ``SMALLEST_STEP`` is taken by holding
  the state and outputs: only the time advances.
* Algorithm state is kept in plain data (floats, ints, lists, small classes), so
  FMU state get/set and serialization cover every filter and accumulator
  (:mod:`arcosim.fmu.fmukit.state`).
* Timing contract (docs/method.md): after ``doStep(t, h)`` the outputs are the
  sample at ``t + h``.

Longer than 450 lines because it is the one FMI 2.0 slave every FMU derives from: the
entry points, the step's checks and its hold below ``SMALLEST_STEP``, the trace and the
state each take a few lines, and apart they would scatter one contract.
"""

from __future__ import annotations

import math
import traceback
from collections.abc import Sequence
from operator import itemgetter
from pathlib import Path
from typing import ClassVar, TextIO
from xml.etree.ElementTree import Element

# Inside an FMU, pythonfmu's runtime bundled beside this package; in the source tree,
# arcosim.fmu.pythonfmu, which re-exports the installed one.
from ..pythonfmu.enums import Fmi2Status
from ..pythonfmu.fmi2slave import Fmi2Slave
from .checks import LARGEST, SMALLEST_STEP, STEP_JITTER, number_problem
from .model_description import ModelInfo, model_description
from .state import restore, snapshot
from .variables import Value, Variable, par

#: Every FMU's last parameter: a CSV of its outputs after every step, at full
#: precision, written from inside whatever host runs it ("" = off).
TRACE_FILE = par(
    "trace_file",
    "",
    "",
    "Path of a CSV to write the outputs to after every step at full precision "
    "(empty = off; an existing file is never overwritten)",
)


_INF = math.inf
isfinite = math.isfinite


def _tuple_getter(indices: Sequence[int]):
    """A function returning ``tuple(v[i] for i in indices)`` (fast, via itemgetter)."""
    if not indices:
        return lambda v: ()
    if len(indices) == 1:
        i = indices[0]
        return lambda v: (v[i],)
    return itemgetter(*indices)


class StepRefusedError(Exception):
    """Raised by :meth:`FmuSlave.step` to refuse a step with fmi2Discard."""


class FmuSlave(Fmi2Slave):
    """Values by value reference, parameter checks, and failure reporting.

    Subclasses define :meth:`declare`, :meth:`check_parameters`,
    :meth:`initialize` and :meth:`step`; the FMI plumbing stays here.
    """

    n_masses: ClassVar[int] = 3  # set per build by the generated script
    model_text: ClassVar[str] = ""
    project_version: ClassVar[str] = "0.0.0"
    experiment: ClassVar[tuple[float, float, float]] = (0.0, 10.0, 1e-3)

    @classmethod
    def declare(cls) -> list[Variable]:
        """Every variable of the FMU, in value-reference order."""
        raise NotImplementedError

    @classmethod
    def interface(cls, n: int) -> dict[str, Variable]:
        """The FMU's variables for ``n`` load masses by name, as built (start values are
        the parameters' defaults): its interface without building it."""
        built = type(cls.__name__, (cls,), {"n_masses": n})
        return {v.name: v for v in (*built.declare(), TRACE_FILE)}

    def check_parameters(self) -> list[str]:
        """Problems with the parameter values, one sentence each (empty if none)."""
        return []

    def initialize(self) -> None:
        """Build the algorithm state from the parameters and set the outputs at t0."""

    def step(self, t: float, h: float) -> None:
        """Advance from ``t`` to ``t + h`` (s): read inputs, write outputs.

        Outputs that are costly and only needed when read may be left stale: list
        their value references in :attr:`lazy`, set :attr:`stale`, and compute them
        in :meth:`refresh`, which runs only when one of them is read.
        """
        raise NotImplementedError

    def refresh(self) -> None:
        """Bring the :attr:`lazy` outputs up to date (called before one of them is read)."""

    # -- construction -------------------------------------------------------------

    def __init__(self, **kwargs: object) -> None:
        super().__init__(**kwargs)
        cls = type(self)
        self.modelName = cls.__name__
        self.variables: list[Variable] = [*cls.declare(), TRACE_FILE]
        self.vr: dict[str, int] = {v.name: i for i, v in enumerate(self.variables)}
        if len(self.vr) != len(self.variables):
            raise ValueError(f"{cls.__name__}: duplicate variable names")
        self.v: list[Value] = [var.initial_value for var in self.variables]
        by_type: dict[str, set[int]] = {
            "Real": set(),
            "Integer": set(),
            "Boolean": set(),
            "String": set(),
        }
        for i, var in enumerate(self.variables):
            by_type[var.type].add(i)
        self._vrs_of_type = {k: frozenset(s) for k, s in by_type.items()}
        self._parameters = frozenset(
            i for i, v in enumerate(self.variables) if v.causality == "parameter"
        )
        self._outputs = frozenset(
            i for i, v in enumerate(self.variables) if v.causality == "output"
        )
        self._real_inputs = [
            i for i, v in enumerate(self.variables) if v.causality == "input" and v.type == "Real"
        ]
        # the hot path: Real inputs as one tuple, and the Reals settable without a word
        self._read_inputs = _tuple_getter(self._real_inputs)
        self._inputs = frozenset(self._real_inputs)
        self._reals = self._vrs_of_type["Real"]
        lo, hi = (self._real_inputs[0], self._real_inputs[-1] + 1) if self._real_inputs else (0, 0)
        # every Real input at once, when they are declared together: set as one slice
        self._input_block = self._real_inputs if self._real_inputs == list(range(lo, hi)) else None
        self._input_slice = slice(lo, hi)
        self._read_outputs = _tuple_getter(sorted(self._outputs))
        self._last_read: list[int] = []  # the last Reals read, and their getter
        self._read_last = _tuple_getter([])
        self.time: float | None = None
        self._h = 0.0  # the step last taken (s): see STEP_JITTER
        self.stale = False
        self.lazy: frozenset[int] = frozenset()
        self.initialized = False
        self._ready = False  # initialized, no problems, time known: the fast path may run
        self.problems: list[str] = []
        self._trace: TextIO | None = None
        self._trace_outputs = sorted(self._outputs)
        self._base_attributes = frozenset(vars(self)) | {"_base_attributes"}

    def to_xml(self, model_options: dict[str, str] | None = None) -> Element:
        """The compliant model description (called by pythonfmu's builder)."""
        info = ModelInfo(
            identifier=self.modelName,
            description=self.model_text,
            version=self.project_version,
            experiment=self.experiment,
        )
        options = {k: str(v).lower() for k, v in (model_options or {}).items()}
        return model_description(info, self.variables, options)

    # -- convenience for subclasses -----------------------------------------------

    def value(self, name: str) -> Value:
        """Current value of the variable called ``name``."""
        return self.v[self.vr[name]]

    def values(self, names: Sequence[str]) -> list[Value]:
        """Current values of several variables, in order."""
        return [self.v[self.vr[n]] for n in names]

    def indices(self, names: Sequence[str]) -> list[int]:
        """Value references of several variables, in order."""
        return [self.vr[n] for n in names]

    def report(self, message: str, status: Fmi2Status = Fmi2Status.error) -> None:
        """Log ``message`` under the category that matches ``status``."""
        self.log(f"{self.instance_name}: {message}", status)

    # -- FMI life cycle -----------------------------------------------------------

    def setup_experiment(self, start_time: float, stop_time=None, tolerance=None) -> None:
        self.time = float(start_time)

    # -- FMU state (fmi2GetFMUstate, fmi2SetFMUstate, serialization) ----------------

    def _get_fmu_state(self) -> dict:
        """Values, time, status and every attribute the subclass made, as JSON data."""
        own = {k: v for k, v in vars(self).items() if k not in self._base_attributes}
        return {
            "values": list(self.v),
            "time": self.time,
            "stale": self.stale,
            "initialized": self.initialized,
            "problems": list(self.problems),
            "algorithm": snapshot(own),
        }

    def _set_fmu_state(self, state: dict) -> None:
        """Restore a state of :meth:`_get_fmu_state`; anything else is refused with an
        error in the log and leaves the instance as it was."""
        try:
            values = list(state["values"])
            if len(values) != len(self.v):
                raise ValueError(f"it has {len(values)} values, this FMU {len(self.v)}")
            algorithm = restore(state["algorithm"])
            scalars = (state["time"], bool(state["stale"]), bool(state["initialized"]))
            problems = [str(p) for p in state["problems"]]
        except Exception as error:  # never fmi2Fatal: the instance stays usable
            self.report(f"FMU state refused: {error}")
            return
        self.v = values
        self.time, self.stale, self.initialized = scalars
        self.problems = problems
        self._ready = self.initialized and not self.problems and self.time is not None
        for name, value in algorithm.items():
            setattr(self, name, value)

    def exit_initialization_mode(self) -> None:
        self.problems = self._checked(self._number_problems)
        if not self.problems:
            self.problems = self._checked(self.check_parameters)
        if not self.problems:
            self.problems = self._checked(self.initialize)
        if not self.problems:
            self.problems = self._checked(self._open_trace)
        for problem in self.problems:
            self.report(problem)
        self.initialized = True
        self._ready = not self.problems and self.time is not None
        # the outputs a step computes (the lazy ones are computed when read)
        self._read_outputs = _tuple_getter(sorted(self._outputs - self.lazy))

    def _number_problems(self) -> list[str]:
        """Real parameters that are not finite numbers within ±LARGEST (SI units)."""
        found = (
            number_problem(self.variables[i].name, self.v[i])
            for i in sorted(self._parameters & self._reals)
        )
        return [problem for problem in found if problem is not None]

    def do_step(self, current_time: float, step_size: float) -> bool:
        if not (  # the common case in few operations; any doubt takes the full checks
            self._ready
            and SMALLEST_STEP <= step_size < _INF
            and -1e-9 <= current_time - self.time <= 1e-9
            and sum(map(abs, self._read_inputs(self.v))) <= LARGEST
        ):
            if not self._step_allowed(current_time, step_size):
                return False
            if step_size < SMALLEST_STEP:
                return self._hold(current_time + step_size)
        if abs(step_size - self._h) > STEP_JITTER * self._h:
            self._h = step_size
        try:
            self.step(current_time, self._h)
        except StepRefusedError as refusal:
            self.report(str(refusal), Fmi2Status.discard)
            return False
        except Exception:  # a bug must not become fmi2Fatal in the user's host
            self.report("internal error, step refused:\n" + traceback.format_exc())
            return False
        if not isfinite(sum(self._read_outputs(self.v))):
            self._refuse_not_finite(current_time, step_size)
            return False
        self.time = current_time + step_size
        if self._trace is not None:
            self._write_trace()
        return True

    def _hold(self, end: float) -> bool:
        """Take a step below SMALLEST_STEP (a summing host's rounding residue): the
        state and the outputs stay as they are, only the time moves to ``end`` (s)."""
        self.time = end
        if self._trace is not None:
            self._write_trace()
        return True

    def _step_allowed(self, current_time: float, step_size: float) -> bool:
        """Every check of a step spelt out; a refusal is logged with its reason."""
        if not self.initialized:
            self.report(
                "doStep called before initialization finished; call "
                "fmi2EnterInitializationMode and fmi2ExitInitializationMode first",
                Fmi2Status.discard,
            )
            return False
        if self.problems:
            self.report("cannot step: " + "; ".join(self.problems), Fmi2Status.discard)
            return False
        problem = self._step_problem(current_time, step_size)
        if problem is not None:
            self.report(problem, Fmi2Status.discard)
            return False
        return True

    def terminate(self) -> None:
        if self._trace is not None:
            self._trace.close()
            self._trace = None

    # -- trace file: every output at full precision, from inside any host ---------

    def _open_trace(self) -> list[str]:
        path = str(self.v[self.vr["trace_file"]])
        if not path:
            return []
        if Path(path).exists():
            return [f"trace_file {path!r} exists; choose a new name (it is never overwritten)"]
        try:
            self._trace = open(path, "x", encoding="utf-8", buffering=1)  # noqa: SIM115
        except OSError as error:
            return [f"trace_file {path!r} cannot be written: {error.strerror}"]
        names = [self.variables[i].name for i in self._trace_outputs]
        self._trace.write(",".join(["time", *names]) + "\n")
        self._write_trace()
        return []

    def _write_trace(self) -> None:
        self._refresh(self._trace_outputs)
        v = self.v
        row = [repr(float(self.time or 0.0))]
        row += [repr(float(v[i])) for i in self._trace_outputs]
        self._trace.write(",".join(row) + "\n")

    def _refuse_not_finite(self, t: float, h: float) -> None:
        """A step gave a non-finite output: refuse it, and every step after it.

        The filters' state after such a step is not worth stepping from, and the
        state before it is not kept (a copy per step would cost more than the step):
        the instance refuses every later step until a saved FMU state is restored.
        """
        bad = [
            self.variables[i].name
            for i in sorted(self._outputs - self.lazy)
            if not isfinite(self.v[i])
        ]
        problem = (
            f"the step from t = {t!r} s by {h!r} s gave non-finite outputs "
            f"({', '.join(bad)}); restore a saved FMU state or instantiate again"
        )
        self.problems = [problem]
        self._ready = False
        self.report(problem, Fmi2Status.discard)

    def _step_problem(self, t: float, h: float) -> str | None:
        if not (math.isfinite(h) and h > 0.0):
            return f"step size {h!r} s refused: it must be a finite number > 0"
        if not math.isfinite(t):
            return f"communication point {t!r} s refused: it must be finite"
        if self.time is not None and abs(t - self.time) > 1e-9 * max(1.0, abs(t)):
            return (
                f"communication point {t!r} s refused: the FMU is at t = {self.time!r} s "
                "(restore a saved FMU state to step from another time)"
            )
        v = self.v
        for i in self._real_inputs:
            if not math.isfinite(v[i]):
                return f"input {self.variables[i].name} = {v[i]!r} is not finite; step refused"
            if abs(v[i]) > LARGEST:
                return (
                    f"input {self.variables[i].name} = {v[i]!r} is beyond ±{LARGEST:g} "
                    "(SI units); step refused"
                )
        return None

    def _checked(self, function) -> list[str]:
        try:
            return list(function() or [])
        except Exception:
            return ["internal error during initialization:\n" + traceback.format_exc()]

    # -- value access (called by pythonfmu's binary) -------------------------------

    def get_real(self, vrs: Sequence[int]) -> list[float]:
        if not self.stale:  # the per-step read of a master, inline
            if vrs == self._last_read:
                return list(self._read_last(self.v))
            if self._reals.issuperset(vrs):
                self._last_read, self._read_last = list(vrs), _tuple_getter(vrs)
                return list(self._read_last(self.v))
        return self._get(vrs, "Real", float)

    def get_integer(self, vrs: Sequence[int]) -> list[int]:
        return self._get(vrs, "Integer", int)

    def get_boolean(self, vrs: Sequence[int]) -> list[bool]:
        return self._get(vrs, "Boolean", bool)

    def get_string(self, vrs: Sequence[int]) -> list[str]:
        return self._get(vrs, "String", str)

    def set_real(self, vrs: Sequence[int], values: Sequence[float]) -> None:
        if vrs == self._input_block:  # the per-step write of every input, in order
            self.v[self._input_slice] = values
        elif self._inputs.issuperset(vrs):  # inputs: always settable, already floats
            v = self.v
            for i, x in zip(vrs, values):
                v[i] = x
        else:
            self._set(vrs, values, "Real", float)

    def set_integer(self, vrs: Sequence[int], values: Sequence[int]) -> None:
        self._set(vrs, values, "Integer", int)

    def set_boolean(self, vrs: Sequence[int], values: Sequence[bool]) -> None:
        self._set(vrs, values, "Boolean", bool)

    def set_string(self, vrs: Sequence[int], values: Sequence[str]) -> None:
        self._set(vrs, values, "String", str)

    def _refresh(self, vrs: Sequence[int]) -> None:
        """Run :meth:`refresh` if ``vrs`` include a stale :attr:`lazy` output."""
        if self.stale and not self.lazy.isdisjoint(vrs):
            self.stale = False
            self.refresh()

    def _get(self, vrs: Sequence[int], vtype: str, cast: type) -> list:
        self._refresh(vrs)
        v = self.v
        if self._vrs_of_type[vtype].issuperset(vrs):
            return [v[i] for i in vrs]
        self.report(f"get{vtype}: value references {list(vrs)} are not all {vtype} variables")
        return [cast(v[i]) if i in self._vrs_of_type[vtype] else cast(0) for i in vrs]

    def _set(self, vrs: Sequence[int], values: Sequence, vtype: str, cast: type) -> None:
        v = self.v
        valid = self._vrs_of_type[vtype]
        for i, x in zip(vrs, values):
            if i not in valid:
                self.report(f"set{vtype}: value reference {i} is not a {vtype} variable; ignored")
            elif i in self._outputs:
                self.report(
                    f"{self.variables[i].name} is an output and cannot be set; ignored",
                    Fmi2Status.warning,
                )
            elif self.initialized and i in self._parameters:
                self.report(
                    f"parameter {self.variables[i].name} is fixed after initialization; "
                    "the new value is ignored (set it before exitInitializationMode)",
                    Fmi2Status.warning,
                )
            else:
                v[i] = cast(x)
