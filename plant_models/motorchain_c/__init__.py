"""The plant FMU's C sources (package data, compiled by :mod:`arcosim.build.cplant`)."""
