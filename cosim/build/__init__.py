"""Building the project's FMUs: recipes, the C plant, the loader, the SSP writer.

- :mod:`~arcosim.build.recipes`: what is built (one :class:`FmuRecipe` per FMU);
- :mod:`~arcosim.build.builder`: :func:`build_all`, :func:`ensure_built`;
- :mod:`~arcosim.build.cache`: where FMUs go, their source digest and lock;
- :mod:`~arcosim.build.cplant`: the plant FMU compiled from C;
- :mod:`~arcosim.build.native_loader`, :mod:`~arcosim.build.exit_fix`: patches of
  pythonfmu's binary;
- :mod:`~arcosim.build.ssp`: the SSP system of the three FMUs.

Imports nothing of :mod:`arcosim.host`, :mod:`arcosim.experiments` or the CLI.
"""
