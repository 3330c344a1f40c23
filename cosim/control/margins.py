"""Both loops' margins for one chain and the user's goals, with a verdict.

:func:`controller_margins` designs the controller as the FMU does, then computes the
full-state loop's margins (:mod:`~arcosim.control.full_state`) and the sensorless loop's
decays (:mod:`~arcosim.control.sensorless_loop`) with the model exact, one step late and
under the model errors of :mod:`~arcosim.control.model_errors`, and at rest with the
hold's dither (the model exact and the corners). The chain given is taken
as the truth, and the controller is designed on that chain with every J_i, k_i scaled
("if the identified chain were this far off"), for both loops alike.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from arcosim.control import full_state
from arcosim.control.model_errors import ERROR, RANDOM_MODELS, ModelError, model_errors
from arcosim.control.sensorless_loop import sensorless_decay
from arcosim.fmu.flexchain.chain import state_space
from arcosim.fmu.flexchain.control import design as control_design
from arcosim.fmu.flexchain.control.controller import REFERENCE_SHARE, shaped_step
from arcosim.fmu.flexchain.control.design import (
    ControllerDesign,
    design_controller,
    goals,
    indexed_values,
)

#: Smaller errors tried, in turn, when the loop is not stable at the error asked for.
SMALLER_ERRORS = (0.1, 0.05, 0.02, 0.01)
#: The shaped step's largest |d²s/dτ²| (dimensionless, at τ ≈ 0.28): 1 rad in T s peaks
#: at this over T² rad/s².
PEAK_ACCELERATION = max(abs(shaped_step(j / 4000)[2]) for j in range(4001))
#: The slowest decay a loop must reach to count as decaying (1/s): a time constant of
#: 10 s at most, not a pole the plant's own friction barely holds inside the unit circle.
MIN_DECAY = 0.1
#: The feedback's bandwidth may be at most this share of the Nyquist frequency π/h, and
#: the chain's fastest mode at most this share of it too (dimensionless).
NYQUIST_SHARE_BANDWIDTH = 0.1
NYQUIST_SHARE_MODE = 0.5
#: What a hold case's name ends with.
AT_REST = ", at rest with the dither"
#: Names of the full-state margins in the JSON, with their units.
FULL_STATE_KEYS = {
    "slowest_decay": "slowest_decay_1_s",
    "decay_one_step_late": "decay_one_step_late_1_s",
    "phase_margin": "phase_margin_deg",
    "crossover": "crossover_rad_s",
    "delay_margin": "delay_margin_s",
    "max_sensitivity": "max_sensitivity",
}


@dataclass(frozen=True)
class LoopDecay:
    """One linearized loop's slowest pole under the case named.

    ``decay`` (1/s; < 0 grows; −inf when the run did not come to rest) and ``frequency``
    (rad/s; nan then); ``J``, ``k``: the factors on J_i, k_i of a model error
    (dimensionless; empty for the model exact).
    """

    model: str
    decay: float
    frequency: float
    J: tuple[float, ...] = ()
    k: tuple[float, ...] = ()

    def as_dict(self) -> dict[str, object]:
        """JSON-ready, units in the keys, None for what is not finite."""
        out = {"model": self.model, "decay_1_s": _finite(self.decay)}
        out["frequency_rad_s"] = _finite(self.frequency)
        if self.J:
            out.update(J_factors=list(self.J), k_factors=list(self.k))
        return out

    def text(self) -> str:
        """``"0.73 1/s at 32 rad/s (J −10 %, k +10 %)"``."""
        model = "" if self.model.startswith("the model exact") else f" ({self.model})"
        if not math.isfinite(self.decay):
            return f"no rest: the simulated move diverged or held the current at i_max{model}"
        where = f" at {self.frequency:.3g} rad/s" if self.frequency > 0.0 else ""
        return f"{self.decay:.3g} 1/s{where}{model}"


@dataclass(frozen=True)
class ControllerMargins:
    """What :func:`controller_margins` found (every figure in SI units, as named).

    Parameters
    ----------
    design : ControllerDesign
        The controller as the FMU designs it for these parameters.
    modes : tuple of float
        The chain's modes with the motor free (rad/s).
    full_state : dict of str to float
        :func:`arcosim.control.full_state.margins` of the design: decays (1/s), the
        phase margin (degrees) at its crossover (rad/s), the delay margin (s), max |S|
        (dimensionless).
    full_state_worst : LoopDecay
        The full-state loop's slowest pole over the model errors.
    sensorless : LoopDecay
        The sensorless loop with the model exact.
    sensorless_late : LoopDecay
        The same, each command applied one step late.
    under_errors : tuple of LoopDecay
        The sensorless loop under each model error (the corners first).
    error : float
        The relative error checked (dimensionless).
    stable_within : float or None
        When some model error makes the loop grow: the largest of ``SMALLER_ERRORS`` at
        which none does (dimensionless; None if none of them).
    hold : tuple of LoopDecay
        The sensorless loop at rest with the hold's dither running
        (:func:`~arcosim.control.sensorless_loop.sensorless_loop` with ``hold=True``):
        the model exact, the two corners and the worst model error if it is neither;
        empty when the design has no dither (``encoder_cpr`` or ``hold_dither`` 0).

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> found = arcosim.controller_margins(chain, h=1e-3, random_models=0)
    >>> found.robust, round(found.worst.decay, 1)  # 1/s: the slowest of the two corners
    (True, 4.0)
    """

    design: ControllerDesign
    modes: tuple[float, ...]
    full_state: dict[str, float]
    full_state_worst: LoopDecay
    sensorless: LoopDecay
    sensorless_late: LoopDecay
    under_errors: tuple[LoopDecay, ...]
    error: float
    stable_within: float | None = field(default=None)
    hold: tuple[LoopDecay, ...] = ()

    @property
    def worst(self) -> LoopDecay:
        """The sensorless loop's slowest pole over the model errors."""
        return min(self.under_errors, key=lambda d: d.decay)

    @property
    def cases(self) -> list[LoopDecay]:
        """Every case checked, in the order model exact, one step late, the worst model
        error, the full-state loop's, the hold's at rest."""
        fs = self.full_state
        return [
            self.sensorless,
            self.sensorless_late,
            self.worst,
            LoopDecay("the full state, the model exact", fs["slowest_decay"], 0.0),
            LoopDecay("the full state, one step late", fs["decay_one_step_late"], 0.0),
            *self.hold,
        ]

    @property
    def failing(self) -> list[LoopDecay]:
        """The :attr:`cases` decaying slower than ``MIN_DECAY`` (or growing), in order."""
        return [c for c in self.cases if not c.decay >= MIN_DECAY]

    @property
    def robust(self) -> bool:
        """Every loop checked decays at ``MIN_DECAY`` or faster."""
        return not self.failing

    def text(self) -> str:
        """The report, one finding a line."""
        d, fs, pct = self.design, self.full_state, f"±{100 * self.error:g} %"
        lines = [
            f"design: load mass {d.control_mass} of {d.n} moved; move_time {d.move_time:g} s, "
            f"bandwidth {d.bandwidth:.4g} rad/s (move_time × bandwidth = "
            f"{control_design.MOVE_BANDWIDTH_PRODUCT:g}), every pole given a decay of at "
            f"least {control_design.DECAY_RATIO * d.bandwidth:.3g} 1/s; step {1e3 * d.h:g} "
            f"ms; i_max {d.i_max:g} A; g_dist {d.g_dist:g} rad/s",
            "modes with the motor free: " + ", ".join(f"{w:.1f}" for w in self.modes) + " rad/s",
            f"full-state loop (true angles and velocities, the upper bound): slowest decay "
            f"{fs['slowest_decay']:.3g} 1/s, one step late {fs['decay_one_step_late']:.3g} "
            f"1/s; phase margin {fs['phase_margin']:.0f}° at {fs['crossover']:.3g} rad/s, "
            f"delay margin {1e3 * fs['delay_margin']:.2g} ms, max |S| "
            f"{fs['max_sensitivity']:.2f}; worst over J_i, k_i {pct}: "
            f"{self.full_state_worst.text()}",
            f"sensorless loop (estimates; linearized: exact encoder, no Coulomb friction): "
            f"slowest decay {self.sensorless.text()}; one step late "
            f"{self.sensorless_late.text()}; worst over J_i, k_i {pct} "
            f"({len(self.under_errors)} models): {self.worst.text()}",
        ]
        if self.hold:
            lines.append(
                "at rest with the hold's dither (its observer's angle and velocity fed back; "
                "linearized as above): " + "; ".join(_at_rest_text(h) for h in self.hold)
            )
        return "\n".join([*lines, self.verdict()])

    def verdict(self) -> str:
        """One line: robust or not, and what to do."""
        pct = f"±{100 * self.error:g} %"
        if self.robust:
            slowest = min(self.cases, key=lambda c: c.decay)  # the margin measured
            return (
                f"verdict: robust: the slowest loop checked decays at {slowest.decay:.3g} 1/s "
                f"({slowest.model}; pass: {MIN_DECAY:g} 1/s or faster); checked: the "
                "sensorless loop with the model exact, one step late and with every J_i, k_i "
                f"within {pct} of the chain's"
                + (", and at rest with the dither" if self.hold else "")
            )
        first = self.failing[0]
        what = f"with {first.model}, the loop " + (
            "does not come to rest in the simulated move"
            if not math.isfinite(first.decay)
            else (
                f"grows at {-first.decay:.3g} 1/s"
                if first.decay < 0.0
                else f"decays at only {first.decay:.3g} 1/s (< {MIN_DECAY:g})"
            )
            + f" at {first.frequency:.3g} rad/s"
        )
        if any(first is h for h in self.hold):  # the moving loop passed every case
            return (
                f"verdict: NOT robust at rest: {what}, where the moving loop decays in "
                "every case checked; hold_dither=0 holds without the dither (the motor then "
                "hunts over 2 to 4 counts, docs/control.md)"
            )
        if first is self.worst and self.stable_within is not None:
            within = f"±{100 * self.stable_within:g} %"
            advice = (
                f"it decays at every model checked within {within}: identify the chain to "
                f"within {within}, or check another move_time or bandwidth the same way"
            )
            return f"verdict: NOT robust to {pct}: {what}; {advice}"
        if first is self.worst:
            advice = "check another move_time or bandwidth the same way"
            return f"verdict: NOT robust to {pct}: {what}; {advice}"
        if "late" in first.model:
            advice = "a shorter step, or a sequential master, which applies each command at once"
        else:
            advice = "a shorter step, another move_time or bandwidth, or a higher i_max"
        needs = self.move_current()
        d = self.design
        if not math.isfinite(first.decay) and needs > REFERENCE_SHARE * d.i_max:
            return (
                f"verdict: NOT stable: {what}: the 1 rad move in {d.move_time:g} s needs "
                f"{needs:.3g} A on the chain's {d.inertia:.3g} kg·m² (i_max {d.i_max:g} A); "
                "check the units of J_mo, J[i] (kg·m²) and k_to (N·m/A), or give a longer "
                "move_time"
            )
        return f"verdict: NOT stable: {what}; try {advice}"

    def move_current(self) -> float:
        """The current the checked move (1 rad in ``move_time``) needs at its peak on the
        chain taken as rigid: J_tot max|s̈| / k_t (A)."""
        d = self.design
        return d.inertia * PEAK_ACCELERATION / (d.move_time**2 * d.k_t)

    def as_dict(self) -> dict[str, object]:
        """Everything as JSON-ready values: units in the keys, None for what is not
        finite."""
        d = self.design
        return {
            "control_mass": d.control_mass,
            "masses": d.n,
            "move_time_s": d.move_time,
            "bandwidth_rad_s": d.bandwidth,
            "step_s": d.h,
            "i_max_A": d.i_max,
            "g_dist_rad_s": d.g_dist,
            "gain_K": list(d.K),
            "modes_rad_s": list(self.modes),
            "full_state": {FULL_STATE_KEYS[k]: _finite(v) for k, v in self.full_state.items()},
            "full_state_worst": self.full_state_worst.as_dict(),
            "sensorless": self.sensorless.as_dict(),
            "sensorless_one_step_late": self.sensorless_late.as_dict(),
            "sensorless_under_errors": [e.as_dict() for e in self.under_errors],
            "hold_with_dither": [e.as_dict() for e in self.hold],
            "error": self.error,
            "min_decay_1_s": MIN_DECAY,
            "robust": self.robust,
            "stable_within": self.stable_within,
            "verdict": self.verdict(),
        }


def _at_rest_text(case: LoopDecay) -> str:
    """``"J +10 %, k −10 %: 1.82 1/s at 31.1 rad/s"`` for a hold case."""
    name = case.model.removesuffix(AT_REST)
    return f"{name}: " + LoopDecay("the model exact", case.decay, case.frequency).text()


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def controller_margins(
    params: Mapping[str, float],
    *,
    h: float,
    error: float = ERROR,
    random_models: int = RANDOM_MODELS,
    started: Callable[[], object] | None = None,
    **goals_,
) -> ControllerMargins:
    """Design the controller for a chain and check both of its loops.

    Parameters
    ----------
    params : mapping of str to float
        The chain under the controller FMU's names: ``J_mo`` (kg·m²), ``k_to`` (N·m/A),
        ``D_m`` (N·m·s/rad), ``f_c`` (N·m), ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]``
        (N·m·s/rad); optionally ``g_dist`` (rad/s) and ``encoder_cpr``.
    h : float
        The control step (s).
    error : float
        The relative model error checked, e (dimensionless, 0 < e < 1).
    random_models : int
        Random models besides the two corners (a count).
    started : callable, optional
        Called once the inputs are checked, before the runs (which take seconds).
    **goals_
        ``control_mass``, ``move_time``, ``bandwidth``, ``i_max``, ``hold_dither`` for
        :func:`~arcosim.fmu.flexchain.control.design.design_controller`.

    Returns
    -------
    ControllerMargins
        With :meth:`~ControllerMargins.text` and :meth:`~ControllerMargins.as_dict`.

    Raises
    ------
    ValueError
        For a chain or goals the design refuses (the message names the parameter), a
        step too coarse for the bandwidth or the chain's fastest mode, or an error
        outside (0, 1).

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> found = arcosim.controller_margins(chain, h=1e-3, random_models=2)
    >>> found.robust, round(found.modes[0], 1)
    (True, 89.3)
    """
    if not 0.0 < error < 1.0:
        raise ValueError(f"model error {error!r} must lie between 0 and 1 (0.1 for ±10 %)")
    _check_step(params, h, goals_.get("move_time", 1.0), goals_.get("bandwidth", 0.0))
    design = _design(params, h, goals_)
    linear = {key: goals_[key] for key in ("control_mass", "move_time", "bandwidth", "i_max")
              if key in goals_}  # fmt: skip
    truth = dict(params)
    errors = model_errors(design.n, error, random_models)
    if started is not None:
        started()

    def full(e: ModelError) -> LoopDecay:
        wrong = _design(e.apply(truth), h, goals_)
        return LoopDecay(e.name, *full_state.decay_on(wrong, truth), e.J, e.k)

    def sensorless(e: ModelError | None, delay: int = 0) -> LoopDecay:
        model = truth if e is None else e.apply(truth)
        found = sensorless_decay(truth, model, h=h, delay=delay, **linear)
        if e is None:
            return LoopDecay("the model exact" + (", one step late" if delay else ""), *found)
        return LoopDecay(e.name, *found, e.J, e.k)

    def at_rest(e: ModelError | None) -> LoopDecay:
        model = truth if e is None else e.apply(truth)
        dither = {k: goals_[k] for k in ("hold_dither",) if k in goals_}
        found = sensorless_decay(truth, model, h=h, hold=True, **linear, **dither)
        if e is None:
            return LoopDecay(f"the model exact{AT_REST}", *found)
        return LoopDecay(f"{e.name}{AT_REST}", *found, e.J, e.k)

    under = tuple(sensorless(e) for e in errors)
    worst = errors[min(range(len(errors)), key=lambda i: under[i].decay)]
    found = ControllerMargins(
        design=design,
        modes=_modes(design),
        full_state=full_state.margins(design),
        full_state_worst=min((full(e) for e in errors), key=lambda d: d.decay),
        sensorless=sensorless(None),
        sensorless_late=sensorless(None, delay=1),
        under_errors=under,
        error=error,
        hold=tuple(at_rest(e) for e in _hold_models(design, errors, worst)),
    )
    if found.robust or found.failing[0] is not found.worst:
        return found
    for smaller in (e for e in SMALLER_ERRORS if e < error):
        models = model_errors(design.n, smaller, random_models)
        if all(sensorless(e).decay >= MIN_DECAY for e in models):
            return ControllerMargins(**{**vars(found), "stable_within": smaller})
    return found


def _hold_models(
    design: ControllerDesign, errors: list[ModelError], worst: ModelError
) -> list[ModelError | None]:
    """The models the hold is checked on: none without a dither; else the model exact
    (None), the two corners and the moving loop's worst model if it is neither."""
    if not design.dither_current > 0.0:
        return []
    return [None, *errors[:2], *([worst] if worst not in errors[:2] else [])]


def _design(params: Mapping[str, float], h: float, goals_: Mapping) -> ControllerDesign:
    """The FMU's design; an overflow on extreme values becomes a ValueError saying so."""
    try:
        return design_controller(params, h=h, **goals_)
    except (ArithmeticError, ValueError) as error:
        if isinstance(error, ValueError) and "fsum" not in str(error):
            raise
        raise ValueError(
            f"the design overflows for these values ({error}): check J[i], k[i], B[i], "
            "the step and move_time or bandwidth"
        ) from None


def _check_step(params: Mapping[str, float], h: float, move_time: float, bandwidth: float) -> None:
    """Refuse a step too coarse for the bandwidth or the chain's fastest mode (ValueError)."""
    _, wc = goals(move_time, bandwidth)
    nyquist = math.pi / h
    if wc > NYQUIST_SHARE_BANDWIDTH * nyquist:
        raise ValueError(
            f"bandwidth {wc:.4g} rad/s is over {NYQUIST_SHARE_BANDWIDTH:g} × the Nyquist "
            f"frequency π/h = {nyquist:.4g} rad/s: use a step ≤ "
            f"{NYQUIST_SHARE_BANDWIDTH * math.pi / wc:.3g} s or a longer move_time"
        )
    J, k, B = (indexed_values(params, name) for name in ("J", "k", "B"))
    try:
        A, _ = state_space(params["J_mo"], params["k_to"], params["D_m"], J, k, B)
        fastest = float(np.abs(np.linalg.eigvals(np.array(A))).max())
    except (ArithmeticError, ValueError, np.linalg.LinAlgError, ZeroDivisionError):
        return  # the design names what is wrong with the chain
    if math.isfinite(fastest) and fastest > NYQUIST_SHARE_MODE * nyquist:
        raise ValueError(
            f"the chain's fastest mode, {fastest:.4g} rad/s, is over {NYQUIST_SHARE_MODE:g} × "
            f"the Nyquist frequency π/h = {nyquist:.4g} rad/s: use a step ≤ "
            f"{NYQUIST_SHARE_MODE * math.pi / fastest:.3g} s"
        )


def _modes(design: ControllerDesign) -> tuple[float, ...]:
    """The chain's modes with the motor free (rad/s), ascending."""
    A, _ = state_space(design.J_m, design.k_t, design.D_m, design.J, design.k, design.B)
    ev = np.linalg.eigvals(np.array(A))
    return tuple(sorted({round(float(abs(e)), 3) for e in ev if abs(e.imag) > 1e-6}))
