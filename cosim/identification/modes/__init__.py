"""``cosim/identification/modes/`` installed as ``arcosim.identification.modes``:
the modes a record shows, and the chain they belong to.

Modules:

subspace        -- PO-MOESP subspace identification, one input and one output
detection       -- the record's modes (stabilization diagram, residues) and the chain's
                   start from them (Modes, DetectedModes, detect_modes)
chain_modes     -- a chain and its driving-point modes, both ways (the Lanczos inverse)
"""
