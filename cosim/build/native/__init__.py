"""Native parts of the FMUs, compiled at build time (see fmu_trampoline.c)."""
