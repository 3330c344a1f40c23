"""Beyond the paper: moving the last mass and stopping it ringing, from the motor alone.

On the bench chain and a five-mass chain, each identified by
:func:`arcosim.identify_drive` from a 20 s log of the same plant (the
``identification`` multi-sine), a 1 rad move of the last mass in 6 s runs by

(a) a drive's cascade tuned out of the box
    (:class:`~arcosim.experiments.motion.baselines.CascadeController`),
(b) the same with ZV input shaping on the modes of the identified chain under the cascade,
(c) the sensorless controller (``MotionController`` on the motor's current and encoder),
(d) the same state feedback fed the plant's true angles and velocities (the upper bound);

then the same move with a load-torque step on the last mass during the hold, and the
sensorless controller (and its upper bound) designed on the identified chain with every
J_i, k_i scaled by independent uniform factors in [0.9, 1.1] and the two corners (all J
+10 % with all k −10 %, and the reverse). The plant is the project's C plant FMU with
realistic sensors (2000-count encoder, 5 mA current noise) unless ``ideal``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from arcosim.build.builder import ensure_built
from arcosim.experiments.closed_loop import LoadStep, LoopRun, OpenLoop, run_closed_loop
from arcosim.experiments.motion.baselines import (
    CascadeController,
    cascade_gains,
    cascade_shaper,
    chain_modes,
    shaped_modes,
)
from arcosim.experiments.motion.findings import (
    CONTROLLERS,
    DISTANCE,
    ERROR_SEEDS,
    FIGURE,
    I_MAX,
    LOAD_TIME,
    LOAD_TORQUE,
    MOTION_DURATION,
    MOVE_TIME,
    SEED,
    ChainFindings,
    MotionResults,
    score_load,
    score_move,
)
from arcosim.experiments.scenarios import IDENTIFICATION_DURATION, identification_current
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.chain import Chain
from arcosim.fmu.flexchain.defaults import ENCODER_CPR, G_DIST, STEP
from arcosim.identification.drive_identification import DriveIdentification, identify_drive
from arcosim.outputs import save_figure

#: The experiment's chains by their names in tables: the bench, and the accuracy
#: benchmark's five-mass chain (kg·m², N·m/rad, N·m·s/rad).
CHAINS = {
    "bench (n = 3)": Chain(J=defaults.J, k=(defaults.K,) * 3, B=(defaults.B,) * 3),
    "five-mass": Chain(J=(2e-4, 3e-4, 2.5e-4, 3e-4, 2e-4), k=(0.4,) * 5, B=(1.5e-5,) * 5),
}


def plant_settings(
    chain: Chain, ideal: bool, seed: int = SEED, encoder_cpr: int = ENCODER_CPR
) -> dict[str, float]:
    """The plant FMU's start values: the chain, the noise seed, the sensors (an encoder
    of ``encoder_cpr`` counts per revolution and 5 mA current noise, none if ``ideal``)."""
    sensors = {"encoder_cpr": 0, "i_noise_std": 0.0} if ideal else {"encoder_cpr": encoder_cpr}
    return {**chain.parameters(motor="J_m"), "seed": seed, **sensors}


def identify_chain(
    folder: Path, chain: Chain, ideal: bool, seed: int = SEED, encoder_cpr: int = ENCODER_CPR
) -> DriveIdentification:
    """The chain as :func:`arcosim.identify_drive` finds it in a log of the plant.

    The log: the ``identification`` multi-sine (40 lines 3–150 rad/s, 3 A, 20 s) on the
    plant FMU of ``folder`` with an encoder of ``encoder_cpr`` counts (exact if
    ``ideal``); known: k_t and J_m (and, with ideal sensors, the friction).

    Parameters
    ----------
    folder : Path
        Folder of FMUs built for ``chain.n`` masses (:func:`arcosim.ensure_built`).
    chain : Chain
        The plant's chain.
    ideal : bool
        Exact sensors (no current noise, an exact encoder) and the friction known.
    seed : int
        The plant's noise seed (an index).
    encoder_cpr : int
        The plant's encoder counts per revolution (a count) unless ``ideal``.

    Returns
    -------
    DriveIdentification
        The identification of the plant's log.

    Examples
    --------
    >>> from arcosim import ensure_built
    >>> chain = arcosim.Chain(J=(2e-4, 3e-4), k=(0.4, 0.4), B=(1e-5, 1e-5))
    >>> result = identify_chain(ensure_built(2), chain, ideal=True)
    >>> [round(J / true - 1.0, 2) for J, true in zip(result.chain.J, chain.J)]  # rel. error
    [0.0, 0.0]

    Raises
    ------
    IdentificationError
        When the log does not support the chain.
    """
    t = np.arange(round(IDENTIFICATION_DURATION / STEP)) * STEP
    log = run_closed_loop(
        folder, chain.n, OpenLoop(identification_current(t)), 0.0, IDENTIFICATION_DURATION,
        plant=plant_settings(chain, ideal, seed, encoder_cpr),
    )  # fmt: skip
    friction = {"D_m": defaults.D_M, "f_c": defaults.F_C} if ideal else {}
    return identify_drive(
        log.time, log.i_a, log.omega_m, log.theta_m, k_t=defaults.K_T, J_m=defaults.J_M,
        encoder_cpr=0 if ideal else encoder_cpr, masses=chain.n, **friction,
    )  # fmt: skip


def design_parameters(
    result: DriveIdentification, ideal: bool, encoder_cpr: int = ENCODER_CPR
) -> dict[str, float]:
    """The controller's parameters (the observer FMU's names) from an identification.

    Parameters
    ----------
    result : DriveIdentification
        The chain identified (:func:`identify_chain`).
    ideal : bool
        An exact encoder (``encoder_cpr`` 0).
    encoder_cpr : int
        The encoder's counts per revolution (a count) unless ``ideal``.

    Returns
    -------
    dict of str to float
        ``J_mo``, ``k_to``, the chain's ``J[i]``, ``k[i]``, ``B[i]``, the friction,
        ``encoder_cpr`` and ``g_dist``, in SI units (:func:`sensorless` takes them).

    Examples
    --------
    >>> from arcosim import ensure_built
    >>> chain = arcosim.Chain(J=(2e-4, 3e-4), k=(0.4, 0.4), B=(1e-5, 1e-5))
    >>> params = design_parameters(identify_chain(ensure_built(2), chain, True), True)
    >>> params["encoder_cpr"], round(params["k[1]"], 2)
    (0, 0.4)
    """
    chain = {k: v for k, v in result.observer_parameters().items() if k != "estimator"}
    return {
        "J_mo": defaults.J_M,
        "k_to": defaults.K_T,
        **chain,
        "encoder_cpr": 0 if ideal else encoder_cpr,
        "g_dist": G_DIST,
    }


def scaled(
    params: Mapping[str, float], J_factors: np.ndarray, k_factors: np.ndarray
) -> dict[str, float]:
    """``params`` with every ``J[i]`` and ``k[i]`` times its factor: a model error.

    Parameters
    ----------
    params : mapping of str to float
        The chain by the observer FMU's names (``J[i]`` in kg·m², ``k[i]`` in N·m/rad, …).
    J_factors, k_factors : ndarray
        The factors on J_1 … J_n and k_1 … k_n (dimensionless), shape ``(n,)`` each.

    Returns
    -------
    dict of str to float
        A copy of ``params``, its ``J[i]`` and ``k[i]`` scaled.

    Examples
    --------
    >>> scaled({"J[1]": 1e-3, "k[1]": 0.2, "B[1]": 1e-5}, [2.0], [0.5])
    {'J[1]': 0.002, 'k[1]': 0.1, 'B[1]': 1e-05}
    """
    out = dict(params)
    for i, (fJ, fk) in enumerate(zip(J_factors, k_factors), start=1):
        out[f"J[{i}]"] = params[f"J[{i}]"] * fJ
        out[f"k[{i}]"] = params[f"k[{i}]"] * fk
    return out


def model_errors(n: int, seeds: tuple[int, ...]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Factors on J_i and k_i: uniform in [0.9, 1.1] per seed, then the two corners.

    Parameters
    ----------
    n : int
        Number of load masses (a count).
    seeds : tuple of int
        Seeds of the random factors (an index each).

    Returns
    -------
    dict of str to tuple of ndarray
        By label, the factors on J_1 … J_n and on k_1 … k_n (dimensionless), shape
        ``(n,)`` each (:func:`scaled` applies them).

    Examples
    --------
    >>> errors = model_errors(2, (1,))
    >>> list(errors)
    ['random, seed 1', 'J +10 %, k −10 %', 'J −10 %, k +10 %']
    >>> bool(np.all(np.abs(errors["random, seed 1"][0] - 1.0) <= 0.1))
    True
    """
    out = {}
    for seed in seeds:
        rng = np.random.default_rng(seed)
        out[f"random, seed {seed}"] = (rng.uniform(0.9, 1.1, n), rng.uniform(0.9, 1.1, n))
    ones = np.ones(n)
    out["J +10 %, k −10 %"] = (1.1 * ones, 0.9 * ones)
    out["J −10 %, k +10 %"] = (0.9 * ones, 1.1 * ones)
    return out


def sensorless(params: Mapping[str, float], h: float = STEP, without: frozenset[str] = frozenset()):
    """The sensorless controller designed on ``params``, reset, the parts named in
    ``without`` switched off.

    Designed for the experiment's move (:data:`MOVE_TIME` s) and current limit
    (:data:`I_MAX` A).

    Parameters
    ----------
    params : mapping of str to float
        ``J_mo``, ``k_to``, ``D_m``, ``f_c`` and the chain by the observer FMU's names
        (SI units; :func:`design_parameters`).
    h : float
        The controller's step (s).
    without : frozenset of str
        The controller's parts to switch off (``PARTS`` of
        :mod:`arcosim.fmu.flexchain.control.controller`; none by default).

    Returns
    -------
    MotionController
        Ready for its first ``step``.

    Examples
    --------
    >>> from arcosim.fmu.flexchain import defaults
    >>> chain = arcosim.Chain(J=defaults.J, k=(defaults.K,) * 3, B=(defaults.B,) * 3)
    >>> motor = {"J_mo": defaults.J_M, "k_to": defaults.K_T, "D_m": defaults.D_M, "f_c": 0.0}
    >>> controller = sensorless({**motor, **chain.parameters()})
    >>> abs(controller.step(STEP, 1.0, 0.0, 0.0, 0.0)) <= I_MAX  # A
    True
    """
    from arcosim.fmu.flexchain.control.controller import MotionController, design_controller

    controller = MotionController(
        design_controller(dict(params), h=h, move_time=MOVE_TIME, i_max=I_MAX), without
    )
    controller.reset()
    return controller


def baselines(params: Mapping[str, float]) -> tuple[CascadeController, CascadeController]:
    """The cascade and the shaped cascade on the identified chain ``params``, reset."""
    gains = cascade_gains(params)
    plain = CascadeController(gains, MOVE_TIME, I_MAX)
    shaped = CascadeController(gains, MOVE_TIME, I_MAX, cascade_shaper(params, gains))
    return plain, shaped


def motion_steps() -> int:
    """The co-simulation steps of the experiment, for a progress bar (a count)."""
    identification = round(IDENTIFICATION_DURATION / STEP)
    moves = (4 + 4 + 2 * (len(ERROR_SEEDS) + 2)) * round(MOTION_DURATION / STEP)
    return len(CHAINS) * (identification + moves)


class Runs:
    """The moves of one chain's plant, each by a controller.

    Each run moves the last mass by ``distance`` from rest over :data:`MOTION_DURATION`
    s on the plant FMU, with the load-torque step during the hold when asked.

    Parameters
    ----------
    folder : Path
        Folder of FMUs built for ``chain.n`` masses (:func:`arcosim.ensure_built`).
    chain : Chain
        The plant's chain.
    ideal : bool
        Exact sensors (no current noise, an exact encoder).
    progress : callable
        Called with the steps done after each run (a count).
    seed : int
        The plant's noise seed (an index).
    encoder_cpr : int
        The plant's encoder counts per revolution (a count) unless ``ideal``; limit
        cycles are counted in them either way.
    distance : float
        The move of the last mass (rad).

    Examples
    --------
    >>> from arcosim import ensure_built
    >>> from arcosim.fmu.flexchain import defaults
    >>> chain = arcosim.Chain(J=defaults.J, k=(defaults.K,) * 3, B=(defaults.B,) * 3)
    >>> runs = Runs(ensure_built(3), chain, ideal=True)
    >>> motor = {"J_mo": defaults.J_M, "k_to": defaults.K_T, "D_m": defaults.D_M, "f_c": 0.0}
    >>> run = runs.run(sensorless({**motor, **chain.parameters()}), full_state=True)
    >>> float(run.time[-1]), bool(abs(run.last[-1] - DISTANCE) < 0.01)  # s; within 1 %
    (6.0, True)
    """

    def __init__(
        self,
        folder: Path,
        chain: Chain,
        ideal: bool,
        progress: Callable[[int], object] = lambda _steps: None,
        seed: int = SEED,
        encoder_cpr: int = ENCODER_CPR,
        distance: float = DISTANCE,
    ) -> None:
        self.folder, self.chain, self.ideal, self.progress = folder, chain, ideal, progress
        self.seed = seed
        self.cpr = encoder_cpr
        self.distance = distance

    def run(self, controller: object, full_state: bool = False, load: bool = False) -> LoopRun:
        """A move of ``distance`` from rest; with ``load``, the load-torque step during the hold."""
        step = LoadStep(self.chain.n, LOAD_TIME, LOAD_TORQUE) if load else None
        run = run_closed_loop(
            self.folder, self.chain.n, controller, self.distance, MOTION_DURATION,
            plant=plant_settings(self.chain, self.ideal, self.seed, self.cpr), load=step,
            full_state=full_state,
        )  # fmt: skip
        self.progress(len(run.i_ref))
        return run

    def four(self, params: Mapping[str, float], load: bool = False) -> dict[str, LoopRun]:
        """The four controllers' runs, by :data:`CONTROLLERS` name."""
        plain, shaped = baselines(params)
        runs = {CONTROLLERS[0]: self.run(plain, load=load)}
        runs[CONTROLLERS[1]] = self.run(shaped, load=load)
        runs[CONTROLLERS[2]] = self.run(sensorless(params), load=load)
        runs[CONTROLLERS[3]] = self.run(sensorless(params), full_state=True, load=load)
        return runs


def run_chain(
    folder: Path,
    name: str,
    chain: Chain,
    ideal: bool,
    status: Callable[[str], object],
    progress: Callable[[int], object],
) -> tuple[ChainFindings, dict[str, LoopRun]]:
    """The experiment on the chain called ``name``; its findings and the four nominal runs
    (the figure's)."""
    status(f"motion control, {name}: identification")
    result = identify_chain(folder, chain, ideal)
    progress(round(IDENTIFICATION_DURATION / STEP))
    params = design_parameters(result, ideal)
    runs = Runs(folder, chain, ideal, progress)
    gains = cascade_gains(params)
    shaper = cascade_shaper(params, gains)
    found = ChainFindings(
        n=chain.n,
        modes=[float(w) for w in chain_modes(params)[0]],
        identification_error=_identification_error(chain, result),
        gains=gains.text(),
        shaper=f"{len(shaper.times)} impulses over {shaper.duration:.3f} s, on "
        + ", ".join(f"{w:.1f}" for w, _ in shaped_modes(params, gains))
        + " rad/s",
    )
    status(f"motion control, {name}: the four controllers")
    nominal = runs.four(params)
    found.moves = {k: score_move(r, DISTANCE, DISTANCE, runs.cpr) for k, r in nominal.items()}
    status(f"motion control, {name}: load-torque step")
    found.loads = {
        k: score_load(r, DISTANCE, DISTANCE, LOAD_TIME, runs.cpr)
        for k, r in runs.four(params, load=True).items()
    }
    for label, (fJ, fk) in model_errors(chain.n, ERROR_SEEDS).items():
        status(f"motion control, {name}: model error {label}")
        wrong = scaled(params, fJ, fk)
        found.errors[label] = tuple(
            score_move(runs.run(sensorless(wrong), full_state=full), DISTANCE, DISTANCE, runs.cpr)
            for full in (False, True)
        )
    return found, nominal


def _identification_error(chain: Chain, result: DriveIdentification) -> dict[str, float]:
    """The largest |error| of the identified J_i and k_i against the plant's (%)."""
    p = result.parameters
    return {
        name: max(abs(100.0 * (p[f"{name}[{i}]"] / true[i - 1] - 1.0))
                  for i in range(1, chain.n + 1))
        for name, true in (("J", chain.J), ("k", chain.k))
    }  # fmt: skip


def motion_control(
    out: Path,
    bench_folder: Path,
    ideal: bool,
    status: Callable[[str], object] = lambda _text: None,
    progress: Callable[[int], object] = lambda _steps: None,
) -> tuple[MotionResults, Path]:
    """The experiment on both chains; its findings and its figure's path.

    Parameters
    ----------
    out : Path
        Folder the figure goes into.
    bench_folder : Path
        Folder of the bench's FMUs (n = 3); the five-mass plant is built in the per-user
        cache (:func:`arcosim.ensure_built`).
    ideal : bool
        Ideal sensors (then the identification is told the friction).
    status : callable
        Called with one line saying what runs.
    progress : callable
        Called with the co-simulation steps done after each run (:func:`motion_steps` in all).

    Returns
    -------
    tuple
        The findings by chain name, and the figure written.
    """
    results: MotionResults = {}
    nominal = {}
    for name, chain in CHAINS.items():
        folder = bench_folder if chain.n == 3 else ensure_built(chain.n)
        results[name], nominal[name] = run_chain(folder, name, chain, ideal, status, progress)
    return results, figure_motion(nominal, out / FIGURE)


#: Colour, line style and width of the four controllers' lines (the bound dashed on top).
_STYLES = (("0.55", "-", 1.6), ("tab:orange", "-", 1.0), ("tab:green", "-", 1.0),
           ("tab:red", "--", 0.9))  # fmt: skip


def figure_motion(runs: dict[str, dict[str, LoopRun]], path: Path) -> Path:
    """The four responses of the last mass on each chain: the move, and the error near the
    target (mrad) with the ±1 % band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(runs), figsize=(5.2 * len(runs), 6.4), squeeze=False)
    for column, (chain, by_controller) in enumerate(runs.items()):
        top, bottom = axes[0, column], axes[1, column]
        for (name, run), (color, style, width) in zip(by_controller.items(), _STYLES):
            look = {"color": color, "ls": style, "lw": width, "label": name}
            top.plot(run.time, run.last, **look)
            bottom.plot(run.time, 1e3 * (run.last - DISTANCE), **look)
        band = 10.0 * DISTANCE
        bottom.axhspan(-band, band, color="0.9", zorder=0)
        bottom.set_ylim(-4 * band, 4 * band)
        top.set_title(f"{chain}: last mass, {DISTANCE:g} rad move", fontsize=9)
        top.set_ylabel("θ_n (rad)")
        bottom.set_ylabel("θ_n − target (mrad); ±1 % shaded")
        bottom.set_xlabel("time (s)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    try:
        return save_figure(fig, path, dpi=110, force=True)
    finally:
        plt.close(fig)
