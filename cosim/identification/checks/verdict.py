"""The verdict on a fit: ``trusted``, or ``untrusted`` with the reasons, each naming what
to check (offline).

The structure choice (:mod:`~arcosim.identification.fit.structure_choice`) picks the
candidate that explains most of the record for its parameters; when the record holds
something outside every candidate (a k_t or J_m error, an unmodelled load, friction the
model does not describe, a mode above the band), it still picks one, and that one soaks
up the misfit. The verdict is therefore taken on the final model from evidence the
choice did not choose by, each a physical bound or a comparison with the record's own
noise:

* **the log's plausibility** (:mod:`~arcosim.identification.checks.plausibility`: the step
  against the motion, the torque balance, the record's length): a log in the wrong
  units fits, confidently and wrongly;
* **the residual against the noise floor** (:mod:`~arcosim.identification.checks.noise_floor`),
  on the final model whatever it is (a modelled load's torque, which lies below the
  excitation, is taken out of the residual and of the floor alike): a model that leaves
  more than :data:`~arcosim.identification.checks.noise_floor.FLOOR_FACTOR` × what the
  encoder's counts and the current's noise explain does not describe the drive;
* **every mode where the record excites it**: a clamped mode of the final chain outside
  the band the current excites (beyond one step of the excitation's own line grid) and
  with no current power above its noise level near it
  (:func:`~arcosim.identification.excitation.band.driven_modes`: a closed loop's current
  drives a wide band however few lines dominate it) is not resolved by the record. The
  fit puts one there when something the chain cannot
  describe is left over: a k_t 10 % high or J_m 10 % low (an inertia on the motor, which
  a stiff extra mass above the band imitates: measured 248 rad/s under 150 rad/s of
  excitation), or a mode above the band;
* **every inertia and stiffness resolved**: a J_i or k_i (or a rigid drive's load
  inertia) within :data:`LEAST_T` standard errors of 0, or with a standard error of 0
  (the record does not move it), is not determined by the record;
* **the excitation against the disturbance observer's band**: an excitation reaching
  above 3·g_dist drives modes that τ̂_reac, and so the fit, cannot see (a motor bench's
  mode at 339 rad/s under the default g_dist of 100 rad/s); it is a doubt when the
  motor's response up there departs from a drive without a mode
  (:func:`~arcosim.identification.checks.above_band.above_band_test`), or when the record
  holds too little excitation above the band to tell.

:func:`judge` collects them; :class:`Verdict` is what ``identify`` reports first, with
exit status 3 when untrusted.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from arcosim.identification.checks.above_band import AboveBand
from arcosim.identification.excitation.band import dob_band, driven_modes
from arcosim.identification.excitation.spectrum import ExcitationSpectrum

#: The verdict's two words.
TRUSTED, UNTRUSTED = "trusted", "untrusted"
#: An inertia or stiffness is resolved by the record when it lies at least this many of
#: its standard errors from 0 (dimensionless; the three-sigma rule: under Gaussian
#: errors a parameter that is 0 reads so by chance 0.3 % of the time).
LEAST_T = 3.0


@dataclass(frozen=True)
class Verdict:
    """Whether a fit is trusted, and why not.

    Attributes
    ----------
    reasons : tuple of str
        Why the fit is not trusted, one sentence each naming what to check (an option
        the user can give); empty when it is trusted.

    Examples
    --------
    >>> from arcosim.identification.checks.verdict import Verdict
    >>> Verdict(()).word, Verdict(("a mode lies above the band",)).word
    ('trusted', 'untrusted')
    """

    reasons: tuple[str, ...] = ()

    @property
    def trusted(self) -> bool:
        """True when no reason stands against the fit."""
        return not self.reasons

    @property
    def word(self) -> str:
        """``"trusted"`` or ``"untrusted"``."""
        return TRUSTED if self.trusted else UNTRUSTED


def resolved_band(spectrum: ExcitationSpectrum | None) -> tuple[float, float] | None:
    """The band of clamped frequencies (rad/s) the record's excitation resolves: its
    lowest and highest frequency widened by one step of its own grid (the ratio of its
    two outermost lines at each end, or the record's resolution 2π/T for a broadband
    excitation); None without excitation.

    Parameters
    ----------
    spectrum : ExcitationSpectrum or None
        What the current's spectrum shows
        (:func:`~arcosim.identification.excitation.spectrum.excitation_spectrum`).

    Returns
    -------
    tuple of float or None
        (lowest, highest) resolved frequency (rad/s).

    Examples
    --------
    >>> lines = np.array([3.0, 6.0, 75.0, 150.0])
    >>> resolved_band(ExcitationSpectrum("lines", lines, np.ones(4), (3.0, 150.0)))
    (1.5, 300.0)
    """
    if spectrum is None or spectrum.kind == "none" or spectrum.highest is None:
        return None
    low, high = float(spectrum.band[0]), float(spectrum.band[1])
    lines = np.sort(np.asarray(spectrum.lines, dtype=float))
    if spectrum.kind != "broadband" and len(lines) >= 2 and lines[0] > 0:
        return float(low / (lines[1] / lines[0])), float(high * (lines[-1] / lines[-2]))
    step = float(spectrum.resolution)
    return float(max(low - step, 0.0)), float(high + step)


def modes_outside(
    modes: Sequence[float],
    spectrum: ExcitationSpectrum | None,
    current: tuple[np.ndarray, float] | None = None,
) -> str | None:
    """A reason when a clamped mode (rad/s) of the final chain lies outside the band the
    excitation resolves (:func:`resolved_band`) and, given the current (A, shape
    ``(N,)``) and its step (s), the current does not drive it either
    (:func:`~arcosim.identification.excitation.band.driven_modes`: its power stands
    above its noise level near the mode); None when every mode is resolved.

    Examples
    --------
    >>> lines = np.geomspace(3.0, 150.0, 40)
    >>> spectrum = ExcitationSpectrum("lines", lines, np.ones(40), (3.0, 150.0))
    >>> modes_outside([11.7, 36.9], spectrum) is None
    True
    >>> modes_outside([11.7, 36.9, 247.6], spectrum)[:42]
    'the chain has a mode at 248 rad/s, outside'
    """
    band = resolved_band(spectrum)
    if band is None:
        return None
    outside = [w for w in modes if not band[0] <= w <= band[1]]
    if outside and current is not None:
        driven = driven_modes(current[0], current[1], np.array(outside))
        outside = [w for w, d in zip(outside, driven) if not d]
    if not outside:
        return None
    listed = ", ".join(f"{w:.3g}" for w in outside)
    return (
        f"the chain has a mode at {listed} rad/s, outside the {spectrum.band[0]:.3g} … "
        f"{spectrum.band[1]:.3g} rad/s the current excites: the record cannot resolve it. "
        "A fit puts one there to take up what the chain cannot describe: check k_t and J_m "
        "(--set k_to=…, --set J_mo=…), or excite the drive where the mode lies; "
        "--masses N fits a given number of masses"
    )


def unresolved(parameters: dict[str, float], std: dict[str, float]) -> str | None:
    """A reason when an inertia or stiffness of the fit is not resolved by the record:
    within :data:`LEAST_T` standard errors of 0, or with a standard error of 0 or none
    (``parameters`` and ``std`` by the observer's names, each in its own unit). The
    dampers are not judged: they are often unresolved on good records, and the report
    gives their bounds.

    Examples
    --------
    >>> unresolved({"J[1]": 4e-4, "k[1]": 0.3}, {"J[1]": 1e-7, "k[1]": 3e-5}) is None
    True
    >>> unresolved({"J[1]": 7e-11, "k[1]": 0.3}, {"J[1]": 2e-6, "k[1]": 3e-5})[:42]
    'the record does not resolve J[1] = 7e-11 ±'

    A rigid drive (n = 0) has no masses to drop: its load inertia at 0 says the motor
    inertia given already holds the drive's whole inertia.

    >>> "--set J_mo" in unresolved({"J_load": 1e-15}, {"J_load": 0.0})
    True
    """
    weak = [
        name
        for name, value in parameters.items()
        if name[:2] in ("J[", "k[") or name == "J_load"
        if not (std.get(name, 0.0) > 0 and abs(value) >= LEAST_T * std[name])
    ]
    if not weak:
        return None
    listed = ", ".join(
        f"{name} = {parameters[name]:.3g} ± {std.get(name, float('nan')):.2g}" for name in weak
    )
    if weak == ["J_load"]:  # n = 0: fewer masses is no remedy
        return (
            f"the record does not resolve {listed} (within {LEAST_T:g} standard errors of "
            "0): the motor inertia given may already be the drive's whole inertia (give the "
            "motor's own, --set J_mo=…), or excite the drive more (a larger current, a "
            "longer record)"
        )
    return (
        f"the record does not resolve {listed} (within {LEAST_T:g} standard errors of 0): "
        "excite the drive more (a larger current, lines around every mode, a longer "
        "record), or fit fewer masses (--masses N)"
    )


def excitation_above_band(
    spectrum: ExcitationSpectrum | None, g_dist: float, test: AboveBand | None = None
) -> str | None:
    """A reason when the excitation reaches above the band the disturbance observer
    passes, 3·g_dist (rad/s; :func:`~arcosim.identification.excitation.band.dob_band`),
    and something may lie there: the modes there are driven, but τ̂_reac holds too
    little of them for the fit to see, and the chain below takes up their response.

    ``test`` (:func:`~arcosim.identification.checks.above_band.above_band_test`) says
    whether the motor's response above the band departs from a drive without a mode
    there: a reason when it does, none when it does not; without it (too little
    excitation above the band to tell) the reach alone is the reason.

    The sample rate's limit of the band, 0.3/h, is not judged here: what lies above it
    is beyond the discrete model's accuracy, not hidden by the user's settings.

    Examples
    --------
    >>> spectrum = ExcitationSpectrum("lines", np.array([69.0, 1571.0]), np.ones(2),
    ...                               (69.0, 1571.0))
    >>> excitation_above_band(spectrum, 1000.0) is None
    True
    >>> excitation_above_band(spectrum, 100.0)[:44]
    'the excitation reaches 1.57e+03 rad/s, above'
    >>> smooth = AboveBand(210.0, 200, 0.3, 103, 300.0)
    >>> excitation_above_band(spectrum, 100.0, smooth) is None
    True
    >>> excitation_above_band(spectrum, 100.0, AboveBand(9e5, 400, 0.0, 203, 300.0))[:41]
    "the motor's response above the 300 rad/s "
    """
    top = dob_band(g_dist)
    if spectrum is None or spectrum.highest is None or spectrum.highest <= top:
        return None
    if test is not None and not test.mode:
        return None
    remedy = (
        "raise the observer's bandwidth "
        f"(--set g_dist={math.ceil(spectrum.highest / 3.0):g} or more) or excite only below it"
    )
    if test is not None:
        return (
            f"the motor's response above the {top:.3g} rad/s the disturbance observer "
            f"passes (3·g_dist) departs from a drive without a mode there ({test.text()}): "
            "a mode lies above the band (or a lag no chain has: the current loop's, a "
            "delay), unseen by the fit, and "
            f"the chain below takes up its response; {remedy}"
        )
    return (
        f"the excitation reaches {spectrum.highest:.3g} rad/s, above the {top:.3g} rad/s "
        "the disturbance observer passes (3·g_dist), with too little response there to "
        "tell whether a mode lies above the band: one would go unseen and the chain below "
        f"take up its response; {remedy}"
    )


def judge(
    doubts: Sequence[str],
    floor: Sequence[str],
    resolution: str | None,
    modes: Sequence[float],
    spectrum: ExcitationSpectrum | None,
    current: tuple[np.ndarray, float] | None = None,
) -> Verdict:
    """The verdict on a final model from the evidence the structure choice did not use.

    Parameters
    ----------
    doubts : sequence of str
        What leaves any fit of the log untrusted, found before the fit
        (:attr:`~arcosim.identification.checks.log_decision.LogDecision.doubts`: the log's
        implausible units or length, :func:`excitation_above_band`).
    floor : sequence of str
        The residual's findings against the noise floor on the final model
        (:func:`~arcosim.identification.checks.noise_floor.floor_warning`,
        :func:`~arcosim.identification.checks.noise_floor.weak_mode_floor_warning`).
    resolution : str or None
        The parameters the record does not resolve (:func:`unresolved`).
    modes : sequence of float
        The final chain's clamped modes (rad/s); empty for a rigid drive.
    spectrum : ExcitationSpectrum or None
        What the current's spectrum shows.
    current : tuple of (ndarray, float), optional
        The current (A, shape ``(N,)``) and its step (s): a mode outside the lines'
        band it drives is resolved (:func:`modes_outside`).

    Returns
    -------
    Verdict
        Untrusted with every reason found, trusted when none.

    Examples
    --------
    >>> judge([], [], None, [], None).word
    'trusted'
    >>> judge(["check the current's scale (--scale i_a=…)"], [], None, [], None).reasons
    ("check the current's scale (--scale i_a=…)",)
    """
    found = [*doubts, *floor]
    for reason in (resolution, modes_outside(modes, spectrum, current)):
        if reason is not None:
            found.append(reason)
    return Verdict(tuple(dict.fromkeys(found)))
