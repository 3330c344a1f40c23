"""Identify the whole chain from the motor alone: every J_i, k_i and B_i, and n (offline).

A chain of masses and springs is fixed by its driving-point response (motor angle in,
reaction torque out; :mod:`arcosim.identification.modes.chain_modes`), so a motor-side
record carries every inertia, stiffness and damping. :func:`identify_whole_chain` reads
the record's modes from a stabilization diagram of the subspace step
(:func:`arcosim.identification.modes.detection.detect_modes`: a mode counts when it comes
back at several model orders and its residue stands above its standard error), starts
the chain from those modes and residues with no search (the Lanczos inverse), and fits
every parameter: by the prediction-error fit from the current to the encoder
(:mod:`arcosim.identification.fit.encoder_fit`, with the motor's friction and a load
torque when asked for) when the encoder's counts are known, else by the output-error
fit to τ̂_reac (:mod:`arcosim.identification.fit.output_error`). A friction not given is
first estimated and taken out of τ̂ (:mod:`arcosim.identification.fit.motor_friction`).
The result is a :class:`ChainChoice`: the chosen n, its fit and the evidence for n.

``masses="auto"`` takes n = the modes that count, confirmed by the data: the fits
without the weakest modes are compared by their information criterion, one weak mode
at a time. An n the record cannot support is refused, naming the modes it shows, the
ones too weakly excited, and what would fix the record.
:func:`arcosim.identification.drive_identification.identify_drive` runs it from a log.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from arcosim.fmu.flexchain.chain import Chain
from arcosim.identification.errors import IdentificationError
from arcosim.identification.excitation.spectrum import ExcitationSpectrum
from arcosim.identification.fit.encoder_fit import refine, unpack
from arcosim.identification.fit.motor_friction import friction_cleaned, without_friction
from arcosim.identification.fit.output_error import (
    ParameterFit,
    check_excited,
    continued_fit,
)
from arcosim.identification.fit.periodic_misfit import (
    PeriodicResponse,
    chain_drive,
    misfit,
    model_response,
    periodic_response,
    smallest_adequate,
)
from arcosim.identification.fit.refusal import (
    T_CONFIRM,
    assumptions,
    masses_asked,
    missing_modes,
    refusal,
)
from arcosim.identification.fit.rigid_drive import rigid_fit
from arcosim.identification.fit.structure_choice import (
    RULE,
    Candidate,
    candidate_of,
    choose,
    friction_form,
    load_choice,
    scores,
    with_sign_shift,
)
from arcosim.identification.fit.weak_modes import without_weak_modes
from arcosim.identification.modes.detection import (
    DetectedModes,
    Modes,
    detect_modes,
    modal_damping,
    record_modes,
)
from arcosim.identification.records.record import (
    EncoderRecord,
    MotorRecord,
    encoder_opening,
    with_friction,
)
from arcosim.identification.threads import single_threaded

#: Largest chain ``masses="auto"`` tries.
MAX_AUTO_MASSES = 8
#: Length (s) of the opening the order check's fits run on (``auto``: the n modes seen,
#: then without the weakest, one at a time while the BIC falls).
CONFIRM_SECONDS = 5.0


def names(n: int) -> list[str]:
    """Parameter names in fit order: ``J[1]…J[n]``, ``k[1]…k[n]``, ``B[1]…B[n]``."""
    return [f"{p}[{i}]" for p in ("J", "k", "B") for i in range(1, n + 1)]


def split(p: np.ndarray, n: int) -> tuple[list[float], list[float], list[float]]:
    """``(J, k, B)`` from the stacked parameter vector (kg·m², N·m/rad, N·m·s/rad)."""
    return list(p[:n]), list(p[n : 2 * n]), list(p[2 * n : 3 * n])


def _lower(n: int) -> Callable[[np.ndarray], np.ndarray]:
    """Bounds: inertias and stiffnesses above a thousandth of their start, dampings ≥ 0."""
    return lambda p: np.concatenate([1e-3 * p[: 2 * n], np.zeros(n)])


def fit_chain(record: MotorRecord, n: int, modes: Modes | None = None) -> ParameterFit:
    """Fit every J_i, k_i, B_i of an n-mass chain to ``record`` by output error, from
    the modal start (steps in the module doc).

    Parameters
    ----------
    record : MotorRecord
        The motor angle (rad) and τ̂_reac (N·m).
    n : int
        Number of load masses (a count), ≥ 1.
    modes : Modes, optional
        The modes to start from (default: :func:`record_modes` of the record).

    Returns
    -------
    ParameterFit
        ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]`` (N·m·s/rad) with standard
        errors; ``extra`` holds the modes the start came from (``modes_rad_s``,
        ``damping_ratios``) and the subspace singular values (``singular_values``).

    Raises
    ------
    IdentificationError
        For n < 1, or a record that shows no motion, no reaction torque or fewer than n
        modes.
    """
    if n < 1:
        raise IdentificationError(f"the chain needs at least one load mass, got {n}")
    check_excited(record)
    if modes is None:
        modes = record_modes(record, n)
    J0, k0 = modes.chain()
    zeta = float(np.mean(np.clip(modes.damping, 1e-4, 0.05)))
    B0 = 2.0 * zeta * k0 / modes.frequency[0]
    note = (
        "chain with the record's clamped modes "
        + ", ".join(f"{w:.4g}" for w in modes.frequency)
        + " rad/s (subspace identification) and their residues; then every parameter free"
    )
    start = np.concatenate([J0, k0, B0])
    result = continued_fit(record, names(n), start, lambda p: split(p, n), note, _lower(n))
    result.extra.update(
        modes_rad_s=[float(w) for w in modes.frequency],
        damping_ratios=[float(z) for z in modes.damping],
        singular_values=[float(s) for s in modes.singular_values[: 2 * n + 4]],
    )
    return result


def information_criterion(
    result: ParameterFit, record: MotorRecord, lag: int | None = None
) -> float:
    """BIC (dimensionless) of ``result`` on ``record`` over N / lag effective samples (lag:
    the Newey–West bandwidth, samples; ``result``'s unless given: compare at one lag)."""
    count = len(record.theta_m)
    effective = max(count / max(lag or result.lag, 1), 2.0)
    rss = result.rms_residual**2
    return effective * math.log(max(rss, 1e-300)) + len(result.values) * math.log(effective)


@dataclass
class ChainChoice:
    """The chosen chain and the evidence for its number of masses: the result of
    :func:`identify_whole_chain`.

    Attributes
    ----------
    n : int
        Load masses chosen (a count).
    fit : ParameterFit
        The fit with n masses.
    criterion : dict of int to float
        BIC per n tried (dimensionless; lower is better).
    rms_residual : dict of int to float
        Rms residual per n tried (N·m).
    refused : dict of int to str
        Per n the record could not support, why.
    seen : int or None
        The modes the record shows that count (a count; the stabilization diagram's,
        :func:`~arcosim.identification.modes.detection.detect_modes`).
    singular_values : ndarray or None
        The subspace step's singular values, relative to the first (dimensionless).
    leaner : ParameterFit or None
        The fit without the weakly determined modes n keeps (those in its ``extra``,
        :func:`~arcosim.identification.fit.weak_modes.without_weak_modes`).
    """

    n: int
    fit: ParameterFit
    criterion: dict[int, float]
    rms_residual: dict[int, float]
    refused: dict[int, str] = field(default_factory=dict)
    seen: int | None = None
    singular_values: np.ndarray | None = None
    leaner: ParameterFit | None = None

    @property
    def chain(self) -> Chain | None:
        """The chosen chain: every J_i, k_i, B_i and, when fitted, the motor friction,
        with their standard errors (none for a value at its bound); None for a rigid
        drive (n = 0)."""
        if self.n == 0:
            return None
        bounds = self.fit.extra.get("bounds", {})
        std = {k: v for k, v in self.fit.std_dict().items() if k not in bounds}
        return Chain.from_parameters(self.fit.as_dict(), std, self.n)


@single_threaded
def identify_whole_chain(
    record: MotorRecord,
    masses: int | str,
    encoder: EncoderRecord | None = None,
    choose_load: bool = True,
    *,
    reading: tuple[MotorRecord, EncoderRecord | None, DetectedModes] | None = None,
    spectrum: ExcitationSpectrum | None = None,
) -> ChainChoice:
    """Fit an n-mass chain (``masses`` an int) or choose n (``masses="auto"``).

    The record's modes come from a stabilization diagram of the subspace step
    (:func:`~arcosim.identification.modes.detection.detect_modes`): a mode counts when it
    comes back at several model orders and its residue stands above its standard error;
    ``auto`` takes n = their number, confirmed by the information criterion one weak
    mode at a time. An n the record cannot support is refused, naming the modes it
    shows, the weak ones and what would fix the record (:func:`arcosim.identify_drive`).

    With ``encoder`` (the same log's current and encoder counts) the chain is fitted by
    the prediction-error fit from the current to the encoder
    (:mod:`arcosim.identification.fit.encoder_fit`: with the motor's friction and a load
    torque when the record asks for them) straight from the modal start; without it,
    by the output-error fit to τ̂_reac.

    Parameters
    ----------
    record : MotorRecord
        The log's reaction-torque record (:func:`~arcosim.motor_record`).
    masses : int or "auto"
        Number of load masses (a count; 0: a rigid drive, fitted as ``J_load`` =
        J_total − J_m with the friction), or ``"auto"`` (0 included).
    encoder : EncoderRecord, optional
        The same log's current → encoder record (:func:`~arcosim.encoder_record`).
    choose_load : bool
        With ``encoder.load`` none: the load torque (none, constant, slow) chosen by the
        rule and the chain refitted with it; False: none kept, the rule only warns.
    reading : tuple of (MotorRecord, EncoderRecord or None, DetectedModes), optional
        ``first_reading(record, masses, encoder)`` with these very arguments (not
        checked), when the caller has it (``identify_drive`` passes ``check``'s).
    spectrum : ExcitationSpectrum, optional
        The log's excitation (``check``'s): when it is periodic over whole periods,
        ``auto`` takes the smallest chain adequate to the response at its lines
        (:mod:`~arcosim.identification.fit.periodic_misfit`) instead of the rule.

    Returns
    -------
    ChainChoice
        ``n``, the fit (``J[i]`` kg·m², ``k[i]`` N·m/rad, ``B[i]`` N·m·s/rad with
        standard errors, and the evidence), the criterion per n tried, refusals.

    Raises
    ------
    IdentificationError
        When ``masses`` is neither a whole number ≥ 0 nor ``"auto"``, or the record
        cannot support the chain asked for (fewer modes than asked; n = 0 needs encoder).

    Examples
    --------
    >>> run = arcosim.run_scenario(arcosim.SCENARIOS["identification"], 2,
    ...                            plant={"J[1]": 4e-4, "J[2]": 8e-4, "k[1]": 0.3, "k[2]": 0.2})
    >>> i_a, omega, theta = (run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m"))
    >>> motor = arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406, D_m=2e-5, f_c=2e-3)
    >>> record = arcosim.motor_record(run.time, i_a, omega, theta, motor, 100.0)
    >>> encoder = arcosim.encoder_record(run.time, i_a, theta, motor, 2000)
    >>> choice = arcosim.identify_whole_chain(record, "auto", encoder)
    >>> choice.n, round(choice.fit.as_dict()["k[1]"], 2)
    (2, 0.3)
    """
    auto = masses == "auto"
    n_asked = None if auto else masses_asked(masses)
    largest = max(MAX_AUTO_MASSES, n_asked or 0)
    unknown = encoder is not None and not encoder.friction_given
    raw = record
    if reading is None:
        reading = first_reading(record, masses, encoder)
    record, encoder, detected = reading
    response = periodic_response(encoder, spectrum) if encoder is not None else None
    n, result, criterion = _choose_and_fit(record, encoder, detected, auto, n_asked, response)
    if unknown:
        # re-read the modes with the fit's friction (far better than the start's)
        D_m, f_c = result.extra["D_m"], result.extra["f_c"]
        cleaned = without_friction(raw, encoder, D_m, f_c)
        again = detect_modes(cleaned, largest)
        if not _same_modes(again, detected):
            record = cleaned
            encoder = with_friction(encoder, D_m, f_c)
            detected = again
            n, result, criterion = _choose_and_fit(
                record, encoder, detected, auto, n_asked, response
            )
    periodic = criterion.pop("periodic", None)
    selection: dict = {"rule": RULE, "masses": {str(m): v for m, v in criterion.items()}}
    if periodic is not None:
        selection["periodic"] = periodic
    if encoder is not None:
        before = result
        result, selection["friction"] = friction_form(record, encoder, n, result, CONFIRM_SECONDS)
        result = kept(response, encoder, n, before, result, "the friction form chosen")
        before, unloaded = result, encoder
        result, encoder, selection["load"] = load_choice(
            record, encoder, n, result, CONFIRM_SECONDS, choose_load
        )
        if kept(response, encoder, n, before, result, "the load torque chosen") is before:
            result, encoder = before, unloaded
        result = with_sign_shift(encoder, n, result)
    result.extra["selection"] = selection
    result.extra.update(
        detected_modes_rad_s=[float(w) for w in detected.frequency],
        residue_t_values=[float(t) for t in detected.t_value],
        weak_modes=[{"rad_s": w, "t": t} for w, t in detected.weak],
        assumptions=assumptions(encoder),
        warnings=[
            f"the mode at {w:.1f} rad/s is weakly determined (residue t = {t:.0f} < "
            f"{T_CONFIRM:g}); the information criterion chose {n} masses"
            for w, t in zip(detected.frequency, detected.t_value)
            if t < T_CONFIRM
        ]
        + result.extra.get("structure_warnings", []),
    )
    refused = {n + 1: missing_modes(detected, n + 1, record)} if detected.weak else {}
    leaner = without_weak_modes(detected, n, encoder and partial(_fit_m, record, encoder, detected))
    return ChainChoice(
        n,
        result,
        criterion,
        {n: result.rms_residual},
        refused,
        detected.n,
        detected.singular_values,
        leaner,
    )


def first_reading(
    record: MotorRecord, masses: int | str, encoder: EncoderRecord | None = None
) -> tuple[MotorRecord, EncoderRecord | None, DetectedModes]:
    """The modes as the fit first reads them (a friction not given estimated from them and
    taken out of τ̂ first) and the records then fitted, which ``check`` judges and the fit
    starts from; raises IdentificationError for a bad ``masses``, no motion or too short."""
    auto = masses == "auto"
    n_asked = None if auto else masses_asked(masses)
    check_excited(record)
    largest = max(MAX_AUTO_MASSES, n_asked or 0)
    detected = detect_modes(record, largest)
    if encoder is not None and not encoder.friction_given and detected.n and n_asked != 0:
        # τ̂ was computed without friction: take it out, read the modes again
        modes = _strongest(detected, detected.n if auto else min(n_asked, detected.n))
        record, D_m, f_c, detected = friction_cleaned(record, encoder, modes, largest)
        encoder = with_friction(encoder, D_m, f_c)
    return record, encoder, detected


def _prediction_error(
    record: MotorRecord | None, encoder: EncoderRecord, modes: Modes
) -> ParameterFit:
    """The prediction-error fit of the chain with ``modes`` (:func:`refine`) from the
    modal start (:meth:`Modes.chain`, dampers from the modal damping)."""
    n = len(modes.frequency)
    J0, k0 = modes.chain()
    B0 = modal_damping(J0, k0, modes)
    start = np.concatenate([J0, k0, B0])
    note = (
        "chain with the record's clamped modes "
        + ", ".join(f"{w:.4g}" for w in modes.frequency)
        + " rad/s (subspace stabilization diagram) and their residues"
    )
    first = ParameterFit(names(n), start, np.zeros_like(start), start, note, 0.0, 0.0, 1, 0)
    first.extra.update(_mode_evidence(modes))
    result = refine(encoder, record, first, n)
    if record is not None:
        result.rms_data = float(np.sqrt(np.mean(record.tau_hat**2)))
    return result


def _fit_m(record: MotorRecord, encoder: EncoderRecord, detected: DetectedModes, m: int):
    """The prediction-error fit of the m strongest modes (m = 0: the rigid drive)."""
    if m == 0:
        return rigid_fit(encoder, record)
    return _prediction_error(record, encoder, _strongest(detected, m))


def _same_modes(a: DetectedModes, b: DetectedModes, tolerance: float = 5e-3) -> bool:
    """Two mode readings agree: as many modes, each within ``tolerance`` (relative)."""
    return a.n == b.n and bool(np.all(abs(a.frequency - b.frequency) <= tolerance * b.frequency))


def _choose_and_fit(
    record: MotorRecord,
    encoder: EncoderRecord | None,
    detected: DetectedModes,
    auto: bool,
    n_asked: int | None,
    response: PeriodicResponse | None = None,
) -> tuple[int, ParameterFit, dict]:
    """n (read, or asked and checked), the fit, and the criterion per n tried.

    ``auto`` starts from the modes the record shows (all of them, weak ones too) and
    drops the weakest one at a time while the information criterion falls, down to the
    rigid drive (n = 0). An n asked for is fitted when the record shows that many
    modes (weak ones with a warning, the caller's) and refused when it does not."""
    n = detected.n if auto else n_asked
    why = refusal(detected, "auto" if auto else n_asked, record, encoder is not None)
    if why:
        raise IdentificationError(why)
    criterion: dict[int, float] = {}
    if n == 0:
        return 0, rigid_fit(encoder, record), criterion
    if encoder is None:
        result = fit_chain(record, n, _strongest(detected, n))
        criterion[n] = information_criterion(result, record)
        return n, result, criterion
    if auto:
        n, criterion = _auto_masses(encoder, detected, response)
        if n == 0:
            return 0, rigid_fit(encoder, record), criterion
    return n, _prediction_error(record, encoder, _strongest(detected, n)), criterion


def _auto_masses(
    encoder: EncoderRecord, detected: DetectedModes, response: PeriodicResponse | None = None
) -> tuple[int, dict]:
    """n by the smallest adequate chain for a periodic record (``response``:
    :func:`_periodic_masses`), else by the rule
    (:mod:`~arcosim.identification.fit.structure_choice`) on the record's first
    :data:`CONFIRM_SECONDS`: from the modes seen, the weakest dropped one at a time as
    long as the rule prefers the chain without it, down to the rigid drive (a pole of
    the noise or of an excitation line adds nothing to the prediction of the encoder);
    where the descent stops above 0, the rigid drive against the chain it stopped at
    (two spurious modes can fit the noise better than one). Returns n and, per n tried,
    its scores."""
    short = encoder_opening(encoder, CONFIRM_SECONDS)

    def candidate(m: int) -> Candidate | None:
        try:
            if m == 0:
                trial = rigid_fit(short, None)
            else:
                trial = _prediction_error(None, short, _strongest(detected, m))
        except (IdentificationError, ValueError, np.linalg.LinAlgError):
            return None  # no chain of m masses fits the opening
        return candidate_of(f"n={m}", trial)

    if response is not None:
        return _periodic_masses(short, detected, response)
    n = detected.n
    tried = {n: candidate(n)}

    def prefers(m: int, over: int) -> bool:  # the rule takes the chain of m masses
        if m not in tried:
            tried[m] = candidate(m)
        pair = [c for c in (tried[m], tried[over]) if c is not None]
        return bool(pair) and choose(pair).name == f"n={m}"

    while n >= 1 and prefers(n - 1, n):
        n -= 1
    if n >= 1 and prefers(0, n):  # a spurious chain between may stop the descent early
        n = 0
    table = scores([c for c in tried.values() if c is not None])
    return n, {m: table[f"n={m}"]["bic"] for m, c in tried.items() if c is not None}


def _periodic_masses(
    short: EncoderRecord, detected: DetectedModes, response: PeriodicResponse
) -> tuple[int, dict]:
    """n for a periodic record: every chain from the modes seen down to the rigid drive
    fitted on the opening ``short`` (the m strongest modes), each judged by its misfit
    at the lines against the response's noise, and the smallest adequate taken
    (:func:`~arcosim.identification.fit.periodic_misfit.smallest_adequate`). Returns n
    and, per n tried, its misfit over its expectation, with ``"periodic"``: the lines,
    the level reached (1: within the noise) and each n's ratio."""
    found = {}
    for m in range(detected.n, -1, -1):
        try:
            trial = _fit_m(None, short, detected, m)
        except (IdentificationError, ValueError, np.linalg.LinAlgError):
            continue  # no chain of m masses fits the opening
        drive = unpack(np.asarray(trial.values, dtype=float), m, short)
        found[m] = misfit(response, model_response(short, drive, response.w))
    if not found:
        raise IdentificationError(f"no chain of 0 … {detected.n} masses fits the record")
    n, level = smallest_adequate(found)
    table: dict = {m: found[m].ratio for m in found}
    table["periodic"] = {
        "lines": len(response.w),
        "periods": response.periods,
        "misfit_over_noise": {str(m): found[m].ratio for m in found},
        "level": level,
        "chosen": n,
    }
    return n, table


def kept(
    response: PeriodicResponse | None,
    encoder: EncoderRecord,
    n: int,
    before: ParameterFit,
    after: ParameterFit,
    step: str,
) -> ParameterFit:
    """``after`` (a step of the fit after the chain's choice: the friction form, the
    load torque), unless the record is periodic (``response``) and ``after`` misfits its
    response beyond the level ``before`` reached (its misfit over the noise, at least
    1): then ``before``, with a warning naming ``step``. The steps' rules weigh the time
    domain, where what no line carries counts (a slow load, a drift): on the motor bench
    the slow load the rule took moved the chain to one that misfits the lines 67 × more
    (J_1 −99.6 %)."""
    if response is None or after is before:
        return after
    a, b = (
        misfit(response, model_response(encoder, chain_drive(f.as_dict(), n, encoder), response.w))
        for f in (before, after)
    )
    if b.cost <= max(a.ratio, 1.0) * b.threshold:
        return after
    before.extra.setdefault("structure_warnings", []).append(
        f"{step} left out: it misfits the response at the periodic excitation's lines "
        f"{b.ratio:.3g} × its noise, the fit without it {a.ratio:.3g} ×"
    )
    return before


def _strongest(detected: DetectedModes, n: int) -> Modes:
    """The n modes with the largest residue t values, by frequency."""
    if detected.n == n:
        return detected.modes()
    keep = np.sort(np.argsort(-detected.t_value)[:n])
    return Modes(
        detected.frequency[keep],
        detected.damping[keep],
        detected.residue[keep],
        detected.singular_values,
        detected.band,
    )


def _mode_evidence(modes: Modes) -> dict:
    return {
        "modes_rad_s": [float(w) for w in modes.frequency],
        "damping_ratios": [float(z) for z in modes.damping],
        "singular_values": [float(x) for x in modes.singular_values[:20]],
    }
