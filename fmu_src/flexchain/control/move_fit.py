"""Every J_i and k_i of the controller's chain refined from a move's own response.

The controller's estimator runs on the chain it was designed on; with that chain's J_i
and k_i off, each by its own error, the estimator rings off the chain's modes, and on a
four-mass chain with independent ±10 % errors the controller settled up to 2 × slower
than the same gains on the true states (docs/design/move-refit.md). A move excites the
chain enough to tell the errors apart:
:class:`~arcosim.fmu.flexchain.control.move_record.MoveRecord` keeps, from the move's start,
what the estimator takes (τ̂_reac and the motor angle, each step), and
:func:`fit_chain` finds the factors on every J_i
and k_i whose model, run open loop from the estimator's state at the move's start,
predicts that τ̂_reac best.

What it fits, and what it leaves out:

* the open-loop error ``τ̂_reac − y`` (y: the model's τ̂_reac, the DOB's low-pass
  included), through a second-order Butterworth low-pass at
  ``defaults.REFINE_LOWPASS``: above it the encoder's counts put noise in the DOB's
  acceleration that the model, driven by the same counts, partly echoes (unfiltered, the
  fit took factors of 2 for that echo);
* only samples the DOB's friction is known on: the controller tells the DOB the
  reference's heading during a move (it subtracts f_c that way), so τ̂_reac is off by up
  to 2 f_c wherever the motor stands or runs the other way. A sample counts once the
  motor has advanced along the heading over ``defaults.REFINE_MOTION_WINDOW`` s, and has
  done so for ``defaults.REFINE_TRUST_AFTER`` s (the DOB's filter and the low-pass to
  forget). Without this, on the four-mass chain's J +10 %, k −10 % corner, the motor
  swung back at the move's end, and the best fit was 20 % off the truth (worse than the
  truth by a cost of 4:1);
* the factors as ``J_i = J_i0 · exp(c_J + δJ_i)``, ``k_i = k_i0 · exp(c_k + δk_i)``, with a
  Gaussian prior: the common factors c within ``defaults.REFINE_COMMON_SPREAD`` and each
  mass's own δ within ``defaults.REFINE_MASS_SPREAD`` (one standard deviation, in
  log). The data, in units of the estimator's noise on τ̂_reac, decide where they
  support more; a move's smooth, slow data do not pin every J_i and k_i alone (without
  the prior, fits reached factors of 0.2–2.2 for a cost below the truth's).

The fit is Levenberg–Marquardt on these residuals with forward-difference Jacobians
(2n open-loop runs per iteration; the common factors' columns are sums of the masses'),
each sample weighted by the time it stands for. What a fit learnt (its :class:`Belief`:
the parameters and their precision) is the next fit's prior, and the factors count from
the chain as designed. It refuses (returns ``None``) what the data cannot
support: trusted samples spanning less than ``defaults.REFINE_MIN_TRUSTED_TIME``, a
model that already predicts the move within the noise (``defaults.REFINE_MIN_EVIDENCE``),
factors outside ``defaults.REFINE_FACTOR_RANGE``, a fit that still misses the data
(``defaults.REFINE_MAX_MISFIT``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from operator import mul

from .. import defaults, linalg
from ..load_observer import LoadTorqueObserver, load_prediction, smooth, smoothing_filter
from ..model_observer import advance
from .move_record import MoveRecord, Sample

__all__ = ["Belief", "ChainFit", "MoveRecord", "Sample", "fit_chain", "open_loop_errors"]


@dataclass(frozen=True)
class Belief:
    """What the fit knows of the parameters ``p = [c_J, c_k, δJ_1…δJ_n, δk_1…δk_n]``
    (module doc): a Gaussian of this mean and precision.

    Before any move it is the prior (mean 0, the spreads' inverse squares on the
    diagonal); after a fit, the fit (its mean) and the data's information added to what
    was known (``JᵀJ`` + the precision before), so that the next move's data move the
    parameters only as far as they are less well known.

    Attributes
    ----------
    mean : tuple of float
        Shape ``(2n + 2,)`` (dimensionless, log factors).
    precision : tuple of tuple of float
        Shape ``(2n + 2, 2n + 2)`` (dimensionless).
    """

    mean: tuple[float, ...]
    precision: tuple[tuple[float, ...], ...]


def prior_belief(n: int, mass_spread: float, common_spread: float) -> Belief:
    """The belief before any move: mean 0, the spreads (in log, dimensionless) as
    independent standard deviations of the common factors and of each mass's own."""
    spreads = [common_spread] * 2 + [mass_spread] * (2 * n)
    m = len(spreads)
    precision = tuple(
        tuple(1.0 / spreads[a] ** 2 if a == b else 0.0 for b in range(m)) for a in range(m)
    )
    return Belief((0.0,) * m, precision)


@dataclass(frozen=True)
class ChainFit:
    """The factors :func:`fit_chain` found.

    Attributes
    ----------
    J_factors, k_factors : tuple of float
        The factor on each J_i and each k_i from the prior's centre (the ``origin`` of
        :func:`fit_chain`; dimensionless), shape ``(n,)`` each.
    cost_before, cost_after : float
        The data's share of the cost (half the sum of squared residuals in units of the
        noise on τ̂_reac, each standing for ``defaults.REFINE_DATA_TIME`` of record;
        dimensionless) with the model the fit started from, and at the fit.
    iterations : int
        Levenberg–Marquardt iterations taken.
    J, k : tuple of float
        The fitted inertias (kg·m²) and stiffnesses (N·m/rad), shape ``(n,)`` each.
    trusted_time : float
        The record's trusted time (s).
    belief : Belief
        What is known of the parameters after the fit (the next move's prior).
    """

    J_factors: tuple[float, ...]
    k_factors: tuple[float, ...]
    cost_before: float
    cost_after: float
    iterations: int
    J: tuple[float, ...] = ()
    k: tuple[float, ...] = ()
    trusted_time: float = 0.0
    belief: Belief | None = None


def open_loop_errors(
    start: LoadTorqueObserver,
    J: Sequence[float],
    k: Sequence[float],
    samples: Sequence[Sample],
    lowpass: float,
) -> list[float]:
    """τ̂_reac less the model's open-loop prediction, low-passed, at every sample (N·m).

    The model (``J``, ``k``, and the estimator's B, g_dist and load mass) starts from the
    estimator's state ``start.s`` (its previous motor angle ``start.u_prev``) and is driven
    by the samples' motor angles, without the Kalman correction; its error passes a
    second-order Butterworth low-pass at ``lowpass`` rad/s, which starts at rest.

    Parameters
    ----------
    start : LoadTorqueObserver
        The estimator at the move's start (not changed).
    J, k : Sequence[float]
        The model's inertias (kg·m²) and stiffnesses (N·m/rad), shape ``(n,)`` each.
    samples : Sequence[Sample]
        The move's steps.
    lowpass : float
        The error's low-pass (rad/s), > 0.

    Returns
    -------
    list of float
        The filtered error at each sample (N·m), shape ``(len(samples),)``.
    """
    models: dict[float, tuple] = {}
    s = list(start.s)
    u_prev = start.u_prev
    z = [0.0, 0.0]
    out = []
    for sample in samples:
        h = sample.h
        found = models.get(h)
        if found is None:
            F, Gamma = load_prediction(J, k, start.B, start.g_dist, h, start.load_mass)
            found = models[h] = (F, Gamma, *smoothing_filter(lowpass, h))
        F, Gamma, Phi, phi = found
        u = sample.theta_m - start.theta0
        s = advance(F, Gamma, s, u_prev, u, h)
        u_prev = u
        z = smooth(Phi, phi, z, sample.tau_reac_hat - s[-1])
        out.append(z[0])
    return out


#: A prediction error beyond this (N·m) is a model that diverged, not a fit's candidate.
DIVERGED = 1e30


class _Problem:
    """The fit's residuals, cost and normal equations in the parameters
    ``p = [c_J, c_k, δJ_1…δJ_n, δk_1…δk_n]`` (module doc)."""

    def __init__(
        self,
        start: LoadTorqueObserver,
        samples: Sequence[Sample],
        origin: tuple[Sequence[float], Sequence[float]],
        prior: Belief,
        lowpass: float,
    ) -> None:
        self.start, self.samples, self.prior, self.lowpass = start, samples, prior, lowpass
        self.origin = origin
        self.n = len(start.J)
        # each trusted sample weighs as the time it stands for (the cost is an integral)
        unit = defaults.REFINE_DATA_TIME
        self.weights = [math.sqrt(s.h / unit) if s.trusted else 0.0 for s in samples]
        self.trusted_time = math.fsum(s.h for s in samples if s.trusted)
        # how far (in log) a trial may go: twice the accepted range, so that a fit that
        # leaves it is seen to, and no trial's model overflows
        self.search = 2.0 * max(abs(math.log(x)) for x in defaults.REFINE_FACTOR_RANGE)

    def logs(self, p: Sequence[float]) -> list[float]:
        """``[log J_i / J_i0 …, log k_i / k_i0 …]`` from the origin, shape ``(2n,)``."""
        n = self.n
        return [p[0] + p[2 + i] for i in range(n)] + [p[1] + p[2 + n + i] for i in range(n)]

    def start_parameters(self) -> list[float]:
        """``p`` of the start's model: its log factors from the origin, their means as the
        common factors."""
        n, (J0, k0) = self.n, self.origin
        dJ = [math.log(a / b) for a, b in zip(self.start.J, J0)]
        dk = [math.log(a / b) for a, b in zip(self.start.k, k0)]
        cJ, ck = math.fsum(dJ) / n, math.fsum(dk) / n
        return [cJ, ck, *(x - cJ for x in dJ), *(x - ck for x in dk)]

    def chain(self, logs: Sequence[float]) -> tuple[list[float], list[float]]:
        """The inertias (kg·m²) and stiffnesses (N·m/rad) at these log factors."""
        n, (J0, k0) = self.n, self.origin
        J = [a * math.exp(x) for a, x in zip(J0, logs[:n])]
        k = [a * math.exp(x) for a, x in zip(k0, logs[n:])]
        return J, k

    def residuals(self, logs: Sequence[float]) -> list[float] | None:
        """The weighted, filtered errors in units of the noise on τ̂_reac; None where
        the model diverges."""
        J, k = self.chain(logs)
        start = self.start
        errors = open_loop_errors(start, J, k, self.samples, self.lowpass)
        if not all(abs(e) < DIVERGED for e in errors):  # nan and inf fail too
            return None
        unit = start.noise.tau_noise_std
        return [w * e / unit for w, e in zip(self.weights, errors)]

    def prior_gradient(self, p: Sequence[float]) -> list[float]:
        """``Λ (p − μ)`` of the prior's Gaussian."""
        d = [a - b for a, b in zip(p, self.prior.mean)]
        return [math.fsum(map(mul, row, d)) for row in self.prior.precision]

    def cost(self, r: Sequence[float], p: Sequence[float]) -> float:
        """Half the sum of squares of the residuals, plus the prior's ``(p − μ)ᵀ Λ (p − μ)``."""
        d = [a - b for a, b in zip(p, self.prior.mean)]
        prior = math.fsum(map(mul, d, self.prior_gradient(p)))
        return 0.5 * (math.fsum(x * x for x in r) + prior)

    def normal_equations(
        self, p: Sequence[float], r: Sequence[float], step: float
    ) -> tuple[list[list[float]], list[float]] | None:
        """``JᵀJ + Λ`` and the cost's gradient at ``p`` by forward differences of
        ``step`` in each log factor (the common factors' columns: their masses' sums);
        None where a bumped model diverges."""
        n, logs = self.n, self.logs(p)
        columns = []
        for j in range(2 * n):
            bumped = logs[:]
            bumped[j] += step
            rj = self.residuals(bumped)
            if rj is None:
                return None
            columns.append([(a - b) / step for a, b in zip(rj, r)])
        cols = [
            [math.fsum(c) for c in zip(*columns[:n])],
            [math.fsum(c) for c in zip(*columns[n:])],
            *columns,
        ]
        m = len(cols)
        A = [[math.fsum(map(mul, cols[a], cols[b])) for b in range(m)] for a in range(m)]
        A = [[x + y for x, y in zip(row, prow)] for row, prow in zip(A, self.prior.precision)]
        g = [math.fsum(map(mul, c, r)) + q for c, q in zip(cols, self.prior_gradient(p))]
        return A, g


def _levenberg_marquardt(
    problem: _Problem, p: list[float], r: list[float], iterations: int, step: float
) -> tuple[list[float], list[float], int, list[list[float]] | None]:
    """Minimize ``problem``'s cost.

    Parameters
    ----------
    problem : _Problem
        The residuals, cost and normal equations.
    p, r : list of float
        The parameters to start from (dimensionless, shape ``(2n + 2,)``) and their
        residuals.
    iterations : int
        At most this many iterations.
    step : float
        The forward differences' step in each log factor (dimensionless).

    Returns
    -------
    tuple
        The parameters, their residuals, the iterations that lowered the cost and the
        last ``JᵀJ + Λ`` (None if none was formed).
    """
    current = problem.cost(r, p)
    A = None
    mu = 1e-3
    taken = 0
    for _ in range(iterations):
        found = problem.normal_equations(p, r, step)
        if found is None:
            break
        A, g = found
        while mu < 1e6:  # raise the damping until a step lowers the cost
            damped = [
                [x * (1.0 + mu) if a == b else x for b, x in enumerate(row)]
                for a, row in enumerate(A)
            ]
            delta = linalg.solve(damped, [[-x] for x in g])
            trial = [a + d[0] for a, d in zip(p, delta)]
            logs = problem.logs(trial)
            far = max(map(abs, logs)) > problem.search
            tr = None if far else problem.residuals(logs)
            tc = math.inf if tr is None else problem.cost(tr, trial)
            if tc < current:
                break
            mu *= 3.0
        else:
            break
        gain, p, r, current = current - tc, trial, tr, tc
        taken += 1
        mu = max(mu / 3.0, 1e-9)
        if gain <= 1e-4 * current:
            break
    return p, r, taken, A


def fit_chain(
    start: LoadTorqueObserver,
    samples: Sequence[Sample],
    origin: tuple[Sequence[float], Sequence[float]] | None = None,
    belief: Belief | None = None,
    evidence: float = defaults.REFINE_MIN_EVIDENCE,
    mass_spread: float = defaults.REFINE_MASS_SPREAD,
    common_spread: float = defaults.REFINE_COMMON_SPREAD,
    lowpass: float = defaults.REFINE_LOWPASS,
    iterations: int = defaults.REFINE_ITERATIONS,
) -> ChainFit | None:
    """The factors on every J_i and k_i that best predict a move's τ̂_reac (module doc).

    Parameters
    ----------
    start : LoadTorqueObserver
        The estimator at the move's start: its model (J, k, B, g_dist, load mass), where
        the fit starts, its state and its noise on τ̂_reac (the residuals' unit). Not
        changed.
    samples : Sequence[Sample]
        The move's steps (:class:`~arcosim.fmu.flexchain.control.move_record.MoveRecord`).
    origin : tuple of Sequence[float], optional
        The chain the prior is centred on and the factors are counted from, ``(J, k)``
        (kg·m², N·m/rad); default the start's own. The controller gives the chain as
        designed, so that moves after moves do not carry the model away from it.
    belief : Belief, optional
        What earlier moves told of the parameters (a :class:`ChainFit`'s ``belief``,
        the start's model at its mean); default :func:`prior_belief` of the spreads.
    evidence : float
        The least data cost of the start's model that the fit takes as showing its
        errors (dimensionless; ``ChainFit.cost_before``'s unit).
    mass_spread, common_spread : float
        The prior's standard deviations (in log, dimensionless) of each mass's own
        factor and of the common factors on every J_i and every k_i.
    lowpass : float
        The open-loop error's low-pass (rad/s).
    iterations : int
        At most this many Levenberg–Marquardt iterations.

    Returns
    -------
    ChainFit or None
        None (the data cannot support a fit) when the trusted samples span less than
        ``defaults.REFINE_MIN_TRUSTED_TIME``, the start's model diverges, its error is
        less than ``evidence`` (the move does not tell the model's errors from the
        noise), the fit leaves a factor outside
        ``defaults.REFINE_FACTOR_RANGE``, or the fitted model still misses the data by more
        than ``defaults.REFINE_MAX_MISFIT`` (the chain model cannot explain them).

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> estimator = arcosim.MotionController(arcosim.design_controller(chain, h=1e-3)).estimator
    >>> fit_chain(estimator.filter, []) is None  # no trusted sample: nothing to fit
    True
    """
    n = len(start.J)
    prior = belief or prior_belief(n, mass_spread, common_spread)
    origin = origin or (start.J, start.k)
    problem = _Problem(start, samples, origin, prior, lowpass)
    if problem.trusted_time < defaults.REFINE_MIN_TRUSTED_TIME:
        return None
    p = list(belief.mean) if belief else problem.start_parameters()
    r = problem.residuals(problem.logs(p))
    if r is None:
        return None
    before = 0.5 * math.fsum(x * x for x in r)
    if before < evidence:
        return None
    step = defaults.REFINE_DIFFERENCE_STEP
    p, r, taken, A = _levenberg_marquardt(problem, p, r, iterations, step)
    if A is None:
        return None
    logs = problem.logs(p)
    factors = [math.exp(x) for x in logs]
    lo, hi = defaults.REFINE_FACTOR_RANGE
    after = 0.5 * math.fsum(x * x for x in r)
    misfit = math.sqrt(2.0 * after * defaults.REFINE_DATA_TIME / problem.trusted_time)
    if not all(lo <= f <= hi for f in factors) or misfit > defaults.REFINE_MAX_MISFIT:
        return None
    J, k = problem.chain(logs)
    known = Belief(tuple(p), tuple(tuple(row) for row in A))
    return ChainFit(
        tuple(factors[:n]), tuple(factors[n:]), before, after, taken,
        tuple(J), tuple(k), problem.trusted_time, known,
    )  # fmt: skip
