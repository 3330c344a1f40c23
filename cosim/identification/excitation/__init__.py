"""``cosim/identification/excitation/`` installed as ``arcosim.identification.excitation``:
what the excitation is, the band it shows modes in, and the one to play.

Modules:

spectrum        -- what the excitation is: lines (leakage-aware), harmonics of one period,
                   or broadband with its band (excitation_spectrum); the lines played
periodic        -- a record of whole periods: the period, its harmonics over the noise
                   (the χ² detection threshold, the local noise level)
harmonics       -- lines that are harmonics of one fundamental (a periodic reference)
merged_lines    -- lines the window merged, told apart again by a least-squares
                   search where the record can (resolve_merged_lines)
periodogram     -- the Hann periodogram, its noise level, the bins that stand over it
line_prominence -- which found lines are lines: the prominence again on their fitted
                   amplitudes, over the noise and the detrend's remnant
band            -- the band a log shows modes in: min(3·g_dist, 0.3/h) (search_band);
                   the modes the current drives (driven_modes)
design          -- the multi-sine to play on a drive (design_excitation, LINE_T)
"""
