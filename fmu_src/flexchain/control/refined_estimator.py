"""The chain's estimator, refitted from each move: the estimates the controller takes.

The controller's estimator (the observer's model-based estimator with its load-torque
state on the controlled mass) runs on the chain it was designed on. A model 10 % off
rings off the chain's modes, its estimate of the last mass lags the truth, and the loop
settles slower than the same gains on the true states (or, on a five-mass chain, grows at
its top mode). :class:`RefinedEstimator` keeps that one estimator and corrects its model
from what each move shows:

* it records the move (:class:`~arcosim.fmu.flexchain.control.move_record.MoveRecord`,
  from :meth:`~RefinedEstimator.restart` at the move's start), and keeps the estimator's
  state at that start;
* ``defaults.REFINE_AT`` move times after the start the controller calls
  :meth:`~RefinedEstimator.refine`: every J_i and k_i is fitted to the move's τ̂_reac
  (:func:`~arcosim.fmu.flexchain.control.move_fit.fit_chain`, run open loop from that
  start state), and the estimator is replaced by the one on the fitted chain, run over
  the move from the same start. The first fit needs ``defaults.REFINE_MIN_EVIDENCE``; a
  model already refitted refits only where a move shows it wrong well above the noise
  (``defaults.REFINE_AGAIN``): a later move starts from a hold's estimates, not from
  rest, and its data took a refitted model away from the plant;
* at rest, while the hold's dither runs and the controlled mass is still
  (:meth:`~RefinedEstimator.settle`; never without an encoder or with ``hold_dither``
  0), the estimator trusts its model more (:meth:`~RefinedEstimator.set_quiet`: the
  unmodelled torque × ``defaults.HOLD_TORQUE_NOISE_SCALE``), each gain designed once.
"""

from __future__ import annotations

import copy
import dataclasses

from .. import defaults
from ..load_observer import LoadTorqueObserver
from .move_fit import Belief, ChainFit, MoveRecord, fit_chain


class RefinedEstimator:
    """The chain's estimator, refitted from each move and quiet at rest (module doc).

    Parameters
    ----------
    estimator : LoadTorqueObserver
        The estimator on the chain as designed, at its start; taken, not copied.
    hold_gain : bool
        Whether :meth:`set_quiet` gives the estimator the hold's gain (default True);
        False keeps the move's gain at rest while :attr:`quiet` still says when the
        chain is quiet.

    Attributes
    ----------
    filter : LoadTorqueObserver
        The estimator whose estimates the controller takes: on the chain as designed,
        then as last refitted.
    origin : tuple of tuple of float
        The chain as designed, ``(J, k)`` (kg·m², N·m/rad), what every refit's factors
        count from.
    belief : Belief or None
        What the moves told of the refit (None: nothing yet).
    record : MoveRecord or None
        The move since :meth:`restart`, until :meth:`refine`.
    start : LoadTorqueObserver or None
        The estimator as it was at the move's start, until :meth:`refine`.
    fit : ChainFit or None
        The last :meth:`refine`'s fit (None: none, or refused).
    quiet : bool
        Whether the estimator runs the hold's gain (:meth:`set_quiet`).
    still : float
        How long the controlled mass's estimate has stayed near its target at rest (s,
        :meth:`settle`).
    move_noise : NoiseModel
        The estimator's noise model for a move.
    hold_gain : bool
        As the parameter.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> estimator = arcosim.MotionController(arcosim.design_controller(chain, h=1e-3)).estimator
    >>> estimator.filter.J, estimator.refined, estimator.quiet
    ((0.0005,), False, False)
    """

    _transient = ("_other",)  # the other gain's designs, rebuilt on use after a restore

    def __init__(self, estimator: LoadTorqueObserver, hold_gain: bool = True) -> None:
        self.filter = estimator
        self.origin = (estimator.J, estimator.k)
        self.belief: Belief | None = None
        self.record: MoveRecord | None = None  # from a move's start until refine()
        self.start: LoadTorqueObserver | None = None
        self.fit: ChainFit | None = None
        self.quiet = False
        self.hold_gain = hold_gain
        self.still = 0.0
        self.move_noise = estimator.noise
        self._other: dict = {}  # the other gain's step models, by step

    @property
    def refined(self) -> bool:
        """Whether the estimator was refitted from this move."""
        return self.fit is not None

    def restart(self) -> None:
        """Start recording the move for :meth:`refine`, from the estimator's state now
        (at a move's start)."""
        self.record = MoveRecord()
        # the steps replace the estimator's lists rather than change them, so a shallow
        # copy keeps its state at the move's start (the step-model cache, _models, is
        # shared; the fit does not use it)
        self.start = copy.copy(self.filter)
        self.fit = None

    def refine(self) -> ChainFit | None:
        """Refit the estimator's every J_i and k_i from the move so far, and end the
        record until the next :meth:`restart`.

        The estimator is replaced by the one on the refitted chain, run over the move's
        samples from the estimator's state at the move's start
        (:func:`~arcosim.fmu.flexchain.control.move_fit.fit_chain`, its prior centred on
        :attr:`origin`); where the fit refuses, it stays as it was.

        Returns
        -------
        ChainFit or None
            The factors taken, or None where the fit refused (kept in :attr:`fit`).
        """
        record, self.record = self.record, None
        start, self.start = self.start, None
        if record is None or start is None:  # refine() ran on this move already
            return None
        # once refitted, the model refits only where a move shows it wrong well above
        # the noise (later moves start from a hold's estimates, not from rest)
        evidence = defaults.REFINE_MIN_EVIDENCE if self.belief is None else defaults.REFINE_AGAIN
        try:
            fit = fit_chain(start, record.samples, self.origin, self.belief, evidence)
        except ValueError:  # a singular step of the fit: no refit, no crash
            fit = None
        self.fit = fit
        if fit is None:
            return None
        self.belief = fit.belief
        refined = copy.copy(start)
        refined.J, refined.k = fit.J, fit.k
        refined._models = {}
        refined.noise = self.filter.noise
        for sample in record.samples:
            refined.step(sample.h, sample.tau_reac_hat, sample.theta_m)
        self.filter = refined
        self._other = {}  # the other gain's designs were the old model's
        return fit

    def set_quiet(self, quiet: bool) -> None:
        """Give the estimator the hold's gain (``quiet``) or the move's, keeping its state.

        The hold's trusts the model more: the unmodelled torque on a load mass times
        ``defaults.HOLD_TORQUE_NOISE_SCALE`` (``torque_noise_std``, N·m). Each gain is
        designed on first use, then kept for the next switch.

        Parameters
        ----------
        quiet : bool
            True at rest, False for a move.
        """
        if not quiet:
            self.still = 0.0
        if quiet == self.quiet:
            return
        if not self.hold_gain:
            self.quiet = quiet
            return
        noise = self.move_noise
        if quiet:
            std = noise.torque_noise_std * defaults.HOLD_TORQUE_NOISE_SCALE
            noise = dataclasses.replace(noise, torque_noise_std=std)
        est = self.filter
        est.noise = noise
        est._models, self._other = self._other, est._models
        self.quiet = quiet

    def settle(self, h: float, off: float) -> None:
        """Choose the gain at rest from how near the controlled mass's estimate stays.

        The hold's gain (:meth:`set_quiet`) once the estimate has stayed within
        ``defaults.HOLD_QUIET_ANGLE`` of its target for ``defaults.HOLD_QUIET_TIME``; the
        move's while it is more than ``defaults.HOLD_QUIET_LEAVE`` off (a load step);
        between the two, the gain it has.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        off : float
            How far the controlled mass's estimate is from its target (rad), ≥ 0.
        """
        self.still = self.still + h if off < defaults.HOLD_QUIET_ANGLE else 0.0
        if off > defaults.HOLD_QUIET_LEAVE:
            self.set_quiet(False)
        elif self.still >= defaults.HOLD_QUIET_TIME:
            self.set_quiet(True)

    def step(self, h: float, tau_reac_hat: float, theta_m: float, heading: float = 0.0) -> None:
        """Step the estimator on the sample that ends a step, and record it during a move.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        tau_reac_hat : float
            The reaction torque observer's estimate τ̂_reac (N·m).
        theta_m : float
            The motor angle the estimator takes (rad).
        heading : float
            The direction the DOB was told the motor runs (−1, 0 or +1), for the record.
        """
        if self.record is not None:
            self.record.step(h, tau_reac_hat, theta_m, heading)
        self.filter.step(h, tau_reac_hat, theta_m)
