"""``cosim/experiments/motion/`` installed as ``arcosim.experiments.motion``: experiment 7,
a move of the last mass by four controllers.

Modules, in the order data flows:

baselines   -- a drive's cascade tuned out of the box, and input shapers (ZV, ZVD)
metrics     -- how a move is scored (settling, residual, peak current, limit cycle)
experiment  -- the move by four controllers, Fig. 10
findings    -- its setup, scores, the four-criteria check, tables and report text
"""
