"""The rule that chooses a fit's structure among candidates, and the candidates' scores.

Every candidate (a friction form, a load model, a number of masses) is a
prediction-error fit (:func:`~arcosim.identification.fit.encoder_fit.refine`) on the same
record with the same noise model, so their normalized innovations compare: their rms
is 1 at the floor the encoder's counts and the process noise explain. The rule:

* each candidate's score is the BIC on the effective sample count N / L (L: the
  Newey–West lag of the richest candidate's innovations, one lag for all),
  ``N/L · log(mean e²) + P · log(N/L)``;
* among the candidates within a margin of the best score's rms innovation, the one
  with the fewest parameters is taken (ties: the lower score): a richer candidate must
  lower the residual by more than that fraction of the noise floor. The margin is
  :data:`RICHER_MARGIN` (1 %) for n, :data:`LOAD_MARGIN` (50 %) for the load
  torque (a slow one counts one parameter more than a constant one),
  :data:`FRICTION_MARGIN` (0.1 %) for the friction form: a slow load's random
  walk absorbs any slow model error (on a clean three-mass log it lowers the rms by
  2.6 % of the floor, with k_t or J_m given 10 % high by 15 %, which would hide the
  misfit the noise floor's warning names; an unmodelled 0.01 N·m load at 0.3 rad/s:
  from 6.5 to 0.98 × the floor) and must earn its place clearly, while leaving out a
  friction term the motor has moves its torque into the dampers (the viscous friction of the
  three-mass chain lowers the rms by 0.24 % of the floor; without it the B_i come out
  +12 … +120 %).

:func:`choose` applies it; :func:`scores` gives the table the report shows;
:func:`friction_form` and :func:`load_choice` run it on the friction form and the load
torque (none, constant, slow) of a whole-chain (or rigid) fit, and refit the whole
record with what it takes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.encoder_fit import chain_size, refine
from arcosim.identification.fit.output_error import ParameterFit
from arcosim.identification.records.record import (
    FRICTION_FORMS,
    LOAD_DRIFT,
    LOADS,
    EncoderRecord,
    MotorRecord,
    encoder_opening,
)

#: A richer candidate (a mode, a load torque) is taken only when it lowers the rms
#: normalized innovation by more than this fraction of the noise floor (dimensionless;
#: the floor is 1).
RICHER_MARGIN = 0.01
#: The same for a friction term (dimensionless).
FRICTION_MARGIN = 0.001
#: The same for a load torque, constant or slow (dimensionless).
LOAD_MARGIN = 0.5

#: The rule, one sentence (for the report).
RULE = (
    "BIC on the effective sample count N/L (L: the Newey–West lag of the richest "
    "candidate's innovations); among the candidates whose rms normalized innovation "
    "(1 = the noise floor) is within a margin of the best BIC's, the one with the fewest "
    f"parameters; margin {RICHER_MARGIN:g} for n, {LOAD_MARGIN:g} for the load torque, "
    f"{FRICTION_MARGIN:g} for the friction form"
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


def choose(candidates: list[Candidate], margin: float = RICHER_MARGIN) -> Candidate:
    """The candidate the rule (module doc) takes, with ``margin`` (a fraction of the
    noise floor, dimensionless).

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
    close = [c for c in candidates if c.rms <= best.rms + margin]
    return min(close, key=lambda c: (c.parameters, table[c.name]["bic"]))


def candidate_of(name: str, fit: ParameterFit) -> Candidate:
    return Candidate(
        name,
        len(fit.values),
        fit.extra["innovation_variance"],
        fit.extra["innovation_count"],
        fit.lag,
    )


def restart(result: ParameterFit, n: int) -> ParameterFit:
    """A start for :func:`refine` from ``result``'s chain (its evidence kept)."""
    chain = np.array(result.values[: chain_size(n)], dtype=float)
    start = ParameterFit(
        result.names[: chain_size(n)],
        chain,
        np.zeros_like(chain),
        chain,
        result.start_note.split("; then")[0],
        0.0,
        result.rms_data,
        1,
        result.evaluations,
    )
    start.extra.update({k: v for k, v in result.extra.items() if k in _EVIDENCE})
    return start


_EVIDENCE = ("modes_rad_s", "damping_ratios", "singular_values")


def with_form(encoder: EncoderRecord, form: str, D_m: float, f_c: float) -> EncoderRecord:
    """``encoder`` fitting the friction ``form`` from ``D_m``, ``f_c`` (the terms it
    leaves out at 0); the noise model unchanged, so candidates compare."""
    return replace(
        encoder,
        friction_form=form,
        D_m=D_m if form in ("viscous", "both") else 0.0,
        f_c=f_c if form in ("coulomb", "both") else 0.0,
    )


def friction_start(result: ParameterFit, encoder: EncoderRecord, name: str) -> float:
    """Start of the friction term ``name`` (``"D_m"`` N·m·s/rad or ``"f_c"`` N·m) for
    the candidates: ``result``'s fitted value, or the record's start where the fit left
    it at its bound (at least 1e-9). Not the larger of the two: the record's start is a
    rough rigid-body reading (D_m 38× the truth on a ball-screw axis)."""
    fitted = float(result.extra[name])
    if name in result.extra.get("bounds", {}) or fitted <= 0.0:
        return max(getattr(encoder, name), 1e-9)
    return max(fitted, 1e-9)


def friction_form(
    record: MotorRecord, encoder: EncoderRecord, n: int, result: ParameterFit, seconds: float
) -> tuple[ParameterFit, dict]:
    """The friction form chosen by the rule (:func:`choose`) among none,
    viscous, Coulomb and both, each fitted on the record's first
    ``seconds`` (s) from ``result``'s chain; ``result`` refitted from the opening's
    friction when the two disagree (:func:`restarted`), and the whole record refitted
    with the form chosen when it is not ``result``'s, its σ widened by the left-out
    term's shift (:func:`with_form_shift`). Given friction: ``result`` as it is."""
    if encoder.friction_given:
        return result, {"given": True}
    # a rigid fit is cheap: the whole record, whose D_m an opening may not resolve
    short = encoder if n == 0 else encoder_opening(encoder, seconds)
    start = restart(result, n)
    D_m, f_c = (friction_start(result, encoder, name) for name in ("D_m", "f_c"))
    candidates, fits = [], {}
    for form in FRICTION_FORMS:
        try:
            fits[form] = refine(with_form(short, form, D_m, f_c), None, start, n)
        except (IdentificationError, ValueError, np.linalg.LinAlgError):
            continue
        candidates.append(candidate_of(form, fits[form]))
    if len(candidates) < 2:
        return result, {"candidates": scores(candidates) if candidates else {}}
    chosen = choose(candidates, FRICTION_MARGIN).name
    table = {"candidates": scores(candidates), "chosen": chosen}
    if "both" in fits and result.extra.get("friction_form") == "both":
        result = restarted(record, encoder, n, result, fits["both"])
    if chosen == "both":
        return result, table
    found = fits[chosen].extra
    final = refine(
        with_form(encoder, chosen, max(found["D_m"], 1e-9), max(found["f_c"], 1e-9)),
        None if n == 0 else record,
        start,
        n,
    )
    if n == 0:
        final.rms_residual, final.rms_data = result.rms_residual, result.rms_data
    if result.extra.get("friction_form") == "both":
        with_form_shift(final, result, fits.get("both"), fits[chosen])
    if "both" in fits:  # a term the rule left out: at most what the full form allows
        both = fits["both"].as_dict(), fits["both"].std_dict()
        at_its_bound = fits["both"].extra.get("bounds", {})  # there σ says nothing
        final.extra["bounds"] = final.extra.get("bounds", {}) | {
            name: at_its_bound.get(name, max(both[0][name], 0.0) + 2.0 * both[1][name])
            for name in ("D_m", "f_c")
            if name not in final.names
        }
    return final, table


def restarted(
    record: MotorRecord, encoder: EncoderRecord, n: int, result: ParameterFit, opening: ParameterFit
) -> ParameterFit:
    """``result`` (both friction terms, the whole record), or its refit from the
    friction of ``opening`` (both terms, the record's opening) when a term of the two
    differs by more than 2σ (the opening's σ): the fit with the lower innovations. Two
    fits of one model on one record that disagree mean one sits in a local minimum:
    in a position loop on a square wave the whole record's fit may leave D_m at 2e-10
    (truth 2e-5) and B_1 +9.8 %, where its opening reads D_m 2.9e-5."""
    full, first = result.as_dict(), opening.as_dict()
    sigma = opening.std_dict()
    names = [name for name in ("D_m", "f_c") if name in full and name in first]
    if all(abs(full[name] - first[name]) <= 2.0 * sigma[name] for name in names):
        return result
    again = refine(
        with_form(encoder, "both", max(first["D_m"], 1e-9), max(first["f_c"], 1e-9)),
        None if n == 0 else record,
        restart(result, n),
        n,
    )
    if again.extra["innovation_variance"] >= result.extra["innovation_variance"]:
        return result
    if n == 0:
        again.rms_residual, again.rms_data = result.rms_residual, result.rms_data
    return again


def with_sign_shift(encoder: EncoderRecord, n: int, result: ParameterFit) -> ParameterFit:
    """``result`` (a chain fitted on ``encoder``, with its friction form and load) with
    every σ widened (:func:`widen`) by how far one more smoothing of the friction's sign
    moves its parameter (:func:`~arcosim.identification.fit.encoder_fit.smoothed_sign`;
    the shifts in ``extra["sign_shift"]``, each parameter's units), when the model
    carries a Coulomb friction (f_c > 0, given or fitted): the fit holds the smoother's
    sign fixed, so its σ leave out the sign's own uncertainty. The sign errs at the
    reversals, where the torque it misplaces goes with the acceleration: the fit takes
    it for inertia and scales every J_i, k_i together. In a PI speed loop with a
    2000-count encoder (``benchmarks.field_accuracy``) J_i, k_i came out +0.06 % on
    average with σ of 0.03 %, within 2σ on 72 of 120; the true sign takes the common
    shift out, and one more round moves them by 0.03–0.08 %. In a position loop on a
    square wave (seed 17) one more round moved f_c by 2.1σ, onto the truth. The rigid
    drive (n = 0) is left as it is: its sign is already smoothed to convergence."""
    if n == 0 or result.extra.get("f_c", 0.0) <= 0.0:
        return result
    values = result.as_dict()
    refit = encoder
    if not encoder.friction_given:
        form = result.extra.get("friction_form", "both")
        D_m, f_c = (max(values.get(name, result.extra[name]), 1e-9) for name in ("D_m", "f_c"))
        refit = with_form(encoder, form, D_m, f_c)
    try:
        again = refine(refit, None, restart(result, n), n, more_rounds=1)
    except (IdentificationError, ValueError, np.linalg.LinAlgError):
        return result
    moved = again.as_dict()
    widen(
        result, {name: moved[name] - values[name] for name in values if name in moved}, "sign_shift"
    )
    return result


def with_form_shift(
    final: ParameterFit,
    full: ParameterFit,
    opening_full: ParameterFit | None = None,
    opening_final: ParameterFit | None = None,
) -> None:
    """Widen each σ of ``final`` (a fit of the form the rule chose, a term left out) by
    how far the left-out term moves that parameter: ``σ² + shift²``, the shift the
    larger of ``value − value in full`` (``full``: the fit of both terms on the same
    record) and, when given, the same difference between ``opening_final`` and
    ``opening_full``, the two forms' fits on the opening where the rule compared them
    (one start: a like-for-like difference even when ``full`` sits in a local minimum).
    The form chosen says the record does not resolve the term; the kept parameters then
    carry what it would have explained (on a ball-screw axis, Coulomb-only: f_c +2.3 %
    with a σ of 0.36 %, the viscous torque taken for Coulomb friction; in a position
    loop on a square wave, B_1 +9.8 % with a σ of 0.8 %, where the opening's two forms
    differ by 8.5 %). The shifts go in ``extra["form_shift"]`` (each parameter's
    units)."""
    values = full.as_dict()
    pair = (opening_final.as_dict(), opening_full.as_dict()) if opening_full else ({}, {})
    shift = {}
    for name, value in zip(final.names, final.values):
        moves = [value - values[name]] if name in values else []
        if name in pair[0] and name in pair[1]:
            moves.append(pair[0][name] - pair[1][name])
        if moves:
            shift[name] = float(max(moves, key=abs))
    widen(final, shift)


def widen(fit: ParameterFit, shift: dict[str, float], key: str = "form_shift") -> None:
    """Each σ of ``fit`` widened by its parameter's ``shift`` (``σ² + shift²``, each
    parameter's units), kept in ``extra[key]`` (``"form_shift"``: a left-out friction
    term's, ``"sign_shift"``: the friction sign's)."""
    fit.std = np.array([np.hypot(s, shift.get(name, 0.0)) for name, s in zip(fit.names, fit.std)])
    fit.extra[key] = shift


def with_load(encoder: EncoderRecord, load: str, drift: float) -> EncoderRecord:
    """``encoder`` carrying the load torque ``load`` (one of :data:`LOADS`), a slow one
    with the random walk ``drift`` (N·m per step)."""
    return replace(encoder, load=load, load_std=drift if load == "slow" else 0.0)


def load_candidate(load: str, fit: ParameterFit) -> Candidate:
    """The load ``load``'s candidate: a slow load counts its random walk as one parameter
    more than a constant one (same ``tau_load``, a richer model), so the rule prefers
    the constant when both explain the record as well."""
    candidate = candidate_of(load, fit)
    return replace(candidate, parameters=candidate.parameters + (load == "slow"))


def load_choice(
    record: MotorRecord,
    encoder: EncoderRecord,
    n: int,
    result: ParameterFit,
    seconds: float,
    choose_load: bool = True,
) -> tuple[ParameterFit, EncoderRecord, dict]:
    """The load torque by the rule (:func:`choose`, margin :data:`LOAD_MARGIN`) among
    none, constant and slow, each fitted on the record's first ``seconds`` (s) from
    ``result``'s chain and friction form; the whole record refitted with the load
    chosen when it is not none. A load the user gave (``encoder.load`` not none, or
    none with ``choose_load`` False) is never overridden: a none given only warns when
    the rule takes a load. Returns the fit, the encoder record it rests on (its load
    the one chosen) and the selection's table (candidates, scores, the one chosen)."""
    if encoder.load != "none":
        return result, encoder, {"given": encoder.load}
    drift = LOAD_DRIFT * float(np.sqrt(np.mean(encoder.drive**2))) * np.sqrt(encoder.h)
    fitted = encoder
    if not encoder.friction_given:
        D_m, f_c = max(result.extra["D_m"], 1e-9), max(result.extra["f_c"], 1e-9)
        fitted = with_form(encoder, result.extra.get("friction_form", "both"), D_m, f_c)
    short, start = encoder_opening(fitted, seconds), restart(result, n)
    candidates = []
    for load in LOADS:
        try:
            trial = refine(with_load(short, load, drift), None, start, n)
        except (IdentificationError, ValueError, np.linalg.LinAlgError):
            continue
        candidates.append(load_candidate(load, trial))
    if len(candidates) < 2 or candidates[0].name != "none":
        return result, encoder, {"candidates": scores(candidates) if candidates else {}}
    chosen = choose(candidates, LOAD_MARGIN)
    table = {"candidates": scores(candidates), "chosen": chosen.name}
    if chosen.name == "none":
        return result, encoder, table
    what = f"{'a slowly varying' if chosen.name == 'slow' else 'a constant'} load torque"
    without = candidates[0].rms
    rms = f"rms innovation {without:.2f} × the noise floor without it, {chosen.rms:.2f} with"
    final = None
    if choose_load:
        try:
            final = refine(with_load(fitted, chosen.name, drift), record if n else None, start, n)
        except (IdentificationError, ValueError, np.linalg.LinAlgError):
            table["refit"] = "failed: the load left out"
    if final is None:
        if not choose_load:
            table["given"] = "none"
        result.extra.setdefault("structure_warnings", []).append(
            f"the residual holds {what} the model leaves out (the selection rule takes "
            f"{chosen.name}: {rms}): an unmodelled load torque; fit it with --load {chosen.name}"
        )
        return result, encoder, table
    carry_over(final, result, n)
    final.extra.setdefault("structure_warnings", []).append(
        f"{what} on the last mass, chosen by the selection rule ({rms}) and fitted "
        f"(tau_load); --load none leaves it out, --load constant|slow states it"
    )
    return final, with_load(encoder, chosen.name, drift), table


def carry_over(final: ParameterFit, result: ParameterFit, n: int) -> None:
    """What ``result``'s structure choices left on it, onto ``final`` (the same chain
    refitted with a load torque): the bounds of the terms it leaves out, the friction
    form's and the friction sign's widening of the σ (:func:`with_form_shift`,
    :func:`with_sign_shift`), its warnings; a rigid fit's
    residuals (n = 0: no τ̂ to predict)."""
    if n == 0:
        final.rms_residual, final.rms_data = result.rms_residual, result.rms_data
    left_out = {k: v for k, v in result.extra.get("bounds", {}).items() if k not in final.names}
    final.extra["bounds"] = final.extra.get("bounds", {}) | left_out
    for key in ("form_shift", "sign_shift"):  # :func:`with_sign_shift`'s too
        if key in result.extra:
            widen(final, result.extra[key], key)
    final.extra["structure_warnings"] = list(result.extra.get("structure_warnings", []))
