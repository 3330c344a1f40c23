"""The observer's algorithms run over a recorded log, offline (no FMU).

The same standard-library code the observer FMU bundles (:mod:`arcosim.fmu.flexchain`),
fed one sample at a time with the step each row takes, as the FMU would be.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from arcosim.fmu.flexchain.observer import Observer, ObserverSettings


def replay(
    settings: ObserverSettings,
    log: Mapping[str, np.ndarray],
    after_sample: Callable[[int, Observer], None] | None = None,
) -> Observer:
    """Run the observer's algorithms over a log; return the observer at its end.

    Parameters
    ----------
    settings : ObserverSettings
        What the observer FMU's parameters would say (mode, actuator, chain, …).
    log : mapping of str to ndarray
        ``time`` (s), ``i_a`` (A), ``omega_m`` (rad/s), ``theta_m`` (rad), each of
        shape ``(N,)``; row k ends the step from row k − 1 (the timing contract).
    after_sample : callable, optional
        ``after_sample(k, observer)``, called for the initial sample (k = 0) and after
        each step.

    Returns
    -------
    Observer
        The observer after the last sample.

    Examples
    --------
    >>> import arcosim
    >>> settings = arcosim.ObserverSettings(mode=2, actuator=arcosim.Actuator(2.09e-5, 0.0406),
    ...                                     g_dist=100.0, g_lpf=100.0, J=(1e-3,), k=(0.5,),
    ...                                     B=(1e-4,), estimator=1)
    >>> still = np.zeros(100)  # 0.1 s at rest
    >>> log = {"time": np.arange(100) * 1e-3, "i_a": still, "omega_m": still, "theta_m": still}
    >>> replay(settings, log).estimator.theta  # the load angles (rad)
    [0.0]
    """
    steps = np.diff(np.asarray(log["time"], dtype=float)).tolist()
    i_a, w, th = (np.asarray(log[c], dtype=float).tolist() for c in ("i_a", "omega_m", "theta_m"))
    observer = Observer(settings, th[0], w[0])
    if after_sample is not None:
        after_sample(0, observer)
    for k in range(1, len(th)):
        observer.step(steps[k - 1], i_a[k], w[k], th[k])
        if after_sample is not None:
            after_sample(k, observer)
    return observer


def estimate_states(settings: ObserverSettings, log: Mapping[str, np.ndarray]) -> np.ndarray:
    """The load angles the observer estimates over a log.

    Parameters
    ----------
    settings : ObserverSettings
        What the observer FMU's parameters would say (mode 2).
    log : mapping of str to ndarray
        ``time`` (s), ``i_a`` (A), ``omega_m`` (rad/s), ``theta_m`` (rad), each of
        shape ``(N,)``.

    Returns
    -------
    ndarray
        The estimated angle of each load mass after each sample (rad), shape ``(N, n)``.

    Examples
    --------
    >>> import arcosim
    >>> settings = arcosim.ObserverSettings(mode=2, actuator=arcosim.Actuator(2.09e-5, 0.0406),
    ...                                     g_dist=100.0, g_lpf=100.0, J=(1e-3,), k=(0.5,),
    ...                                     B=(1e-4,), estimator=1)
    >>> still = np.zeros(100)
    >>> log = {"time": np.arange(100) * 1e-3, "i_a": still, "omega_m": still, "theta_m": still}
    >>> estimate_states(settings, log).shape
    (100, 1)
    """
    out = np.empty((len(log["time"]), len(settings.J)))

    def keep(k: int, observer: Observer) -> None:
        out[k] = observer.estimator.theta

    replay(settings, log, keep)
    return out
