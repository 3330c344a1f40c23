"""The project's benchmarks (a source checkout's, not installed with the wheel).

- :mod:`benchmarks.accuracy`: every method on several chains against the truth
  (``arcosim bench accuracy``, or ``python -m benchmarks.accuracy``);
- :mod:`benchmarks.speed`: µs per co-simulation step and seconds per fit
  (``arcosim bench speed``, or ``python -m benchmarks.speed``);
- :mod:`benchmarks.controller_speed`: the controller FMU's µs per step through fmpy for
  1, 3 and 5 masses (``python -m benchmarks.controller_speed``);
- :mod:`benchmarks.part_margins`: the sensorless loop's decay under model errors with a
  controller part switched off (``python -m benchmarks.part_margins --without move_refit``);
- :mod:`benchmarks.public_records`: ``check`` and ``identify`` on public measured records
  of real drives against their published values (``arcosim bench public --data DIR``);
- :mod:`benchmarks.memory`, :mod:`benchmarks.noise_envelope`: measurements run as scripts;
- :mod:`benchmarks.link_frequencies`: the flexible-link FMU's frequencies against the
  continuous beam's, for 2, 4 and 8 elements (``python -m benchmarks.link_frequencies``).
- :mod:`benchmarks.published_link`: a link we did not write, Quanser's rotary flexible
  link from its published parameters, on the link FMU and on the continuous beam's modes
  (:mod:`benchmarks.simulators.modal_link`, a simulator written apart from the FMU), identified
  from the hub (``python -m benchmarks.published_link``).
- :mod:`benchmarks.thirdparty_chain`: a chain assembled from Dymola-exported FMUs
  (:mod:`benchmarks.simulators.thirdparty_plant`), identified and controlled
  (``arcosim bench thirdparty --fmus DIR``); :mod:`benchmarks.thirdparty_cosim`, the same
  chain coupled explicitly in co-simulation (one-off, why it is not).

The rows and their parts:

- :mod:`benchmarks.cases`: the chains and sensors the accuracy rows score on;
- :mod:`benchmarks.chain_accuracy`, :mod:`benchmarks.load_accuracy`,
  :mod:`benchmarks.beam_accuracy`, :mod:`benchmarks.field_accuracy`,
  :mod:`benchmarks.excitation_accuracy` (on the logs of :mod:`benchmarks.excitations`):
  the rows of ``arcosim bench accuracy``;
- :mod:`benchmarks.verdict_accuracy`: the whole-chain fit's verdict on logs with and
  without a user's mistake (``arcosim bench verdict``);
- :mod:`benchmarks.control_accuracy`: sensorless motion control against its four criteria
  (``arcosim bench control``); :mod:`benchmarks.control_margins`, the controller's margins;
- :mod:`benchmarks.fleet_accuracy`: the fleet's drift alarms and its scaling
  (``arcosim bench fleet``); :mod:`benchmarks.fleet_store`, the rows per second its
  store takes (``python -m benchmarks.fleet_store``);
- :mod:`benchmarks.tracking_accuracy`: the observer FMU's tracker on drives that wear
  while they work, and its per-step cost (``arcosim bench tracking``);
- :mod:`benchmarks.public_loaders`, :mod:`benchmarks.public_figure`: the public records'
  readers and the motor bench's figure;
- :mod:`benchmarks.sample_log`: writes the sample drive log the examples identify;
- :mod:`benchmarks.golden`: the outputs a refactor must leave byte for byte the same;
- :mod:`benchmarks.simulators`: the simulators written apart from the plant FMU.

They import :mod:`arcosim`; nothing in :mod:`arcosim` imports them.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

from arcosim import ArcosimError


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
