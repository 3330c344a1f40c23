"""Co-simulation speed: ``python benchmarks/throughput.py [--quick] [--runs R]``.

The same as ``arcosim bench speed``; see ``cosim/throughput.py`` for what it measures.
Writes ``reports/throughput.md`` and ``reports/throughput.json``.
"""

import sys

from cosim.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "speed", *sys.argv[1:]]))
