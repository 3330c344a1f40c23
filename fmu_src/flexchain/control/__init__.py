"""``fmu_src/flexchain/control/`` installed as ``arcosim.fmu.flexchain.control``: the motion
controller the controller FMU runs, in pure Python (standard library only).

Modules, in the order data flows:

* :mod:`~arcosim.fmu.flexchain.control.design` — the discrete motor and chain, the state
  feedback from the chain and a move time or bandwidth.
* :mod:`~arcosim.fmu.flexchain.control.motor_observer` — the motor's angle and velocity
  below a count at rest, for the hold's dither.
* :mod:`~arcosim.fmu.flexchain.control.move_record` — the samples of a move kept for its fit.
* :mod:`~arcosim.fmu.flexchain.control.move_fit` — the chain refitted from a finished move.
* :mod:`~arcosim.fmu.flexchain.control.refined_estimator` — the chain's estimator, refitted
  from each move.
* :mod:`~arcosim.fmu.flexchain.control.encoder_edge` — the encoder edge a slow motor crosses.
* :mod:`~arcosim.fmu.flexchain.control.hold_edge` — holding near an encoder edge.
* :mod:`~arcosim.fmu.flexchain.control.hold_dither` — the dither that holds against sticking.
* :mod:`~arcosim.fmu.flexchain.control.controller` — the controller: estimates, reference
  shaping, feedback, limit.
"""
