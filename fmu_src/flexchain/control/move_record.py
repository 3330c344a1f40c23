"""A move's samples as the controller's estimators take them, and which of them the fit
of :mod:`~arcosim.fmu.flexchain.control.move_fit` may trust.

A sample is trusted once the motor has advanced along the heading the DOB was told over
``defaults.REFINE_MOTION_WINDOW`` s, and has kept doing so for
``defaults.REFINE_TRUST_AFTER`` s: the controller tells the DOB the reference's heading
during a move (weighed against the encoder's edges), so τ̂_reac is off by up to 2 f_c
wherever the motor stands or runs the other way unseen, and the DOB's filter and the
fit's low-pass must forget it.
"""

from __future__ import annotations

from dataclasses import dataclass

from .. import defaults


@dataclass(frozen=True)
class Sample:
    """One step of a move as the controller's estimator took it.

    Attributes
    ----------
    h : float
        The step (s).
    tau_reac_hat : float
        τ̂_reac at its end (N·m).
    theta_m : float
        The motor angle the estimator took there (rad).
    trusted : bool
        Whether the DOB's friction was known over the last
        ``defaults.REFINE_TRUST_AFTER`` s (module doc).
    """

    h: float
    tau_reac_hat: float
    theta_m: float
    trusted: bool


class MoveRecord:
    """What a move gives the controller's estimator, one step at a time (module doc).

    Parameters
    ----------
    window : float
        How far back the motor's advance along the heading is measured (s).
    trust_after : float
        How long that advance must have held for a sample to be trusted (s).

    Attributes
    ----------
    samples : list of Sample
        The move's steps so far.
    elapsed : float
        Their duration (s).

    Examples
    --------
    >>> record = MoveRecord(window=2e-3, trust_after=0.0)
    >>> for k in range(4):
    ...     record.step(1e-3, 0.01, 1e-3 * k, heading=1.0)
    >>> [s.trusted for s in record.samples]  # trusted once the motor advanced over 2 ms
    [False, False, True, True]
    """

    def __init__(
        self,
        window: float = defaults.REFINE_MOTION_WINDOW,
        trust_after: float = defaults.REFINE_TRUST_AFTER,
    ) -> None:
        self.window = window
        self.trust_after = trust_after
        self.samples: list[Sample] = []
        self.elapsed = 0.0
        self._trusted_for = 0.0
        self._recent: list[tuple[float, float]] = []  # (time, motor angle) within the window

    def step(self, h: float, tau_reac_hat: float, theta_m: float, heading: float) -> None:
        """Keep the sample that ends a step.

        Parameters
        ----------
        h : float
            The step (s), > 0.
        tau_reac_hat : float
            τ̂_reac at its end (N·m).
        theta_m : float
            The motor angle the estimator takes (rad).
        heading : float
            The direction the DOB was told the motor runs (−1, 0 or +1).
        """
        self.elapsed += h
        recent = self._recent
        recent.append((self.elapsed, theta_m))
        while len(recent) > 1 and recent[1][0] <= self.elapsed - self.window + 1e-12:
            recent.pop(0)
        t0, theta0 = recent[0]
        advanced = t0 <= self.elapsed - self.window + 1e-12 and (theta_m - theta0) * heading > 0.0
        self._trusted_for = self._trusted_for + h if advanced else 0.0
        trusted = advanced and self._trusted_for >= self.trust_after
        self.samples.append(Sample(h, tau_reac_hat, theta_m, trusted))
