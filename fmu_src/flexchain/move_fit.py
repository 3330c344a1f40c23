"""Every J_i and k_i of the controller's chain refined from a move's own response.

The estimator bank (:mod:`~arcosim.fmu.flexchain.estimator_bank`) scales every J_i by one
factor and every k_i by another: errors that differ from mass to mass change the chain's
mode shapes, which no such pair reproduces, and on a four-mass chain with independent
±10 % errors the controller then settled up to 2 × slower than the same gains on the
true states (docs/development.md). A move excites the chain enough to tell them apart:
:class:`MoveRecord` keeps, from the move's start, what the bank's estimators take (τ̂_reac
and the motor angle, each step), and :func:`fit_chain` finds the factors on every J_i
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
(2n open-loop runs per iteration; the common factors' columns are sums of the masses').
It refuses (returns ``None``) a record with fewer than ``defaults.REFINE_MIN_TRUSTED``
trusted samples and a fit that leaves a factor outside ``defaults.REFINE_FACTOR_RANGE``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from operator import mul

from . import defaults, linalg
from .load_observer import LoadTorqueObserver, load_prediction, smoothing_filter


@dataclass(frozen=True)
class Sample:
    """One step of a move as the bank's estimators took it.

    Attributes
    ----------
    h : float
        The step (s).
    tau_reac_hat : float
        τ̂_reac at its end (N·m).
    theta_m : float
        The motor angle the estimators took there (rad).
    trusted : bool
        Whether the DOB's friction was known over the last
        ``defaults.REFINE_TRUST_AFTER`` s (module doc).
    """

    h: float
    tau_reac_hat: float
    theta_m: float
    trusted: bool


class MoveRecord:
    """What a move gives the bank's estimators, one step at a time (module doc).

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
            The motor angle the estimators take (rad).
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


@dataclass(frozen=True)
class ChainFit:
    """The factors :func:`fit_chain` found.

    Attributes
    ----------
    J_factors, k_factors : tuple of float
        The factor on each J_i and each k_i (dimensionless), shape ``(n,)`` each.
    cost_before, cost_after : float
        The data's share of the cost (half the sum of squared residuals in units of the
        noise on τ̂_reac, dimensionless) at the factors 1 and at the fit.
    iterations : int
        Levenberg–Marquardt iterations taken.
    """

    J_factors: tuple[float, ...]
    k_factors: tuple[float, ...]
    cost_before: float
    cost_after: float
    iterations: int


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
    z0 = z1 = 0.0
    out = []
    for sample in samples:
        h = sample.h
        found = models.get(h)
        if found is None:
            F, Gamma = load_prediction(J, k, start.B, start.g_dist, h, start.load_mass)
            Phi, phi = smoothing_filter(lowpass, h)
            found = models[h] = (F, Gamma, Phi, phi)
        F, Gamma, ((p00, p01), (p10, p11)), (q0, q1) = found
        u = sample.theta_m - start.theta0
        w0, w1 = u_prev, (u - u_prev) / h
        s = [sum(map(mul, row, s)) + g[0] * w0 + g[1] * w1 for row, g in zip(F, Gamma)]
        u_prev = u
        e = sample.tau_reac_hat - s[-1]
        z0, z1 = p00 * z0 + p01 * z1 + q0 * e, p10 * z0 + p11 * z1 + q1 * e
        out.append(z0)
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
        prior: Sequence[float],
        lowpass: float,
    ) -> None:
        self.start, self.samples, self.prior, self.lowpass = start, samples, prior, lowpass
        self.n = len(start.J)
        self.weights = [1.0 if s.trusted else 0.0 for s in samples]
        # how far (in log) a trial may go: twice the accepted range, so that a fit that
        # leaves it is seen to, and no trial's model overflows
        self.search = 2.0 * max(abs(math.log(x)) for x in defaults.REFINE_FACTOR_RANGE)

    def logs(self, p: Sequence[float]) -> list[float]:
        """``[log J_i / J_i0 …, log k_i / k_i0 …]``, shape ``(2n,)``."""
        n = self.n
        return [p[0] + p[2 + i] for i in range(n)] + [p[1] + p[2 + n + i] for i in range(n)]

    def residuals(self, logs: Sequence[float]) -> list[float] | None:
        """The weighted, filtered errors in units of the noise on τ̂_reac; None where
        the model diverges."""
        n, start = self.n, self.start
        J = [a * math.exp(x) for a, x in zip(start.J, logs[:n])]
        k = [a * math.exp(x) for a, x in zip(start.k, logs[n:])]
        errors = open_loop_errors(start, J, k, self.samples, self.lowpass)
        if not all(abs(e) < DIVERGED for e in errors):  # nan and inf fail too
            return None
        unit = start.noise.tau_noise_std
        return [w * e / unit for w, e in zip(self.weights, errors)]

    def cost(self, r: Sequence[float], p: Sequence[float]) -> float:
        """Half the sum of squares of the residuals and of the prior's terms."""
        prior = math.fsum((x / s) ** 2 for x, s in zip(p, self.prior))
        return 0.5 * (math.fsum(x * x for x in r) + prior)

    def normal_equations(
        self, p: Sequence[float], r: Sequence[float], step: float
    ) -> tuple[list[list[float]], list[float]] | None:
        """``JᵀJ + P⁻¹`` and the cost's gradient at ``p`` by forward differences of
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
        g = [math.fsum(map(mul, cols[a], r)) + p[a] / self.prior[a] ** 2 for a in range(m)]
        for a in range(m):
            A[a][a] += 1.0 / self.prior[a] ** 2
        return A, g


def _levenberg_marquardt(
    problem: _Problem, r: list[float], iterations: int, step: float
) -> tuple[list[float], list[float], int]:
    """Minimize ``problem``'s cost from p = 0 (its residuals there ``r``); return the
    parameters, their residuals and the iterations taken."""
    p = [0.0] * (2 * problem.n + 2)
    current = problem.cost(r, p)
    mu = 1e-3
    taken = 0
    while taken < iterations:
        taken += 1
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
        mu = max(mu / 3.0, 1e-9)
        if gain <= 1e-4 * current:
            break
    return p, r, taken


def fit_chain(
    start: LoadTorqueObserver,
    samples: Sequence[Sample],
    mass_spread: float = defaults.REFINE_MASS_SPREAD,
    common_spread: float = defaults.REFINE_COMMON_SPREAD,
    lowpass: float = defaults.REFINE_LOWPASS,
    iterations: int = defaults.REFINE_ITERATIONS,
) -> ChainFit | None:
    """The factors on every J_i and k_i that best predict a move's τ̂_reac (module doc).

    Parameters
    ----------
    start : LoadTorqueObserver
        The estimator at the move's start: its model (J, k, B, g_dist, load mass), its
        state and its noise on τ̂_reac (the residuals' unit). Not changed.
    samples : Sequence[Sample]
        The move's steps (:class:`MoveRecord`).
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
        None when fewer than ``defaults.REFINE_MIN_TRUSTED`` samples are trusted, the
        model as given diverges, or the fit leaves a factor outside
        ``defaults.REFINE_FACTOR_RANGE``.

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> bank = arcosim.MotionController(arcosim.design_controller(chain, h=1e-3)).bank
    >>> fit_chain(bank.chosen, []) is None  # no trusted sample: nothing to fit
    True
    """
    n = len(start.J)
    prior = [common_spread] * 2 + [mass_spread] * (2 * n)
    problem = _Problem(start, samples, prior, lowpass)
    if sum(problem.weights) < defaults.REFINE_MIN_TRUSTED:
        return None
    r = problem.residuals([0.0] * (2 * n))
    if r is None:
        return None
    before = 0.5 * math.fsum(x * x for x in r)
    p, r, taken = _levenberg_marquardt(problem, r, iterations, defaults.REFINE_DIFFERENCE_STEP)
    factors = [math.exp(x) for x in problem.logs(p)]
    lo, hi = defaults.REFINE_FACTOR_RANGE
    if not all(lo <= f <= hi for f in factors):
        return None
    after = 0.5 * math.fsum(x * x for x in r)
    return ChainFit(tuple(factors[:n]), tuple(factors[n:]), before, after, taken)
