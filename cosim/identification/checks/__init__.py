"""``cosim/identification/checks/`` installed as ``arcosim.identification.checks``:
can a log support a fit, and is a fit trusted.

Modules:

plausibility    -- are the log's units and length plausible? (the step against the motion,
                   the torque balance, the record's length against the lowest line and mode)
log_decision    -- the one set of decisions check reports and identify refuses by
                   (decide_log, LogDecision)
log_check       -- can a log support identification? (check_log, CheckReport)
noise_floor     -- the residual the encoder's counts and the current's noise explain
frf             -- the measured response torque → motor speed (H1 at the lines, Welch,
                   indirect), the model's, the residual against the noise floor
above_band      -- does a mode lie above 3·g_dist? the response there against a drive's
                   mode-free form, a χ² test (above_band_test, AboveBand)
verdict         -- is a fit trusted? the reasons when not, each naming what to check
                   (Verdict, judge)
"""
