"""One BLAS thread for the identification's many small matrix operations.

The fits work on matrices of ten to fifty rows (exponentials, Riccati steps, small
least-squares problems). OpenBLAS's thread pool makes each call wait on its threads:
on a two-core machine under load, a five-mass identification took 7.2 s with the
default threads and 1.7 s with one (`benchmarks/field_accuracy.py`, seed 1). The
limit holds only inside the decorated call; the caller's setting is restored after.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TypeVar

from threadpoolctl import threadpool_limits

F = TypeVar("F", bound=Callable)


def single_threaded(function: F) -> F:
    """Run ``function`` with BLAS limited to one thread."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with threadpool_limits(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
