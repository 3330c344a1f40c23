"""The sentences a whole-chain result carries (offline): what it rests on
(:func:`assumptions`), why a record cannot support a chain (:func:`missing_modes`), and
the one rule the fit refuses by and ``check`` judges by (:func:`refusal`), and the
number of masses asked (:func:`masses_asked`).
"""

from __future__ import annotations

import numpy as np

from arcosim.identification.errors import IdentificationError
from arcosim.identification.modes.detection import DetectedModes, chain_of
from arcosim.identification.records.record import EncoderRecord, MotorRecord

#: A mode whose residue is below this many standard errors is reported as weakly
#: determined (the result's warnings).
T_CONFIRM = 30.0

#: Why a rigid drive needs the encoder's counts (appended to the refusal).
RIGID_NEEDS = (
    "; a rigid drive (n = 0) is fitted from the current to the encoder: give the "
    "encoder's counts per revolution (encoder_cpr)"
)


def assumptions(encoder: EncoderRecord | None) -> dict[str, str]:
    """What the result is conditional on, one line each (for the report)."""
    scale = (
        "k_t and J_m are given, not fitted: if both are off by a relative ε, every J_i, "
        "k_i, B_i (and D_m, f_c, the load torque) is off by the same ε (the model is "
        "homogeneous in torque); one of them alone off distorts the chain unevenly, by "
        "up to about 1.5 ε (measured on a five-mass chain: k_t +5 % gave J_i, k_i "
        "−1.5 … +7.3 %, J_m +5 % gave −0.5 … +4.2 %)"
    )
    out = {"actuator": scale}
    if encoder is None:
        out["fit"] = "output-error fit to τ̂_reac (no encoder counts given: encoder_cpr = 0)"
        return out
    out["encoder"] = f"{2 * np.pi / encoder.count:.0f} counts per revolution, error q²/12"
    if encoder.friction_given:
        out["friction"] = f"given: D_m = {encoder.D_m:.4g} N·m·s/rad, f_c = {encoder.f_c:.4g} N·m"
    else:
        out["friction"] = "fitted (D_m, f_c with standard errors)"
    out["load"] = {
        "none": "no load torque modelled",
        "constant": "a constant load torque on the last mass, fitted",
        "slow": "a constant plus slowly varying load torque on the last mass, fitted",
    }[encoder.load]
    return out


def missing_modes(detected: DetectedModes, n: int | None, record: MotorRecord) -> str:
    """Why the record cannot support n masses (n None: not even one), and what to do."""
    found = ", ".join(f"{w:.1f}" for w in detected.frequency) or "none"
    text = (
        f"the record shows {detected.n} excited mode(s) below {detected.band:.0f} rad/s "
        f"({found} rad/s)"
    )
    if n is not None:
        text += f", {chain_of(n)} has {n}"
    if detected.weak:
        weak = ", ".join(f"{w:.1f} rad/s (t = {t:.1f})" for w, t in detected.weak)
        text += f"; seen but too weakly excited: {weak}"
    return text + (
        ": excite every mode (more current per line: fewer lines, or a higher amplitude; "
        "lines on both sides of each mode, up to the band; a longer record; a finer "
        f"encoder; band = min(3·g_dist, 0.3/h) = {detected.band:.0f} rad/s), "
        "see `arcosim.design_excitation`, or fit fewer masses"
    )


def refusal(
    detected: DetectedModes, masses: int | str, record: MotorRecord, encoder: bool = True
) -> str | None:
    """Why the modes read cannot support ``masses`` (a count, or ``"auto"``), or None:
    the one rule :func:`~arcosim.identification.fit.whole_chain.identify_whole_chain`
    refuses by and ``check`` judges by.

    An n asked for is refused only when the record shows fewer modes (weak ones are
    fitted with a warning); n = 0, the rigid drive, needs the encoder record
    (``encoder``); without it, ``auto`` refuses a record whose modes are all weak."""
    n = detected.n if masses == "auto" else int(masses)
    if n > detected.n:
        return missing_modes(detected, n, record)
    if n == 0 and not encoder:
        return missing_modes(detected, None, record) + RIGID_NEEDS
    if not encoder and masses == "auto" and float(np.max(detected.t_value)) < T_CONFIRM:
        t = ", ".join(f"{t:.0f}" for t in detected.t_value)
        why = f"residue t values {t}, all under {T_CONFIRM:g}"
        return f"every mode the record shows is weakly determined ({why}): " + missing_modes(
            detected, None, record
        )
    return None


def masses_asked(masses: int | str) -> int:
    """The number of load masses a user asked for (``--masses``, not ``auto``).

    Parameters
    ----------
    masses : int or str
        A whole number ≥ 0 (0: a rigid drive).

    Returns
    -------
    int
        ``masses`` as an int.

    Raises
    ------
    IdentificationError
        When it is not a whole number ≥ 0 (the message names ``auto`` too).

    Examples
    --------
    >>> masses_asked("2")
    2
    """
    try:
        n = int(masses)
    except ValueError:
        n = -1
    if n < 0 or str(masses).strip() not in (str(n), "auto"):
        raise IdentificationError(
            f"--masses must be a whole number ≥ 0 (0: a rigid drive) or 'auto', got {masses!r}"
        )
    return n
