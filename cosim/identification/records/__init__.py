"""``cosim/identification/records/`` installed as ``arcosim.identification.records``:
the records a log gives every fit.

Modules:

record          -- the two records every fit reads: MotorRecord (θ_m, τ̂_reac) and EncoderRecord
                   (k_t·i_a in, encoder counts out); their openings
low_pass        -- the zero-phase low-pass of the offline velocity (low_passed)
"""
