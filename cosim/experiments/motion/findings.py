"""What the motion control experiment found: its scores, the Done-when check, its tables
and its section of ``report.md``.

Shared by :mod:`arcosim.experiments.motion.experiment` (which fills
:class:`MotionResults`), ``arcosim reproduce`` (which prints the tables) and the
control benchmark (which counts :func:`done_when` per seed).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from arcosim.experiments.closed_loop import LoopRun
from arcosim.experiments.motion.metrics import (
    limit_cycle_counts,
    peak_current,
    residual_rms,
    settling_time,
)
from arcosim.experiments.report import markdown_table
from arcosim.fmu.flexchain import defaults

#: The experiment's number in ``report.md`` and the printed text (after the others).
NUMBER = 7
#: Its figure, written into the report's folder.
FIGURE = "fig10_motion_control.png"
#: The move of the last mass (rad), its profile's duration (s) and the run's length (s).
DISTANCE = 1.0
MOVE_TIME = 1.0
MOTION_DURATION = 6.0
#: Every controller's current limit (A).
I_MAX = 3.0
#: The load torque on the last mass during the hold (N·m): a tenth of what 1 A gives.
LOAD_TORQUE = 0.1 * defaults.K_T
#: When it steps on (s).
LOAD_TIME = 3.0
#: Seeds of the random model errors in the experiment (the benchmark runs 20).
ERROR_SEEDS = (1,)
#: The plant's noise seed.
SEED = 1


#: The four controllers, in the tables' order.
CONTROLLERS = ("cascade", "cascade + ZV shaping", "sensorless", "full state (upper bound)")
#: The residual vibration's window at the end of a run (s).
WINDOW = 2.0
#: Done when: settled within ±1 % by this time (s) …
SETTLE_LIMIT = 2.5
#: … within this factor of the upper bound's settling time …
UPPER_BOUND_FACTOR = 1.3
#: … with a residual at most this fraction of the cascade's or ``RESIDUAL_FLOOR`` (rad) …
RESIDUAL_FRACTION = 0.1
RESIDUAL_FLOOR = 1e-3
#: … and no limit cycle at the motor larger than this many encoder counts (peak to peak).
LIMIT_CYCLE_COUNTS = 1.0


@dataclass(frozen=True)
class MoveScore:
    """One point-to-point move of the last mass, scored.

    Attributes
    ----------
    settle_1, settle_05 : float
        Settling time of the last mass within ±1 % and ±0.5 % of the move (s; ``inf``:
        never within the run).
    residual : float
        Rms of the last mass about the target over the run's last :data:`WINDOW` s (rad).
    peak_current : float
        Largest |i_ref| (A).
    limit_cycle : float
        Peak-to-peak encoder angle of the motor over the last :data:`WINDOW` s (counts).

    Examples
    --------
    >>> score = MoveScore(0.9, 1.0, 1e-4, 2.5, 1.0)
    >>> score.as_dict()["settle_1"], score.peak_current  # s, A
    (0.9, 2.5)
    """

    settle_1: float
    settle_05: float
    residual: float
    peak_current: float
    limit_cycle: float

    def as_dict(self) -> dict[str, float]:
        """The scores by name (SI units, counts)."""
        return asdict(self)


def score_move(run: LoopRun, target: float, distance: float, encoder_cpr: int) -> MoveScore:
    """Score a run that moves the last mass by ``distance`` to ``target`` from t = 0.

    Parameters
    ----------
    run : LoopRun
        The closed-loop run (:func:`~arcosim.experiments.closed_loop.run_closed_loop`).
    target : float
        Where the last mass should come to rest (rad).
    distance : float
        The move (rad): the settling bands are ±1 % and ±0.5 % of it.
    encoder_cpr : int
        The encoder's counts per revolution (a count), to count the limit cycle in.

    Returns
    -------
    MoveScore
        Its settling times, residual, peak current and limit cycle.

    Examples
    --------
    >>> t = np.arange(0.0, 6.0005, 1e-3)
    >>> last = np.minimum(t, 1.0)  # a ramp to 1 rad in 1 s, then still
    >>> run = LoopRun(t, np.vstack([last, last]), last, 0 * t, 0 * t, np.full(6000, 0.5))
    >>> score_move(run, 1.0, 1.0, 2000)
    MoveScore(settle_1=0.991, settle_05=0.996, residual=0.0, peak_current=0.5, limit_cycle=0.0)
    """
    y = run.last
    return MoveScore(
        settle_1=settling_time(run.time, y, target, 0.01 * abs(distance)),
        settle_05=settling_time(run.time, y, target, 0.005 * abs(distance)),
        residual=residual_rms(run.time, y, target, WINDOW),
        peak_current=peak_current(run.i_ref),
        limit_cycle=limit_cycle_counts(run.time, run.theta_m, encoder_cpr, WINDOW),
    )


@dataclass(frozen=True)
class LoadScore:
    """The last mass's hold under a load-torque step at ``step_time``.

    Attributes
    ----------
    peak : float
        Largest |θ_n − target| after the step (rad).
    held : float
        Mean θ_n − target over the run's last second (rad): what the controller's
        model leaves of the load's static deflection.
    recovery : float
        Time from the step until the last mass stays within ±1 % of the move (s).
    limit_cycle : float
        Peak-to-peak motor angle over the last :data:`WINDOW` s (counts).
    """

    peak: float
    held: float
    recovery: float
    limit_cycle: float

    def as_dict(self) -> dict[str, float]:
        """The scores by name (SI units, counts)."""
        return asdict(self)


def score_load(
    run: LoopRun, target: float, distance: float, step_time: float, encoder_cpr: int
) -> LoadScore:
    """Score the hold of a run with a load-torque step at ``step_time`` (s)."""
    y, t = run.last, run.time
    after = t >= step_time
    return LoadScore(
        peak=float(np.max(np.abs(y[after] - target))),
        held=float(np.mean(y[t > t[-1] - 1.0] - target)),
        recovery=settling_time(t, y, target, 0.01 * abs(distance), start=step_time),
        limit_cycle=limit_cycle_counts(t, run.theta_m, encoder_cpr, WINDOW),
    )


def done_when(sensorless: MoveScore, cascade: MoveScore, upper: MoveScore) -> dict[str, bool]:
    """The controller's four criteria for one move of the sensorless controller.

    Parameters
    ----------
    sensorless, cascade, upper : MoveScore
        The sensorless controller's move, the cascade's and the full-state upper bound's
        (the same design).

    Returns
    -------
    dict of str to bool
        ``settles`` (±1 % by :data:`SETTLE_LIMIT` s), ``residual`` (at most
        max(:data:`RESIDUAL_FRACTION` × the cascade's, :data:`RESIDUAL_FLOOR`)),
        ``near_bound`` (within :data:`UPPER_BOUND_FACTOR` × the upper bound's ±1 %
        settling), ``no_limit_cycle`` (at most :data:`LIMIT_CYCLE_COUNTS` counts).

    Examples
    --------
    >>> good = MoveScore(1.2, 1.4, 2e-4, 0.3, 1.0)
    >>> cascade = MoveScore(math.inf, math.inf, 1.5e-2, 0.3, 0.0)
    >>> all(done_when(good, cascade, good).values())
    True
    """
    return {
        "settles": sensorless.settle_1 <= SETTLE_LIMIT,
        "residual": sensorless.residual
        <= max(RESIDUAL_FRACTION * cascade.residual, RESIDUAL_FLOOR),
        "near_bound": sensorless.settle_1 <= UPPER_BOUND_FACTOR * upper.settle_1,
        "no_limit_cycle": sensorless.limit_cycle <= LIMIT_CYCLE_COUNTS,
    }


@dataclass
class ChainFindings:
    """What the experiment found on one chain (SI units).

    Attributes
    ----------
    n : int
        Number of load masses (a count).
    modes : list of float
        The identified chain's modes (rad/s), motor free.
    identification_error : dict of str to float
        The largest |error| of the identified J_i and of the k_i (%).
    gains : str
        The cascade's gains, one line.
    shaper : str
        The shaper's impulses, one line.
    moves : dict of str to MoveScore
        The 1 rad move by each of :data:`CONTROLLERS`.
    loads : dict of str to LoadScore
        The same move with a load-torque step during the hold.
    errors : dict of str to tuple of MoveScore
        Model errors by label: (sensorless, upper bound) with the same wrong model.
    """

    n: int
    modes: list[float] = field(default_factory=list)
    identification_error: dict[str, float] = field(default_factory=dict)
    gains: str = ""
    shaper: str = ""
    moves: dict[str, MoveScore] = field(default_factory=dict)
    loads: dict[str, LoadScore] = field(default_factory=dict)
    errors: dict[str, tuple[MoveScore, MoveScore]] = field(default_factory=dict)


#: The experiment's results by chain name.
MotionResults = dict[str, ChainFindings]

MOVE_HEADER = [
    "chain",
    "controller",
    "settling ±1 % (s)",
    "settling ±0.5 % (s)",
    "residual rms (mrad)",
    "peak current (A)",
    "motor limit cycle (counts)",
]


def _counts(value: float) -> str:
    """Encoder counts for a table: whole as they are, fractions (ideal sensors) to 0.01."""
    return f"{value:.0f}" if value == round(value) else f"{value:.2f}"


def _seconds(value: float) -> str:
    return "never" if math.isinf(value) else f"{value:.2f}"


def move_rows(results: MotionResults) -> list[list[str]]:
    """One row per chain and controller: the 1 rad move's scores."""
    rows = []
    for chain, found in results.items():
        for name in CONTROLLERS:
            s = found.moves[name]
            rows.append(
                [
                    chain,
                    name,
                    _seconds(s.settle_1),
                    _seconds(s.settle_05),
                    f"{1e3 * s.residual:.2f}",
                    f"{s.peak_current:.3f}",
                    _counts(s.limit_cycle),
                ]
            )
    return rows


LOAD_HEADER = [
    "chain",
    "controller",
    "peak deviation (mrad)",
    "held error (mrad)",
    "back within ±1 % (s)",
    "motor limit cycle (counts)",
]


def load_rows(results: MotionResults) -> list[list[str]]:
    """One row per chain and controller: the hold under the load-torque step."""
    rows = []
    for chain, found in results.items():
        for name, s in found.loads.items():
            rows.append(
                [
                    chain,
                    name,
                    f"{1e3 * s.peak:.2f}",
                    f"{1e3 * s.held:+.2f}",
                    _seconds(s.recovery),
                    _counts(s.limit_cycle),
                ]
            )
    return rows


ERROR_HEADER = [
    "chain",
    "model",
    "sensorless ±1 % (s)",
    "upper bound ±1 % (s)",
    "residual rms (mrad)",
    "motor limit cycle (counts)",
    "Done-when criteria met",
]


def error_rows(results: MotionResults) -> list[list[str]]:
    """One row per chain and model: the sensorless controller against its upper bound."""
    rows = []
    for chain, found in results.items():
        cascade = found.moves["cascade"]
        cases = {"identified": (found.moves["sensorless"], found.moves[CONTROLLERS[3]])}
        cases.update(found.errors)
        for label, (sensorless, upper) in cases.items():
            met = done_when(sensorless, cascade, upper)
            rows.append(
                [
                    chain,
                    label,
                    _seconds(sensorless.settle_1),
                    _seconds(upper.settle_1),
                    f"{1e3 * sensorless.residual:.2f}",
                    _counts(sensorless.limit_cycle),
                    f"{sum(met.values())}/4"
                    + (
                        ""
                        if all(met.values())
                        else f" (not: {', '.join(k for k, v in met.items() if not v)})"
                    ),
                ]
            )
    return rows


def setup_rows(results: MotionResults) -> list[list[str]]:
    """One row per chain: the identified modes and errors, the cascade's gains, the shaper."""
    return [
        [
            chain,
            ", ".join(f"{w:.1f}" for w in found.modes),
            f"{found.identification_error['J']:.2f} %, {found.identification_error['k']:.2f} %",
            found.gains,
            found.shaper,
        ]
        for chain, found in results.items()
    ]


SETUP_HEADER = [
    "chain",
    "identified modes (rad/s)",
    "max |J_i|, |k_i| error",
    "cascade",
    "ZV shaper",
]


def motion_markdown(results: MotionResults) -> str:
    """``report.md``'s section of the experiment (empty when it did not run)."""
    if not results:
        return ""
    return f"""
## {NUMBER}. Beyond the paper: moving the last mass, and stopping it ringing, from the motor alone

On the bench chain and the five-mass chain (J = 0.2, 0.3, 0.25, 0.3, 0.2 g·m², every k =
0.4 N·m/rad, B = 1.5·10⁻⁵ N·m·s/rad), each identified by `identify_drive` from a 20 s
log of the same plant (the `identification` multi-sine; k_t and J_m known), a
{DISTANCE:g} rad move of the last mass from rest, in {MOTION_DURATION:g} s runs at 1 ms, current
limit {I_MAX:g} A, by four controllers: (a) a drive's cascade tuned out of the box, a
velocity PI on the motor encoder at half the identified first mode on the total inertia
(its zero at a quarter of that), a position P at a quarter of it, on a minimum-jerk
profile of {MOVE_TIME:g} s with its velocity and torque fed forward; (b) the same with ZV
shaping on the modes of the identified chain under that cascade; (c) the sensorless
controller designed on the identified chain for a {MOVE_TIME:g} s move (state feedback on
the observer's estimates from the motor's current and encoder); (d) the same state
feedback fed the plant's true angles and velocities (the upper bound). Scores of the
last mass: settling within ±1 % and ±0.5 % of the move (one encoder count is 0.3 % of a
radian), rms about the target over the last {WINDOW:g} s, peak current, and the motor's
peak-to-peak angle over the last {WINDOW:g} s in encoder counts (a limit cycle).

{markdown_table(SETUP_HEADER, setup_rows(results))}

{markdown_table(MOVE_HEADER, move_rows(results))}

The same move with a load torque of {1e3 * LOAD_TORQUE:.2f} mN·m (a tenth of what 1 A
gives) stepping onto the last mass at {LOAD_TIME:g} s: its largest deviation, its mean
error over the last second (the sensorless controller's estimate settles to zero
error; the true load is then off by the load torque times the model's compliance
error), and when it is back within ±1 %:

{markdown_table(LOAD_HEADER, load_rows(results))}

Model errors: the sensorless controller and its upper bound designed on the identified
chain with every J_i and k_i scaled by independent uniform factors in [0.9, 1.1] (seed
{", ".join(str(s) for s in ERROR_SEEDS)} of numpy's generator; `arcosim bench control`
runs 20 on three other chains) and the two corners. Done when: ±1 % within
{SETTLE_LIMIT:g} s, a residual at most max({RESIDUAL_FRACTION:g} × the cascade's,
{1e3 * RESIDUAL_FLOOR:g} mrad), within {UPPER_BOUND_FACTOR:g} × the upper bound's settling,
no motor limit cycle beyond {LIMIT_CYCLE_COUNTS:g} count:

{markdown_table(ERROR_HEADER, error_rows(results))}

![Fig. 10]({FIGURE})
"""
