"""``cosim/identification/link/`` installed as ``arcosim.identification.link``:
a flexible link on a hub.

Modules:

beam_model      -- a beam on a hub: its clamped modes, hub participations, tip shape
                   (Link, ModalModel, modal_model)
beam_fit        -- EI, ρA, damping (or the modal model) from current and encoder
                   (fit_link, fit_modes, Geometry)
link_identification -- the whole job on a link from its hub's log (identify_link,
                   LinkIdentification)
beam_motion     -- the tip's deflection and eq. 7's reaction torque over a log
                   (tip_motion), the linear model's limits
"""
