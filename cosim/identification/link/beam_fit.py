"""Identify a flexible link from the hub alone: EI, ρA, its modes and damping (offline).

The link is the modal model of :mod:`arcosim.identification.link.beam_model`: given its
length L, tip mass m_tip (and tip inertia J_tip, hub radius r, else 0), the bending
stiffness EI and mass per length ρA fix every clamped mode and its hub participation.
Written as masses on their own springs to the hub (:meth:`ModalModel.star`), the link
is a drive model of :mod:`arcosim.identification.fit.kalman` (``Drive(star=True)``), so
the fit is the chain's prediction-error fit from the motor current to the encoder
(:mod:`arcosim.identification.fit.encoder_fit`: the same Kalman predictor, friction sign
passes and Newey–West standard errors), on these parameters:

* ``EI`` (N·m²), ``rhoA`` (kg/m; held when the user gives it, from the link's weighed
  mass), the damping ratio ``zeta[i]`` of each mode below the record's band, then the
  motor's ``D_m``, ``f_c`` when not given (:func:`fit_link`);
* without the geometry, each mode's frequency ``omega[i]`` (rad/s), ``zeta[i]`` and
  hub participation ``b[i]``, and the link's inertia outside the modes ``J_rest``
  (:func:`fit_modes`).

Start: the record's first clamped mode (the subspace stabilization diagram,
:func:`arcosim.identification.modes.detection.detect_modes`) fixes EI/ρA for each ρA
(the modes scale as √EI), and a scan of the innovations over ρA on the record's
opening picks ρA; with ρA given, EI follows from the first mode directly, and one
clamped mode in the band suffices (without it, a record that shows one is refused: one
mode cannot tell EI from ρA). The fit then runs on openings twice as long each time, up
to the whole record (a lightly damped mode's cost has local minima spaced π/T).

:func:`arcosim.identification.link.beam_motion.tip_motion` runs the Kalman smoother of the
fitted model over the record: the tip's deflection and the link's reaction torque.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy import optimize

from arcosim.identification.errors import IdentificationError
from arcosim.identification.fit.encoder_fit import innovation_criterion, stuck_aware_sign
from arcosim.identification.fit.kalman import Drive, Kalman, innovations
from arcosim.identification.fit.newey_west import decorrelation_lag, newey_west_covariance
from arcosim.identification.fit.output_error import SCAN_SECONDS, ParameterFit
from arcosim.identification.fit.refusal import T_CONFIRM
from arcosim.identification.link.beam_model import Link, ModalModel, modal_model, modal_report
from arcosim.identification.modes.detection import DetectedModes, detect_modes
from arcosim.identification.records.record import EncoderRecord, MotorRecord, encoder_opening
from arcosim.identification.threads import single_threaded

#: Damping ratio every mode starts from (dimensionless).
START_ZETA = 0.01
#: ρA values the start scans (a count), log-spaced over :data:`SCAN_DECADES`.
SCAN_COUNT = 41
#: Decades of ρA the start scans, centred where the beam's inertia equals J_m.
SCAN_DECADES = 4.0
#: A fitted mode whose hub participation is below this many standard errors is warned of.
T_WEAK = 10.0
#: Largest modal damping ratio the fit allows (dimensionless): a mode the record barely
#: excites may otherwise run off to an overdamped pole.
MAX_ZETA = 0.5
#: Modes above the fitted ones that a fit with ρA given keeps flexible (a count): EI
#: and ρA fix them, the last fitted damping ratio damps them.
ABOVE_BAND = 1
#: Iterations of each least-squares stage.
MAX_ITERATIONS = 40
#: Modes beyond the fitted ones whose quasi-static tip deflection the tip estimate keeps.
STATIC_MODES = 8


@dataclass(frozen=True)
class Geometry:
    """What the user knows of the link: its length, tip mass, tip inertia, hub radius.

    Attributes
    ----------
    L : float
        Length (m), > 0.
    m_tip : float
        Tip mass (kg), ≥ 0.
    J_tip : float
        Tip inertia (kg·m²), ≥ 0.
    r_hub : float
        Clamp radius (m), ≥ 0.

    Examples
    --------
    >>> Geometry(L=0.3, m_tip=0.005).link(EI=0.04, rhoA=0.03)  # N·m², kg/m
    Link(EI=0.04, rhoA=0.03, L=0.3, m_tip=0.005, J_tip=0.0, r_hub=0.0)
    """

    L: float
    m_tip: float = 0.0
    J_tip: float = 0.0
    r_hub: float = 0.0

    def link(self, EI: float, rhoA: float) -> Link:
        """The link of this geometry with ``EI`` (N·m²) and ``rhoA`` (kg/m)."""
        return Link(EI, rhoA, self.L, self.m_tip, self.J_tip, self.r_hub)


def drive_of(model: ModalModel, D_m: float, f_c: float) -> Drive:
    """The Kalman drive model of a link's modes (masses on springs to the hub, the rest
    of the link rigid on it) with the motor friction ``D_m`` (N·m·s/rad), ``f_c`` (N·m)."""
    J, k, B = model.star()
    return Drive(J, k, B, float(D_m), float(f_c), star=True, J_rigid=max(model.J_rest, 0.0))


@dataclass(frozen=True)
class _Problem:
    """A parameterization of the link: names, ``model(p)`` and the bounds."""

    names: list[str]
    model: Callable[[np.ndarray], ModalModel]
    lower: np.ndarray
    upper: np.ndarray


@single_threaded
def fit_link(
    record: EncoderRecord,
    motor: MotorRecord,
    geometry: Geometry,
    modes: int | None = None,
    rhoA: float | None = None,
) -> ParameterFit:
    """Fit EI, ρA (unless given), the modal damping and (when not given) the motor
    friction.

    Parameters
    ----------
    record : EncoderRecord
        The current in (N·m), the encoder out (rad), the motor's J_m and friction
        (:func:`~arcosim.identification.records.record.encoder_record`).
    motor : MotorRecord
        The same log's τ̂_reac record (:func:`~arcosim.identification.records.record.motor_record`),
        for the start's first clamped mode.
    geometry : Geometry
        L, m_tip, J_tip, r_hub.
    modes : int, optional
        Modes in the model (a count; default: those below the record's band, at least
        one); the rest of the link is rigid on the hub.
    rhoA : float, optional
        The link's mass per length (kg/m, its weighed mass over L), held: then EI
        follows from the record's first clamped mode alone (the modes scale as
        √(EI/ρA)), and one mode in the band suffices; the model keeps
        :data:`ABOVE_BAND` mode(s) above the band flexible (EI and ρA fix them). Without
        it the record must show a second clamped mode, or the fit is refused.

    Returns
    -------
    ParameterFit
        ``EI`` (N·m²), ``rhoA`` (kg/m; not when given), ``zeta[i]``, then ``D_m``,
        ``f_c`` with standard errors; ``extra`` holds the modal model
        (``modes_rad_s``, ``participation``, ``tip_shape_m``, ``J_link``), the
        equivalent chain, the start, the evidence, ``rhoA_given`` (kg/m, or None) and
        ``modes_above_band`` (a count).

    Raises
    ------
    IdentificationError
        When the record shows no clamped mode, only one without ``rhoA``, or the fit
        diverges; or ``rhoA`` is not a number > 0.

    Examples
    --------
    A fit of a simulated link from its hub's record is the example of
    :func:`arcosim.experiments.flexible_link.score_link`. A mass per length that is not
    > 0 is refused before the record is read:

    >>> fit_link(None, None, Geometry(0.4), rhoA=0.0)
    Traceback (most recent call last):
    ...
    arcosim.identification.errors.IdentificationError: the link's mass per length ...
    """
    if rhoA is not None and not (np.isfinite(rhoA) and rhoA > 0):
        raise IdentificationError(f"the link's mass per length rhoA must be > 0 kg/m, got {rhoA}")
    detected = detect_modes(motor, 8)
    first = _first_mode(detected, motor)
    if rhoA is None:
        if not np.any(detected.frequency > 2.0 * first):  # a second mode, weak or not
            raise IdentificationError(one_mode_only(detected, first))
        EI0, rhoA0, count, note = _start(record, detected, geometry, first)
    else:
        EI0, rhoA0, count, note = _given_start(detected, geometry, first, rhoA)
    count = count if modes is None else modes
    held = rhoA is not None
    skip = 1 if held else 2

    above = ABOVE_BAND if held else 0

    def model(p: np.ndarray) -> ModalModel:
        link = geometry.link(p[0], rhoA0 if held else p[1])
        zeta = p[skip : skip + count]
        zeta = np.concatenate([zeta, np.full(above, zeta[-1])])
        return modal_model(link, count + above).with_damping(zeta)

    zetas = [f"zeta[{i}]" for i in range(1, count + 1)]
    names = ["EI", *zetas] if held else ["EI", "rhoA", *zetas]
    start = [EI0, *([] if held else [rhoA0]), *([START_ZETA] * count)]
    lower = [1e-3 * EI0, *([] if held else [1e-3 * rhoA0]), *([0.0] * count)]
    upper = [np.inf, *([] if held else [np.inf]), *([MAX_ZETA] * count)]
    problem = _Problem(names, model, np.array(lower), np.array(upper))
    result = _fit(record, problem, np.array(start), note)
    fitted = model(result.values)
    result.extra.update(
        modal_report(fitted),
        detected_modes_rad_s=[float(w) for w in detected.frequency],
        residue_t_values=[float(t) for t in detected.t_value],
        J_link=fitted.J_link,
        rhoA_given=float(rhoA) if held else None,
        modes_above_band=above,
    )
    return result


@single_threaded
def fit_modes(record: EncoderRecord, motor: MotorRecord, modes: int | None = None) -> ParameterFit:
    """A link's modal model when its geometry is unknown: each mode's frequency, damping
    and hub participation, and the link's inertia outside the modes.

    Parameters
    ----------
    record : EncoderRecord
        The current in (N·m), the encoder out (rad).
    motor : MotorRecord
        The same log's τ̂_reac record, for the start (the modes it shows, their
        residues r_i = b_i² ω_i⁴).
    modes : int, optional
        Modes fitted (a count; default: every mode the record shows that counts).

    Returns
    -------
    ParameterFit
        ``omega[i]`` (rad/s), ``zeta[i]``, ``b[i]`` (√kg·m), ``J_rest`` (kg·m²), then
        ``D_m``, ``f_c``, with standard errors; ``extra`` as :func:`fit_link`'s.

    Raises
    ------
    IdentificationError
        When the record shows fewer modes than asked, or none.
    """
    detected = detect_modes(motor, 8)
    _first_mode(detected, motor)
    count = detected.n if modes is None else modes
    if detected.n < count:
        raise IdentificationError(missing_link_modes(detected, count))
    w0 = detected.frequency[:count]
    b0 = np.sqrt(detected.residue[:count]) / w0**2
    zeta0 = np.clip(detected.damping[:count], 1e-3, 0.2)
    rest0 = 0.1 * float(np.sum(b0**2))
    note = "the record's modes " + ", ".join(f"{w:.4g}" for w in w0) + " rad/s and residues"

    def model(p: np.ndarray) -> ModalModel:
        w, zeta, b = p[:count], p[count : 2 * count], p[2 * count : 3 * count]
        J_link = float(np.sum(b**2)) + p[3 * count]
        return ModalModel(w, b, np.zeros(count), zeta, J_link, 1.0)

    names = [f"{p}[{i}]" for p in ("omega", "zeta", "b") for i in range(1, count + 1)]
    names.append("J_rest")
    start = np.concatenate([w0, zeta0, b0, [rest0]])
    lower = np.concatenate([0.5 * w0, np.zeros(count), 1e-3 * b0, [0.0]])
    upper = np.concatenate([2.0 * w0, np.full(count, MAX_ZETA), np.full(count + 1, np.inf)])
    result = _fit(record, _Problem(names, model, lower, upper), start, note)
    result.extra.update(modal_report(model(result.values)))
    result.extra.pop("tip_shape_m")
    b, std = result.values[2 * count : 3 * count], result.std[2 * count : 3 * count]
    result.extra["warnings"] = [
        f"the mode at {w:.1f} rad/s is weakly determined (hub participation {x:.3g} ± "
        f"{e:.2g}): it may be no mode of the link; fit fewer (modes=…)"
        for w, x, e in zip(result.values[:count], b, std)
        if x < T_WEAK * e
    ]
    return result


def _start(
    record: EncoderRecord, detected: DetectedModes, geometry: Geometry, first: float
) -> tuple[float, float, int, str]:
    """The fit's start: EI (N·m²) and ρA (kg/m) with the record's first clamped mode
    ``first`` (rad/s), the modes below the band (a count) and a note for the report.
    With a tip, ρA from the record's ratio of the second mode to the first; without
    one (the ratio is the bare beam's), from a scan of the innovations over ρA."""

    def stiffness(rhoA: float) -> float:
        """EI (N·m²) that puts the first clamped mode on the record's: the modes scale
        as √EI at a fixed ρA."""
        return (first / modal_model(geometry.link(1.0, rhoA), 1).frequency[0]) ** 2

    def at(rhoA: float, count: int) -> ModalModel:
        return modal_model(geometry.link(stiffness(rhoA), rhoA), count)

    centre = record.J_m * 3.0 / ((geometry.r_hub + geometry.L) ** 3 - geometry.r_hub**3)
    grid = centre * np.logspace(-SCAN_DECADES / 2, SCAN_DECADES / 2, SCAN_COUNT)
    second = _second_mode(detected, first)
    if second is not None and (geometry.m_tip > 0 or geometry.J_tip > 0):
        # the tip's share of the link's mass sets ω₂/ω₁: ρA from the record's ratio
        rhoA0 = _ratio_match(lambda x: at(x, 2).frequency, grid, second / first)
        how = f"from the ratio of the second mode ({second:.4g} rad/s) to the first"
    else:
        short = encoder_opening(record, SCAN_SECONDS)
        rhoA0 = _scanned(short, at, grid, detected.band)
        how = f"by a scan of the innovations on the first {short.duration:g} s"
    modes = max(1, int(np.sum(at(rhoA0, 8).frequency < detected.band)))
    EI0 = stiffness(rhoA0)
    note = (
        f"first clamped mode {first:.4g} rad/s (subspace stabilization diagram), ρA {how}: "
        f"EI = {EI0:.4g} N.m², ρA = {rhoA0:.4g} kg/m"
    )
    return EI0, rhoA0, modes, note


def _given_start(
    detected: DetectedModes, geometry: Geometry, first: float, rhoA: float
) -> tuple[float, float, int, str]:
    """The fit's start with ρA given (kg/m): EI (N·m²) that puts the first clamped mode
    on the record's ``first`` (rad/s; the modes scale as √EI at a fixed ρA), ρA, the
    modes below the band (a count, at least one) and a note for the report."""
    EI0 = (first / modal_model(geometry.link(1.0, rhoA), 1).frequency[0]) ** 2
    modes = max(1, int(np.sum(modal_model(geometry.link(EI0, rhoA), 8).frequency < detected.band)))
    note = (
        f"first clamped mode {first:.4g} rad/s (subspace stabilization diagram) with ρA "
        f"given ({rhoA:.4g} kg/m): EI = {EI0:.4g} N.m²"
    )
    return EI0, rhoA, modes, note


def _scanned(
    short: EncoderRecord,
    at: Callable[[float, int], ModalModel],
    grid: np.ndarray,
    band: float,
) -> float:
    """The ρA (kg/m) whose link (``at(ρA, modes)``, every mode below ``band`` rad/s)
    predicts the encoder of ``short`` best: the best of ``grid``, then refined between
    its neighbours."""
    in_band = [max(1, int(np.sum(at(float(x), 8).frequency < band))) for x in grid]
    costs = [_cost(short, at(float(x), n).with_damping(START_ZETA)) for x, n in zip(grid, in_band)]
    best = int(np.argmin(costs))
    logs = np.log(grid)
    found = optimize.minimize_scalar(
        lambda x: _cost(short, at(float(np.exp(x)), in_band[best]).with_damping(START_ZETA)),
        bounds=(logs[max(best - 1, 0)], logs[min(best + 1, len(grid) - 1)]),
        method="bounded",
        options={"xatol": 1e-3},
    )
    return float(np.exp(found.x))


def _seen(detected: DetectedModes) -> str:
    """What the record shows below its band: the modes (rad/s), the weak ones."""
    found = ", ".join(f"{w:.1f}" for w in detected.frequency)
    found = f"modes at {found} rad/s" if found else "no mode that counts"
    text = f"below its band ({detected.band:.0f} rad/s) the record shows {found}"
    if detected.weak:
        weak = ", ".join(f"{w:.1f} rad/s (t = {t:.1f})" for w, t in detected.weak)
        text += f", and too weakly excited to count: {weak}"
    return text


def _excite(detected: DetectedModes) -> str:
    """How to excite a link's modes better (a clause for a refusal)."""
    return (
        "more current per line (fewer lines, or a higher amplitude), lines on both sides "
        "of each mode up to the band, a longer record, a finer encoder; the band is "
        f"min(3·g_dist, 0.3/h) = {detected.band:.0f} rad/s (`arcosim.design_excitation`)"
    )


def missing_link_modes(detected: DetectedModes, count: int | None) -> str:
    """Why the record cannot support a link of ``count`` modes (None: not even one
    clamped mode), and what to do.

    Parameters
    ----------
    detected : DetectedModes
        The modes the record shows (:func:`~arcosim.identification.modes.detection.detect_modes`).
    count : int or None
        The modes asked for (a count), or None when the record shows none that counts.

    Returns
    -------
    str
        The refusal, naming the modes seen (rad/s) and the band (rad/s).

    Examples
    --------
    >>> from arcosim.identification.modes.detection import DetectedModes
    >>> none = np.empty(0)
    >>> detected = DetectedModes(none, none, none, none, [], np.empty(0, int), 150.0, none)
    >>> missing_link_modes(detected, None)[:58]
    'the record shows no clamped mode of the link that counts ('
    """
    if count is None:
        head = "the record shows no clamped mode of the link that counts"
        tail = "excite the link's first clamped mode"
    else:
        head = f"the record shows {detected.n} clamped mode(s) of the link, {count} asked"
        tail = "fit fewer modes (modes=…), or excite each mode asked"
    return f"{head} ({_seen(detected)}): {tail}: {_excite(detected)}"


def one_mode_only(detected: DetectedModes, first: float) -> str:
    """Why EI and ρA cannot both be fitted from a record with one clamped mode
    ``first`` (rad/s), and the two ways out: ρA given, or the second mode excited.

    Parameters
    ----------
    detected : DetectedModes
        The modes the record shows.
    first : float
        The first clamped mode that counts (rad/s).

    Returns
    -------
    str
        The refusal, naming ``--set rhoA``.

    Examples
    --------
    >>> from arcosim.identification.modes.detection import DetectedModes
    >>> one = np.array([15.0])
    >>> detected = DetectedModes(one, one, one, one, [], np.zeros(1, int), 75.0, one)
    >>> "--set rhoA=M/L" in one_mode_only(detected, 15.0)
    True
    """
    return (
        f"the record shows one clamped mode of the link ({first:.1f} rad/s; "
        f"{_seen(detected)}): EI and ρA move it alike (the modes scale as √(EI/ρA)), so "
        "one mode cannot tell them apart. Give the link's mass per length, --set "
        "rhoA=M/L (kg/m: its weighed mass M over its length L; rhoA= in the library), "
        "to fit EI from this mode; or excite the second clamped mode inside the band: "
        + _excite(detected)
    )


def _first_mode(detected: DetectedModes, motor: MotorRecord) -> float:
    """The lowest mode that counts (rad/s), or the refusal naming what is missing."""
    strong = detected.frequency[detected.t_value >= T_CONFIRM]
    if not strong.size:
        raise IdentificationError(missing_link_modes(detected, None))
    return float(strong[0])


def _second_mode(detected: DetectedModes, first: float) -> float | None:
    """The strongest detected mode above 2 × the first (rad/s), or None."""
    above = (detected.frequency > 2.0 * first) & (detected.t_value >= T_CONFIRM)
    if not np.any(above):
        return None
    return float(detected.frequency[above][np.argmax(detected.t_value[above])])


def _ratio_match(
    frequencies: Callable[[float], np.ndarray], grid: np.ndarray, ratio: float
) -> float:
    """The ρA (kg/m) on or between ``grid`` whose ω₂/ω₁ is nearest ``ratio``."""

    def mismatch(log_rhoA: float) -> float:
        w = frequencies(float(np.exp(log_rhoA)))
        return abs(np.log(w[1] / w[0] / ratio))

    logs = np.log(grid)
    best = int(np.argmin([mismatch(x) for x in logs]))
    low, high = logs[max(best - 1, 0)], logs[min(best + 1, len(logs) - 1)]
    found = optimize.minimize_scalar(mismatch, bounds=(low, high), method="bounded")
    return float(np.exp(found.x))


def _cost(record: EncoderRecord, model: ModalModel) -> float:
    with np.errstate(all="ignore"):
        e = innovations(record, drive_of(model, record.D_m, record.f_c))
    cost = float(np.sum(e**2))
    return cost if np.isfinite(cost) else np.inf


def _fit(record: EncoderRecord, problem: _Problem, start: np.ndarray, note: str) -> ParameterFit:
    """The prediction-error fit of ``problem`` on openings of growing length (from
    :data:`SCAN_SECONDS` to the whole record), then the friction sign from the
    smoother's states and a last pass on the whole record."""
    friction = not record.friction_given
    names = list(problem.names) + (["D_m", "f_c"] if friction else [])
    values = np.concatenate([start, [record.D_m, record.f_c]] if friction else [start])
    lower = np.concatenate([problem.lower, [0.0, 0.0]] if friction else [problem.lower])
    upper = np.concatenate([problem.upper, [np.inf, np.inf]] if friction else [problem.upper])
    seconds, runs = SCAN_SECONDS, 0
    while True:
        part = encoder_opening(record, seconds)
        values, residual, jac, more = _least_squares(part, problem, values, (lower, upper))
        runs += more
        if part.duration >= record.duration:
            break
        seconds *= 2.0
    drive = _drive(problem, values, record)
    with np.errstate(all="ignore"):
        states = Kalman.of(record, drive).smoothed(record, drive)
    if np.all(np.isfinite(states)):
        m = len(drive.J) + 1
        record = replace(
            record, friction_sign=stuck_aware_sign(record, drive, states), velocity=states[:, m]
        )
        values, residual, jac, more = _least_squares(record, problem, values, (lower, upper))
        runs += more
    drive = _drive(problem, values, record)
    lag = decorrelation_lag(residual, 1)
    std = np.sqrt(np.clip(np.diag(newey_west_covariance(jac, residual, lag)), 0.0, None))
    extra = {
        "information_criterion": innovation_criterion(residual, len(values)),
        "innovation_variance": float(np.mean(residual**2)),
        "torque_std": record.torque_std,
        "friction": "fitted" if friction else "given",
        "D_m": drive.D_m,
        "f_c": drive.f_c,
    }
    return ParameterFit(
        names=names,
        values=values,
        std=std,
        start=np.concatenate([start, [record.D_m, record.f_c]] if friction else [start]),
        start_note=note + "; then the prediction-error fit from the current to the encoder",
        rms_residual=float(np.sqrt(np.mean(residual**2))),
        rms_data=1.0,
        lag=lag,
        evaluations=runs,
        extra=extra,
    )


def _drive(problem: _Problem, p: np.ndarray, record: EncoderRecord) -> Drive:
    """The drive of parameter vector ``p`` (the problem's, then D_m, f_c when fitted)."""
    D_m, f_c = (p[-2], p[-1]) if not record.friction_given else (record.D_m, record.f_c)
    return drive_of(problem.model(p), D_m, f_c)


def _least_squares(
    record: EncoderRecord,
    problem: _Problem,
    first: np.ndarray,
    bounds: tuple[np.ndarray, np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Least squares on the innovations from ``first``: values, innovations, their
    Jacobian by parameter (N − 1, P), model runs. Each parameter is scaled by its start."""
    scale = np.maximum(np.abs(first), 1e-9)

    def residual(x: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            e = innovations(record, _drive(problem, x * scale, record))
        if not np.all(np.isfinite(e)):
            raise IdentificationError(
                "the flexible link's prediction-error fit diverged (the record does not "
                "determine the link): excite its modes better, or check L, m_tip and "
                "rhoA when given"
            )
        return e

    lower, upper = bounds[0] / scale, bounds[1] / scale
    result = optimize.least_squares(
        residual,
        np.clip(first / scale, lower, upper),
        bounds=(lower, upper),
        x_scale="jac",
        diff_step=1e-6,
        max_nfev=MAX_ITERATIONS,
    )
    runs = int(result.nfev * (len(first) + 1))
    return result.x * scale, result.fun, result.jac / scale, runs


def modal_of(result: ParameterFit, geometry: Geometry, count: int | None = None) -> ModalModel:
    """The fitted link's modal model (of :func:`fit_link`'s result).

    ``count`` modes, the next :data:`STATIC_MODES` in its quasi-static tip deflection; a
    mode beyond the fitted damping ratios takes the last of them. ρA is the fitted or
    the given one.

    Parameters
    ----------
    result : ParameterFit
        :func:`fit_link`'s result: ``EI`` (N·m²), ``rhoA`` (kg/m, or ``rhoA_given`` in
        its ``extra``), ``zeta[i]`` (dimensionless).
    geometry : Geometry
        The link's length, tip and hub.
    count : int, optional
        Modes wanted (a count; default the fit's, with ρA given those above the band
        it kept too).

    Returns
    -------
    ModalModel
        The link's modes.

    Examples
    --------
    >>> fit = ParameterFit(["EI", "rhoA", "zeta[1]"], np.array([1.0, 1.0, 0.01]),
    ...                    np.full(3, 1e-3), np.ones(3), "a guess", 0.1, 1.0, 5, 40)
    >>> model = modal_of(fit, Geometry(L=1.0), 2)
    >>> np.round(np.sqrt(model.frequency), 4).tolist(), model.damping.tolist()
    ([1.8751, 4.6941], [0.01, 0.01])
    """
    values = result.as_dict()
    zeta = [values[n] for n in result.names if n.startswith("zeta[")]
    above = int(result.extra.get("modes_above_band", 0))
    count = len(zeta) + above if count is None else count
    rhoA = values["rhoA"] if "rhoA" in values else float(result.extra["rhoA_given"])
    link = geometry.link(values["EI"], rhoA)
    zeta_all = np.concatenate([zeta, np.full(max(count - len(zeta), 0), zeta[-1])])[:count]
    full = modal_model(link, count + STATIC_MODES).first(count)
    return full.with_damping(zeta_all)
