"""The hold's dither: a square current at rest that lets the encoder see inside a count.

At rest an incremental encoder reads the same count wherever the motor sits inside it,
and a motor held from that reading hunts over two to four counts (docs/design/hold-dither.md:
with the true motor angle and velocity the same loop holds one count or none). A square
current ``±A`` over ``P`` control steps (``defaults.HOLD_DITHER_PERIOD``, 8 ms) moves the
motor, free at that frequency (far above its first spring's mode), along a known
periodic path of peak-to-peak ``A k_t (P h)² / (16 J_m)``; the amplitude is chosen for
``defaults.HOLD_DITHER`` counts. The reading less that path has a quantization error
that changes from sample to sample (subtractive dither), and an observer of the motor
alone (:class:`~arcosim.fmu.flexchain.control.motor_observer.MotorObserver`)
averages it into the motor's angle and velocity below a count, for the state feedback
(both) and the estimator's input (the angle). The velocity carries the dither's periodic
error (about 0.7 rad/s rms at 125 Hz with the observer's poles at 300 rad/s); fed back with
the estimator on the identified chain alone, it made the five-mass chain diverge with its
model's J 10 % high and k 10 % low. With the estimator's chain refitted from the move
(:mod:`~arcosim.fmu.flexchain.control.refined_estimator`), which takes the model near the
truth, that chain holds one count there (docs/design/hold-dither.md).

Friction is cancelled along the dither's velocity, which the motor follows; what the
slow motion meets then is a viscous friction of about ``2 f_c / v_peak`` per rad/s, the
dither's linearization of Coulomb friction, and it damps the motor at rest (cancelling it
too, along the slow velocity as well, held the motor over two counts on every chain).
"""

from __future__ import annotations

import math

from .. import defaults
from ..dob import mean_sign, sign
from .design import ControllerDesign
from .motor_observer import MotorObserver


class HoldDither:
    """The dither's current, its path and the motor's angle below a count.

    Parameters
    ----------
    design : ControllerDesign
        The motor's terms, the encoder and ``hold_dither`` (its step h is the dither's).

    Attributes
    ----------
    amplitude : float
        A (A), ``design.dither_current``.
    observer : MotorObserver
        The motor alone, on the de-dithered reading and the current less the dither's:
        its ``s[2]``, ``s[1]`` are the motor's angle (rad, relative to the controller's
        start) and velocity (rad/s).

    Examples
    --------
    >>> chain = {"J_mo": 2.09e-5, "k_to": 0.0406, "D_m": 2e-5, "f_c": 2e-3,
    ...          "J[1]": 5e-4, "k[1]": 0.16, "B[1]": 1e-5}
    >>> dither = HoldDither(arcosim.design_controller(chain, h=1e-3))
    >>> dither.start(0.0, 0.0)
    >>> [round(dither.command(1e-3)[0], 3) for _ in range(8)]  # A, one period
    [0.283, 0.283, -0.283, -0.283, -0.283, -0.283, 0.283, 0.283]
    """

    def __init__(self, design: ControllerDesign) -> None:
        self.design = design
        h = design.h
        self.period = design.dither_steps
        self.amplitude = design.dither_current
        self.observer = MotorObserver(design, defaults.HOLD_OBSERVER_BANDWIDTH)
        # the path's mean over a period, so that the path is taken about the motor's angle
        self.start(0.0, 0.0)
        samples = []
        for _ in range(self.period):
            self.command(h)
            samples.append(self.path)
        self.mean = math.fsum(samples) / self.period
        self.start(0.0, 0.0)

    def start(self, theta: float, omega: float) -> None:
        """Start the dither with the motor at ``theta`` (rad, relative) and ``omega`` (rad/s)."""
        self.k = 0
        self.path = 0.0  # the dither's motion at the next sample (rad)
        self.velocity = self.before = 0.0  # … its velocity there and at the last (rad/s)
        self.current = self.friction = 0.0  # what acts over the step to the next sample
        self.observer.s = [0.0, omega, theta]

    def measure(self, h: float, i_a: float, theta: float) -> float:
        """The motor's angle at this sample (rad, relative).

        Parameters
        ----------
        h : float
            Time since the previous sample (s), > 0.
        i_a : float
            Current that acted over the step ending here (A), the dither's included.
        theta : float
            The encoder's reading, relative to the controller's start (rad).

        Returns
        -------
        float
            The observer's angle, the dither's path taken out (its velocity, which the
            controller feeds back too, is ``observer.s[1]``). Also kept: ``reading`` (rad), the
            reading less the path, and ``steady`` (A), the current less the dither's and
            less the Coulomb friction that acted (f_c times the mean sign of the dither's
            velocity plus the observer's slow one).
        """
        d = self.design
        # the friction that acted: along the dither's velocity plus the slow motion's
        slow = self.observer.s[1]
        friction = d.f_c * mean_sign(self.before + slow, self.velocity + slow)
        self.steady = i_a - self.current - friction / d.k_t
        self.reading = theta - (self.path - self.mean)
        self.observer.step(h, self.steady, self.reading)
        return self.observer.s[2]

    def command(self, h: float) -> tuple[float, float]:
        """The dither's current over the next step (A) and the friction to cancel (N·m).

        The square starts a quarter period in, so that the motor's path is centred on
        where it was; the friction is f_c times the sign of the dither's mean velocity
        over the step.
        """
        d = self.design
        phase = (self.k + self.period // 4) % self.period
        current = self.amplitude if phase < self.period // 2 else -self.amplitude
        accel = d.k_t * current / d.J_m
        velocity = self.velocity + accel * h
        self.friction = d.f_c * sign(self.velocity + velocity)
        self.path += (self.velocity + 0.5 * accel * h) * h
        self.before, self.velocity = self.velocity, velocity
        self.current = current
        self.k += 1
        return current, self.friction
