"""``cosim/experiments/`` installed as ``arcosim.experiments``: the paper's experiments
on the simulated bench, and the report of ``arcosim reproduce``.

Modules, in the order data flows:

current_commands -- current commands (A) over arrays of step times: multi-sine, chirp, …
scenarios        -- a current command, a duration and FMU settings, run as one co-simulation
paper            -- the paper's own Table II, in SI units
metrics          -- how estimates are scored against the plant's truth
load_scores      -- how a load torque estimate is scored (settling, settled error, lag)
flexible_link    -- a flexible link on the link plant FMU: its run, the fit from the hub, scores
reproduce        -- the seven experiments, one function each (``reproduce``)
findings         -- what they found, as tables and as ``report.md``'s text
reproduce_figures -- Figs. 4–9 from the runs and what they found
report           -- the figures drawn, and tables as Markdown or text
tracking_figure  -- a tracked replay drawn: each parameter, its ±σ band, the commissioning value
control_scenarios -- the closed-loop scenarios: the controller FMU moving the plant's last mass
closed_loop      -- the plant FMU with a Python controller in the loop (sequential, zero delay)
motion/          -- experiment 7: a move of the last mass by four controllers (baselines,
                    metrics, experiment, findings)

Sits above :mod:`arcosim.host`, :mod:`arcosim.build` and :mod:`arcosim.identification`.
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "IDEAL_SENSORS": "arcosim.experiments.scenarios",
    "recording_columns": "arcosim.experiments.scenarios",
    "CONTROL_SCENARIOS": "arcosim.experiments.control_scenarios",
    "run_control_scenario": "arcosim.experiments.control_scenarios",
    "move_summary": "arcosim.experiments.control_scenarios",
    "Results": "arcosim.experiments.findings",
    "draw_tracking": "arcosim.experiments.tracking_figure",
    "BROADBAND_LINES": "arcosim.experiments.scenarios",
    "IDENTIFICATION_LINES": "arcosim.experiments.scenarios",
    "IDENTIFICATION_DURATION": "arcosim.experiments.scenarios",
    "identification_current": "arcosim.experiments.scenarios",
    "LoadProfile": "arcosim.experiments.scenarios",
    "percent_error": "arcosim.experiments.metrics",
    "flexible_score": "arcosim.experiments.metrics",
    "LoadScore": "arcosim.experiments.load_scores",
    "score_profile": "arcosim.experiments.load_scores",
    "markdown_table": "arcosim.experiments.report",
    "LINK_FMU": "arcosim.experiments.flexible_link",
    "LINK_DURATION": "arcosim.experiments.flexible_link",
    "LinkRig": "arcosim.experiments.flexible_link",
    "LinkRun": "arcosim.experiments.flexible_link",
    "simulate_link": "arcosim.experiments.flexible_link",
    "score_link": "arcosim.experiments.flexible_link",
    "clamped_frequencies": "arcosim.experiments.flexible_link",
    "LoopRun": "arcosim.experiments.closed_loop",
    "OpenLoop": "arcosim.experiments.closed_loop",
    "run_closed_loop": "arcosim.experiments.closed_loop",
    "CascadeController": "arcosim.experiments.motion.baselines",
    "cascade_gains": "arcosim.experiments.motion.baselines",
    "chain_modes": "arcosim.experiments.motion.baselines",
    "identify_chain": "arcosim.experiments.motion.experiment",
    "design_parameters": "arcosim.experiments.motion.experiment",
    "sensorless": "arcosim.experiments.motion.experiment",
    "scaled": "arcosim.experiments.motion.experiment",
    "model_errors": "arcosim.experiments.motion.experiment",
    "Runs": "arcosim.experiments.motion.experiment",
    "DISTANCE": "arcosim.experiments.motion.findings",
    "MOVE_TIME": "arcosim.experiments.motion.findings",
    "MOTION_DURATION": "arcosim.experiments.motion.findings",
    "I_MAX": "arcosim.experiments.motion.findings",
    "UPPER_BOUND_FACTOR": "arcosim.experiments.motion.findings",
    "MoveScore": "arcosim.experiments.motion.findings",
    "score_move": "arcosim.experiments.motion.findings",
    "done_when": "arcosim.experiments.motion.findings",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
