"""The rule that chooses a fit's structure among candidates, and the candidates' scores.

Every candidate (a friction form, a load model, a number of masses) is a
prediction-error fit (:func:`~arcosim.identification.encoder_fit.refine`) on the same
record with the same noise model, so their normalized innovations compare: their rms
is 1 at the floor the encoder's counts and the process noise explain. The rule:

* each candidate's score is the BIC on the effective sample count N / L (L: the
  Newey–West lag of the richest candidate's innovations, one lag for all),
  ``N/L · log(mean e²) + P · log(N/L)``;
* among the candidates within :data:`RICHER_MARGIN` of the best score's rms
  innovation, the one with the fewest parameters is taken (ties: the lower score): a
  richer candidate must lower the residual by more than that fraction of the noise
  floor.

:func:`choose` applies it; :func:`scores` gives the table the report shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: A richer candidate is taken only when it lowers the rms normalized innovation by
#: more than this fraction of the noise floor (dimensionless; the floor is 1).
RICHER_MARGIN = 0.01

#: The rule, one sentence (for the report).
RULE = (
    "BIC on the effective sample count N/L (L: the Newey–West lag of the richest "
    "candidate's innovations); among the candidates whose rms normalized innovation is "
    f"within {RICHER_MARGIN:g} of the floor-relative rms of the best BIC, the one with the "
    "fewest parameters"
)


@dataclass(frozen=True)
class Candidate:
    """One structure tried.

    Attributes
    ----------
    name : str
        What it is (``"viscous"``, ``"slow"``, ``"n=2"`` …).
    parameters : int
        Fitted parameters (a count).
    variance : float
        Mean square normalized innovation (dimensionless; 1 at the noise floor).
    count : int
        Innovations (a count).
    lag : int
        Their Newey–West lag (samples).
    """

    name: str
    parameters: int
    variance: float
    count: int
    lag: int

    @property
    def rms(self) -> float:
        """Rms normalized innovation (dimensionless)."""
        return math.sqrt(self.variance)


def bic(candidate: Candidate, lag: int) -> float:
    """BIC (dimensionless) of ``candidate`` on the effective sample count N / ``lag``.

    Examples
    --------
    >>> round(bic(Candidate("none", 2, 1.0, 1000, 10), 10), 2)  # 2 log(100)
    9.21
    """
    effective = max(candidate.count / max(lag, 1), 2.0)
    return effective * math.log(max(candidate.variance, 1e-300)) + candidate.parameters * (
        math.log(effective)
    )


def scores(candidates: list[Candidate]) -> dict[str, dict[str, float]]:
    """Per candidate: its parameters, rms normalized innovation and BIC (one lag: the
    richest candidate's), JSON-able."""
    lag = max(candidates, key=lambda c: c.parameters).lag
    return {
        c.name: {"parameters": c.parameters, "rms_innovation": c.rms, "bic": bic(c, lag)}
        for c in candidates
    }


def choose(candidates: list[Candidate]) -> Candidate:
    """The candidate the rule (module doc) takes.

    Examples
    --------
    >>> a = Candidate("viscous", 1, 1.000, 10000, 10)
    >>> b = Candidate("both", 2, 0.999, 10000, 10)  # 0.05 % lower: not worth a parameter
    >>> choose([a, b]).name
    'viscous'
    >>> choose([a, Candidate("both", 2, 0.8, 10000, 10)]).name
    'both'
    """
    table = scores(candidates)
    best = min(candidates, key=lambda c: table[c.name]["bic"])
    close = [c for c in candidates if c.rms <= best.rms + RICHER_MARGIN]
    return min(close, key=lambda c: (c.parameters, table[c.name]["bic"]))
