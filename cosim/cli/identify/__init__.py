"""``cosim/cli/identify/`` installed as ``arcosim.cli.identify``: ``arcosim identify``, one
module per method.

Modules:

command       -- ``arcosim identify``: its parser, and the method chosen
options       -- the options every method shares: ``--masses``, ``--out``, the report
observer      -- ``--method observer``: the observer FMU replayed over the log
output_error  -- ``--method output-error``: the uniform chain's k and B
whole_chain   -- ``--method whole-chain``: every J_i, k_i, B_i and n
load_torque   -- ``--method load-torque``: the torque on a load mass over time
beam          -- ``--method beam``: a flexible link's EI, ρA and damping from the hub
plot          -- ``--plot``: the figures of an identification
"""
