"""Every default of the project, in one place (SI units).

The plant's defaults are the paper's bench (Khalil & Sabanovic) in SI units: its linear
springs mapped to rotary values at a 10 mm lever, the motor friction assumed for the
EC-motor class (``docs/method.md``). The sensors, the observer's bandwidths and the
co-simulation step follow. The FMUs declare these as their parameters' start values,
and the offline tools (identification, scenarios, benchmarks) read them from here.
"""

from __future__ import annotations

from .codes import Estimator, Mode

# -- the plant: the paper's bench ---------------------------------------------------
J_M = 2.09e-5  #: motor inertia (kg·m²)
K_T = 0.0406  #: torque constant (N·m/A)
D_M = 2e-5  #: motor viscous friction (N·m·s/rad), assumed
F_C = 2e-3  #: motor Coulomb friction (N·m), assumed
J = (5.15299e-4, 5.15299e-4, 6.192707e-4)  #: load inertias J_1 … J_3 (kg·m²)
K = 0.1627  #: spring stiffness (N·m/rad)
B = 8.88e-6  #: spring damping (N·m·s/rad)
MODES = (16.8, 30.2, 90.1)  #: flexible modes of motor + chain (rad/s)

# -- the sensors ----------------------------------------------------------------------
ENCODER_CPR = 2000  #: encoder counts per revolution after quadrature (0 = ideal)
I_NOISE_STD = 0.005  #: current-sensor noise, standard deviation (A)

# -- the observer -----------------------------------------------------------------------
G_DIST = 100.0  #: bandwidth of the disturbance observer G(s) = g/(s + g) (rad/s)
G_LPF = 100.0  #: bandwidth of the filter on the recursion's later stages (rad/s)
#: Offline, the motor velocity is the angle's derivative smoothed without lag at this
#: many times g_dist (G(s) has removed most of what it cuts there).
VELOCITY_SMOOTHING = 4.0
MODE = Mode.STATE_ESTIMATION  #: what the observer FMU runs unless told otherwise
ESTIMATOR = Estimator.RECURSION  #: mode 2's estimator: the paper's recursion
KAPPA_CORRECTION = True  #: mode 1 applies the multi-mass correction κ
OMEGA_MIN = 5.0  #: mode 0: speed below which the motor counts as stopped (rad/s)
G_ID = 30.0  #: mode 0: bandwidth of the extra low-pass on the fit (rad/s; 0 = none)
TORQUE_NOISE_STD = 1e-4  #: model-based observer: unmodelled torque on each mass (N·m)
TAU_NOISE_STD = 1.5e-3  #: model-based observer: white noise on τ̂_reac (N·m)
LOAD_MASS = 0  #: the load mass whose external torque is estimated (0 = none)
#: Bandwidth ω_L of the load torque estimate (rad/s). Measured on the bench (README,
#: "Sensorless load torque"): 5 rad/s keeps a step's settled error within 1 % with
#: realistic sensors and within 10 % with inertias 1 % off, with a 0.47 s lag at 2 rad/s;
#: 10 rad/s cuts the lag to 0.34 s but quadruples what a 1 % model error leaks in (a
#: model error at a frequency inside the bandwidth looks like a load torque).
LOAD_TORQUE_BANDWIDTH = 5.0
#: Tracking the chain in service (:mod:`~arcosim.fmu.flexchain.chain_tracker`): 0 = off.
TRACKING = 0
#: The tracker's memory (s): samples weigh e^(−age / tracking_time). A minute of the
#: moves of a position loop resolves each stiffness to about 1 % (σ) on the bench's
#: two-mass chain, and wear takes weeks: a minute follows it with room to spare.
TRACKING_TIME = 60.0
#: The relative change of a tracked parameter that counts as drift (dimensionless): 5 %,
#: above the tracker's bias on a healthy chain (about 1 % on the stiffnesses) and below
#: the 10 % that a model-based controller's margins are scored at.
DRIFT_THRESHOLD = 0.05

# -- the excitation source: the rigid maneuver of mode 1 ---------------------------------
#: Peak current (A): well above f_c / k_t ≈ 0.05 A (``waveforms.rigid_maneuver``).
RIGID_AMPLITUDE = 3.0
RIGID_FREQUENCY = 2.1  #: about an eighth of the bench's first mode (rad/s)
RIGID_PERIODS = 8  #: the maneuver's length in periods, ramps included (a count)
RIGID_RAMP_PERIODS = 3  #: each raised-cosine ramp's length in periods (a count)

# -- the co-simulation ----------------------------------------------------------------
STEP = 1e-3  #: communication step (s)


def inertias(n: int) -> list[float]:
    """Load inertias (kg·m²) for n masses: the bench's for n = 3, else J_1 for each."""
    return list(J) if n == 3 else [J[0]] * n


# -- the flexible link (the FlexLinkPlant FMU, plant_models/flexlink_c) ------------------
#: A 0.4 m aluminium strip (about 20 mm × 2.4 mm) with a 20 g tip mass on the bench's
#: motor: first clamped mode 39.8 rad/s with the tip mass (69.5 rad/s without).
#: Hermite cubic elements of the built FMU (``arcosim build --elements``): the first three
#: clamped modes within 0.2 %. The fastest element mode grows as the count squared and its
#: decay β ω² as the count to the fourth: past 8 elements take a lower ``LINK_BETA`` (the
#: FMU refuses decays over 1e6 1/s).
LINK_ELEMENTS = 6
LINK_EI = 1.0  #: bending stiffness EI (N·m²)
LINK_RHOA = 0.1  #: mass per length ρA (kg/m)
LINK_L = 0.4  #: length from the clamp to the tip (m)
LINK_M_TIP = 0.02  #: tip mass (kg)
LINK_J_TIP = 0.0  #: tip mass's inertia about its own centre (kg·m²)
LINK_R_HUB = 0.01  #: radius of the clamp from the motor's axis (m)
#: Stiffness-proportional damping β (s): mode j damped ζ_j = β ω_j / 2 (0.1 % for the
#: first clamped mode, 0.8 % for the second).
LINK_BETA = 5e-5


# -- the motion and vibration controller (ActionReactionController) ----------------------
MOVE_TIME = 1.0  #: duration of a shaped point-to-point move (s); 0 = set by the bandwidth
BANDWIDTH = 0.0  #: feedback bandwidth ω_c (rad/s); 0 = set by the move time
I_MAX = 10.0  #: current limit of the controller's command (A)
#: The controller's estimator: unmodelled torque on each load mass (N·m), ten times the
#: observer's TORQUE_NOISE_STD, so the Kalman gain trusts τ̂_reac more than the model: with
#: the observer's 1e-4 the bench's two-mass loop held a 37 mrad limit cycle when the
#: model's J were 10 % high and its k 10 % low; at 1e-3 it settled (1e-2: unstable).
CONTROL_TORQUE_NOISE_STD = 1e-3
#: The reference model's motor speed (rad/s) above which the controller tells its DOB the
#: motor's heading (the reference's): at a move's speeds the motor crosses less than a
#: count per step, and the DOB alone took it as stuck and left the estimator uncorrected
#: (five-mass chain: 1.74 × the full-state bound's settling time, 0.98 × with it; 0.05,
#: 0.3 and 1 rad/s were also tried on `arcosim bench control`'s chains).
CONTROL_MOVING_SPEED = 0.6
#: Until the hold's dither starts, the encoder's edges are weighed against the reference's
#: heading (:meth:`~arcosim.fmu.flexchain.control.encoder_edge.CrossedEdge.heading`): a motor that
#: crosses new edges one way at most this far apart (s; at 2000 counts a third of a rad/s)
#: slides that way until as long again has passed, and for this long after an edge against
#: the reference's heading the DOB decides from its samples. Taken as stuck while it crept
#: to rest after a move, the motor left the DOB's reaction torque the estimator's own
#: prediction (within ±f_c); told the reference's heading while it turned round within a
#: move, the DOB removed friction the wrong way (1 mN·m off over 0.1 s). The four-mass
#: chain's corners (`arcosim bench control`) settled at 2.45 and 1.81 s against full-state
#: bounds of 1.52 and 1.38 s; with the edges at 1.45 and 1.73 s (docs/design/dob-heading.md).
SLIDING_INTERVAL = 10e-3
#: The controller refits its estimator's every J_i and k_i from a move's response
#: (:mod:`~arcosim.fmu.flexchain.control.move_fit`) this share of the move time after the move's
#: start (dimensionless). On `arcosim bench control`'s four-mass chain (20 seeds, 42 runs;
#: a prototype) 0.6, 0.7 and 0.8 met all four criteria on 36, 38 and 35 (none, 23): the
#: choice is within the counts' noise; later leaves the feedback less time, earlier less
#: data (docs/design/move-refit.md).
REFINE_AT = 0.7
#: The fit's low-pass on the open-loop error of τ̂_reac (rad/s): above the chain's modes,
#: below the encoder's noise in the DOB's acceleration.
REFINE_LOWPASS = 150.0
#: A sample counts for the fit once the motor has advanced along the DOB's heading over
#: this long (s) …
REFINE_MOTION_WINDOW = 5e-3
#: … and has kept doing so for this long (s): the DOB's filter and the low-pass forget
#: the friction's error of the samples before.
REFINE_TRUST_AFTER = 0.05
#: The fit's prior (one standard deviation, in log): each mass's own factor on J_i and
#: k_i about the common ones …
REFINE_MASS_SPREAD = 0.075
#: … and the common factors on every J_i and every k_i (dimensionless).
REFINE_COMMON_SPREAD = 0.5
#: The time each sample's squared error stands for in the fit's cost (s): the cost is an
#: integral over the record, whatever the step.
REFINE_DATA_TIME = 1e-3
#: The fit refuses a move whose trusted samples span less than this (s) …
REFINE_MIN_TRUSTED_TIME = 0.05
#: … whose model as it stands misses τ̂_reac by less than this cost (the data's half sum
#: of squares in units of the noise on τ̂_reac; dimensionless): the move does not tell
#: the model's errors from the noise (on the four-mass chain of `arcosim bench control` the
#: identified chain's cost was 0.5–1.2, ±10 % models' 1.7–177) …
REFINE_MIN_EVIDENCE = 3.0
#: … the least cost at which a model already refitted refits (dimensionless): a later
#: move starts from a hold's estimates, not from rest, and a fit on the four-mass chain's
#: return moves (cost 5–7) took the model from 1.8 % to 5–8 % off the plant …
REFINE_AGAIN = 20.0
#: … whose fitted model still misses it by more than this rms (in units of that noise,
#: over the trusted time; dimensionless): the chain model cannot explain the data (there,
#: 0.033–0.060 after every fit; a master alternating 1 and 0.5 ms steps left 0.40) …
REFINE_MAX_MISFIT = 0.15
#: … and factors outside this range from the chain as designed
#: (dimensionless).
REFINE_FACTOR_RANGE = (0.5, 2.0)
#: At most this many Levenberg–Marquardt iterations …
REFINE_ITERATIONS = 10
#: … on forward differences of this step in each log factor (dimensionless).
REFINE_DIFFERENCE_STEP = 1e-3
#: The hold's dither (encoder counts, peak to peak): at rest the controller adds a square
#: current that moves the motor over this much of a count, so that the encoder's reading,
#: less the dither's known path, tells where the motor is inside its count
#: (:mod:`~arcosim.fmu.flexchain.control.hold_dither`); 0 = off. On `arcosim bench control`'s
#: chains at 20 seeds it took the runs meeting all four criteria from 18 to 34 of 126 and
#: those holding the motor within one count from 21 to 42. The amplitude was chosen with
#: the dither observer's velocity fed back as well: 0.5–0.8 did alike on seeds 1–3, 0.9
#: held the tests' bench two-mass chain over two counts (docs/design/hold-dither.md).
HOLD_DITHER = 0.7
#: Its period (s): 125 Hz, far above the chains' modes; taken as a whole number of control
#: steps, a multiple of four and at least four (8 steps at 1 ms).
HOLD_DITHER_PERIOD = 8e-3
#: When it starts: this share of the move time after the reference comes to rest.
HOLD_DITHER_AFTER = 0.5
#: The hold's estimator gain: once the dither runs and the controlled mass's estimate has
#: stayed within HOLD_QUIET_ANGLE (rad) of its target for HOLD_QUIET_TIME (s), the
#: estimators' unmodelled torque is CONTROL_TORQUE_NOISE_STD × HOLD_TORQUE_NOISE_SCALE,
#: until the next move or until the estimate is more than HOLD_QUIET_LEAVE (rad) off (a
#: load step: its residual over 6–8 s 0.74 mrad on the bench three-mass chain with the
#: hold's gain kept, 0.40 with the move's back at 10 mrad, 0.35 at 20). The dither's
#: current and the friction it switches add noise to τ̂_reac that the move's gain passed
#: to the load estimates, and the feedback moved the motor with them: `bench control`'s
#: four-mass chain, seeds 1–3, held one count on 0 of 12 runs, on 7, 10, 12 and 11 of 12
#: at 0.5 (and 0.4), 0.3, 0.2 and 0.1. Switched at the dither's start, with the chain
#: still ringing, its corners settled 0.7 s later (docs/design/hold-estimator-gain.md). The factor
#: (dimensionless):
HOLD_TORQUE_NOISE_SCALE = 0.2
#: … how near its target the controlled mass's estimate must stay (rad),
HOLD_QUIET_ANGLE = 5e-3
#: … for how long before the hold's gain is taken (s),
HOLD_QUIET_TIME = 0.3
#: … and how far off it gives the move's gain back (rad).
HOLD_QUIET_LEAVE = 20e-3
#: Where the hold keeps the motor's mean (:mod:`~arcosim.fmu.flexchain.control.hold_edge`): within
#: HOLD_EDGE_NEAR counts of an encoder edge, so that the dither crosses that edge alone;
#: the hold's target moves by the least that takes it there, up to 0.5 + HOLD_EDGE_SWITCH
#: − HOLD_EDGE_NEAR counts (0 = the mean on an edge, 0.5 = off). With the target half way
#: between two edges (`arcosim bench control --target-offset 0.19`) it took the two-mass
#: chain from 53 to 80 of 80 runs within one count at rest, the three-mass chain from 67
#: to 76 (docs/design/hold-near-edge.md). Counts:
HOLD_EDGE_NEAR = 0.3
#: … how far past the middle of a count the needed angle goes before the other edge is
#: taken (counts): the edge is not traded back and forth on the load estimate's noise,
HOLD_EDGE_SWITCH = 0.1
#: … and the low-pass on that angle (rad/s).
HOLD_EDGE_BANDWIDTH = 2.0
#: Bandwidth of the motor-alone observer that averages the de-dithered reading (rad/s):
#: at 150, with its velocity and the DOB fed from it too, two chains diverged at the J
#: +10 %, k −10 % corner (docs/design/hold-dither.md).
HOLD_OBSERVER_BANDWIDTH = 300.0


# -- the observer on a flexible link (star of modes, ReactionTorqueObserver) -------------
#: The most link modes the observer FMU declares parameters for (a count).
LINK_MODES_MAX = 4
LINK_MODES = 0  #: link modes the observer runs on (0 = the chain of J, k, B)
#: The default link's (LINK_EI … LINK_BETA above) hub-locked modes as
#: ``arcosim.identification.link.beam_model.modal_model`` gives them (24 elements, rounded):
#: frequencies ω_i (rad/s), damping ratios β ω_i / 2, hub participations b_i (kg·m per
#: modal unit, i.e. √kg·m) and tip shape values φ_i(L) (m per modal unit).
LINK_OMEGA = (39.8506, 334.044, 1021.83, 2096.2)
LINK_ZETA = (0.0009963, 0.008351, 0.02555, 0.05241)
LINK_PARTICIPATION = (0.0743893, 0.0102678, 0.00362431, 0.00188969)
LINK_TIP_SHAPE = (5.81171, -2.61984, 1.70307, -1.24195)
#: The default link's inertia outside its four modes, rigid on the hub (kg·m²).
LINK_J_RIGID = 3.42719e-6
