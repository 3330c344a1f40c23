"""``cosim/identification/fit/`` installed as ``arcosim.identification.fit``:
the chain's parameters fitted to a record, and its structure chosen.

Modules:

linear_model    -- the linear-model numerics on numpy: expm, the zero-order hold, the
                   Riccati equation by doubling (the FMU package's, on numpy)
newey_west      -- standard errors of a fit whose residuals are coloured
modal_recursion -- linear recursions over a whole record in modal coordinates
output_error    -- the output-error fit every chain fit shares: predict τ̂_reac, fit it,
                   on growing openings (ParameterFit, fit, continued_fit)
uniform_fit     -- the paper's uniform chain: one k and one B (uniform_chain)
kalman          -- motor and chain as one linear model; its Kalman predictor, smoother
encoder_fit     -- the prediction-error fit from the current to the encoder (refine)
motor_friction  -- the motor's friction when only k_t and J_m are given: its start
rigid_drive     -- the rigid drive, n = 0: the load inertia J_total − J_m (rigid_fit)
structure_choice-- the stated rule that picks n, the friction form, the load model
periodic_misfit -- a model against a periodic record's own noise: the response at the
                   played lines averaged over the periods, its spread, the misfit's χ²
                   test, the smallest adequate structure (periodic_response, misfit)
whole_chain     -- every J_i, k_i, B_i and n from the motor alone (identify_whole_chain,
                   ChainChoice)
refusal         -- a whole-chain result's assumptions, and why a record cannot support a
                   chain (missing_modes)
weak_modes      -- the chain without the weak modes it keeps, for the floor's check
                   (without_weak_modes)
"""
