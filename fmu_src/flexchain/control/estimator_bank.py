"""A bank of the chain's estimators on scaled models, and the one whose model predicts best.

The controller's estimator runs on the identified chain. With every J_i 10 % high and
every k_i 10 % low it rings 10 % off the chain's modes, its estimate of the last mass lags
the truth, and the loop settles up to 2.4 × slower than the same gains on the true states
(or, on a five-mass chain, grows at its top mode). :class:`EstimatorBank` runs the same
estimator on the chain with every J_i × a and every k_i × b, for a and b each in
``defaults.BANK_SCALES`` (3 × 3 models with the defaults, the chain itself among them),
all on the same inputs (τ̂_reac and the drive's angle), and gives the controller the
estimates of the member whose model predicts τ̂_reac best.

What "best" means: each member's model also runs open loop (no Kalman correction) from
the start, and the square of its open-loop prediction error of τ̂_reac, low-passed over
``defaults.BANK_MEMORY`` s, is its score. The corrected filters' own innovations do not
tell the models apart (every member follows τ̂_reac; chosen by them, the choice changed
every few steps); an open-loop model's error grows with its modes' frequency error. The
bank moves to another member only when that one's score is below
(1 − ``defaults.BANK_HYSTERESIS``) × the present one's, so it does not chatter between
members that predict alike (the chain itself is kept on an identified chain).

It chooses from a move's response only: the controller restarts the open-loop models on
their members' estimates and clears the scores when a move starts (:meth:`restart`), and
lets the choice change only until ``defaults.BANK_CHOICE_AFTER`` move times after the
move. A load torque, unknown to the open-loop models, grows every member's error, not
alike: left to choose at rest, the bank took a load step on the bench's three-mass chain
for a model error and moved to the wrong members (0.91 mrad left, 0.43 on the chain).

The common factors cannot follow errors that differ from mass to mass. So the bank also
records the move (:class:`~arcosim.fmu.flexchain.control.move_record.MoveRecord`, from
:meth:`restart`), and ``defaults.REFINE_AT`` move times after its start the controller
calls :meth:`refine`: the chosen member's every J_i and k_i are fitted to the move's
τ̂_reac (:func:`~arcosim.fmu.flexchain.control.move_fit.fit_chain`), the member is replaced by
the estimator on the fitted chain run over the move from the member's state at its
start, and the choice rests for good: a later move starts from a hold's estimates, not
from rest, and its data took a refined model away from the plant, so a refined member
refits only where a move shows its model wrong well above the noise
(``defaults.REFINE_AGAIN``). On `arcosim bench control`'s four-mass
chain this took the runs meeting all four criteria from 23 to 34 of 42.

At rest, while the hold's dither runs and the controlled mass is still (:meth:`settle`;
never without an encoder or with ``hold_dither`` 0), every member trusts its model more
(:meth:`set_quiet`: the unmodelled torque × ``defaults.HOLD_TORQUE_NOISE_SCALE``), each
gain designed once.
"""

from __future__ import annotations

import copy
import dataclasses
import math

from .. import defaults
from ..load_observer import LoadTorqueObserver
from .move_fit import Belief, ChainFit, MoveRecord, fit_chain


class EstimatorBank:
    """The chain's estimator on every scaled model, and the one chosen (module doc).

    Parameters
    ----------
    estimator : LoadTorqueObserver
        The estimator on the chain as given, at its start; copied, not stepped.
    scales : tuple of float
        The factors on every J_i and, independently, every k_i (dimensionless).

    Attributes
    ----------
    members : list of LoadTorqueObserver
        One per (J factor, k factor), J's factor the outer loop.
    factors : list of tuple of float
        Each member's (J factor, k factor) as built (a refinement leaves them).
    score : list of float
        Each member's low-passed squared open-loop error of τ̂_reac (N²·m²).
    pick : int
        The member whose estimates the controller takes.
    quiet : bool
        Whether the members run the hold's gain (:meth:`set_quiet`).
    still : float
        How long the controlled mass's estimate has stayed near its target at rest (s,
        :meth:`settle`).
    move_noise : NoiseModel
        The members' noise model for a move (the estimator's).
    origins : list of tuple
        Each member's (J, k) as built (kg·m², N·m/rad), what its refinements count from.
    beliefs : list of Belief or None
        What the moves told of each member's refinement (None: nothing yet).
    record : MoveRecord or None
        The move since :meth:`restart`, until :meth:`refine`.
    starts : list of LoadTorqueObserver
        Each member as it was at the move's start, until :meth:`refine`.
    fit : ChainFit or None
        The last :meth:`refine`'s fit (None: none, or refused).
    refined : bool
        Whether the chosen member was refined from this move (``fit`` is not None).
    settled : bool
        Whether a member was ever refined: the choice then rests for good.
    hold_gain : bool
        Whether :meth:`set_quiet` gives the members the hold's gain (default True); False
        keeps the move's gain at rest while :attr:`quiet` still says when the chain is quiet.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> bank = arcosim.MotionController(arcosim.design_controller(chain, h=1e-3)).bank
    >>> len(bank.members), bank.factors[bank.pick], bank.chosen.J
    (9, (1.0, 1.0), (0.0005,))
    """

    _transient = ("_other",)  # the other gain's designs, rebuilt on use after a restore

    def __init__(
        self, estimator: LoadTorqueObserver, scales: tuple[float, ...] = defaults.BANK_SCALES
    ) -> None:
        self.members: list[LoadTorqueObserver] = []
        self.factors: list[tuple[float, float]] = []
        for a in scales:
            for b in scales:
                member = copy.deepcopy(estimator)
                member.J = tuple(a * x for x in estimator.J)
                member.k = tuple(b * x for x in estimator.k)
                member._models = {}  # designed on first use for the scaled chain
                self.members.append(member)
                self.factors.append((a, b))
        # each member's model as built: what its refinements are counted from (move_fit)
        self.origins = [(m.J, m.k) for m in self.members]
        self.beliefs: list[Belief | None] = [None] * len(self.members)  # what moves told
        self.settled = False  # refined once: the choice rests for good
        self.open_loop = [list(m.s) for m in self.members]
        self.score = [0.0] * len(self.members)
        self.record: MoveRecord | None = None  # from a move's start until refine()
        self.starts: list[LoadTorqueObserver] = []
        self.fit: ChainFit | None = None
        self.quiet = False
        self.hold_gain = True
        self.still = 0.0
        self.move_noise = estimator.noise
        self._other: dict[int, dict] = {}
        self.pick = min(
            range(len(self.factors)),
            key=lambda j: abs(self.factors[j][0] - 1.0) + abs(self.factors[j][1] - 1.0),
        )

    @property
    def chosen(self) -> LoadTorqueObserver:
        """The member whose estimates the controller takes."""
        return self.members[self.pick]

    def restart(self) -> None:
        """Start the open-loop models on their members' estimates, clear the scores and
        start recording the move for :meth:`refine` (at a move's start)."""
        self.open_loop = [list(m.s) for m in self.members]
        self.score = [0.0] * len(self.members)
        self.record = MoveRecord()
        # the steps replace the members' lists rather than change them, so a shallow
        # copy keeps each state at the move's start (the step-model cache, _models, is
        # shared; the fit does not use it)
        self.starts = [copy.copy(m) for m in self.members]
        self.fit = None

    @property
    def refined(self) -> bool:
        """Whether the chosen member was refined from this move."""
        return self.fit is not None

    def refine(self) -> ChainFit | None:
        """Refine the chosen member's every J_i and k_i from the move so far, and end the
        record until the next :meth:`restart`.

        The member is replaced by the estimator on the refined chain, run over the move's
        samples from the chosen member's state at the move's start
        (:func:`~arcosim.fmu.flexchain.control.move_fit.fit_chain`, its prior centred on the
        member's model as built), and the choice rests for good; where the fit refuses,
        the member stays as it was and the choice goes on.

        Returns
        -------
        ChainFit or None
            The factors taken, or None where the fit refused (kept in :attr:`fit`).
        """
        record, self.record = self.record, None
        if record is None:  # refine() ran on this move already
            return None
        start = self.starts[self.pick]
        self.starts = []
        belief = self.beliefs[self.pick]
        # once refined, a member refits only where a move shows its model wrong well
        # above the noise (later moves start from a hold's estimates, not from rest)
        evidence = defaults.REFINE_MIN_EVIDENCE if belief is None else defaults.REFINE_AGAIN
        try:
            fit = fit_chain(start, record.samples, self.origins[self.pick], belief, evidence)
        except ValueError:  # a singular step of the fit: no refinement, no crash
            fit = None
        self.fit = fit
        if fit is None:  # the choice goes on as it would have
            return None
        self.settled = True
        self.beliefs[self.pick] = fit.belief
        refined = copy.copy(start)
        refined.J, refined.k = fit.J, fit.k
        refined._models = {}
        refined.noise = self.members[self.pick].noise
        for sample in record.samples:
            refined.step(sample.h, sample.tau_reac_hat, sample.theta_m)
        self.members[self.pick] = refined
        self._other.pop(self.pick, None)  # the other gain's designs were the old model's
        return fit

    def set_quiet(self, quiet: bool) -> None:
        """Give every member the hold's gain (``quiet``) or the move's, keeping its state.

        The hold's trusts the model more: each member's unmodelled torque on a load mass
        times ``defaults.HOLD_TORQUE_NOISE_SCALE`` (``torque_noise_std``, N·m). Each gain
        is designed on first use, then kept for the next switch.

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
        for j, member in enumerate(self.members):
            member.noise = noise
            member._models, self._other[j] = self._other.get(j, {}), member._models
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

    def step(
        self,
        h: float,
        tau_reac_hat: float,
        theta_m: float,
        choose: bool = True,
        heading: float = 0.0,
    ) -> None:
        """Step every member on the sample that ends a step, record it, then choose.

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        tau_reac_hat : float
            The reaction torque observer's estimate τ̂_reac (N·m).
        theta_m : float
            The motor angle the estimators take (rad).
        choose : bool
            Whether the choice may change at this sample. When not, only the members
            step: the scores and open-loop models are not read again before
            :meth:`restart` sets them anew. Never after :meth:`refine`.
        heading : float
            The direction the DOB was told the motor runs (−1, 0 or +1), for the record.
        """
        if self.record is not None:
            self.record.step(h, tau_reac_hat, theta_m, heading)
        if self.settled:  # a member was refined: the choice is over for good (module doc),
            # and only the chosen member's estimates are ever read again (a refit starts
            # from its own state), so the others rest
            self.chosen.step(h, tau_reac_hat, theta_m)
            return
        if not choose:  # the scores and open-loop models are restarted before they count
            for member in self.members:
                member.step(h, tau_reac_hat, theta_m)
            return
        forget = math.exp(-h / defaults.BANK_MEMORY)
        for j, member in enumerate(self.members):
            error = self._open_loop_error(j, member, h, tau_reac_hat, theta_m)
            member.step(h, tau_reac_hat, theta_m)
            self.score[j] = forget * self.score[j] + (1.0 - forget) * error * error
        best = min(range(len(self.members)), key=self.score.__getitem__)
        if self.score[best] < (1.0 - defaults.BANK_HYSTERESIS) * self.score[self.pick]:
            self.pick = best

    def _open_loop_error(
        self, j: int, member: LoadTorqueObserver, h: float, tau_reac_hat: float, theta_m: float
    ) -> float:
        """Advance member ``j``'s open-loop model (its step model without the Kalman
        correction, on the member's own previous motor angle) and return τ̂_reac less
        its prediction (N·m). Call before the member's own step."""
        self.open_loop[j] = s = member.predict(h, theta_m, self.open_loop[j])
        return tau_reac_hat - s[-1]
