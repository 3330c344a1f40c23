"""The paper's three experiments on the bench, and four beyond it (``arcosim reproduce``).

1. actuator self-identification with the load detached (mode 0);
2. five rigid maneuvers with different noise seeds (mode 1), with the actuator terms
   of experiment 1 → Table II next to the paper's own rows, and Fig. 4;
3. a flexible maneuver with energy at all three modes (mode 2), with the mean k̂, B̂
   of experiment 2 → Fig. 5 (the flexible response) and Fig. 6 (estimated against
   true angle of every mass, the model-based observer of experiment 4 beside it);
4. beyond the paper: the whole bench chain (every J_i, k_i, B_i, and n) identified
   from one identification record with only the actuator terms of experiment 1
   known (:mod:`arcosim.identification.fit.whole_chain`), then every mass's angle
   estimated in mode 2 (model-based observer) with those parameters alone → Fig. 7;
5. beyond the paper: a load torque on mass 3 (a step of a tenth of the drive's peak
   torque, then a 2 rad/s sine) during the broadband maneuver, estimated from the motor
   alone (model-based observer with ``load_mass = 3``), with the true chain and with
   experiment 4's chain: settling time, settled error, lag of the sine (scenario
   ``load-torque``, :mod:`arcosim.identification.load_torque`) → Fig. 8;
6. beyond the paper: a flexible link (the link plant FMU) identified from the hub's
   current and encoder alone — EI, ρA, the clamped modes, eq. 7's reaction torque and
   the tip angle against the plant's (:mod:`arcosim.experiments.flexible_link`) → Fig. 9.
7. beyond the paper: a 1 rad move of the last mass on the bench and a five-mass chain,
   each identified by ``identify_drive``, by a drive's cascade, the cascade with input
   shaping, the sensorless controller and its full-state upper bound, a load-torque
   step and model errors (:mod:`arcosim.experiments.motion.experiment`) → Fig. 10.

:func:`reproduce` writes ``report.md``, the figures and the runs as CSV into a folder.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from arcosim.build.builder import ensure_built, fmu_variables
from arcosim.experiments.findings import (
    N_MASSES,
    SEEDS,
    TRUE_CHAIN,
    Results,
    report_markdown,
)
from arcosim.experiments.flexible_link import (
    EXPERIMENT_RIG,
    LINK_DURATION,
    LINK_FMU,
    LINK_UNITS,
    LinkRun,
    score_link,
    simulate_link,
)
from arcosim.experiments.load_scores import score_profile
from arcosim.experiments.metrics import flexible_score
from arcosim.experiments.motion.experiment import motion_control, motion_steps
from arcosim.experiments.motion.findings import FIGURE as MOTION_FIGURE
from arcosim.experiments.reproduce_figures import (
    link_figure,
    load_torque_figure,
    paper_figures,
    whole_chain_figure,
)
from arcosim.experiments.scenarios import (
    LOAD_PROFILE,
    SCENARIOS,
    recording_columns,
    run_scenario,
)
from arcosim.fmu.flexchain import defaults
from arcosim.fmu.flexchain.codes import Estimator, Mode
from arcosim.fmu.flexchain.defaults import G_DIST, STEP
from arcosim.fmu.flexchain.dob import Actuator
from arcosim.fmu.flexchain.observer import ObserverSettings
from arcosim.host.master import Recording
from arcosim.identification.fit.whole_chain import ChainChoice, identify_whole_chain
from arcosim.identification.offline_observer import estimate_states
from arcosim.identification.records.record import encoder_record, motor_record
from arcosim.logs import units_path, write_csv
from arcosim.outputs import check_output_folder, refuse_existing, warn_left_over, write_text

#: The runs written by default, each its log only (``all_csv``: every run, every signal).
DEFAULT_CSV = ("selfid.csv", "rigid_seed1.csv", "flexible.csv", "identification.csv")
DEFAULT_CSV += ("load_true_chain.csv", "flexible_link.csv")
#: The figures, Fig. 4 … Fig. 10.
PAPER_FIGURES = ("fig4_reaction_torque.png", "fig5_flexible_response.png")
PAPER_FIGURES += ("fig6_state_estimates.png", "fig7_whole_chain.png", "fig8_load_torque.png")
PAPER_FIGURES += ("fig9_flexible_link.png", MOTION_FIGURE)

#: Every run :func:`reproduce` may write as CSV (``all_csv``), each with its units sidecar.
RUNS = ("selfid.csv", *(f"rigid_seed{seed}.csv" for seed in SEEDS), "flexible.csv")
RUNS += ("identification.csv", "whole_chain.csv", "load_true_chain.csv")
RUNS += ("load_identified_chain.csv", "flexible_link.csv")
#: The files :func:`reproduce` writes into its folder.
OUTPUTS = (*RUNS, *(units_path(run).name for run in RUNS), *PAPER_FIGURES, "report.md")


def reproduce(
    out: Path,
    ideal: bool = False,
    show_progress: bool = True,
    fmu_dir: Path | None = None,
    force: bool = False,
    all_csv: bool = False,
    tool_names: bool = False,
) -> Results:
    """Run the seven experiments, write CSVs, figures and ``report.md`` into ``out``.

    Parameters
    ----------
    out : Path
        The folder to write into (created if needed).
    ideal : bool
        Ideal sensors (exact angle, true velocity, no noise) instead of the realistic
        2000-count encoder and 5 mA rms current noise.
    show_progress : bool
        Whether to show a progress bar on stderr (what runs, then the figures).
    fmu_dir : Path, optional
        Folder of the FMUs, built there if missing or stale (default: the per-user cache).
    force : bool
        Whether the files of :data:`OUTPUTS` may be replaced (those the run does not
        write are kept, and named in a warning: :func:`~arcosim.outputs.warn_left_over`).
    all_csv : bool
        Whether to write every run with every signal rather than :data:`DEFAULT_CSV`,
        each with the log's columns only.
    tool_names : bool
        Whether the CSV columns are named for other tools (:func:`arcosim.logs.tool_name`).

    Returns
    -------
    Results
        What the experiments found, and every file written.

    Raises
    ------
    UserError
        When ``out`` is not a folder that can be written, or one of :data:`OUTPUTS`
        exists in it and not ``force`` (checked before any run); every file is written
        atomically.

    Examples
    --------
    ``arcosim.reproduce(Path("reports"))`` runs them all (a minute or two) and
    ``print(results.text())`` shows their tables. A folder that holds an earlier report
    is refused before anything runs:

    >>> import tempfile
    >>> from pathlib import Path
    >>> out = Path(tempfile.mkdtemp())
    >>> _ = (out / "report.md").write_text("")
    >>> arcosim.reproduce(out)
    Traceback (most recent call last):
    ...
    arcosim.errors.UserError: --out ...: report.md exist(s) already; add --force ...
    """
    from tqdm import tqdm

    check_output_folder(out)
    if not force:
        refuse_existing(out, OUTPUTS)
    folder = ensure_built(N_MASSES, fmu_dir)
    results = Results()
    with tqdm(
        total=_total_steps(),
        unit="step",
        unit_scale=True,
        disable=not show_progress,
        desc="reproduce",
    ) as bar:
        bench = _Bench(
            out, folder, ideal, results, bar.update, bar.set_postfix_str, all_csv, tool_names
        )
        actuator = _self_identification(bench)
        rigid, k_mean, b_mean = _rigid_maneuvers(bench, actuator)
        flexible = _flexible_maneuver(bench, actuator, k_mean, b_mean)
        identification, estimated = _whole_chain(bench, actuator, flexible)
        loaded = _load_torque(bench, actuator) if estimated is not None else None
        link = _flexible_link(bench)
        bar.set_postfix_str(f"writing the figures and report.md into {out}")
        if loaded is not None:
            results.files.append(load_torque_figure(out, loaded))
        results.files += paper_figures(out, rigid, flexible, results, k_mean, b_mean, estimated)
        if estimated is not None:
            results.files.append(whole_chain_figure(out, identification, results))
        results.files.append(link_figure(out, *link))
        results.motion, figure = motion_control(out, folder, ideal, bar.set_postfix_str, bar.update)
        results.files.append(figure)
        report = report_markdown(results, ideal, k_mean, b_mean)
        results.files.append(write_text(out / "report.md", report, force=True))
    warn_left_over(out, OUTPUTS, results.files)
    return results


def _total_steps() -> int:
    """The co-simulation steps of the seven experiments, for the progress bar (a count)."""
    return (
        round(SCENARIOS["selfid"].duration / STEP)
        + len(SEEDS) * round(SCENARIOS["rigid"].duration / STEP)
        + 2 * round(SCENARIOS["flexible"].duration / STEP)
        + round(SCENARIOS["identification"].duration / STEP)
        + 2 * round(LOAD_PROFILE.duration / STEP)
        + round(LINK_DURATION / STEP)
        + motion_steps()
    )


@dataclass
class _Bench:
    """Where the experiments run and write: the output folder, the FMUs, the sensors,
    the results being filled in, and the progress bar's two calls."""

    out: Path
    folder: Path
    ideal: bool
    results: Results
    progress: Callable[[int], object]
    status: Callable[[str], object]
    all_csv: bool = False
    tool_names: bool = False

    def run(self, name: str, **settings: dict) -> Recording:
        """Co-simulate the scenario ``name`` on the bench (``plant=``, ``observer=``)."""
        self.status(name)
        return run_scenario(
            SCENARIOS[name],
            N_MASSES,
            ideal=self.ideal,
            fmu_dir=self.folder,
            progress=self.progress,
            **settings,
        )

    def keep(self, name: str, recording: Recording) -> None:
        """Write ``recording`` as the CSV ``name`` in the output folder: with
        ``all_csv`` every signal, else only a run of :data:`DEFAULT_CSV`, its log."""
        if self.all_csv or name in DEFAULT_CSV:
            columns = recording_columns(recording, log_only=not self.all_csv)
            path = write_csv(
                self.out / name,
                columns,
                units=recording.units,
                tool_names=self.tool_names,
                force=True,
            )
            self.wrote_csv(path)

    def wrote_csv(self, path: Path) -> None:
        """Count the CSV ``path`` and its units sidecar among the files written."""
        self.results.files += [path, units_path(path)]

    @functools.cached_property
    def encoder_cpr(self) -> int:
        """The plant's encoder counts per revolution (0: ideal sensors, no counts)."""
        if self.ideal:
            return 0
        return int(fmu_variables(self.folder)["plant"]["encoder_cpr"].start)


def _self_identification(bench: _Bench) -> dict[str, float]:
    """Experiment 1: the actuator terms, the load detached (mode 0).

    Fills ``results.actuator``; returns the terms as observer parameters (``dkt``,
    ``dJm``, ``D_m``, ``f_c``) for the experiments after it.
    """
    selfid = bench.run("selfid")
    final = {k.split(".", 1)[1]: v[-1] for k, v in selfid.signals.items()}
    bench.results.actuator = {
        k: float(final[k])
        for k in ("dkt_hat", "dJm_hat", "D_m_hat", "f_c_hat", "self_id_rank_deficient")
    }
    bench.keep("selfid.csv", selfid)
    return {
        "dkt": final["dkt_hat"],
        "dJm": final["dJm_hat"],
        "D_m": final["D_m_hat"],
        "f_c": final["f_c_hat"],
    }


def _rigid_maneuvers(bench: _Bench, actuator: dict[str, float]) -> tuple[Recording, float, float]:
    """Experiment 2: k and B from five rigid maneuvers (mode 1), one per seed.

    Fills ``results.rigid``; returns the first maneuver's recording (Fig. 4's) and the
    mean k̂ (N·m/rad) and B̂ (N·m·s/rad).
    """
    runs = []
    for seed in SEEDS:
        rec = bench.run("rigid", plant={"seed": seed}, observer=actuator)
        k_hat, b_hat = rec["observer.k_hat"][-1], rec["observer.B_hat"][-1]
        bench.results.rigid.append(
            {
                "seed": seed,
                "k": float(k_hat),
                "B": float(b_hat),
                "valid": bool(rec["observer.id_valid"][-1]),
            }
        )
        bench.keep(f"rigid_seed{seed}.csv", rec)
        runs.append(rec)
    k_mean = float(np.mean([r["k"] for r in bench.results.rigid]))
    b_mean = float(np.mean([r["B"] for r in bench.results.rigid]))
    return runs[0], k_mean, b_mean


def _flexible_maneuver(
    bench: _Bench, actuator: dict[str, float], k_mean: float, b_mean: float
) -> Recording:
    """Experiment 3: every mass's angle by the paper's recursion (mode 2), with the
    uniform chain of experiment 2's mean k̂ (N·m/rad) and B̂ (N·m·s/rad, at least 0).

    Fills ``results.scores``; returns the recording (Figs. 5 and 6).
    """
    chain = {
        f"{p}[{i}]": v
        for i in range(1, N_MASSES + 1)
        for p, v in (("k", k_mean), ("B", max(b_mean, 0.0)))
    }
    flexible = bench.run("flexible", observer={**actuator, **chain})
    bench.keep("flexible.csv", flexible)
    bench.results.scores = _angle_scores(flexible, flexible["plant.theta_m_true"])
    return flexible


def _whole_chain(
    bench: _Bench, actuator: dict[str, float], flexible: Recording
) -> tuple[Recording, Recording | None]:
    """Experiment 4: the whole chain (n too) from one identification record, then every
    mass's angle by the model-based observer with it on experiment 3's maneuver.

    Fills ``results.masses``, ``whole_chain``, ``whole_chain_std`` and, when n is the
    plant's, ``whole_scores``; returns the identification record and the observer's run
    (None when n is not the plant's: the FMUs cannot co-simulate).
    """
    results = bench.results
    identification = bench.run("identification", plant={"seed": 1}, observer=actuator)
    bench.keep("identification.csv", identification)
    bench.status("whole-chain fit")
    choice = _fit_whole_chain(identification, results.actuator, bench.encoder_cpr)
    results.masses = choice.n
    results.whole_chain = choice.fit.as_dict()
    results.whole_chain_std = choice.fit.std_dict()
    if choice.n != N_MASSES:
        return identification, None
    identified = {**actuator, **results.whole_chain, "estimator": int(Estimator.MODEL_BASED)}
    estimated = bench.run("flexible", observer=identified)
    bench.keep("whole_chain.csv", estimated)
    results.whole_scores = _angle_scores(estimated, flexible["plant.theta_m_true"])
    return identification, estimated


def _load_torque(bench: _Bench, actuator: dict[str, float]) -> dict[str, Recording]:
    """Experiment 5: the load torque on mass 3 from the motor alone, with the true chain
    and with experiment 4's (which must have the plant's n).

    Fills ``results.load`` and ``results.load_angles``; returns the runs by chain.
    """
    results = bench.results
    loaded = {}
    for label, chain, name in (
        ("true chain", TRUE_CHAIN, "load_true_chain.csv"),
        ("identified chain", results.whole_chain, "load_identified_chain.csv"),
    ):
        loaded[label] = bench.run(LOAD_PROFILE.scenario().name, observer={**actuator, **chain})
        bench.keep(name, loaded[label])
    for label, rec in loaded.items():
        estimate = rec["observer.tau_load_hat"]
        results.load[label] = score_profile(rec.time, estimate, LOAD_PROFILE).as_dict()
        results.load_angles[label] = _angle_scores(rec, rec["plant.theta_m_true"])
    results.load_angles["true chain, no torque state"] = _angles_without_torque_state(
        loaded["true chain"], results.actuator, bench.encoder_cpr
    )
    return loaded


def _flexible_link(bench: _Bench) -> tuple[LinkRun, dict[str, np.ndarray]]:
    """Experiment 6: the link plant FMU driven by a multi-sine, identified from its hub's
    current and encoder alone (EI, ρA, the damping), then eq. 7's reaction torque and the
    tip angle over the record by the fitted model's smoother.

    Fills ``results.link``; returns the run and the estimates (Fig. 9).
    """
    bench.status("flexible link")
    run = simulate_link(bench.folder / LINK_FMU, EXPERIMENT_RIG)
    bench.progress(len(run.time) - 1)
    bench.status("flexible-link fit")
    findings = score_link(run, EXPERIMENT_RIG)
    bench.results.link = findings.as_dict()
    columns = run.log()  # the log; with all_csv the plant's truth and the estimates too
    if bench.all_csv:
        columns.update(run.signals)
        columns.update({f"{name}_hat": x for name, x in findings.estimates.items()})
    path = write_csv(
        bench.out / "flexible_link.csv",
        columns,
        units={name: LINK_UNITS[name.removesuffix("_hat")] for name in columns},
        tool_names=bench.tool_names,
        force=True,
    )
    bench.wrote_csv(path)
    return run, findings.estimates


def _angle_scores(run: Recording, motor: np.ndarray) -> list[float]:
    """:func:`flexible_score` of every mass's estimated angle in ``run`` against the
    plant's, over the true motor angle ``motor`` (rad, shape (N,))."""
    return [
        flexible_score(run[f"observer.theta_hat[{i}]"], run[f"plant.theta[{i}]"], motor)
        for i in range(1, N_MASSES + 1)
    ]


def _angles_without_torque_state(
    rec: Recording, actuator: dict[str, float], cpr: int
) -> list[float]:
    """Experiment 5's run and true chain without the torque state: what the unmodelled
    load costs, as every mass's angle score."""
    settings = ObserverSettings(
        mode=Mode.STATE_ESTIMATION,
        actuator=_terms(actuator),
        g_dist=G_DIST,
        g_lpf=G_DIST,
        J=tuple(defaults.J),
        k=(defaults.K,) * N_MASSES,
        B=(defaults.B,) * N_MASSES,
        estimator=Estimator.MODEL_BASED,
        encoder_cpr=cpr,
    )
    log = {c: rec[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")}
    log["time"] = rec.time
    theta = estimate_states(settings, log)
    motor = rec["plant.theta_m_true"]
    return [
        flexible_score(theta[:, i], rec[f"plant.theta[{i + 1}]"], motor) for i in range(N_MASSES)
    ]


def _terms(actuator: dict[str, float]) -> Actuator:
    """The actuator terms experiment 1 identified, on the bench's nominal J_m and k_t."""
    return Actuator(
        defaults.J_M,
        defaults.K_T,
        actuator["dkt_hat"],
        actuator["dJm_hat"],
        actuator["D_m_hat"],
        actuator["f_c_hat"],
    )


def _fit_whole_chain(
    identification: Recording, actuator: dict[str, float], cpr: int
) -> ChainChoice:
    """Experiment 4's fit: every J_i, k_i, B_i and n from the motor's signals alone."""
    terms = _terms(actuator)
    signals = [identification[f"plant.{c}"] for c in ("i_a", "omega_m", "theta_m")]
    record = motor_record(identification.time, *signals, terms, G_DIST)
    encoder = None
    if cpr > 0:  # ideal sensors: no counts
        encoder = encoder_record(identification.time, signals[0], signals[2], terms, cpr)
    return identify_whole_chain(record, "auto", encoder)
