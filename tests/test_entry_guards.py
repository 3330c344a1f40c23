"""NULL and state guards at every C entry point, as Reference-FMUs' framework
has: the plant's binary answers fmi2Error to a NULL instance (without touching it), to
a NULL array or result pointer, and to a call its FMI 2.0 co-simulation state does not
allow (logged); the Python FMUs' trampoline answers fmi2Error to a NULL instance.

Called through ctypes on the binaries themselves, so nothing in between checks first.
"""

from __future__ import annotations

import ctypes
import sys
import zipfile
from ctypes import POINTER, byref, c_char_p, c_double, c_int, c_size_t, c_uint, c_void_p
from pathlib import Path

import pytest

from arcosim.host.instance import FmuInstance

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux binaries")

OK, WARNING, DISCARD, ERROR = 0, 1, 2, 3
LOGGER = ctypes.CFUNCTYPE(None, c_void_p, c_char_p, c_int, c_char_p, c_char_p)


class Callbacks(ctypes.Structure):
    _fields_ = [
        ("logger", LOGGER),
        ("allocateMemory", c_void_p),
        ("freeMemory", c_void_p),
        ("stepFinished", c_void_p),
        ("componentEnvironment", c_void_p),
    ]


def _binary(fmu: Path, folder: Path) -> tuple[ctypes.CDLL, str, dict]:
    from fmpy import read_model_description

    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    md = read_model_description(str(folder))
    identifier = md.coSimulation.modelIdentifier
    lib = ctypes.CDLL(str(folder / "binaries" / "linux64" / f"{identifier}.so"))
    return lib, md.guid, {v.name: v for v in md.modelVariables}


# every entry that takes an instance, with arguments that would be valid for a live one
VR = (c_uint * 1)(0)


def _calls(variables: dict) -> dict:
    """name → (argument types after the instance, arguments)."""
    by_type = {t: (c_uint * 1)(0) for t in ("Real", "Integer", "Boolean", "String")}
    for v in reversed(list(variables.values())):  # the first variable of each type
        by_type[v.type] = (c_uint * 1)(v.valueReference)
    reals, ints, strings = (c_double * 1)(), (c_int * 1)(), (c_char_p * 1)(b"")
    state, size, status = c_void_p(), c_size_t(), c_int()
    return {
        "fmi2SetDebugLogging": ([c_int, c_size_t, c_void_p], [1, 0, None]),
        "fmi2SetupExperiment": (
            [c_int, c_double, c_double, c_int, c_double],
            [0, 0.0, 0.0, 0, 0.0],
        ),
        "fmi2EnterInitializationMode": ([], []),
        "fmi2ExitInitializationMode": ([], []),
        "fmi2Terminate": ([], []),
        "fmi2Reset": ([], []),
        "fmi2DoStep": ([c_double, c_double, c_int], [0.0, 1e-3, 1]),
        "fmi2CancelStep": ([], []),
        "fmi2GetReal": ([c_void_p, c_size_t, c_void_p], [by_type["Real"], 1, reals]),
        "fmi2GetInteger": ([c_void_p, c_size_t, c_void_p], [by_type["Integer"], 1, ints]),
        "fmi2GetBoolean": ([c_void_p, c_size_t, c_void_p], [by_type["Boolean"], 1, ints]),
        "fmi2GetString": ([c_void_p, c_size_t, c_void_p], [by_type["String"], 1, strings]),
        "fmi2SetReal": ([c_void_p, c_size_t, c_void_p], [by_type["Real"], 1, reals]),
        "fmi2SetInteger": ([c_void_p, c_size_t, c_void_p], [by_type["Integer"], 1, ints]),
        "fmi2SetBoolean": ([c_void_p, c_size_t, c_void_p], [by_type["Boolean"], 1, ints]),
        "fmi2SetString": ([c_void_p, c_size_t, c_void_p], [by_type["String"], 1, strings]),
        "fmi2GetFMUstate": ([c_void_p], [byref(state)]),
        "fmi2SetFMUstate": ([c_void_p], [None]),
        "fmi2FreeFMUstate": ([c_void_p], [byref(state)]),
        "fmi2SerializedFMUstateSize": ([c_void_p, c_void_p], [None, byref(size)]),
        "fmi2SerializeFMUstate": ([c_void_p, c_void_p, c_size_t], [None, None, 0]),
        "fmi2DeSerializeFMUstate": ([c_void_p, c_size_t, c_void_p], [None, 0, byref(state)]),
        "fmi2GetDirectionalDerivative": (
            [c_void_p, c_size_t, c_void_p, c_size_t, c_void_p, c_void_p],
            [VR, 1, VR, 1, reals, reals],
        ),
        "fmi2SetRealInputDerivatives": (
            [c_void_p, c_size_t, c_void_p, c_void_p],
            [VR, 1, ints, reals],
        ),
        "fmi2GetRealOutputDerivatives": (
            [c_void_p, c_size_t, c_void_p, c_void_p],
            [VR, 1, ints, reals],
        ),
        "fmi2GetStatus": ([c_int, c_void_p], [0, byref(status)]),
        "fmi2GetRealStatus": ([c_int, c_void_p], [2, reals]),
        "fmi2GetIntegerStatus": ([c_int, c_void_p], [0, ints]),
        "fmi2GetBooleanStatus": ([c_int, c_void_p], [4, ints]),
        "fmi2GetStringStatus": ([c_int, c_void_p], [3, strings]),
    }


def _call(lib: ctypes.CDLL, name: str, component, calls: dict) -> int:
    argtypes, args = calls[name]
    function = getattr(lib, name)
    function.restype = c_int
    function.argtypes = [c_void_p, *argtypes]
    return function(component, *args)


@pytest.mark.parametrize(
    "name",
    ["MotorChainPlant", "ReactionTorqueObserver", "ExcitationSource", "ActionReactionController"],
)
def test_a_null_instance_is_refused_by_every_entry(fmus, tmp_path, name) -> None:
    lib, _, variables = _binary(fmus / f"{name}.fmu", tmp_path)
    calls = _calls(variables)
    for function in calls:
        assert _call(lib, function, None, calls) == ERROR, function
    lib.fmi2FreeInstance.argtypes = [c_void_p]
    lib.fmi2FreeInstance(None)  # void: returns, touches nothing


#: states in which each entry is refused (by FMI 2.0's co-simulation state machine);
#: doStep before initialization answers fmi2Discard by the project's convention
REFUSED = {
    "fmi2SetupExperiment": ("initialization", "step", "terminated"),
    "fmi2EnterInitializationMode": ("initialization", "step", "terminated"),
    "fmi2ExitInitializationMode": ("instantiated", "step", "terminated"),
    "fmi2Terminate": ("instantiated", "initialization", "terminated"),
    "fmi2DoStep": ("terminated",),
    **{f"fmi2Get{t}": ("instantiated",) for t in ("Real", "Integer", "Boolean", "String")},
    **{f"fmi2Set{t}": ("terminated",) for t in ("Real", "Integer", "Boolean", "String")},
    **{
        f"fmi2Get{t}Status": ("instantiated", "initialization")
        for t in ("", "Real", "Integer", "Boolean", "String")
    },
}
STATES = ("instantiated", "initialization", "step", "terminated")


def _instance(lib: ctypes.CDLL, guid: str, state: str, heard: list[str]):
    @LOGGER
    def logger(env, instance, status, category, message):
        heard.append(message.decode())

    callbacks = Callbacks(logger, None, None, None, None)
    lib.fmi2Instantiate.restype = c_void_p
    lib.fmi2Instantiate.argtypes = [
        c_char_p,
        c_int,
        c_char_p,
        c_char_p,
        POINTER(Callbacks),
        c_int,
        c_int,
    ]
    c = lib.fmi2Instantiate(b"guard", 1, guid.encode(), b"", byref(callbacks), 0, 1)
    assert c
    lib.fmi2EnterInitializationMode.argtypes = lib.fmi2ExitInitializationMode.argtypes = [c_void_p]
    lib.fmi2Terminate.argtypes = [c_void_p]
    steps = {
        "initialization": [lib.fmi2EnterInitializationMode],
        "step": [lib.fmi2EnterInitializationMode, lib.fmi2ExitInitializationMode],
        "terminated": [
            lib.fmi2EnterInitializationMode,
            lib.fmi2ExitInitializationMode,
            lib.fmi2Terminate,
        ],
    }
    for function in steps.get(state, []):
        assert function(c) == OK
    return c, (logger, callbacks)  # keep the callbacks alive with the instance


@pytest.mark.parametrize("state", STATES)
def test_the_plant_refuses_a_call_its_state_does_not_allow(fmus, tmp_path, state) -> None:
    lib, guid, variables = _binary(fmus / "MotorChainPlant.fmu", tmp_path)
    heard: list[str] = []
    c, keep = _instance(lib, guid, state, heard)
    calls = _calls(variables)
    refused = [f for f, states in REFUSED.items() if state in states]
    for function in refused:
        before = len(heard)
        assert _call(lib, function, c, calls) == ERROR, function
        assert f"{function} is not allowed" in " ".join(heard[before:]), (function, heard)
    if state in ("instantiated", "initialization"):
        assert _call(lib, "fmi2DoStep", c, calls) == DISCARD
        assert "doStep called before initialization finished" in heard[-1]
    lib.fmi2FreeInstance.argtypes = [c_void_p]
    lib.fmi2FreeInstance(c)
    del keep


def test_the_plant_refuses_null_arrays_and_result_pointers(fmus, tmp_path) -> None:
    lib, guid, _ = _binary(fmus / "MotorChainPlant.fmu", tmp_path)
    heard: list[str] = []
    c, keep = _instance(lib, guid, "step", heard)
    f = lib
    f.fmi2GetReal.argtypes = f.fmi2SetReal.argtypes = [c_void_p, c_void_p, c_size_t, c_void_p]
    assert f.fmi2GetReal(c, None, 1, (c_double * 1)()) == ERROR
    assert f.fmi2GetReal(c, VR, 1, None) == ERROR
    assert f.fmi2SetReal(c, None, 1, (c_double * 1)()) == ERROR
    assert f.fmi2GetReal(c, None, 0, None) == OK  # nothing asked, nothing read
    f.fmi2GetFMUstate.argtypes = f.fmi2FreeFMUstate.argtypes = [c_void_p, c_void_p]
    assert f.fmi2GetFMUstate(c, None) == ERROR
    assert f.fmi2FreeFMUstate(c, None) == ERROR
    f.fmi2SerializedFMUstateSize.argtypes = [c_void_p, c_void_p, c_void_p]
    state = c_void_p()
    assert f.fmi2GetFMUstate(c, byref(state)) == OK
    assert f.fmi2SerializedFMUstateSize(c, state, None) == ERROR
    f.fmi2DeSerializeFMUstate.argtypes = [c_void_p, c_void_p, c_size_t, c_void_p]
    assert f.fmi2DeSerializeFMUstate(c, None, 100, byref(state)) == ERROR
    assert f.fmi2FreeFMUstate(c, byref(state)) == OK and not state.value
    assert sum("is NULL; call refused" in h for h in heard) >= 6
    f.fmi2FreeInstance.argtypes = [c_void_p]
    f.fmi2FreeInstance(c)
    del keep


def test_the_plant_still_runs_the_standard_sequence(fmus) -> None:
    """setup, set, enter, exit, steps, reset, again; terminate, free: no word logged."""
    with FmuInstance(fmus / "MotorChainPlant.fmu", "sequence") as plant:
        plant.initialize({"k[1]": 0.2})
        assert plant.do_step(0.0, 1e-3) == 0
        plant.slave.reset()
        plant.initialize({"k[1]": 0.3})
        assert plant.do_step(0.0, 1e-3) == 0
        assert plant.get(["k[1]"]) == [0.3]
        assert not plant.messages
