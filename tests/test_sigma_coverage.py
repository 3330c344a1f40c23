"""The whole-chain fit's σ of J_i, k_i cover the truth as often as they claim.

A Gaussian estimate with an honest σ lies within 2σ of the truth with probability
0.9545, so over independent seeds the count within 2σ of each parameter is binomial;
the test fails when a count falls below what honest σ reach but with a small
probability. On the PI speed loop with a constant load (2000-count encoder, Coulomb
friction given) the friction's sign from the smoother errs at the reversals and the fit
takes the misplaced torque for inertia: every J_i, k_i came out about +0.06 % with a σ
of 0.03 % (four of the six within 2σ on 4 of these 8 seeds), until the σ counted how far
one more smoothing of the sign moves them
(:func:`arcosim.identification.fit.structure_choice.with_sign_shift`).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import binom, norm

from benchmarks.field_accuracy import ROWS, run_row

ROW = "three-mass, PI loop, constant load"
SEEDS = range(1, 9)
#: P(|z| ≤ 2) for a Gaussian estimate with an honest σ.
WITHIN = float(norm.cdf(2.0) - norm.cdf(-2.0))
#: Chance that honest σ fail the test (dimensionless), shared over the parameters.
FALSE_ALARM = 0.01


def fewest_within(seeds: int, parameters: int) -> int:
    """The smallest count within 2σ (of ``seeds``) that honest σ reach but with
    probability at most ``FALSE_ALARM / parameters`` (Bonferroni: one test per
    parameter, each binomial over independent seeds).

    Examples
    --------
    >>> fewest_within(8, 6)  # fewer than 5 of 8 has probability < 0.17 % under honest σ
    5
    """
    return int(binom.ppf(FALSE_ALARM / parameters, seeds, WITHIN))


def test_fewest_within_is_the_binomial_tail() -> None:
    k = fewest_within(8, 6)
    assert binom.cdf(k - 1, 8, WITHIN) <= FALSE_ALARM / 6 < binom.cdf(k, 8, WITHIN)


@pytest.mark.slow
def test_the_sigma_of_every_J_and_k_covers_the_truth_as_claimed() -> None:
    row = ROWS[ROW]
    runs = [run_row(row, seed) for seed in SEEDS]
    assert all(r["n"] == row.drive.n for r in runs), [r.get("n") for r in runs]
    z = np.array([np.divide(r["J"] + r["k"], r["J_std"] + r["k_std"]) for r in runs])
    within = (np.abs(z) <= 2.0).sum(axis=0)  # per parameter, over the seeds
    names = [f"{p}[{i}]" for p in "Jk" for i in range(1, row.drive.n + 1)]
    least = fewest_within(len(runs), len(names))
    assert np.all(within >= least), dict(zip(names, within.tolist())) | {"least": least}
    assert all(r["verdict"] == "trusted" for r in runs)


#: Seeds of the 4 kHz row on which the fit is quickest (about 12 s each).
FOUR_KHZ_SEEDS = (3, 7)


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="at 4 kHz the chain's stuck rule (the torque without the motor's inertia) reads "
    "a motor passing through 0 as held: k_1 +0.03 … +0.045 % with σ 0.013 % (z +2.1 … +2.8), "
    "which one more smoothing round does not move",
)
def test_k_1_at_4_khz_is_covered_as_claimed() -> None:
    """Pins the bias the sign's shift leaves (design record "The friction sign"): with
    f_c = 0, the true sign, or the stuck rule without or with the motor's inertia k_1
    comes out right. Passes, and so fails the mark, once the sign covers k_1 at 4 kHz."""
    row = ROWS["three-mass, 4 kHz"]
    runs = [run_row(row, seed) for seed in FOUR_KHZ_SEEDS]
    assert all(r["n"] == row.drive.n for r in runs), [r.get("n") for r in runs]
    z = [r["k"][0] / r["k_std"][0] for r in runs]
    within = sum(abs(x) <= 2.0 for x in z)
    assert within >= fewest_within(len(runs), 1), z
