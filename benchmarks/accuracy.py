"""Accuracy of every method on several chains: ``python benchmarks/accuracy.py [--quick]``.

The same as ``arcosim bench accuracy``; see ``cosim/accuracy.py`` for what it runs.
Writes ``reports/accuracy.md`` and ``reports/accuracy.json``.
"""

import sys

from cosim.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "accuracy", *sys.argv[1:]]))
