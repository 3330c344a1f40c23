"""The motor–spring–mass chain plant: physics, sensors and its FMU class.

Standard library only (bundled into ``MotorChainPlant.fmu``).
"""
