"""``plant_models/motorchain/`` installed as ``arcosim.plant.motorchain``: the
motor–spring–mass chain plant in Python, the reference of the C plant.

Standard library only. The shipped plant FMU is the C one (``motorchain_c/``); its
interface, the modelDescription.xml and the C header, is generated from this package's
FMU class (:mod:`arcosim.build.cplant`). Modules, in the order data flows:

* :mod:`~arcosim.plant.motorchain.physics` — the equations of motion, integrated exactly
  over each step, Coulomb friction's events included.
* :mod:`~arcosim.plant.motorchain.fmu` — ``MotorChainPlant``: the sensors (encoder,
  current noise) and the FMU's variables.
"""
