"""``ExcitationSource``: the scenarios' current commands as an FMI 2.0 co-simulation FMU.

Feeds the plant's ``i_ref`` in any FMI host (an SSP system, ecos, Simulink) with the
same signals that ``arcosim.experiments.current_commands`` gives offline (both evaluate
:mod:`arcosim.fmu.flexchain.waveforms`). After ``doStep(t, h)`` the
output is the command for the step that starts at ``t + h``.
"""

from __future__ import annotations

from typing import ClassVar

from ..flexchain import defaults, waveforms
from ..flexchain.codes import SIGNAL_NAMES, Signal, choice_problem
from ..fmukit import FmuSlave, Variable, out, par, range_problems


class ExcitationSource(FmuSlave):
    """A current command: rigid maneuver, multi-sine, chirp or filtered random."""

    model_text: ClassVar[str] = (
        "Current command for the motor-chain plant: the drift-free rigid maneuver of "
        "chain identification (mode 1), a multi-sine, a chirp or filtered random noise. "
        "After doStep(t, h) the output is the command for the step starting at t + h."
    )

    @classmethod
    def declare(cls) -> list[Variable]:
        return [
            par(
                "signal",
                int(Signal.RIGID),
                "",
                ", ".join(f"{int(code)} = {name}" for code, name in SIGNAL_NAMES.items()),
            ),
            par(
                "amplitude",
                defaults.RIGID_AMPLITUDE,
                "A",
                "Peak current (rms for filtered random); the rigid maneuver's needs to be "
                "well above f_c / k_t",
            ),
            par(
                "frequency",
                defaults.RIGID_FREQUENCY,
                "rad/s",
                "Rigid maneuver frequency; lowest multi-sine line; chirp start",
            ),
            par(
                "frequency_end",
                120.0,
                "rad/s",
                "Highest multi-sine line; chirp end; filtered random cut-off",
            ),
            par(
                "periods",
                defaults.RIGID_PERIODS,
                "",
                "Rigid maneuver length in periods, ramps included",
            ),
            par(
                "ramp_periods",
                defaults.RIGID_RAMP_PERIODS,
                "",
                "Rigid maneuver raised-cosine ramp length in periods",
            ),
            par("lines", 10, "", "Number of multi-sine lines (log-spaced)"),
            par("duration", 10.0, "s", "Chirp length; 0 after it"),
            par("offset", 0.0, "A", "Constant added to the signal"),
            par("seed", 1, "", "Seed of the multi-sine phases and of the random signal"),
            out("i_ref", "A", "Current command for the step that starts at the current time"),
        ]

    def check_parameters(self) -> list[str]:
        v = self.value
        problems = range_problems(
            v,
            positive=["frequency", "frequency_end", "duration"],
            finite=["amplitude", "offset"],
        )
        problem = choice_problem("signal", v("signal"), SIGNAL_NAMES)
        if problem:
            problems.append(problem)
        for name, least in (("periods", 1), ("ramp_periods", 1), ("lines", 1)):
            if v(name) < least:
                problems.append(f"parameter {name} = {v(name)} must be >= {least}")
        if 2 * v("ramp_periods") > v("periods"):
            problems.append(
                f"parameters ramp_periods = {v('ramp_periods')} and periods = {v('periods')}: "
                "two ramps must fit in the maneuver (2 ramp_periods <= periods)"
            )
        return problems

    def initialize(self) -> None:
        v = self.value
        self.signal = v("signal")
        self.amplitude, self.offset = v("amplitude"), v("offset")
        self.frequency, self.frequency_end = v("frequency"), v("frequency_end")
        self.periods, self.ramp_periods = v("periods"), v("ramp_periods")
        self.duration = v("duration")
        self.lines = waveforms.log_spaced(self.frequency, self.frequency_end, v("lines"))
        self.phases = waveforms.multisine_phases(v("lines"), v("seed"))
        self.noise = waveforms.FilteredNoise(self.amplitude, self.frequency_end, v("seed"))
        self.out_vr = self.vr["i_ref"]
        t0 = self.time or 0.0
        self.v[self.out_vr] = 0.0 if self.signal == Signal.RANDOM else self.command(t0, 0.0)

    def step(self, t: float, h: float) -> None:
        self.v[self.out_vr] = self.command(t + h, h)

    def command(self, t: float, h: float) -> float:
        """The command at time ``t`` (s); ``h`` is the step just taken (random signal)."""
        if self.signal == Signal.RIGID:
            x = waveforms.rigid_maneuver(
                t, self.amplitude, self.frequency, self.periods, self.ramp_periods
            )
        elif self.signal == Signal.MULTISINE:
            x = waveforms.multisine(t, self.amplitude, self.lines, self.phases)
        elif self.signal == Signal.CHIRP:
            x = waveforms.chirp(
                t, self.amplitude, self.frequency, self.frequency_end, self.duration
            )
        else:
            x = self.noise.next(h)
        return self.offset + x
