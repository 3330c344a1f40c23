"""``cosim/identification/`` installed as ``arcosim.identification``: identifying a flexible
drive offline from its log, on numpy and scipy alone (no FMU, no FMI host).

The modules in pipeline order: the records a log gives, the modes they show, the fits,
the whole job on a drive; then the log's check before any fit, and the excitation to
record. The public entry points are importable from ``arcosim`` directly.

Records
-------
records           -- the two records every fit reads: MotorRecord (θ_m, τ̂_reac) and
                     EncoderRecord (k_t·i_a in, encoder counts out); their openings
low_pass          -- the zero-phase low-pass of the offline velocity (low_passed)

Modes
-----
spectrum          -- what the excitation is: lines (leakage-aware), harmonics of one
                     period, or broadband with its band (excitation_spectrum)
harmonics         -- lines that are harmonics of one fundamental (a periodic reference)
line_prominence   -- which found lines are lines: the prominence again on their fitted
                     amplitudes, over the noise and the detrend's remnant
band              -- the band a log shows modes in: min(3·g_dist, 0.3/h) (search_band)
subspace          -- PO-MOESP subspace identification, one input and one output
modal_start       -- the record's modes (stabilization diagram, residues) and the
                     chain's start from them (Modes, DetectedModes, detect_modes)
chain_modes       -- a chain and its driving-point modes, both ways (the Lanczos inverse)

Fit
---
newey_west        -- standard errors of a fit whose residuals are coloured
modal_recursion   -- linear recursions over a whole record in modal coordinates
output_error      -- the output-error fit every chain fit shares: predict τ̂_reac, fit
                     it, on growing openings (ParameterFit, fit, continued_fit)
uniform_fit       -- the paper's uniform chain: one k and one B (uniform_chain)
kalman            -- motor and chain as one linear model; its Kalman predictor, smoother
encoder_fit       -- the prediction-error fit from the current to the encoder (refine)
motor_friction    -- the motor's friction when only k_t and J_m are given: its start
rigid_drive       -- the rigid drive, n = 0: the load inertia J_total − J_m (rigid_fit)
structure_choice  -- the stated rule that picks n, the friction form, the load model
whole_chain       -- every J_i, k_i, B_i and n from the motor alone (identify_whole_chain,
                     ChainChoice)
fit_notes         -- a whole-chain result's assumptions, and why a record cannot
                     support a chain (missing_modes)
noise_floor       -- the residual the encoder's counts and the current's noise explain
weak_modes        -- the chain without the weak modes it keeps, for the floor's check
                     (without_weak_modes)

Flexible link
-------------
beam_model        -- a beam on a hub: its clamped modes, hub participations, tip shape
                     (Link, ModalModel, modal_model)
beam_fit          -- EI, ρA, damping (or the modal model) from current and encoder
                     (fit_link, fit_modes, Geometry)
beam_motion       -- the tip's deflection and eq. 7's reaction torque over a log
                     (tip_motion), the linear model's limits

Drive
-----
drive             -- the whole job from a log (identify_drive, DriveIdentification)
load_torque       -- the torque on a load mass over a log (estimate_load_torque)
offline_observer  -- the observer FMU's algorithms run over a log

Checks
------
plausibility      -- are the log's units and length plausible? (the step against the
                     motion, the torque balance, the record's length against the
                     lowest line and the lowest mode)
log_decision      -- the one set of decisions check reports and identify refuses by
                     (decide_log, LogDecision)
log_check         -- can a log support identification? (check_log, CheckReport)
verdict           -- is a fit trusted? the reasons when not, each naming what to check
                     (Verdict, judge)

View
----
frf               -- the measured response torque → motor speed (H1 at the lines, Welch,
                     indirect), the model's, the residual against the noise floor

Excitation
----------
excitation_design -- the multi-sine to play on a drive (design_excitation, LINE_T)

Support
-------
blas              -- one BLAS thread inside the fits
errors            -- IdentificationError
"""
