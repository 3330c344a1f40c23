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
    """Run ``function`` with BLAS limited to one thread.

    Parameters
    ----------
    function : callable
        The function to limit; the caller's thread setting is restored after each call.

    Returns
    -------
    callable
        ``function`` wrapped, with its name and docstring.

    Examples
    --------
    >>> from threadpoolctl import threadpool_info
    >>> @single_threaded
    ... def blas_threads():
    ...     return {pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas"}
    >>> blas_threads() <= {1}, blas_threads.__name__
    (True, 'blas_threads')
    """

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with threadpool_limits(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
