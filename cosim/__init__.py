"""``cosim/`` installed as ``arcosim``: sensorless identification and state estimation of
flexible drives.

A motor drives a chain of inertias joined by springs (a robot joint, a belt drive,
a multi-inertia test bench). From the motor's current and encoder alone, arcosim
estimates the load disturbance, the reaction torque, every inertia, stiffness and
damping of the chain, and the angle of every load mass (the action-reaction method
of Khalil and Sabanovic; ``docs/method.md``). It ships the method as FMI 2.0
co-simulation FMUs and this library on fmpy. Units are SI throughout: A, rad,
rad/s, N·m, kg·m², N·m/rad, N·m·s/rad, s.

Drive logs
----------
read_log            -- a drive log (CSV: time, i_a, omega_m, theta_m) as a DriveLog
DriveLog            -- time (s) and the measured columns of a log, SI units
write_csv           -- columns of equal length as a CSV file
parse_scales        -- ``--scale COLUMN=FACTOR`` texts as the factors read_log takes
read_text_file      -- a UTF-8 text file's text; any other encoding refused, naming it
tool_keys           -- JSON data with every key as other tools keep names (``J_1``)
COLUMN_UNITS        -- the unit (SI) of each column arcosim writes, by the column's name
read_chain          -- the Chain of a whole-chain report file
Chain               -- a chain's values: n, J_m, every J_i, k_i, B_i, the friction, σ where known

Identifying the drive from a log (numpy/scipy, no FMU needed)
-------------------------------------------------------------
identify_drive      -- every J_i, k_i, B_i (and n) from a log, k_t and J_m known
DriveIdentification -- its result: the chain, standard errors, assumptions, evidence
Verdict             -- whether a fit is trusted, and the reasons when not (its .verdict)
check_log           -- can a log support identification? (before any fit)
identify_link       -- a flexible link's EI, ρA, damping and modes from its hub's log
identify_uniform_chain -- the paper's uniform chain (one k, one B) by output error, J_i known
UniformChainIdentification -- its result: the chain, the fit, the report
design_excitation   -- the multi-sine to play on the drive for identification
Actuator            -- the motor's terms: J_mo, k_to, Δk_t, ΔJ, D_m, f_c
motor_record        -- a log as the reaction-torque record the fits use
encoder_record      -- a log as the current → encoder record of the refinement
identify_whole_chain -- the whole-chain fit from those records (what identify_drive runs)
uniform_chain       -- the paper's uniform chain: k and B by output error
estimate_load_torque -- the torque on a load mass over a log (the observer's estimator)
LoadEstimate        -- its result: the torque, the load angles, the summary
ObserverSettings    -- the observer FMU's parameters as one value (estimate_load_torque's)

Motion and vibration control (the FMU's algorithms, standard library; margins on numpy)
-------------------------------------------------------------------------------
design_controller   -- state feedback and reference shaping for a chain and a move time
ControllerDesign    -- its result: the discrete model, the gain, the goals
MotionController    -- moves a load mass and damps the chain from current and encoder
controller_margins  -- both loops' margins for a chain and goals, model errors included (numpy)
ControllerMargins   -- its result, with a verdict

Scenarios and co-simulation
---------------------------
SCENARIOS           -- the named scenarios (selfid, rigid, flexible, identification, …)
Scenario            -- a current command, a duration and FMU settings
run_scenario        -- co-simulate plant + observer FMUs through one scenario
cosimulate          -- the fixed-step master for two FMU instances
FmuInstance         -- one FMU instance on fmpy, values by name
Recording           -- time and recorded signals of a run
replay_log          -- feed a drive log to the observer FMU
run_ssp             -- run an SSP system (e.g. ActionReaction.ssp)
reproduce           -- the paper's experiments and four beyond them: tables, report.md, figures

Excitation signals (A, sampled at the step times)
-------------------------------------------------
multisine           -- a sum of sines with random phases, scaled to a peak
rigid_maneuver      -- a slow sine under raised-cosine ramps (mode 1)
chirp               -- a linear frequency sweep
filtered_random     -- low-passed Gaussian noise of a given rms

Condition monitoring of a fleet of axes (Dask)
----------------------------------------------
identify_fleet      -- every new log of every axis identified, one row each in a store
fleet_drift         -- each axis's parameters against its baseline; alarms on drift
fleet_figures       -- the drift drawn: an overview of every axis, a figure per alarmed one

Building and checking FMUs
--------------------------
build_all           -- build the three FMUs and their SSP into a folder
ensure_built        -- the folder of current FMUs, built if needed (per-user cache)
validate            -- FMI compliance and behaviour checks of an FMU file

Files a command writes (checked before the work, written atomically, never over an input)
------------------------------------------------------------------------------------------
check_output        -- refuse an output file before the work starts unless it can be written
check_output_folder -- the same for an output folder, created
refuse_existing     -- refuse a folder that already holds files a command would write
same_file           -- whether two paths name one file
write_text          -- text written atomically (UTF-8)
write_bytes         -- bytes written atomically
save_figure         -- a matplotlib figure saved atomically

Errors
------
ArcosimError        -- base of every error arcosim raises for a user to fix
UserError           -- a bad argument, file or datum
BuildError          -- an FMU could not be built
IdentificationError -- a record or setting the identification cannot work with
RefusedFitError     -- a record that cannot support a whole-chain fit (exit status 1)
ChainFileError      -- a chain file read_chain cannot read

The paper's experiments and the report are the command ``arcosim reproduce``
(:func:`reproduce`, its tables :meth:`~arcosim.experiments.findings.Results.text`).

Every name above is importable from ``arcosim`` directly (loaded on first use, so
``import arcosim`` stays fast); the subpackages are ``arcosim.identification``,
``arcosim.host``, ``arcosim.build``, ``arcosim.control``, ``arcosim.experiments``,
``arcosim.sweeps``, ``arcosim.fleet``, ``arcosim.fmu`` (the code inside the FMUs) and
``arcosim.plant``.

Modules and subpackages, in the order data flows (each subpackage's docstring lists its
modules):

fmu (``fmu_src/``)        -- the code inside the FMUs: the algorithms and every default
plant (``plant_models/``) -- the plant: a Python reference and the C sources
build                     -- the FMUs built into a folder or the per-user cache
portability               -- what makes an FMU portable, checked on its files
host                      -- the FMUs run on fmpy: instances, the master, replay, SSP, validation
logs                      -- drive logs read and checked; recordings written as CSV
identification            -- the drive identified offline from a log (numpy/scipy, no FMU)
chainfile                 -- a whole-chain report read back as its chain (``read_chain``)
control                   -- the motion controller's margins checked on numpy (``arcosim control``)
experiments               -- the paper's experiments on the simulated bench, the report
sweeps                    -- Monte Carlo and grid sweeps of co-simulations
fleet                     -- many axes identified over time, and their parameters' drift
outputs                   -- every file a command writes: checked first, written atomically
errors, version           -- the errors a user can fix; the installed version
lazy                      -- a package's public names, each loaded on first use
cli, __main__             -- the ``arcosim`` command (imported by nothing else)

Examples
--------
>>> import arcosim
>>> arcosim.Actuator(J_mo=2.09e-5, k_to=0.0406).k_to
0.0406
"""

from __future__ import annotations

from arcosim.lazy import public_api
from arcosim.version import __version__

#: Public name → the module that defines it.
_API = {
    "read_log": "arcosim.logs",
    "DriveLog": "arcosim.logs",
    "write_csv": "arcosim.logs",
    "parse_scales": "arcosim.logs",
    "read_text_file": "arcosim.logs",
    "tool_keys": "arcosim.logs",
    "COLUMN_UNITS": "arcosim.logs",
    "read_chain": "arcosim.chainfile",
    "Chain": "arcosim.fmu.flexchain.chain",
    "identify_drive": "arcosim.identification.drive_identification",
    "DriveIdentification": "arcosim.identification.drive_identification",
    "Verdict": "arcosim.identification.checks.verdict",
    "check_log": "arcosim.identification.checks.log_check",
    "identify_link": "arcosim.identification.link.link_identification",
    "identify_uniform_chain": "arcosim.identification.uniform_identification",
    "UniformChainIdentification": "arcosim.identification.uniform_identification",
    "design_excitation": "arcosim.identification.excitation.design",
    "estimate_load_torque": "arcosim.identification.load_torque",
    "LoadEstimate": "arcosim.identification.load_torque",
    "ObserverSettings": "arcosim.fmu.flexchain.observer",
    "Actuator": "arcosim.fmu.flexchain.dob",
    "motor_record": "arcosim.identification.records.record",
    "encoder_record": "arcosim.identification.records.record",
    "identify_whole_chain": "arcosim.identification.fit.whole_chain",
    "uniform_chain": "arcosim.identification.fit.uniform_fit",
    "design_controller": "arcosim.fmu.flexchain.control.design",
    "ControllerDesign": "arcosim.fmu.flexchain.control.design",
    "MotionController": "arcosim.fmu.flexchain.control.controller",
    "controller_margins": "arcosim.control.margins",
    "ControllerMargins": "arcosim.control.margins",
    "SCENARIOS": "arcosim.experiments.scenarios",
    "Scenario": "arcosim.experiments.scenarios",
    "run_scenario": "arcosim.experiments.scenarios",
    "cosimulate": "arcosim.host.master",
    "FmuInstance": "arcosim.host.instance",
    "Recording": "arcosim.host.master",
    "replay_log": "arcosim.host.replay",
    "run_ssp": "arcosim.host.ssp",
    "reproduce": "arcosim.experiments.reproduce",
    "multisine": "arcosim.experiments.current_commands",
    "rigid_maneuver": "arcosim.experiments.current_commands",
    "chirp": "arcosim.experiments.current_commands",
    "filtered_random": "arcosim.experiments.current_commands",
    "identify_fleet": "arcosim.fleet.identify",
    "fleet_drift": "arcosim.fleet.drift",
    "fleet_figures": "arcosim.fleet.figures",
    "build_all": "arcosim.build.builder",
    "ensure_built": "arcosim.build.builder",
    "validate": "arcosim.host.validate",
    "check_output": "arcosim.outputs",
    "check_output_folder": "arcosim.outputs",
    "refuse_existing": "arcosim.outputs",
    "same_file": "arcosim.outputs",
    "write_text": "arcosim.outputs",
    "write_bytes": "arcosim.outputs",
    "save_figure": "arcosim.outputs",
    "ArcosimError": "arcosim.errors",
    "UserError": "arcosim.errors",
    "BuildError": "arcosim.errors",
    "IdentificationError": "arcosim.identification.errors",
    "RefusedFitError": "arcosim.identification.errors",
    "ChainFileError": "arcosim.chainfile",
}
_names, __getattr__, __dir__ = public_api("arcosim", _API, globals())
__all__ = ["__version__", *_names]
