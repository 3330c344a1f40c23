"""Run source → plant → observer in libcosim (libcosimpy, the Open Simulation Platform's
C++ engine) and report as JSON: the outputs come from the FMUs' own trace files
(full precision), plus the environment and libpython checks of chain_run.py.

    python libcosim_run.py SPEC.json OUT.json

SPEC as for chain_run.py, plus "variables": {component: {name: [vr, type]}} (this
interpreter need not have fmpy) and "traces": {component: csv path}.
"""

from __future__ import annotations

import json
import os
import sys

from chain_run import mapped_libpythons


def main(spec_path, out_path):
    with open(spec_path) as f:
        spec = json.load(f)
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimSlave import CosimLocalSlave

    environ_before = dict(os.environ)
    maps_before = mapped_libpythons()
    nanos = round(spec["h"] * 1e9)
    execution = CosimExecution.from_step_size(step_size=nanos)
    index = {}
    for name, fmu in spec["components"].items():
        index[name] = execution.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name=name))
        assert index[name] >= 0, f"libcosim could not add {name}"
    for name, values in spec["parameters"].items():
        values = {**values, "trace_file": spec["traces"][name]}
        for var, value in values.items():
            vr, kind = spec["variables"][name][var]
            setter = {
                "Real": execution.real_initial_value,
                "Integer": execution.integer_initial_value,
                "Boolean": execution.boolean_initial_value,
                "String": execution.string_initial_value,
            }[kind]
            cast = {"Real": float, "Integer": int, "Boolean": bool, "String": str}[kind]
            assert setter(index[name], vr, cast(value)), f"{name}.{var}"
    for a, out, b, inp in spec["connections"]:
        vr_out = spec["variables"][a][out][0]
        vr_in = spec["variables"][b][inp][0]
        status = execution.connect_real_variables(index[a], vr_out, index[b], vr_in)
        assert status == 0, f"libcosim refused the connection {a}.{out} -> {b}.{inp}"
    ok = execution.simulate_until(target_time=round(spec["stop"] * 1e9))
    maps_loaded = mapped_libpythons()
    environ_loaded = dict(os.environ)
    del execution  # terminates and frees the instances
    changed = sorted(
        k
        for k in set(environ_before) | set(environ_loaded) | set(os.environ)
        if not (environ_before.get(k) == environ_loaded.get(k) == os.environ.get(k))
    )
    with open(out_path, "w") as f:
        json.dump(
            {
                "python": sys.version,
                "simulated": bool(ok),
                "environ_changed": changed,
                "libpython_before": maps_before,
                "libpython_after": maps_loaded,
            },
            f,
        )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
