"""``arcosim bench``: the project's benchmarks (``accuracy``, ``speed``), also
runnable as the scripts in ``benchmarks/``."""

from __future__ import annotations

import argparse

from cosim import accuracy, throughput


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register ``arcosim bench`` and its benchmarks."""
    p = subparsers.add_parser("bench", help="run a benchmark (accuracy, speed)")
    benchmarks = p.add_subparsers(title="benchmarks", metavar="BENCHMARK", required=True)
    accuracy.add_parser(benchmarks)
    throughput.add_parser(benchmarks)
