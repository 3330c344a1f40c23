"""Identify a drive from its log: every J_i, k_i, B_i of the load chain (and n), from the
motor's current and encoder alone, with only the motor's datasheet values known.

:func:`identify_drive` is the one call for the whole job (what ``arcosim identify LOG
--method whole-chain`` runs): it builds the records the fits need from the log
(:func:`~arcosim.identification.records.record.motor_record`,
:func:`~arcosim.identification.records.record.encoder_record`), runs
:func:`~arcosim.identification.fit.whole_chain.identify_whole_chain`, and returns the result with
what
it rests on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from arcosim.fmu.flexchain.chain import Chain
from arcosim.fmu.flexchain.defaults import G_DIST
from arcosim.identification.checks.log_decision import LogDecision, decide_log
from arcosim.identification.checks.noise_floor import (
    floor_warning,
    noise_floor,
    tau_residual,
    weak_mode_floor_warning,
)
from arcosim.identification.checks.verdict import Verdict, judge, unresolved
from arcosim.identification.errors import IdentificationError, RefusedFitError
from arcosim.identification.fit.encoder_fit import FIT_UNITS, RIGID_LOAD
from arcosim.identification.fit.motor_friction import without_friction
from arcosim.identification.fit.periodic_misfit import (
    chain_drive,
    inadequate_reason,
    misfit,
    model_response,
    periodic_response,
)
from arcosim.identification.fit.whole_chain import ChainChoice, identify_whole_chain, split
from arcosim.identification.modes.chain_modes import driving_point_modes
from arcosim.identification.records.record import LOADS, MotorRecord
from arcosim.identification.threads import single_threaded


@dataclass(frozen=True)
class DriveIdentification:
    """The identified drive, and the evidence and assumptions it rests on.

    Parameters
    ----------
    masses : int
        Number of load masses (a count), read from the record with ``masses="auto"``;
        0 for a rigid drive.
    parameters : dict of str to float
        ``J[i]`` (kg·m²), ``k[i]`` (N·m/rad), ``B[i]`` (N·m·s/rad) — the observer
        FMU's own parameter names; for a rigid drive ``J_load`` (J_total − J_m, kg·m²)
        instead — and, when fitted, ``D_m`` (N·m·s/rad), ``f_c`` (N·m) and the load
        torque (N·m).
    std : dict of str to float
        Their standard errors (Newey–West), same names and units; none for a
        parameter at its bound (the report's ``bounds`` give its upper bound instead).
    assumptions : dict of str to str
        What the result is conditional on (k_t and J_m given, the encoder's counts,
        friction given or fitted, the load model), one sentence each.
    warnings : list of str
        What may limit the result, one sentence each: the log's implausible units or
        length (:func:`~arcosim.identification.checks.log_check.log_plausibility`, as
        ``check`` gives them), a weakly determined mode, a residual well above the
        noise floor (:mod:`arcosim.identification.checks.noise_floor`).
    choice : ChainChoice
        The whole-chain fit's evidence (modes, criterion per n, refusals).
    record : MotorRecord
        The reaction-torque record the fit started from.
    friction : dict of str to float
        The motor friction the result rests on, given or fitted: ``D_m``
        (N·m·s/rad) and ``f_c`` (N·m); a term the selection rule left out is 0 (its
        bound is in the report).
    verdict : Verdict
        Whether the result is trusted, and the reasons when not, each naming what to
        check (:func:`~arcosim.identification.checks.verdict.judge`: the log's plausibility,
        the final model's residual against the noise floor, its modes against the
        excited band, the excitation against the band the fit searches).

    Examples
    --------
    >>> from arcosim.identification.drive_identification import DriveIdentification
    >>> result = DriveIdentification(1, {"J[1]": 1e-3, "k[1]": 0.5, "B[1]": 1e-4},
    ...                              {"J[1]": 2e-6, "k[1]": 1e-3, "B[1]": 3e-6}, {})
    >>> result.chain.k, result.chain.k_std  # N·m/rad
    ((0.5,), (0.001,))
    """

    masses: int
    parameters: dict[str, float]
    std: dict[str, float]
    assumptions: dict[str, str]
    warnings: list[str] = field(default_factory=list)
    choice: ChainChoice | None = None
    record: MotorRecord | None = None
    friction: dict[str, float] = field(default_factory=dict)
    verdict: Verdict = field(default_factory=Verdict)

    @property
    def chain(self) -> Chain | None:
        """The identified chain: every J_i, k_i, B_i and the motor friction the result
        rests on, with their standard errors; None for a rigid drive (n = 0).

        The motor inertia ``J_m`` is not in it: it was given (the datasheet's), not
        identified. Written as the report (:meth:`report`) and read back
        (:func:`arcosim.read_chain`), it is this chain again.
        """
        if self.masses == 0 or RIGID_LOAD in self.parameters:
            return None
        return Chain.from_parameters({**self.friction, **self.parameters}, self.std, self.masses)

    @property
    def units(self) -> dict[str, str]:
        """The SI unit of every parameter of the result (:attr:`parameters`, the
        friction, and the terms the fit bounds instead: the report's ``bounds``), by name.

        Examples
        --------
        >>> DriveIdentification(1, {"J[1]": 1e-3, "k[1]": 0.5}, {}, {}).units
        {'J[1]': 'kg·m²', 'k[1]': 'N·m/rad'}
        """
        bounded = self.choice.fit.extra.get("bounds", {}) if self.choice is not None else {}
        names = dict.fromkeys([*self.parameters, *self.friction, *bounded])
        return {name: FIT_UNITS.get(name) or Chain.unit(name) for name in names}

    def observer_parameters(self) -> dict[str, float]:
        """The observer FMU's parameters that estimate every load angle with this chain.

        ``J[i]``, ``k[i]``, ``B[i]``, the friction ``D_m`` and ``f_c`` (given or fitted),
        and ``estimator = 1``: the model-based observer (the paper's recursion,
        estimator 0, diverges from the second mass on; ``docs/method.md``). Mode 2, the
        FMU's default, runs them. A rigid drive (n = 0) has no chain: its load inertia
        ``J_load`` goes to the motor's (``dJm``, the inertia error the observer adds to
        J_mo), and the DOB's τ̂_reac is then the load torque.

        Examples
        --------
        >>> result = DriveIdentification(1, {"J[1]": 1e-3, "k[1]": 0.5, "B[1]": 1e-4}, {},
        ...                              {}, friction={"D_m": 2e-5, "f_c": 2e-3})
        >>> result.observer_parameters()["estimator"], result.observer_parameters()["f_c"]
        (1, 0.002)
        """
        if RIGID_LOAD in self.parameters:  # a rigid drive: its load is motor inertia
            return {"dJm": self.parameters[RIGID_LOAD], **self.friction}
        return {**self.chain.parameters(), "estimator": 1}

    def report(self) -> dict[str, object]:
        """Everything, JSON-able (what ``arcosim identify --json`` prints)."""
        fit = self.choice.fit
        record = self.record
        extra = fit.extra
        out: dict[str, object] = {
            "method": "whole-chain",
            "verdict": self.verdict.word,
            "reasons": list(self.verdict.reasons),
            "masses": self.masses,
        }
        out.update(self.parameters)
        out.update({k: v for k, v in self.friction.items() if k not in out})  # given
        out["std"] = dict(self.std)
        out["units"] = self.units
        out.update(
            start=fit.start_note,
            velocity=record.velocity_source,
            rms_residual=fit.rms_residual,
            rms_data=fit.rms_data,
            newey_west_lag=fit.lag,
            duration=record.duration,
            evaluations=fit.evaluations,
            modes_rad_s=extra["modes_rad_s"],
            damping_ratios=extra["damping_ratios"],
            residue_t_values=extra["residue_t_values"],
            weak_modes=extra["weak_modes"],
            refused={str(n): why for n, why in self.choice.refused.items()},
            assumptions=dict(self.assumptions),
            warnings=list(self.warnings),
            criterion={str(n): v for n, v in self.choice.criterion.items()},
            masses_seen=self.choice.seen,
            selection=extra.get("selection", {}),
            bounds=dict(extra.get("bounds", {})),
        )
        if self.choice.singular_values is not None:
            out["singular_values"] = [float(x) for x in self.choice.singular_values[:16]]
        if "load_torque_range" in extra:
            out["load_torque_range"] = extra["load_torque_range"]
        return out


@single_threaded
def identify_drive(
    time: Sequence[float] | np.ndarray,
    i_a: Sequence[float] | np.ndarray,
    omega_m: Sequence[float] | np.ndarray,
    theta_m: Sequence[float] | np.ndarray,
    *,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    masses: int | str = "auto",
    D_m: float | None = None,
    f_c: float | None = None,
    load: str | None = None,
    g_dist: float = G_DIST,
) -> DriveIdentification:
    """Every J_i, k_i, B_i of the load chain, and n, from a drive log.

    Only the motor's datasheet values are needed: k_t and J_m (a common error of both
    scales every J_i, k_i, B_i by the same factor; the result says so). The motor's
    friction is fitted with the chain unless both ``D_m`` and ``f_c`` are given.

    Parameters
    ----------
    time : array_like
        Sample times (s), shape ``(N,)``, a constant step.
    i_a : array_like
        Motor current (A), shape ``(N,)``: the current that acted over the step ending
        at each sample (the timing contract).
    omega_m : array_like
        Motor velocity (rad/s), shape ``(N,)`` (the encoder's backward difference is
        fine: it is recognised and replaced by a lag-free derivative).
    theta_m : array_like
        Motor angle (rad), shape ``(N,)``, as the encoder gives it (whole counts).
    k_t : float
        Torque constant (N·m/A), from the datasheet (the observer FMU's ``k_to``).
    J_m : float
        Motor inertia (kg·m²), from the datasheet (the observer FMU's ``J_mo``).
    encoder_cpr : int
        The encoder's counts per revolution (a count); 0 for an angle that is not
        quantized (then the friction must be given and no load torque modelled).
    masses : int or "auto"
        Number of load masses (a count; 0: a rigid drive), or ``"auto"`` to read it
        from the record (0 included).
    D_m, f_c : float, optional
        Motor viscous (N·m·s/rad) and Coulomb (N·m) friction, when known; fitted
        otherwise.
    load : {None, "none", "constant", "slow"}
        A load torque on the last mass in the model: none, constant, or constant
        plus a slow drift (fitted and reported). None (the default): chosen by the
        selection rule among the three on the final fit
        (:func:`~arcosim.identification.fit.structure_choice.load_choice`), the chain
        refitted with the one taken; the report's ``selection["load"]`` holds the
        candidates and their scores. A load given is never overridden (``"none"``
        given: the rule only warns).
    g_dist : float
        Bandwidth of the disturbance observer that computes τ̂_reac (rad/s).

    Returns
    -------
    DriveIdentification
        The chain, its standard errors, and what the result rests on.

    Raises
    ------
    RefusedFitError
        A record that cannot support the chain (the message names the missing or weak
        mode and what would fix the record, after the log's implausible units or length
        when :func:`~arcosim.identification.checks.log_check.log_plausibility` found any):
        :class:`~arcosim.identification.errors.RefusedFitError`, an ``IdentificationError``.
    IdentificationError
        Settings the fit cannot use.

    Examples
    --------
    A two-mass chain the plant FMU simulates under the ``identification`` excitation
    (40 lines, 3–150 rad/s, 3 A, 20 s), identified from the motor's signals alone
    (its friction fitted):

    >>> chain = {"J[1]": 4e-4, "J[2]": 8e-4, "k[1]": 0.3, "k[2]": 0.2}
    >>> run = arcosim.run_scenario(arcosim.SCENARIOS["identification"], 2, plant=chain)
    >>> log = [run.time] + [run[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    >>> result = arcosim.identify_drive(*log, k_t=0.0406, J_m=2.09e-5, encoder_cpr=2000)
    >>> result.masses
    2
    >>> [round(result.parameters[name], 2) for name in ("k[1]", "k[2]")]  # N·m/rad
    [0.3, 0.2]
    """
    if not (k_t > 0 and J_m > 0):
        raise IdentificationError(f"k_t and J_m must be > 0, got k_t = {k_t}, J_m = {J_m}")
    if load is not None and load not in LOADS:
        raise IdentificationError(f"load must be one of {', '.join(LOADS)}, got {load!r}")
    friction_given = D_m is not None and f_c is not None
    time, i_a, omega_m, theta_m = (
        np.asarray(x, dtype=float) for x in (time, i_a, omega_m, theta_m)
    )
    # the one set of decisions `check` reports: its problems are the fit's refusals
    decision = decide_log(
        time,
        i_a,
        omega_m,
        theta_m,
        k_t=k_t,
        J_m=J_m,
        encoder_cpr=encoder_cpr,
        g_dist=g_dist,
        masses=masses,
        D_m=D_m,
        f_c=f_c,
        load=load or "none",
    )
    plausibility = decision.plausibility
    if decision.problems:
        # the warnings first (the log's implausible units or length lead), as check says
        raise RefusedFitError("; ".join(decision.warnings + decision.problems))
    record, encoder = decision.record, decision.encoder
    try:
        choice = identify_whole_chain(
            record,
            masses,
            encoder,
            choose_load=load is None,
            reading=decision.reading,
            spectrum=decision.spectrum,
        )
    except IdentificationError as error:  # the record supports no chain: a refusal
        why = f"{'; '.join(plausibility)}; the fit: {error}" if plausibility else str(error)
        raise RefusedFitError(why) from error
    fit = choice.fit
    parameters = fit.as_dict()
    floor_findings = _against_floor(time, i_a, choice, decision, k_t, J_m, encoder_cpr, g_dist)
    floor_findings += _against_periodic_noise(choice, decision)
    chain = split(fit.values, choice.n)
    std = {k: v for k, v in fit.std_dict().items() if k not in fit.extra.get("bounds", {})}
    verdict = judge(
        decision.doubts,
        floor_findings,
        unresolved(parameters, std),
        driving_point_modes(chain[0], chain[1])[0] if choice.n else [],
        decision.spectrum,
        (i_a, decision.step),
    )
    return DriveIdentification(
        masses=choice.n,
        parameters=parameters,
        std=std,
        assumptions=_load_said(dict(fit.extra["assumptions"]), load),
        warnings=decision.warnings + list(fit.extra["warnings"]) + floor_findings,
        choice=choice,
        record=record,
        friction={"D_m": D_m, "f_c": f_c}
        if friction_given
        else {k: parameters.get(k, 0.0) for k in ("D_m", "f_c")},  # left out: 0
        verdict=verdict,
    )


def _against_floor(
    time: np.ndarray,
    i_a: np.ndarray,
    choice: ChainChoice,
    decision: LogDecision,
    k_t: float,
    J_m: float,
    encoder_cpr: int,
    g_dist: float,
) -> list[str]:
    """The final model's residual against the noise floor, whatever the model: with a
    load torque modelled, both without their content below half the lowest excited line
    (the load's, :func:`~arcosim.identification.checks.noise_floor.load_removed`); then, when
    the fit keeps weakly determined modes, the fit without them. Each finding one
    sentence naming what to check; empty at the floor."""
    fit, record, encoder = choice.fit, decision.record, decision.encoder
    parameters = fit.as_dict()
    below = None  # no load modelled: the whole residual
    if fit.extra.get("load", "none") != "none":
        lowest = decision.spectrum.lowest if decision.spectrum is not None else None
        below = 0.5 * lowest if lowest else 0.0  # 0: its mean only
    chain = split(fit.values, choice.n)
    rigid = parameters.get(RIGID_LOAD, 0.0)
    floor, sigma_i = noise_floor(time, i_a, chain, k_t, J_m, encoder_cpr, g_dist, rigid, below)
    motor = record
    if fit.extra.get("friction") == "fitted" and encoder is not None:
        friction = (parameters.get("D_m", 0.0), parameters.get("f_c", 0.0))
        motor = without_friction(motor, encoder, *friction)
    rms = tau_residual(motor, i_a, k_t, chain, rigid, below)
    above = floor_warning(rms, floor, sigma_i)
    if above is None and choice.leaner is not None:
        # a weak mode kept may take up what a wrong k_t or J_m leaves: the fit without
        dropped = choice.leaner.extra["dropped_weak_modes_rad_s"]
        leaner = split(choice.leaner.values, choice.n - len(dropped))
        rms = tau_residual(motor, i_a, k_t, leaner, 0.0, below)
        above = weak_mode_floor_warning(dropped, rms, floor, sigma_i)
    return [above] if above else []


def _against_periodic_noise(choice: ChainChoice, decision: LogDecision) -> list[str]:
    """The final model's misfit at the lines of a periodic excitation against the noise
    its periods show (:mod:`~arcosim.identification.fit.periodic_misfit`), whatever the
    model: one sentence naming what to check when it misfits, else empty (and empty
    for a record that is not periodic over enough whole periods)."""
    encoder = decision.encoder
    if encoder is None:
        return []
    response = periodic_response(encoder, decision.spectrum)
    if response is None:
        return []
    n = choice.n
    drive = chain_drive(choice.fit.as_dict(), n, encoder)
    found = misfit(response, model_response(encoder, drive, response.w))
    choice.fit.extra["periodic_misfit"] = {"lines": found.lines, "over_noise": found.ratio}
    if found.adequate:
        return []
    tried = choice.fit.extra.get("selection", {}).get("periodic", {}).get("misfit_over_noise")
    sizes = [int(m) for m in tried] if tried else [n]
    return [inadequate_reason(n, found, sizes)]


def _load_said(assumptions: dict[str, str], load: str | None) -> dict[str, str]:
    """``assumptions`` with the load's saying whether the user gave it or the rule chose it.

    Examples
    --------
    >>> _load_said({"load": "no load torque modelled"}, None)["load"]
    'no load torque modelled, chosen by the selection rule (--load not given)'
    """
    if load is None and "load" in assumptions:
        assumptions["load"] += ", chosen by the selection rule (--load not given)"
    elif "load" in assumptions:
        assumptions["load"] += f" (--load {load} given)"
    return assumptions
