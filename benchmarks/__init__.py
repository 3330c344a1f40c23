"""The project's benchmarks (a source checkout's, not installed with the wheel).

- :mod:`benchmarks.accuracy`: every method on several chains against the truth
  (``arcosim bench accuracy``, or ``python -m benchmarks.accuracy``);
- :mod:`benchmarks.speed`: µs per co-simulation step and seconds per fit
  (``arcosim bench speed``, or ``python -m benchmarks.speed``);
- :mod:`benchmarks.public_records`: ``check`` and ``identify`` on public measured records
  of real drives against their published values (``arcosim bench public --data DIR``);
- :mod:`benchmarks.memory`, :mod:`benchmarks.b_bias`, :mod:`benchmarks.noise_envelope`:
  one-off measurements, run as scripts;
- :mod:`benchmarks.link_frequencies`: the flexible-link FMU's frequencies against the
  continuous beam's, for 2, 4 and 8 elements (``python -m benchmarks.link_frequencies``).
- :mod:`benchmarks.published_link`: a link we did not write, Quanser's rotary flexible
  link from its published parameters, on the link FMU and on the continuous beam's modes
  (:mod:`benchmarks.modal_link`, a simulator written apart from the FMU), identified
  from the hub (``python -m benchmarks.published_link``).
- :mod:`benchmarks.thirdparty_chain`: a chain assembled from Dymola-exported FMUs
  (:mod:`benchmarks.thirdparty_plant`), identified and controlled
  (``arcosim bench thirdparty --fmus DIR``); :mod:`benchmarks.thirdparty_cosim`, the same
  chain coupled explicitly in co-simulation (one-off, why it is not).

They import :mod:`arcosim`; nothing in :mod:`arcosim` imports them.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

from arcosim.errors import ArcosimError


def progress(text: str) -> None:
    """Print one progress line of a benchmark's run (indented, flushed at once)."""
    print(f"  … {text}", flush=True)


def main(
    name: str, add_parser: Callable[[argparse._SubParsersAction], None], argv: Sequence[str]
) -> int:
    """Run benchmark ``name`` (registered by ``add_parser``) with ``argv``; the exit code."""
    parser = argparse.ArgumentParser(prog="arcosim bench")
    add_parser(parser.add_subparsers(dest="benchmark", required=True))
    args = parser.parse_args([name, *argv])
    try:
        return int(args.execute(args) or 0)
    except ArcosimError as error:
        print(f"benchmark: error: {error}", file=sys.stderr)
        return 2
