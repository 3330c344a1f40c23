"""``fmu_src/pythonfmu/`` installed as ``arcosim.fmu.pythonfmu``: a stand-in, in the source
tree, for the pythonfmu runtime each FMU bundles.

Inside an FMU, ``<bundle>/pythonfmu/`` is pythonfmu's own runtime, copied there by
:mod:`arcosim.build.portable`, and :mod:`..fmukit.slave` imports it relatively, so
the FMU never runs a host's pythonfmu. Here, where the bundle does not exist, the
same relative import reaches this package, which re-exports the installed pythonfmu.
It is never bundled. Its modules ``enums`` and ``fmi2slave`` re-export the installed
pythonfmu's modules of those names.
"""
