"""``cosim/identification/`` installed as ``arcosim.identification``: identifying a flexible
drive offline from its log, on numpy and scipy alone (no FMU, no FMI host).

The subpackages in pipeline order: the records a log gives, the excitation they carry,
the modes they show, the fits, the flexible link; then the checks of a log before a fit
and of a fit after it. The public entry points are importable from ``arcosim`` directly.

Subpackages
-----------
records             -- the records a log gives every fit
excitation          -- what the excitation is, the band it shows modes in, and the one to play
modes               -- the modes a record shows, and the chain they belong to
fit                 -- the chain's parameters fitted to a record, and its structure chosen
link                -- a flexible link on a hub
checks              -- can a log support a fit, and is a fit trusted

Modules
-------
drive_identification -- the whole job from a log
load_torque          -- the torque on a load mass over a log
uniform_identification -- the paper's uniform chain by output error, with its report
offline_observer     -- the observer FMU's algorithms run over a log
threads              -- one BLAS thread inside the fits
errors               -- IdentificationError
"""

from arcosim.lazy import public_api

#: Public name → the module that defines it (the package's API; ``tests/test_public_api.py``).
_API: dict[str, str] = {
    "LINES": "arcosim.identification.excitation.design",
    "DURATION": "arcosim.identification.excitation.design",
    "search_band": "arcosim.identification.excitation.band",
    "MAX_AUTO_MASSES": "arcosim.identification.fit.whole_chain",
    "MeasuredResponse": "arcosim.identification.checks.frf",
    "measured_response": "arcosim.identification.checks.frf",
    "model_response": "arcosim.identification.checks.frf",
    "residual_spectrum": "arcosim.identification.checks.frf",
    "current_noise": "arcosim.identification.checks.noise_floor",
    "identify_uniform_chain": "arcosim.identification.uniform_identification",
    "UniformChainIdentification": "arcosim.identification.uniform_identification",
    "LoadEstimate": "arcosim.identification.load_torque",
    "MotorRecord": "arcosim.identification.records.record",
    "driving_point_modes": "arcosim.identification.modes.chain_modes",
    "chain_from_modes": "arcosim.identification.modes.chain_modes",
    "ParameterFit": "arcosim.identification.fit.output_error",
    "Link": "arcosim.identification.link.beam_model",
    "ModalModel": "arcosim.identification.link.beam_model",
    "modal_model": "arcosim.identification.link.beam_model",
    "Geometry": "arcosim.identification.link.beam_fit",
    "fit_link": "arcosim.identification.link.beam_fit",
    "modal_of": "arcosim.identification.link.beam_fit",
    "tip_motion": "arcosim.identification.link.beam_motion",
    "replay": "arcosim.identification.offline_observer",
    "estimate_states": "arcosim.identification.offline_observer",
    "single_threaded": "arcosim.identification.threads",
}
__all__, __getattr__, __dir__ = public_api(__name__, _API, globals())
