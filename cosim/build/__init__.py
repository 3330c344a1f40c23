"""Building the project's FMUs: recipes, the C plant, the loader, the SSP writer.

- :mod:`~arcosim.build.recipes`: what is built (one :class:`FmuRecipe` per FMU);
- :mod:`~arcosim.build.builder`: :func:`build_all`, :func:`ensure_built`;
- :mod:`~arcosim.build.cache`: where FMUs go, their source digest and lock;
- :mod:`~arcosim.build.cplant`: the plant FMU compiled from C;
- :mod:`~arcosim.build.portable`, :mod:`~arcosim.build.exit_fix`: the portable layout
  and the C trampoline in front of pythonfmu's binary, the exit-time fix of that binary;
- :mod:`~arcosim.build.ssp`: the SSP system of the three FMUs.

Imports nothing of :mod:`arcosim.host`, :mod:`arcosim.experiments` or the CLI.
"""
