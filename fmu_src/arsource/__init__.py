"""``fmu_src/arsource/`` installed as ``arcosim.fmu.arsource``: the excitation source FMU
class.

* :mod:`~arcosim.fmu.arsource.fmu` — ``ExcitationSource``, a thin FMI wrapper around
  :mod:`arcosim.fmu.flexchain.waveforms`: the current command the plant's ``i_ref`` reads.
"""
