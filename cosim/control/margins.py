"""Both loops' margins for one chain and the user's goals, with a verdict.

:func:`controller_margins` designs the controller as the FMU does, then computes the
full-state loop's margins (:mod:`~arcosim.control.full_state`) and the sensorless loop's
decays (:mod:`~arcosim.control.sensorless_loop`) with the model exact, one step late and
under the model errors of :mod:`~arcosim.control.model_errors`: the chain given is taken
as the truth and the controller's model as that chain with every J_i, k_i scaled, i.e.
"if the identified chain were this far off". ``arcosim control`` prints it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from arcosim.control import full_state
from arcosim.control.model_errors import ERROR, RANDOM_MODELS, model_errors
from arcosim.control.sensorless_loop import sensorless_decay
from arcosim.fmu.flexchain import control_design
from arcosim.fmu.flexchain.control_design import (
    ControllerDesign,
    design_controller,
    plant_matrices,
)

#: Smaller errors tried, in turn, when the loop is not stable at the error asked for.
SMALLER_ERRORS = (0.05, 0.02, 0.01)


@dataclass(frozen=True)
class LoopDecay:
    """One linearized loop's slowest pole: its decay (1/s; < 0 grows) and frequency (rad/s),
    for the model error named."""

    model: str
    decay: float
    frequency: float


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
        The full-state loop's slowest decay over the model errors.
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

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> found = arcosim.controller_margins(chain, h=1e-3, random_models=0)
    >>> found.robust, found.worst.model  # the slowest of the two corners
    (True, 'J +10 %, k −10 %')
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

    @property
    def worst(self) -> LoopDecay:
        """The sensorless loop's slowest pole over the model errors."""
        return min(self.under_errors, key=lambda d: d.decay)

    @property
    def robust(self) -> bool:
        """Every linearized sensorless loop decays: model exact, one step late, every error."""
        return min(self.sensorless.decay, self.sensorless_late.decay, self.worst.decay) > 0.0

    def text(self) -> str:
        """The report, one finding a line."""
        d, fs, pct = self.design, self.full_state, f"±{100 * self.error:g} %"
        lines = [
            f"design: load mass {d.control_mass} of {d.n} moved; move_time {d.move_time:g} s, "
            f"bandwidth {d.bandwidth:.4g} rad/s (move_time × bandwidth = "
            f"{control_design.MOVE_BANDWIDTH_PRODUCT:g}), every pole given a decay of "
            f"{control_design.DECAY_RATIO * d.bandwidth:.3g} 1/s; step {1e3 * d.h:g} ms; "
            f"i_max {d.i_max:g} A",
            "modes with the motor free: " + ", ".join(f"{w:.1f}" for w in self.modes) + " rad/s",
            f"full-state loop (true angles and velocities, the upper bound): slowest decay "
            f"{fs['slowest_decay']:.2f} 1/s, one step late {fs['decay_one_step_late']:.2f} "
            f"1/s; phase margin {fs['phase_margin']:.0f}° at {fs['crossover']:.0f} rad/s, "
            f"delay margin {1e3 * fs['delay_margin']:.1f} ms, max |S| "
            f"{fs['max_sensitivity']:.2f}; worst over J_i, k_i {pct}: "
            f"{_decay_text(self.full_state_worst)}",
            f"sensorless loop (estimates; linearized: exact encoder, no Coulomb friction): "
            f"slowest decay {_decay_text(self.sensorless)}; one step late "
            f"{_decay_text(self.sensorless_late)}; worst over J_i, k_i {pct} "
            f"({len(self.under_errors)} models): {_decay_text(self.worst)}",
        ]
        return "\n".join([*lines, self.verdict()])

    def verdict(self) -> str:
        """One line: robust or not, and what to do."""
        pct = f"±{100 * self.error:g} %"
        if self.robust:
            return (
                f"verdict: robust: the sensorless loop decays with the model exact, one step "
                f"late and with every J_i, k_i checked within {pct} of the chain's"
            )
        growing = [e for e in (self.sensorless, self.sensorless_late, self.worst) if e.decay <= 0]
        first = growing[0]
        if self.stable_within is not None:
            within = f"±{100 * self.stable_within:g} %"
            advice = (
                f"it decays at every model checked within {within}: identify the chain to "
                f"within {within}, or check another move_time or bandwidth the same way"
            )
        else:
            advice = "check another move_time or bandwidth the same way"
        return (
            f"verdict: NOT robust to {pct}: with {first.model} the sensorless loop grows at "
            f"{-first.decay:.2f} 1/s at {first.frequency:.0f} rad/s; {advice}"
        )

    def as_dict(self) -> dict[str, object]:
        """Everything as JSON-ready values (SI units; keys name them)."""
        d = self.design
        return {
            "control_mass": d.control_mass,
            "masses": d.n,
            "move_time_s": d.move_time,
            "bandwidth_rad_s": d.bandwidth,
            "step_s": d.h,
            "i_max_A": d.i_max,
            "gain_K": list(d.K),
            "modes_rad_s": list(self.modes),
            "full_state": dict(self.full_state),
            "full_state_worst": vars(self.full_state_worst),
            "sensorless": vars(self.sensorless),
            "sensorless_one_step_late": vars(self.sensorless_late),
            "sensorless_under_errors": [vars(e) for e in self.under_errors],
            "error": self.error,
            "robust": self.robust,
            "stable_within": self.stable_within,
            "verdict": self.verdict(),
        }


def _decay_text(d: LoopDecay) -> str:
    where = f" at {d.frequency:.0f} rad/s" if d.frequency > 0.0 else ""
    model = "" if d.model == "exact" else f" ({d.model})"
    return f"{d.decay:.2f} 1/s{where}{model}"


def controller_margins(
    params: Mapping[str, float],
    *,
    h: float,
    error: float = ERROR,
    random_models: int = RANDOM_MODELS,
    **goals,
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
    **goals
        ``control_mass``, ``move_time``, ``bandwidth``, ``i_max``, ``hold_dither`` for
        :func:`~arcosim.fmu.flexchain.control_design.design_controller`.

    Returns
    -------
    ControllerMargins
        With :meth:`~ControllerMargins.text` and :meth:`~ControllerMargins.as_dict`.

    Raises
    ------
    ValueError
        For a chain or goals the design refuses (the message names the parameter), or an
        error outside (0, 1).

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
    design = design_controller(params, h=h, **goals)
    linear = {key: goals[key] for key in ("control_mass", "move_time", "bandwidth", "i_max")
              if key in goals}  # fmt: skip
    truth = dict(params)
    errors = model_errors(design.n, error, random_models)
    full_worst = min(
        (LoopDecay(e.name, full_state.decay_on(design, e.apply(truth)), 0.0) for e in errors),
        key=lambda d: d.decay,
    )

    def sensorless(name: str, model: Mapping[str, float], delay: int = 0) -> LoopDecay:
        return LoopDecay(name, *sensorless_decay(truth, model, h=h, delay=delay, **linear))

    under = tuple(sensorless(e.name, e.apply(truth)) for e in errors)
    found = ControllerMargins(
        design=design,
        modes=_modes(design),
        full_state=full_state.margins(design),
        full_state_worst=full_worst,
        sensorless=sensorless("exact", truth),
        sensorless_late=sensorless("exact", truth, delay=1),
        under_errors=under,
        error=error,
    )
    if found.robust or min(found.sensorless.decay, found.sensorless_late.decay) <= 0.0:
        return found
    for smaller in (e for e in SMALLER_ERRORS if e < error):
        models = model_errors(design.n, smaller, random_models)
        if all(sensorless(e.name, e.apply(truth)).decay > 0.0 for e in models):
            return ControllerMargins(**{**vars(found), "stable_within": smaller})
    return found


def _modes(design: ControllerDesign) -> tuple[float, ...]:
    """The chain's modes with the motor free (rad/s), ascending."""
    A, _ = plant_matrices(design.J_m, design.k_t, design.D_m, design.J, design.k, design.B)
    ev = np.linalg.eigvals(np.array(A))
    return tuple(sorted({round(float(abs(e)), 3) for e in ev if abs(e.imag) > 1e-6}))
